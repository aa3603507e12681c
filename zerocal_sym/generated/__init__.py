"""Generated CasADi builders, one module per mechanism (``zerocal regen``)."""
