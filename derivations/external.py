"""A mechanism derived outside the package: a derivation file anywhere, its generated module beside it.

``zerocal regen --derivation my_dir/my_mech.py`` imports the file, calls its
``build() -> SymbolicMechanism`` (written with :mod:`derivations.mechanism`),
renders the result with :func:`derivations.codegen.render` and writes
``my_dir/my_mech_generated.py`` (:func:`default_out`; ``--out`` to choose).
A robot file beside it names it (``mechanism = "<its name>"``,
``mechanism_module = "my_mech_generated.py"``).

The generated module's inputs hash covers the derivation file and the
installed ``derivations/mechanism.py`` and ``derivations/codegen.py``
(:func:`sources_of`): ``--check`` calls it stale when any of them changed.
Helper modules the derivation imports from its own directory (it is on
``sys.path`` while it is imported and built) are not covered.  Its
``DERIVATION`` line is the derivation's path relative to the generated module,
so that the contract suite finds it (:func:`derivation_of`) and the directory
may move.

Every failure is a :class:`DerivationError` naming the file (and the line in it,
where there is one): no such file, not Python, no ``build()``, a ``build()``
that raises, a name that is a built-in mechanism's.
"""
from __future__ import annotations

import hashlib
import importlib
import importlib.util
import os
import sys
import traceback
from functools import lru_cache
from pathlib import Path

from derivations import codegen
from derivations.mechanism import SymbolicMechanism, derive
from zerocal_sym.errors import ZerocalError

#: the generated module's default name: ``<derivation stem><GENERATED_SUFFIX>.py`` beside the derivation
GENERATED_SUFFIX = "_generated"
#: the longest message of a user's exception quoted in an error (the rest is cut)
MAX_MESSAGE = 300


class DerivationError(ZerocalError):
    """A derivation file that cannot be derived (missing, not Python, no ``build()``, raising, a built-in name)."""


def default_out(derivation) -> Path:
    """Where ``zerocal regen --derivation`` writes by default: ``<stem>_generated.py`` beside the derivation."""
    derivation = Path(derivation)
    return derivation.with_name(derivation.stem + GENERATED_SUFFIX + ".py")


def sources_of(derivation) -> list:
    """The files the inputs hash of a derivation's generated module covers."""
    return [codegen.HERE / "mechanism.py", codegen.HERE / "codegen.py", codegen.HERE / "geometry.py",
            Path(derivation).resolve()]


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or "(no message)"
    return text if len(text) <= MAX_MESSAGE else text[:MAX_MESSAGE - 3] + "..."


def _where(path: Path, exc: BaseException) -> str:
    """``path:line`` of the deepest frame of ``exc``'s traceback in the file ``path`` (``path`` if none)."""
    target = path.resolve()
    line = None
    for frame in traceback.extract_tb(exc.__traceback__):
        try:
            if Path(frame.filename).resolve() == target:
                line = frame.lineno
        except (OSError, ValueError):
            continue
    if isinstance(exc, SyntaxError) and exc.lineno and Path(exc.filename or "").resolve() == target:
        line = exc.lineno
    return f"{path}:{line}" if line else str(path)


class _on_path:
    """The derivation's directory first on ``sys.path`` while it is imported and built (its helper modules)."""

    def __init__(self, directory: Path):
        self.directory = str(directory)

    def __enter__(self):
        sys.path.insert(0, self.directory)

    def __exit__(self, *exc):
        try:
            sys.path.remove(self.directory)
        except ValueError:
            pass


def _module_key(path: Path) -> str:
    digest = hashlib.sha256(str(path.resolve()).encode()).hexdigest()[:12]
    return f"zerocal_derivation_{digest}"


