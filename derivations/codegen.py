"""Turn a :class:`~derivations.mechanism.SymbolicMechanism` into Python source
that builds CasADi ``Function`` objects.

The generated module is readable (common subexpressions as named locals), has
no sympy dependency, and starts with a header naming its source, the sympy
version and a hash of its inputs (the derivation sources).  ``zerocal regen``
rewrites it; ``zerocal regen --check`` compares a fresh derivation with the
committed file.
"""
from __future__ import annotations

import hashlib
from pathlib import Path

import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

_CA_FUNCS = ["sin", "cos", "tan", "asin", "acos", "atan", "atan2", "exp", "log", "sign", "fabs"]


class CasadiPrinter(PythonCodePrinter):
    """Print sympy expressions as CasADi-compatible Python (``ca.<fn>``)."""

    _kf = {**{k: "ca." + k for k in _CA_FUNCS}, "Abs": "ca.fabs"}

    def _print_Pow(self, expr, rational=False):
        return self._hprint_Pow(expr, rational=rational, sqrt="ca.sqrt")

    def _print_known_func(self, expr):
        known = self.known_functions[expr.__class__.__name__]
        return "{}({})".format(known, ", ".join(self._print(a) for a in expr.args))

    def _print_Float(self, expr):
        return repr(float(expr))


for _k in CasadiPrinter._kf:
    setattr(CasadiPrinter, "_print_" + _k, CasadiPrinter._print_known_func)


HERE = Path(__file__).resolve().parent
GENERATED_DIR = HERE.parent / "zerocal_sym" / "generated"


def _relative(path) -> str:
    """How the header and the hash name a derivation source: ``derivations/...`` for the package's own files,
    the file name for one outside the package (a user's derivation: its directory may move)."""
    path = Path(path).resolve()
    try:
        return path.relative_to(HERE.parent).as_posix()
    except ValueError:
        return path.name


def input_hash(sources) -> str:
    """SHA-256 (first 16 hex digits) over the derivation sources (their names, :func:`_relative`, and bytes)."""
    h = hashlib.sha256()
    for path in sorted(sources, key=_relative):
        h.update(_relative(path).encode())
        h.update(Path(path).read_bytes())
    return h.hexdigest()[:16]


def _matrix_code(name: str, mat: sp.Matrix, printer) -> str:
    if mat.cols == 1:
        body = "ca.vertcat(" + ", ".join(printer.doprint(mat[i, 0]) for i in range(mat.rows)) + ")"
    else:
        rows = ["ca.horzcat(" + ", ".join(printer.doprint(mat[i, j]) for j in range(mat.cols)) + ")"
                for i in range(mat.rows)]
        body = "ca.vertcat(\n        " + ",\n        ".join(rows) + ",\n    )"
    return f"    {name} = {body}"


def _free_symbols(exprs) -> set:
    """The union of the ``free_symbols`` of ``exprs``, each distinct subexpression visited once.

    (``Basic.free_symbols`` is the union over the arguments, recomputed at every occurrence of a shared
    subexpression: most of a second on the Delta's trees.)  A class with its own ``free_symbols`` (an atom,
    or one with bound variables) answers for itself, so the set is the same.
    """
    memo = {}

    def fs(e):
        r = memo.get(e)
        if r is None:
            if type(e).free_symbols is sp.Basic.free_symbols:
                r = set().union(*(fs(a) for a in e.args))
            else:
                r = e.free_symbols
            memo[e] = r
        return r

    return set().union(*(fs(e) for e in exprs))


def _emit_exprs(lines, exprs, printer, prefix):
    """CSE ``exprs`` into ``lines`` (locals ``<prefix>0, ...``); the reduced expressions."""
    repl, reduced = sp.cse(exprs, symbols=sp.numbered_symbols(prefix))
    for sym, expr in repl:
        lines.append(f"    {printer.doprint(sym)} = {printer.doprint(expr)}")
    return reduced


