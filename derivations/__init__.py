"""Symbolic derivations (sympy) for zerocal_sym.

Nothing in the runtime package imports this package: the derivations write
committed CasADi builders into ``zerocal_sym/generated/`` and ``zerocal regen``
re-runs them.  One module per mechanism; :mod:`derivations.mechanism` holds the
mechanism-independent parts (implicit differentiation, the measuring-mechanism
model) and :mod:`derivations.codegen` turns sympy expressions into Python.
"""
