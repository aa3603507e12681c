"""Identification as stages: estimate -> check -> diagnose -> budget -> result.

Each stage imports only the stages before it (``tests/test_layers.py``):

* the shared basics, here, import no stage: :mod:`~.banded`, :mod:`~.chi2`,
  :mod:`~.covariance`, :mod:`~.fisher`, :mod:`~.linear`, :mod:`~.identifiability`,
  :mod:`~.result` (the result record), :mod:`~.whitened` (the linearised, whitened problem);
* :mod:`~.estimate` -- the estimators: TSVD, Gauss-Newton / Ipopt, the robust loss, the fit with the
  revisits' shared error, the exact model;
* :mod:`~.check` -- is the fit what the noise model says: the chi² test, the per-reading statistics,
  plausibility, a robust fit's outliers;
* :mod:`~.diagnose` -- why not: the likely causes, the deletions, the refits without readings, the
  verdict in the result;
* :mod:`~.budget` -- what the answer can be trusted to: the bias the robot-file entries held fixed can put
  on it (per estimator, its exact worst corner), the error budget, the choice of the parameter set, the test
  of each group of entries;
* the drivers, here too, compose the stages into results: :mod:`~.nlls` (``identify_nlls``),
  :mod:`~.tsvd` (``identify_tsvd``), :mod:`~.fitcheck`, :mod:`~.nlls_robust`, :mod:`~.batch`,
  :mod:`~.nlls_rounds`, :mod:`~.loop`, :mod:`~.montecarlo`, :mod:`~.one_shot`, :mod:`~.scipy_reference`,
  :mod:`~.compare_report`, and the execution of studies: :mod:`~.parallel`, :mod:`~.dask_cluster`,
  :mod:`~.stats`, :mod:`~.progress`.
"""