def _emit_solve(lines, k, solve, printer):
    """``X = ca.solve(A, B)`` of a :class:`~derivations.mechanism.LinearSolve` (``X = ca.det(A)`` of a
    :class:`~derivations.mechanism.Determinant`), its entries unpacked."""
    A, B, X = solve.A, solve.B, solve.X
    if not B.rows:
        red = _emit_exprs(lines, list(A), printer, f"a{k}_")
        lines.append(_matrix_code(f"A{k}", sp.Matrix(A.rows, A.cols, red), printer))
        lines.append(f"    {printer.doprint(X[0, 0])} = ca.det(A{k})")
        return
    red = _emit_exprs(lines, list(A) + list(B), printer, f"a{k}_")
    lines.append(_matrix_code(f"A{k}", sp.Matrix(A.rows, A.cols, red[:A.rows * A.cols]), printer))
    lines.append(_matrix_code(f"B{k}", sp.Matrix(B.rows, B.cols, red[A.rows * A.cols:]), printer))
    lines.append(f"    X{k} = ca.solve(A{k}, B{k})")
    for i in range(X.rows):
        for j in range(X.cols):
            lines.append(f"    {printer.doprint(X[i, j])} = X{k}[{i}, {j}]")


def _emit_newton(lines, newton):
    """The body of a forward kinematics solved by Newton steps (``fk(theta, g)``)."""
    lines += [
        "    P = _fk_start(g)[0]",
        f"    for _ in range({int(newton.iterations)}):",
        "        f, f_P = _fk_residual(P, theta, g)",
        "        P = P - ca.solve(f_P, f)",
        "    f = _fk_residual(P, theta, g)[0]",
        f"    ok = ca.mmax(ca.fabs(f)) <= {float(newton.tol)!r}",
        "    P = ca.if_else(ok, P, ca.DM.nan(P.numel(), 1))",
        "    return (P,)",
    ]


def _emit_compose(lines, compose, m):
    """The exact distance composed of ``fk`` and ``measuring`` at the actual joints and geometry."""
    th = [f"theta_cmd[{k}]" for k in range(m)]
    lines.append("    g_act = [g[k] for k in range(g.numel())]")
    for q, (offset, idx) in enumerate(compose):
        if offset:
            th[idx] = f"{th[idx]} + err[{q}]"
        else:
            lines.append(f"    g_act[{idx - m}] = g_act[{idx - m}] + err[{q}]")
    lines += [
        "    g_act = ca.vertcat(*g_act)",
        f"    theta = ca.vertcat({', '.join(th)})",
        "    P = _fk(theta, g_act)[0]",
        "    return (_measuring(P, g_act)[0],)",
    ]


def emit_function(fname: str, spec: dict, printer) -> str:
    """Python source of ``_<fname>(inputs...)`` returning CasADi expressions."""
    args = [n for n, _ in spec["inputs"]]
    lines = [f"def _{fname}({', '.join(args)}):", f'    """{spec["doc"]}"""']
    if "newton" in spec:
        _emit_newton(lines, spec["newton"])
        return "\n".join(lines)
    if "compose" in spec:
        _emit_compose(lines, spec["compose"], len(spec["inputs"][0][1]))
        return "\n".join(lines)
    names = [n for n, _ in spec["outputs"]]
    mats = [m for _, m in spec["outputs"]]
    flat = [e for m in mats for e in m]
    solves = spec.get("solves", [])
    used = _free_symbols(flat + [e for sv in solves for e in list(sv.A) + list(sv.B)])
    for argname, syms in spec["inputs"]:
        for k, s in enumerate(syms):
            if s in used:
                lines.append(f"    {printer.doprint(s)} = {argname}[{k}]")
    for k, solve in enumerate(solves):
        _emit_solve(lines, k, solve, printer)
    reduced = _emit_exprs(lines, flat, printer, "t")
    pos = 0
    for name, m in zip(names, mats):
        n = m.rows * m.cols
        lines.append(_matrix_code(name, sp.Matrix(m.rows, m.cols, reduced[pos:pos + n]), printer))
        pos += n
    lines.append(f"    return ({', '.join(names)},)")
    return "\n".join(lines)


