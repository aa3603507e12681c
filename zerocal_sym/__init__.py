"""zerocal_sym: zero-offset calibration of parallel robots.

Layers (imports go one way): ``derivations/`` (sympy, not imported at run
time) -> :mod:`zerocal_sym.generated` (committed CasADi builders) ->
:mod:`~zerocal_sym.model.mechanism`, :mod:`~zerocal_sym.model.robot`,
:mod:`~zerocal_sym.model.kinematics`, :mod:`~zerocal_sym.model.noise`,
:mod:`~zerocal_sym.identify.fisher` (models) -> identification and design -> CLI and
notebooks.

Units: mm and radians inside; degrees at the user-facing edges.
"""
__version__ = "0.1.0"
