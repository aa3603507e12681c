"""Regenerate the CasADi builders from the sympy derivations.

Needs the ``derive`` extra (sympy); this is the only command that imports it.
``--check`` writes nothing and exits 1 when the generated code differs from a
fresh derivation.

Without ``--derivation``: every built-in mechanism, ``derivations/`` into
``zerocal_sym/generated/`` (``--out-dir`` for another directory).

With ``--derivation FILE.py``: a mechanism of your own, anywhere.  The file
defines ``build() -> SymbolicMechanism`` (``derivations.mechanism``); its
generated module is written beside it as ``<stem>_generated.py`` (``--out``
to choose), and a robot file names it with ``mechanism_module``
(docs/new-mechanism.md).  Its inputs hash covers the file and the installed
``derivations/mechanism.py`` and ``derivations/codegen.py``.
"""
import argparse

NAME = "regen"
HELP = "regenerate the generated code from the sympy derivations (needs sympy)"
#: regen reads no robot file: --robot is not offered (given, it is the one-line error of cli/_checks.py)
ROBOT_HELP = argparse.SUPPRESS


def add_arguments(p):
    from zerocal_sym.cli._paths import InputFile, OutputDir, OutputFile

    p.add_argument("--check", action="store_true", help="compare only; exit 1 if stale")
    p.add_argument("--out-dir", default=None, metavar="DIR", type=OutputDir(("*.py",)),
                   help="the built-in mechanisms: write into this directory instead of zerocal_sym/generated/")
    p.add_argument("--derivation", default=None, metavar="FILE.py", type=InputFile("the derivation"),
                   help="a mechanism of your own: derive this file (build() -> SymbolicMechanism) and write its "
                        "generated module, by default beside it as <stem>_generated.py")
    p.add_argument("--out", default=None, metavar="FILE.py", type=OutputFile(),
                   help="with --derivation: the generated module (default: <stem>_generated.py beside the "
                        "derivation)")


def _needs_sympy():
    from zerocal_sym.errors import ZerocalError

    try:
        import derivations.codegen  # noqa: F401
    except ImportError as exc:
        raise ZerocalError(f"regen needs the derivations and sympy (pip install -e '.[derive]'): {exc}") from None


def _run_derivation(args):
    import sys

    from derivations.external import regen_file

    out, changed, mech = regen_file(args.derivation, args.out, check=args.check)
    if args.check:
        if changed:
            print(f"stale: {out}", file=sys.stderr)
            print(f"generated code of mechanism {mech.name} is stale: run `zerocal regen --derivation "
                  f"{args.derivation}`", file=sys.stderr)
            return 1
        print(f"generated code of mechanism {mech.name} in {out} is up to date")
        return 0
    print(f"wrote {out} (mechanism {mech.name})" if changed else
          f"generated code of mechanism {mech.name} in {out} is up to date")
    return 0


def run(args):
    import sys

    _needs_sympy()
    if args.derivation is not None:
        return _run_derivation(args)
    from derivations.codegen import GENERATED_DIR, regen

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
