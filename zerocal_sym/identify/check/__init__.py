"""The check stage: does the fit agree with the noise model, and is the answer a robot's?

The chi² test and the per-reading statistics (:mod:`~.statistics`), the plausibility limits
(:mod:`~.plausibility`), what is left of a robust fit once its outliers are left out (:mod:`~.robust_fit`).
Imports the shared basics only.
"""