def load_derivation(path):
    """Import the derivation file ``path`` (under a private module name); a DerivationError if it cannot be."""
    path = Path(path)
    if not path.exists():
        raise DerivationError("no such derivation file", where=str(path))
    if not path.is_file():
        raise DerivationError("the derivation is not a file", where=str(path))
    if path.suffix != ".py":
        raise DerivationError("a derivation is a Python file (.py) defining build() -> SymbolicMechanism",
                              where=str(path))
    key = _module_key(path)
    spec = importlib.util.spec_from_file_location(key, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[key] = mod
    try:
        with _on_path(path.resolve().parent):
            spec.loader.exec_module(mod)
    except SyntaxError as exc:
        sys.modules.pop(key, None)
        raise DerivationError(f"not valid Python: {exc.msg}", where=_where(path, exc)) from None
    except Exception as exc:  # noqa: BLE001 -- a user's file: whatever it raises is theirs, told in one line
        sys.modules.pop(key, None)
        raise DerivationError(f"importing it raised {type(exc).__name__}: {_one_line(exc)}",
                              where=_where(path, exc)) from None
    return mod


def _builtin_names() -> set:
    from zerocal_sym.model.mechanism import REGISTRY

    return set(REGISTRY) | set(codegen.MECHANISMS)


def derive_file(path, check_forms: bool = True):
    """Import the derivation ``path`` and build its mechanism: ``(module, SymbolicMechanism)``, derived.

    ``build()`` normally ends with ``return derive(mech)``; a mechanism returned underived is derived
    here.  With ``check_forms``, a ``check_paper_forms(mech)`` the module defines is run too.

    Raises
    ------
    DerivationError
        No such file, not Python, no ``build()``, ``build()`` (or the derivation, or the form check)
        raised, it did not return a SymbolicMechanism, its name is not an identifier or is a built-in
        mechanism's.
    """
    path = Path(path)
    mod = load_derivation(path)
    build = getattr(mod, "build", None)
    if not callable(build):
        raise DerivationError("no build() function: a derivation defines build() -> SymbolicMechanism "
                              "(from derivations.mechanism)", where=str(path))

    def call(what, fn, *args):
        try:
            with _on_path(path.resolve().parent):
                return fn(*args)
        except Exception as exc:  # noqa: BLE001 -- a user's derivation
            raise DerivationError(f"{what} raised {type(exc).__name__}: {_one_line(exc)}",
                                  where=_where(path, exc)) from None

    mech = call("build()", build)
    if not isinstance(mech, SymbolicMechanism):
        raise DerivationError(f"build() returned {type(mech).__name__}, not a derivations.mechanism."
                              "SymbolicMechanism", where=str(path))
    if not isinstance(mech.name, str) or not mech.name.isidentifier():
        raise DerivationError(f"mechanism name {mech.name!r}: a name is a Python identifier (letters, digits, _)",
                              where=str(path))
    if mech.name in _builtin_names():
        raise DerivationError(f"mechanism name {mech.name!r} is a built-in mechanism's: name yours otherwise "
                              f"(built in: {', '.join(sorted(_builtin_names()))})", where=str(path))
    if not mech.outputs:
        call("derive()", derive, mech)
    if check_forms and callable(getattr(mod, "check_paper_forms", None)):
        call("check_paper_forms()", mod.check_paper_forms, mech)
    return mod, mech


def generate_file(derivation, out=None, check_forms: bool = True):
    """Derive the file ``derivation``: ``(out path, generated source, SymbolicMechanism)`` (nothing written).

    ``out`` default :func:`default_out`.  The ``DERIVATION`` line is the derivation's path relative to
    ``out``'s directory.
    """
    derivation = Path(derivation)
    out = Path(out) if out is not None else default_out(derivation)
    if derivation.exists() and out.resolve() == derivation.resolve():
        raise DerivationError("the generated module would overwrite the derivation itself: choose another --out",
                              where=str(derivation))
    _, mech = derive_file(derivation, check_forms)
    rel = Path(os.path.relpath(derivation.resolve(), out.resolve().parent)).as_posix()
    return out, codegen.render(mech, sources_of(derivation), derivation=rel), mech


def regen_file(derivation, out=None, check: bool = False):
    """Write (or with ``check`` compare) the generated module of the derivation file.

    Returns
    -------
    (Path, bool, SymbolicMechanism)
        The generated module, whether it differed from a fresh derivation (and, without ``check``, was
        written), the mechanism.
    """
    out, text, mech = generate_file(derivation, out)
    old = out.read_text(encoding="utf-8") if out.is_file() else None
    changed = old != text
    if changed and not check:
        from zerocal_sym.io.files import atomic_write_text

        atomic_write_text(out, text)
    return out, changed, mech


@lru_cache(maxsize=None)
def _derived(where: str) -> SymbolicMechanism:
    if where.endswith(".py"):
        return derive_file(where)[1]
    return importlib.import_module(where).build()


def derivation_of(generated_module) -> SymbolicMechanism:
    """The derived :class:`SymbolicMechanism` a generated module was written from (its ``DERIVATION``).

    A module name is imported and built; a ``.py`` path is taken relative to the generated module's file.
    Derived once per process and path.

    Raises
    ------
    DerivationError
        The module names no derivation (generated before ``DERIVATION`` was written), or it cannot be derived.
    """
    where = getattr(generated_module, "DERIVATION", None)
    if not where:
        raise DerivationError(f"the generated module {generated_module.__name__} names no DERIVATION: regenerate "
                              "it (zerocal regen --derivation)", where=getattr(generated_module, "__file__", None))
    if where.endswith(".py"):
        where = str((Path(generated_module.__file__).resolve().parent / where).resolve())
    return _derived(where)
