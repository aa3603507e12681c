"""The study spec (TOML): read and validated into a :class:`Study` of :class:`Cell` s.

A *study* crosses robot files, measurement designs, noise levels and true
source errors; each combination is a *cell* (the runner is
:mod:`zerocal_sym.cli.study`).  :func:`load_spec` builds every cell (robots
loaded, poses checked) before anything runs.

Spec (paths relative to the spec file; angles in degrees, lengths in mm)::

    name = "noise study"          # optional
    seed = 0                      # optional (default 0)
    trials = 1000000              # trials per cell
    chunk = 10000                 # trials per chunk file (default min(10000, trials))
    params = "paper"              # identified parameters (default: each mechanism's default set, e.g. the zero
                                  # offsets and the MAEMM)
    streams = "common"            # "common" (default): trial t draws the same numbers in every cell;
                                  # "independent": each cell its own stream
    robots = ["paper", "examples/delta.toml"]   # "paper": the built-in robot; label: the file's stem
    noise = ["paper", "scale-only", 0.5, 2]     # named, or factors of each robot's default noise (the paper's
                                                # for the paper's robot; a robot file's [noise]) (default ["paper"])

    [[design]]                    # one or more
    scheme = "auto"               # the robot's boundary scheme (or "paper" / "ring"), with
    n = 6                         # poses per boundary (default: the scheme's)
    # poses = "poses.csv"         # or a pose file (instead of scheme/n)
    # robots = ["delta"]          # only for these robots (labels); label = "ring6" to name it

    [[truth]]                     # one or more; source errors by name, the others zero
    name = "A"                    # optional (default truth1, truth2, ...)
    robots = ["delta"]            # optional: only for these robots
    theta1 = 2
    theta2 = -1
    theta3 = 0.5

Errors in the spec are one line naming the file and the line; among them a
parameter set that a design's poses cannot identify (rank of the sensitivity
below the number of parameters, :func:`~zerocal_sym.cli._checks.identifiability_problem`),
an ``n`` beyond ``--n``'s cap and a study this machine cannot hold
(:mod:`zerocal_sym.cli.study_size`: the chunk files per cell, the memory of
a cell's summary and of a chunk's identification).
"""
from __future__ import annotations

import hashlib
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from zerocal_sym.cli._checks import MAX_N
from zerocal_sym.cli.study_size import check_spec
from zerocal_sym.errors import ZerocalError
from zerocal_sym.identify.parallel import chunk_ranges

SPEC_KEYS = ("name", "seed", "trials", "chunk", "params", "streams", "robots", "noise", "design", "truth")
DESIGN_KEYS = ("scheme", "n", "poses", "robots", "label")
TRUTH_RESERVED = ("name", "robots")
NAMED_NOISE = ("paper", "scale-only", "servo-only", "none")
DEFAULT_CHUNK = 10000
#: the most trials per chunk file (the chunk's arrays are held in memory: 10^6 trials x p values)
MAX_CHUNK = 1_000_000
#: the most chunk files per cell (ceil(trials / chunk); the chunk list is built before the run)
MAX_CHUNKS_PER_CELL = 1_000_000
#: the largest factor of the paper's noise (x 1000: a servo error of 2.4 deg per joint, 1.1 mm per reading)
MAX_NOISE_FACTOR = 1000.0
CELL_FORMAT = "zerocal study cell v1"


class StudySpecError(ZerocalError):
    """A study spec that is malformed (names the file and line)."""


