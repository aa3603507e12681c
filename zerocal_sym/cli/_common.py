"""What several commands share: pose schemes, true errors by name, the paper's Table 2 guard.

Nothing here knows a mechanism by name: sizes come from ``robot.m`` /
``robot.n``, names from the mechanism (joints, pose coordinates, source
errors), the pose scheme from the robot's workspace (``paper`` on a
rectangle, ``ring`` on a cylinder).  The paper's Table 2 is used only where
a command is the paper's (``--group``, ``reproduce``).
"""
from __future__ import annotations

import math

#: The scheme parameter n when ``--n`` is not given, by scheme: the paper's n = 3
#: (its eps rule's choice, Section 5); the ring scheme's n = 6 (``docs/delta.md``: n = 4
#: is the fewest that identify the Delta's 6 parameters, but cond(G) = 3186
#: there; 233 at n = 6); the corner scheme's n = 64 (every corner of the box).
#: A scheme not listed: the fewest that identify.
DEFAULT_N = {"paper": 3, "ring": 6, "corners": 64}


def scheme_names() -> tuple:
    """Every pose scheme a workspace shape has (``paper``, ``ring``)."""
    from zerocal_sym.model.workspace import SHAPES

    return tuple(dict.fromkeys(cls.scheme_name for cls in SHAPES.values()))


def n_params(robot) -> int:
    """p: the mechanism's identified set (the paper's: the zero offsets and the MAEMM, m + n)."""
    return len(robot.errors.resolve("default"))


def min_n(robot) -> int:
    """The smallest scheme parameter n whose K - 1 changes can identify the p parameters (K = 2n, or n corners)."""
    return robot.workspace.min_scheme_n(n_params(robot))


def default_n(robot) -> int:
    """Poses per boundary of the robot's scheme when ``--n`` is not given (:data:`DEFAULT_N`)."""
    return max(DEFAULT_N.get(robot.workspace.scheme_name, 0), min_n(robot))


def check_scheme(robot, scheme, option: str = "--scheme") -> str:
    """The scheme to use: ``scheme`` (None: the robot's own); one that does not fit the workspace is an error."""
    from zerocal_sym.errors import ZerocalError

    ws = robot.workspace
    if scheme is None:
        return ws.scheme_name
    if scheme != ws.scheme_name:
        raise ZerocalError(f"{option} {scheme} does not fit robot {robot.name!r}: its workspace is a {ws.kind} "
                           f"({ws.describe()} mm), whose scheme is {option} {ws.scheme_name}")
    return scheme


def scheme_poses(robot, scheme=None, n=None, identifiable: bool = True, option: str = "--scheme"):
    """The K poses of the robot's boundary scheme (the paper's on a rectangle, the ring on a cylinder: K = 2n;
    the corner scheme on a box: K = n).

    Parameters
    ----------
    scheme : str, optional
        Must be the robot's (default).
    n : int, optional
        Poses per boundary; default :func:`default_n`.
    identifiable : bool
        Refuse an n whose 2n - 1 changes are fewer than the p = m + n parameters.

    Returns
    -------
    (ndarray, shape (2n, n_pose), int n)
    """
    from zerocal_sym.errors import PoseError

    check_scheme(robot, scheme, option)
    n = default_n(robot) if n is None else int(n)
    p = n_params(robot)
    K = robot.workspace.scheme_size(n)
    if identifiable and K - 1 < p:
        raise PoseError(f"--n {n} gives K = {K} poses, {K - 1} measured changes: too few to identify the "
                        f"{p} parameters ({', '.join(robot.errors.resolve('default'))}); "
                        f"n >= {min_n(robot)} needed")
    return robot.workspace.boundary_scheme(n), n


def add_revisits_argument(p, what: str = "the measurement file") -> None:
    """``--allow-revisits`` (a command that reads measurement or pose files)."""
    p.add_argument("--allow-revisits", action="store_true",
                   help=f"accept a pose visited again after other poses in {what} (a design's replicates) "
                        "without its '# revisits: allowed' line; a pose repeated right after itself is refused "
                        "either way")


def revisits_meta(P) -> dict:
    """``{"revisits": "allowed"}`` when the poses ``P`` (K, n) revisit a pose, else ``{}``: what a file made
    of them says (a file zerocal writes with revisits says they are intended)."""
    from zerocal_sym.io.csvtext import REVISITS_ALLOWED, REVISITS_KEY
    from zerocal_sym.model.revisits import REVISIT_TOL, pose_groups

    lab = pose_groups(P, REVISIT_TOL)
    return {REVISITS_KEY: REVISITS_ALLOWED} if lab.size and lab.max() + 1 < lab.size else {}