def render(mech, sources, derivation: str | None = None) -> str:
    """The full generated module for ``mech`` as a string.

    Parameters
    ----------
    mech : SymbolicMechanism
        Derived (:func:`derivations.mechanism.derive`).
    sources : list of Path
        The files the inputs hash covers (the derivation, ``mechanism.py``, ``codegen.py``).
    derivation : str, optional
        Where the derivation is, written as ``DERIVATION`` for the tests that compare the generated code
        with sympy: a module name (``derivations.mechanisms.planar_2dof``), or a ``.py`` path relative to
        the generated module (a derivation outside the package, :mod:`derivations.external`).
    """
    printer = CasadiPrinter({"fully_qualified_modules": True, "inline": True})
    src_names = ", ".join(_relative(p) for p in sorted(sources, key=_relative))
    geo_units = {str(s): mech.geometry_units.get(str(s), "mm") for s in mech.geometry}
    pose_units = {str(s): mech.pose_units.get(str(s), "mm") for s in mech.pose}
    home_pose = mech.home_pose if isinstance(mech.home_pose, (str, type(None))) else "home_pose"
    source_errors = [(e.name, e.role, e.unit, str(e.target), None if e.lever is None else str(e.lever))
                     for e in mech.source_errors]
    out = [
        f'"""Generated CasADi builders for the mechanism ``{mech.name}``.',
        "",
        "GENERATED -- DO NOT EDIT.  Regenerate with "
        + (f"``zerocal regen --derivation {derivation}`` (in this directory)." if str(derivation).endswith(".py")
           else "``zerocal regen``."),
        f"source: {src_names}",
        f"inputs hash: {input_hash(sources)}",
        f"sympy: {sp.__version__}",
        '"""',
        "import casadi as ca",
        "",
        f"NAME = {mech.name!r}",
        "#: where this module was derived from: a module name, or a .py file relative to this module",
        f"DERIVATION = {derivation!r}",
        f"DESCRIPTION = {mech.description!r}",
        f"POSE_NAMES = {[str(s) for s in mech.pose]!r}",
        f"JOINT_NAMES = {[str(s) for s in mech.joints]!r}",
        f"GEOMETRY_NAMES = {[str(s) for s in mech.geometry]!r}",
        f"GEOMETRY_UNITS = {geo_units!r}",
        f"JOINT_KINDS = {list(mech.joint_kinds)!r}",
        f"POSE_UNITS = {pose_units!r}",
        "#: (name, role, unit, target, lever arm) of each source error, in vector order",
        "SOURCE_ERRORS = [",
        *[f"    {row!r}," for row in source_errors],
        "]",
        f"SOURCE_ERROR_NAMES = {[e.name for e in mech.source_errors]!r}",
        f"HOME_JOINTS = {None if mech.home_joints is None else [float(v) for v in mech.home_joints]!r}",
        "#: None (HOME_JOINTS), 'workspace centre' or the name of the function giving the home pose",
        f"HOME_POSE = {home_pose!r}",
        f"MEASURING_BASE = {[str(s) for s in mech.base_point]!r}",
        f"MEASURING_OFFSET = {[str(s) for s in mech.platform_offset]!r}",
        f"GAUGE_NAMES = {list(mech.gauge)!r}",
        f"GAUGE_FIX = {list(mech.gauge_fix)!r}",
        f"WORKSPACE = {mech.workspace!r}",
        f"WORKSPACE_DEFAULTS = {mech.workspace_defaults!r}",
        f"ALIASES = {mech.aliases!r}",
        f"LIST_ALIASES = {mech.list_aliases!r}",
        f"DEFAULTS = {mech.defaults!r}",
        f"PARAM_SETS = {mech.param_sets!r}",
        f"DEFAULT_SET = {tuple(mech.default_set)!r}",
        f"NOISE = {mech.noise!r}",
        f"POSITIVE = {list(mech.positive)!r}",
        "FUNCTION_SIGNATURES = {",
    ]
    for fname, spec in mech.outputs.items():
        ins = [(n, len(s)) for n, s in spec["inputs"]]
        outs = [(n, tuple(m.shape)) for n, m in spec["outputs"]]
        out.append(f"    {fname!r}: ({ins!r}, {outs!r}),")
    out.append("}")
    for fname, spec in mech.outputs.items():
        out += ["", "", emit_function(fname, spec, printer)]
    out += [
        "",
        "",
        "def build_functions():",
        '    """Build every CasADi ``Function`` of this mechanism (SX graphs).',
        "",
        "    Returns",
        "    -------",
        "    dict of str -> casadi.Function",
        '    """',
        "    funcs = {}",
        "    for fname, (ins, outs) in FUNCTION_SIGNATURES.items():",
        "        syms = [ca.SX.sym(n, k) for n, k in ins]",
        "        res = globals()['_' + fname](*syms)",
        "        funcs[fname] = ca.Function(fname, syms, list(res), [n for n, _ in ins], [n for n, _ in outs])",
        "    return funcs",
        "",
    ]
    return "\n".join(out)


