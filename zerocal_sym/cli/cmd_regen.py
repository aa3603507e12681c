"""Regenerate the CasADi builders from the sympy derivations.

Needs the ``derive`` extra (sympy); this is the only command that imports it.
``--check`` writes nothing and exits 1 when the committed generated code
differs from a fresh derivation.
"""
NAME = "regen"
HELP = "regenerate zerocal_sym/generated/ from derivations/ (needs sympy)"


def add_arguments(p):
    p.add_argument("--check", action="store_true", help="compare only; exit 1 if stale")
    from zerocal_sym.cli._paths import OutputDir

    p.add_argument("--out-dir", default=None, metavar="DIR", type=OutputDir(("*.py",)),
                   help="write into this directory instead")


def run(args):
    import sys

    try:
        from derivations.codegen import GENERATED_DIR, regen
    except ImportError as exc:
        from zerocal_sym.errors import ZerocalError

        raise ZerocalError(f"regen needs the derivations and sympy (pip install -e '.[derive]'): {exc}") from None
    changed = regen(out_dir=args.out_dir, check=args.check)
    from zerocal_sym.cli._interrupt import outputs_written

    outputs_written()  # from here on it only reports: a Ctrl-C or SIGTERM does not change its status
    target = args.out_dir or GENERATED_DIR
    if args.check:
        if changed:
            for p in changed:
                print(f"stale: {p}", file=sys.stderr)
            print("generated code is stale: run `zerocal regen`", file=sys.stderr)
            return 1
        print(f"generated code in {target} is up to date")
        return 0
    for p in changed:
        print(f"wrote {p}")
    if not changed:
        print(f"generated code in {target} is up to date")
    return 0