def poses_arg(robot, spec, n, identifiable: bool = True, allow_revisits: bool = False):
    """Poses from ``--poses SCHEME|FILE`` (None: the robot's scheme) with ``--n``.

    Returns
    -------
    (ndarray, shape (K, n_pose), str description)
    """
    if spec is None or spec in scheme_names():
        P, n = scheme_poses(robot, spec, n, identifiable, option="--poses")
        return P, f"{robot.workspace.scheme_name} scheme, n = {n}"
    from zerocal_sym.io.poses import load_poses

    return load_poses(spec, robot, allow_revisits, measured=True), str(spec)


def check_round_poses(robot, P, theta_cmd, source: str, allow_revisits: bool = False, region=None) -> None:
    """Refuse a measurement round (``compensate --template``) that identify would refuse.

    The checks of ``zerocal identify`` on the poses themselves: enough poses
    for the p = m + n parameters (and the loader's minimum), every pose
    inside the workspace, reachable and away from singular configurations
    (the robot's singularity margin), no pose repeated right after itself
    (nor after other poses, unless ``allow_revisits``), the poses not on one
    line, and the paper's identification matrix G of full rank.  ``region``:
    the region a design's poses carry (:func:`zerocal_sym.io.poses.load_design_poses`),
    whose singularity margin replaces the workspace check.

    Raises
    ------
    PoseError
        Naming ``source`` (the pose file or the scheme) and the pose.
    """
    import numpy as np

    from zerocal_sym.errors import PoseError
    from zerocal_sym.identify.linear import identification_matrix
    from zerocal_sym.identify.estimate.tsvd_round import COLLINEAR_RTOL, RANK_RTOL
    from zerocal_sym.io.duplicates import first_duplicate
    from zerocal_sym.io.measurements import MIN_POSES
    from zerocal_sym.model import kinematics as kin

    K, p = len(P), n_params(robot)
    names = ", ".join(robot.errors.resolve("default"))
    need = max(MIN_POSES, p + 1)
    why = "identify would refuse this measurement round"
    if K < need:
        raise PoseError(f"{K} poses give {K - 1} measured changes: too few for the {p} parameters ({names}); a "
                        f"measurement round needs at least {need} poses ({why})", where=source)
    try:  # a design's own region (load_design_poses): its margin, not the workspace
        theta = (kin.check_poses(robot, P, in_workspace=True) if region is None
                 else kin.check_poses(robot, P, margin=region["region_singularity_margin"]))
    except PoseError as exc:
        raise PoseError(f"{exc.where}: {exc.message} ({why})" if exc.where else f"{exc.message} ({why})",
                        where=source) from None
    from zerocal_sym.model import units

    from zerocal_sym.io.measurement_checks import revisit_hint
    from zerocal_sym.model.revisits import consecutive_repeat

    for what, X, tol in ((f"commanded {units.joint_noun(robot)}", units.joints_to_user(robot, theta_cmd), 1e-9),
                         ("target", P, 1e-9)):
        k = consecutive_repeat(X, tol)
        if k is not None:
            raise PoseError(f"pose {k}: repeats the {what} of the pose before it, a zero change ({why})",
                            where=source)
        dup = None if allow_revisits else first_duplicate(X, tol)
        if dup is not None:
            k, j = dup
            raise PoseError(f"pose {k}: repeats the {what} of pose {j}, {revisit_hint('pose file')} ({why})",
                            where=source)
    spread = np.linalg.svd(P - P.mean(axis=0), compute_uv=False)
    if spread[1] <= COLLINEAR_RTOL * spread[0]:
        raise PoseError(f"the {K} poses lie on one straight line: the offsets and the MAEMM are not identifiable "
                        f"from them ({why})", where=source)
    G, _ = identification_matrix(robot, P, theta=theta)
    s = np.linalg.svd(G, compute_uv=False)
    if not s[-1] > RANK_RTOL * s[0]:
        from zerocal_sym.identify.identifiability import null_space_phrase

        null = null_space_phrase(robot, theta, robot.errors.resolve("default"))
        raise PoseError(f"the identification matrix G of these poses has rank {int(np.sum(s > RANK_RTOL * s[0]))} "
                        f"< {p}: the parameters {names} are not identifiable from them"
                        + (f" ({null})" if null else "") + f" ({why})", where=source)