#: Every mechanism: generated module name -> its derivation module.
MECHANISMS = {
    "planar_2dof": "derivations.mechanisms.planar_2dof",
    "delta_rotary": "derivations.mechanisms.delta_rotary",
    "delta_linear": "derivations.mechanisms.delta_linear",
    "hexapod": "derivations.mechanisms.hexapod",
}


def derive_all(check_forms: bool = True) -> dict:
    """Derive every mechanism of :data:`MECHANISMS`: ``{name: SymbolicMechanism}``.

    Parameters
    ----------
    check_forms : bool
        Also assert the symbolic reduction to the paper's forms (where a
        derivation module has ``check_paper_forms``).
    """
    import importlib

    derived = {}
    for name, modname in MECHANISMS.items():
        mod = importlib.import_module(modname)
        mech = mod.build()
        if check_forms and hasattr(mod, "check_paper_forms"):
            mod.check_paper_forms(mech)
        derived[name] = mech
    return derived


def generate(out_dir: Path | None = None, check_forms: bool = True, derived: dict | None = None) -> dict:
    """Derive every mechanism and return ``{path: source}`` (nothing written).

    Parameters
    ----------
    out_dir : Path, optional
        Directory the files are meant for (default ``zerocal_sym/generated``).
    check_forms : bool
        Also assert the symbolic reduction to the paper's forms.
    derived : dict, optional
        The mechanisms as :func:`derive_all` returns them (derived already,
        e.g. once for several checks in one process); default: derived here.
    """
    import importlib

    out_dir = Path(out_dir) if out_dir else GENERATED_DIR
    if derived is None:
        derived = derive_all(check_forms)
    files = {}
    for name, modname in MECHANISMS.items():
        mod = importlib.import_module(modname)
        sources = [HERE / "mechanism.py", HERE / "codegen.py", HERE / "geometry.py", Path(mod.__file__)]
        files[out_dir / f"{name}.py"] = render(derived[name], sources, derivation=modname)
    return files


def regen(out_dir: Path | None = None, check: bool = False) -> list:
    """Write (or with ``check`` compare) the generated modules.

    Returns
    -------
    list of Path
        The files that differ from a fresh derivation (``check``) or that
        were written.
    """
    files = generate(out_dir)
    changed = []
    for path, text in files.items():
        old = path.read_text() if path.exists() else None
        if old != text:
            changed.append(path)
            if not check:
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_text(text)
    return changed


if __name__ == "__main__":  # pragma: no cover
    import sys

    changed = regen(check="--check" in sys.argv)
    for p in changed:
        print(p)
