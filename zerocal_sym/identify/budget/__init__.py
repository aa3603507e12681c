"""The budget stage: what each answer can be trusted to.

The bias the robot-file entries held fixed can put on the offsets (:mod:`~.bias`; per estimator, its worst
corner on the exact model: :mod:`~.bias_exact`), the error budget of an answer against its noise
(:mod:`~.error_budget`), the choice of the parameter set of least expected error (:mod:`~.choose`) and the
likelihood-ratio test of each group of robot-file entries (:mod:`~.freeing`).  Imports the stages before it.
"""
