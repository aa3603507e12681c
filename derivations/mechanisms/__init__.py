"""One derivation module per mechanism (each defines ``build() -> SymbolicMechanism``)."""