# --------------------------------------------------------------------------- values by name

def parse_named_values(items, robot, option: str = "--set") -> dict:
    """``NAME=VALUE`` items (source-error names of the robot's mechanism) -> {name: value} in user units.

    Degrees for angles, mm otherwise (``robot.errors[name].user_unit``).

    Raises
    ------
    ZerocalError
        An item without ``=``, an unknown name (listing the known ones), a
        value that is not a finite number, a name given twice.
    """
    from zerocal_sym.errors import ZerocalError

    errors = robot.errors
    out = {}
    for it in items or ():
        name, sep, text = it.partition("=")
        name = name.strip()
        if not sep:
            raise ZerocalError(f"{option} {it!r}: expected NAME=VALUE (degrees for angles, mm otherwise)")
        if name not in errors.names:
            raise ZerocalError(f"{option} {it!r}: unknown source error {name!r} of mechanism "
                               f"{robot.mechanism_name} (known: {', '.join(errors.names)})")
        try:
            v = float(text)
        except ValueError:
            raise ZerocalError(f"{option} {it!r}: bad value {text.strip()!r} (a number in "
                               f"{errors[name].user_unit})") from None
        if not math.isfinite(v):
            raise ZerocalError(f"{option} {it!r}: the value must be finite")
        if name in out:
            raise ZerocalError(f"{option}: {name} given twice")
        out[name] = v
    return out


def format_named(robot, vec, names=None, nonzero: bool = True) -> str:
    """``theta1=2 deg, rMx=1 mm`` for a source-error vector (internal units)."""
    errors = robot.errors
    d = errors.to_dict(vec, names, user=True)
    parts = [f"{k}={v:.10g} {errors[k].user_unit}" for k, v in d.items() if v != 0 or not nonzero]
    return ", ".join(parts) if parts else "none"


def vector_arg(values, k: int, option: str, names, unit: str):
    """``values`` (a list from ``nargs="+"``) as k finite floats, or a one-line error naming ``names``."""
    import numpy as np

    from zerocal_sym.errors import ZerocalError

    v = np.asarray(values, float)
    if v.shape != (k,):
        raise ZerocalError(f"{option} needs {k} values ({', '.join(names)}, {unit}), got {len(values)}")
    if not np.all(np.isfinite(v)):
        raise ZerocalError(f"{option} must be finite numbers ({unit})")
    return v


def write_out(args, obj) -> None:
    """``--out FILE.json``: the JSON the command prints with ``--json``, written all-or-nothing (if given)."""
    out = getattr(args, "out", None)
    if out:
        from zerocal_sym.io.files import json_safe, write_json

        write_json(out, json_safe(obj))


def fmt_values(v, spec=".10g", sep=" ") -> str:
    return sep.join(format(float(x), spec) for x in v)


# --------------------------------------------------------------------------- the paper's Table 2

def has_paper_tables(robot) -> bool:
    """Whether the robot's source errors are those Table 2 names (the paper's planar robot)."""
    from zerocal_sym.paper.tables import PLANAR

    return tuple(robot.errors.names) == tuple(PLANAR.names)


def require_paper_tables(robot, what: str, alternative: str = "give the true errors by --set NAME=VALUE") -> None:
    """Raise a one-line ZerocalError unless Table 2 applies to the robot."""
    from zerocal_sym.errors import ZerocalError

    if not has_paper_tables(robot):
        raise ZerocalError(f"{what} is the paper's: it needs Table 2's source errors, those of the paper's planar "
                           f"2-DOF robot; robot {robot.name!r} is a {robot.mechanism_name} ({robot.m} joints, "
                           f"source errors {', '.join(robot.errors.names[:4])}, ...): {alternative}")


def truth_from_meta(meas, robot):
    """The true source errors a simulated measurement file states (``# true_errors: theta1=2, rMx=1``), or None.

    ``zerocal simulate`` writes that line (user units: deg for angles, mm
    otherwise); a file without it, or with names that are not the robot's,
    gives None.
    """
    import re

    text = meas.meta.get("true_errors")
    if not text:
        return None
    values = {}
    for item in re.split(r"[,\s]+", text.strip()):
        name, sep, v = item.partition("=")
        if not sep or name not in robot.errors.names:
            return None
        try:
            values[name] = float(v)
        except ValueError:
            return None
    return robot.errors.from_user(values) if values or text.strip() == "none" else None