@dataclass
class Cell:
    """One combination robot x design x noise x truth."""

    id: str
    robot: object
    robot_label: str
    design_label: str
    poses: np.ndarray
    theta: np.ndarray
    noise_label: str
    noise: object
    truth_label: str
    truth: np.ndarray
    truth_user: dict
    params: tuple
    stream: int

    def settings(self, study) -> dict:
        """What identifies the cell's results (cell.json); ``trials`` is not part of it."""
        from zerocal_sym.io.files import json_safe

        r = self.robot
        return json_safe({
            "format": CELL_FORMAT, "id": self.id,
            "robot": {"label": self.robot_label, "name": r.name, "mechanism": r.mechanism_name,
                      "sha256": r.sha256},
            "design": self.design_label, "poses_mm": self.poses.tolist(),
            "noise": {"label": self.noise_label, **self.noise.to_dict(r)},
            "truth": {"label": self.truth_label, "values": self.truth_user,
                      "units": {k: r.errors[k].user_unit for k in self.truth_user}},
            "params": list(self.params), "seed": study.seed, "stream": self.stream, "chunk": study.chunk,
        })

    def digest(self, study) -> str:
        """SHA-256 of :meth:`settings` (canonical JSON): recorded in each chunk file of the cell."""
        import json

        text = json.dumps(self.settings(study), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()


@dataclass
class Study:
    """A parsed, validated study spec."""

    path: Path
    name: str
    seed: int
    trials: int
    chunk: int
    params: str
    streams: str
    cells: list = field(default_factory=list)
    #: ``[(label, path)]``: the files the spec names (robot and pose files), inputs no output may overwrite
    inputs: list = field(default_factory=list)

    @property
    def chunks_per_cell(self) -> int:
        return len(chunk_ranges(self.trials, self.chunk))


class _Where:
    """Line numbers of keys in the spec text (top level, or inside the k-th ``[[table]]``)."""

    def __init__(self, path, text):
        self.path, self.lines = str(path), text.splitlines()

    def _blocks(self, table):
        heads = [i for i, ln in enumerate(self.lines) if re.match(rf"\s*\[\[\s*{re.escape(table)}\s*\]\]", ln)]
        out = []
        for h in heads:
            end = next((j for j in range(h + 1, len(self.lines)) if re.match(r"\s*\[", self.lines[j])),
                       len(self.lines))
            out.append((h, end))
        return out

    def __call__(self, key=None, table=None, index=None) -> str:
        line = None
        if table is None:
            end = next((j for j, ln in enumerate(self.lines) if re.match(r"\s*\[", ln)), len(self.lines))
            rng = range(0, end)
        else:
            blocks = self._blocks(table)
            if index is None or index >= len(blocks):
                return self.path
            h, end = blocks[index]
            line = h + 1
            rng = range(h + 1, end)
        if key is not None:
            for j in rng:
                if re.match(rf"\s*(\"?){re.escape(key)}\1\s*=", self.lines[j]):
                    line = j + 1
                    break
            else:
                if table is None:  # a table of that name: [key] or [[key]]
                    line = self.header(key)
        return f"{self.path}:{line}" if line else self.path

    def header(self, key):
        """The line (1-based) of the first ``[key]`` or ``[[key]]`` header, or None."""
        for j, ln in enumerate(self.lines):
            if re.match(rf"\s*\[\[?\s*(\"?){re.escape(key)}\1\s*\]", ln):
                return j + 1
        return None


def _slug(s: str) -> str:
    s = re.sub(r"[^A-Za-z0-9.+-]+", "-", str(s)).strip("-.")
    return s or "x"


def _is_int(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _is_num(v) -> bool:
    if not isinstance(v, (int, float)) or isinstance(v, bool):
        return False
    try:
        return math.isfinite(float(v))
    except OverflowError:  # an integer beyond any float
        return False


def _noise_levels(raw, where):
    from zerocal_sym.model.noise import NoiseModel

    if not isinstance(raw, list) or not raw:
        raise StudySpecError("noise must be a non-empty list of paper | scale-only | servo-only | none, factors "
                             "of the paper's noise, or {scale = a, servo = b} tables", where=where("noise"))
    out = []
    for v in raw:
        if isinstance(v, str):
            if v not in NAMED_NOISE:
                raise StudySpecError(f"unknown noise level {v!r} (named: {', '.join(NAMED_NOISE)}; or a factor "
                                     "of the paper's noise)", where=where("noise"))
            out.append((v, lambda robot, v=v: NoiseModel.named(v, robot)))
        elif _is_num(v):
            if not 0 <= v <= MAX_NOISE_FACTOR:
                raise StudySpecError(f"noise factor {v!r} must be >= 0 and at most {MAX_NOISE_FACTOR:g} (times the "
                                     "robot's default noise)", where=where("noise"))
            out.append((f"x{float(v):g}", lambda robot, f=float(v): robot.noise.scaled(f, f)))
        elif isinstance(v, dict):
            bad = [k for k in v if k not in ("scale", "servo")]
            vals = [v.get("scale", 1.0), v.get("servo", 1.0)]
            if bad or not all(_is_num(x) and 0 <= x <= MAX_NOISE_FACTOR for x in vals):
                raise StudySpecError(f"noise table {v!r}: keys scale and servo, factors >= 0 (at most "
                                     f"{MAX_NOISE_FACTOR:g}) of the robot's two noise terms", where=where("noise"))
            out.append((f"scale{float(vals[0]):g}-servo{float(vals[1]):g}",
                        lambda robot, a=float(vals[0]), b=float(vals[1]): robot.noise.scaled(a, b)))
        else:
            shown = f"an integer of {len(str(abs(v)))} digits" if isinstance(v, int) and abs(v) >= 10**30 else repr(v)
            raise StudySpecError(f"noise level {shown}: a name or a finite number", where=where("noise"))
    labels = [lab for lab, _ in out]
    dup = sorted({lab for lab in labels if labels.count(lab) > 1})
    if dup:
        raise StudySpecError(f"noise level {dup[0]} given twice", where=where("noise"))
    return out


def _robots(raw, base, where):
    from zerocal_sym.model.robot import load_robot, paper_robot

    if not isinstance(raw, list) or not raw or not all(isinstance(r, str) and r for r in raw):
        raise StudySpecError('robots must be a non-empty list of robot files (or "paper" for the built-in robot)',
                             where=where("robots"))
    out = {}
    for r in raw:
        if r == "paper":
            label, robot = "paper", paper_robot()
        else:
            p = Path(r) if Path(r).is_absolute() else base / r
            try:
                robot = load_robot(p)
            except ZerocalError as exc:
                raise StudySpecError(f"robot {r!r}: {exc}", where=where("robots")) from None
            label = _slug(p.stem)
        if label in out:
            raise StudySpecError(f"two robots with the label {label!r} (a file's stem): rename one",
                                 where=where("robots"))
        out[label] = robot
    return out


def _filter(tab, labels, where_key):
    f = tab.get("robots")
    if f is None:
        return None
    if not isinstance(f, list) or not all(isinstance(x, str) for x in f):
        raise StudySpecError("robots must be a list of robot labels", where=where_key("robots"))
    unknown = [x for x in f if x not in labels]
    if unknown:
        raise StudySpecError(f"unknown robot label {unknown[0]!r} (labels: {', '.join(labels)})",
                             where=where_key("robots"))
    return set(f)


def _design_poses(tab, robot, base, wk, allow_revisits=False):
    """(label, poses) of one [[design]] table for one robot."""
    from zerocal_sym.cli._common import check_scheme, scheme_poses
    from zerocal_sym.io.poses import load_poses

    if "poses" in tab:
        p = Path(tab["poses"]) if Path(tab["poses"]).is_absolute() else base / tab["poses"]
        try:
            P = load_poses(p, robot, allow_revisits, measured=True)
        except ZerocalError as exc:
            raise StudySpecError(f"poses for robot {robot.name!r}: {exc}", where=wk("poses")) from None
        return tab.get("label") or f"poses-{_slug(p.stem)}", P
    scheme = tab.get("scheme", "auto")
    try:
        scheme = check_scheme(robot, None if scheme == "auto" else scheme, option="scheme =")
        P, n = scheme_poses(robot, scheme, tab.get("n"), option="scheme =")
    except ZerocalError as exc:
        raise StudySpecError(f"robot {robot.name!r}: {exc.message}", where=wk("scheme" if "scheme" in tab else
                                                                            "n" if "n" in tab else None)) from None
    return tab.get("label") or f"{scheme}{n}", P


def _first_unassembled(robot, theta, err):
    """The first pose (index) where the exact distance model with the errors ``err`` is not finite, or None."""
    from zerocal_sym.model import kinematics as kin

    with np.errstate(all="ignore"):
        rho, de, dt = kin.distance_jacobians(robot, theta, err)
    bad = ~(np.isfinite(rho) & np.all(np.isfinite(de), axis=1) & np.all(np.isfinite(dt), axis=1))
    return int(np.flatnonzero(bad)[0]) if bad.any() else None


def load_spec(path, allow_revisits: bool = False) -> Study:
    """Read and validate a study spec (TOML); every cell is built (robots loaded, poses checked).

    Raises
    ------
    StudySpecError
        Naming the spec file and the line.
    """
    from zerocal_sym.cli._checks import MAX_N, identifiability_problem
    from zerocal_sym.identify.montecarlo import offsets_missing
    from zerocal_sym.cli._common import parse_named_values
    from zerocal_sym.identify.check.plausibility import DEFAULT_MAX_MAEMM_MM, DEFAULT_MAX_OFFSET_DEG
    from zerocal_sym.model import kinematics as kin

    from zerocal_sym.model.robot import read_toml

    path = Path(path)
    raw = read_toml(path, StudySpecError, "study spec")
    where = _Where(path, path.read_text(encoding="utf-8").removeprefix("\ufeff"))
    base = path.parent
    for k in raw:
        if k not in SPEC_KEYS:
            raise StudySpecError(f"unknown key '{k}' (allowed: {', '.join(SPEC_KEYS)})", where=where(k))
    if "trials" not in raw:
        raise StudySpecError("missing key 'trials' (trials per cell)", where=str(path))
    trials = raw["trials"]
    if not _is_int(trials) or trials < 1:
        raise StudySpecError(f"trials must be a positive integer, got {trials!r}", where=where("trials"))
    seed = raw.get("seed", 0)
    if not _is_int(seed) or seed < 0:
        raise StudySpecError(f"seed must be a non-negative integer, got {seed!r}", where=where("seed"))
    chunk = raw.get("chunk", min(DEFAULT_CHUNK, trials))
    if not _is_int(chunk) or not 1 <= chunk <= MAX_CHUNK:
        raise StudySpecError(f"chunk must be a positive integer of at most {MAX_CHUNK} (trials per chunk file), "
                             f"got {chunk!r}", where=where("chunk"))
    if -(-trials // chunk) > MAX_CHUNKS_PER_CELL:
        raise StudySpecError(f"trials = {trials} in chunks of {chunk} make {-(-trials // chunk)} chunk files per cell: "
                             f"at most {MAX_CHUNKS_PER_CELL} (give a larger chunk, or fewer trials)",
                             where=where("chunk" if "chunk" in raw else "trials"))
    params = raw.get("params", "paper")
    if not isinstance(params, str):
        raise StudySpecError("params must be a string (paper | all | names joined by , or +)", where=where("params"))
    streams = raw.get("streams", "common")
    if streams not in ("common", "independent"):
        raise StudySpecError(f"streams must be 'common' or 'independent', got {streams!r}", where=where("streams"))
    name = raw.get("name", path.stem)
    if not isinstance(name, str):
        raise StudySpecError("name must be a string", where=where("name"))
    robots = _robots(raw.get("robots"), base, where)
    noises = _noise_levels(raw.get("noise", ["paper"]), where)
    designs, truths = raw.get("design"), raw.get("truth")
    for key, tabs in (("design", designs), ("truth", truths)):
        if isinstance(tabs, dict):
            raise StudySpecError(f"[{key}] is a single table: write [[{key}]] (double brackets: one or more "
                                 f"[[{key}]] tables)", where=where(key))
        if not isinstance(tabs, list) or not tabs or not all(isinstance(t, dict) for t in tabs):
            raise StudySpecError(f"at least one [[{key}]] table is needed", where=where(key))
    study = Study(path=path, name=name, seed=seed, trials=trials, chunk=chunk, params=params, streams=streams)
    labels = list(robots)
    for rl, robot in robots.items():
        try:
            names = robot.errors.resolve(params)
        except ValueError as exc:
            raise StudySpecError(f"params for robot {rl!r}: {exc}", where=where("params")) from None
        missing = offsets_missing(robot.errors, names)  # compare's check
        if missing:
            raise StudySpecError(f"params = {params!r} for robot {rl!r}: {missing}", where=where("params"))
        for di, dt in enumerate(designs):
            def wd(key, _i=di):
                return where(key, "design", _i)

            for k, v in dt.items():
                if k not in DESIGN_KEYS:
                    raise StudySpecError(f"unknown key '{k}' in [[design]] (allowed: {', '.join(DESIGN_KEYS)})",
                                         where=wd(k))
            if "poses" in dt and ("scheme" in dt or "n" in dt):
                raise StudySpecError("give poses = FILE or scheme/n, not both", where=wd("poses"))
            for k, ok in (("poses", lambda v: isinstance(v, str)), ("scheme", lambda v: isinstance(v, str)),
                          ("label", lambda v: isinstance(v, str) and v),
                          ("n", lambda v: _is_int(v) and 2 <= v <= MAX_N)):
                if k in dt and not ok(dt[k]):
                    raise StudySpecError(f"{k} = {dt[k]!r}: expected "
                                         + (f"an integer >= 2 and <= {MAX_N} (poses per boundary)" if k == "n" else
                                            "a string"), where=wd(k))
            flt = _filter(dt, labels, wd)
            if flt is not None and rl not in flt:
                continue
            dlabel, P = _design_poses(dt, robot, base, wd, allow_revisits)
            try:
                theta = kin.check_poses(robot, P)
            except ZerocalError as exc:
                raise StudySpecError(f"robot {rl!r}: {exc}", where=wd(None)) from None
            if P.shape[0] - 1 < len(names):
                raise StudySpecError(f"robot {rl!r}: {P.shape[0]} poses give {P.shape[0] - 1} changes, fewer than "
                                     f"the {len(names)} parameters", where=wd(None))
            for ti, tt in enumerate(truths):
                def wt(key, _i=ti):
                    return where(key, "truth", _i)

                flt = _filter(tt, labels, wt)
                if flt is not None and rl not in flt:
                    continue
                tlabel = tt.get("name", f"truth{ti + 1}")
                if not isinstance(tlabel, str) or not tlabel:
                    raise StudySpecError("name must be a non-empty string", where=wt("name"))
                values = {k: v for k, v in tt.items() if k not in TRUTH_RESERVED}
                for k in values:
                    if k not in robot.errors.names:
                        raise StudySpecError(f"robot {rl!r}: unknown source error {k!r} in [[truth]] (mechanism "
                                             f"{robot.mechanism_name}: {', '.join(robot.errors.names)}; and the "
                                             f"table's keys {', '.join(TRUTH_RESERVED)})", where=wt(k))
                for k, v in values.items():
                    if not _is_num(v):
                        raise StudySpecError(f"{k} = {v!r}: expected a finite number (deg for angles, mm otherwise)",
                                             where=wt(k))
                    if k in robot.errors.zero_offsets and abs(v) > DEFAULT_MAX_OFFSET_DEG:
                        raise StudySpecError(f"{k} = {v!r} deg: beyond the plausible {DEFAULT_MAX_OFFSET_DEG:g} deg "
                                             "of a zero offset (the identification's plausibility limit; the "
                                             "truth is in degrees)", where=wt(k))
                try:
                    user = parse_named_values([f"{k}={v}" for k, v in values.items()], robot, "truth")
                except ZerocalError as exc:
                    bad = next((k for k in values if k not in robot.errors.names), None)
                    raise StudySpecError(f"robot {rl!r}: {exc.message}", where=wt(bad)) from None
                truth = robot.errors.from_user(user)
                measuring = [k for k in robot.errors.measuring if k in values]
                if measuring and math.hypot(*(float(values[k]) for k in measuring)) > DEFAULT_MAX_MAEMM_MM:
                    raise StudySpecError(f"MAEMM {', '.join(f'{k} = {values[k]!r}' for k in measuring)} mm: beyond "
                                         f"the plausible |rM| <= {DEFAULT_MAX_MAEMM_MM:g} mm (the identification's "
                                         "plausibility limit)", where=wt(measuring[0]))
                out = _first_unassembled(robot, theta, truth)
                if out is not None:
                    raise StudySpecError(f"robot {rl!r}, design {dlabel}: with these true errors pose {out} is not an "
                                         "assembly of the robot (its measured distance is not finite): errors this "
                                         "large are not a calibration's", where=wt(None))
                problem = identifiability_problem(robot, theta, names, err0=truth)
                if problem:
                    raise StudySpecError(f"robot {rl!r}, design {dlabel}: params = {params!r}: {problem}",
                                         where=wd(None))
                for nl, noise_of in noises:
                    noise = noise_of(robot)  # the robot's: named, or factors of its default noise
                    cid = "_".join(_slug(x) for x in (rl, dlabel, nl, tlabel))
                    stream = 0 if streams == "common" else int.from_bytes(
                        hashlib.sha256(cid.encode()).digest()[:4], "little")
                    if any(c.id == cid for c in study.cells):
                        raise StudySpecError(f"two cells named {cid!r}: give the [[design]]/[[truth]] tables "
                                             "distinct labels/names", where=wt("name") if "name" in tt else wd(None))
                    study.cells.append(Cell(cid, robot, rl, dlabel, P, theta, nl, noise, tlabel,
                                            truth.copy(), user, names, stream))
    if not study.cells:
        raise StudySpecError("no cell: every [[design]] or [[truth]] is filtered out for every robot",
                             where=str(path))
    check_spec(study, where, StudySpecError)  # what this machine can hold: chunk files, memory
    from zerocal_sym.model.robot import module_file

    robot_files = [base / r for r in raw["robots"] if r != "paper"]
    study.inputs = ([("a robot file of the spec", f) for f in robot_files]
                    + [("the mechanism module of a robot file of the spec", m) for m in map(module_file, robot_files)
                       if m is not None]
                    + [("a pose file of the spec", base / dt["poses"]) for dt in designs if "poses" in dt])
    return study

