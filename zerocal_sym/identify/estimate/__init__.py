"""The estimate stage: the estimators and the exact model they fit.

TSVD (:mod:`~.tsvd_round`, :mod:`~.tsvd_many`, :mod:`~.truncated_svd`, its std per parameter
:mod:`~.tsvd_uncertainty`); Gauss-Newton and Ipopt on the exact model (:mod:`~.nlls_inputs`,
:mod:`~.nlls_problem`, :mod:`~.nlls_banded`, :mod:`~.nlls_solve`); the robust loss's iteration
(:mod:`~.robust`); the fit with the revisits' shared error (:mod:`~.nlls_shared`, its REML estimate
:mod:`~.revisits`); the exact whitened model of a problem (:mod:`~.exact_model`).  Imports the shared
basics only.
"""
