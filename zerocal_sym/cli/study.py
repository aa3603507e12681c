"""The study runner: robots x designs x noise levels x truths x trials, chunked, resumable.

A *study* (a TOML spec, :func:`load_spec`) crosses robot files, measurement
designs, noise levels and true source errors; each combination is a *cell*.
Every cell runs the same number of one-shot identifications (Ipopt on the
exact model, :func:`~zerocal_sym.identify.batch.identify_batch`), split in
chunks of consecutive trials.  Each chunk is written atomically (temporary
file + ``os.replace``) to ``OUT/<cell-id>/chunk-<k>.npz``, one array per
column:

``trial`` (int64), ``est_<param>`` and ``std_<param>`` per identified
parameter (rad / mm), ``chi2``, ``success``, ``confirmed`` (bool) and
``time_s`` (the identification time of the chunk, 0-d).

A rerun skips the chunks already on disk (a chunk whose trials are not the
expected ones, e.g. after ``trials`` changed, is recomputed), so an
interrupted study resumes where it stopped; ``OUT/<cell-id>/cell.json``
records the cell's settings, and a rerun whose settings differ (other than
``trials``) is refused.  The summary (:func:`summarize`) is merged from the
chunk files: per cell and parameter the bias, RMS, sample std, the CRLB at
the truth and RMS/CRLB, quantiles (5 %, median, 95 %) of the errors, the
mean reported std, failures.

Spec (paths relative to the spec file; angles in degrees, lengths in mm)::

    name = "noise study"          # optional
    seed = 0                      # optional (default 0)
    trials = 1000000              # trials per cell
    chunk = 10000                 # trials per chunk file (default min(10000, trials))
    params = "paper"              # identified parameters (default: the zero offsets and the MAEMM)
    streams = "common"            # "common" (default): trial t draws the same numbers in every cell;
                                  # "independent": each cell its own stream
    robots = ["paper", "examples/delta.toml"]   # "paper": the built-in robot; label: the file's stem
    noise = ["paper", "scale-only", 0.5, 2]     # named, or factors of the paper's noise (default ["paper"])

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

Errors in the spec are one line naming the file and the line.
"""
from __future__ import annotations

import hashlib
import io
import json
import math
import re
import sys
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from zerocal_sym.errors import ZerocalError
from zerocal_sym.identify.one_shot import OneShotTask, one_shot_chunk
from zerocal_sym.identify.parallel import chunk_ranges, describe_scheduler, run_chunks
from zerocal_sym.identify.stats import QUANTILES, Stats

SPEC_KEYS = ("name", "seed", "trials", "chunk", "params", "streams", "robots", "noise", "design", "truth")
DESIGN_KEYS = ("scheme", "n", "poses", "robots", "label")
TRUTH_RESERVED = ("name", "robots")
NAMED_NOISE = ("paper", "scale-only", "servo-only", "none")
DEFAULT_CHUNK = 10000
CELL_FORMAT = "zerocal study cell v1"
_CHUNK_RE = re.compile(r"^chunk-(\d+)\.npz$")


class StudySpecError(ZerocalError):
    """A study spec that is malformed (names the file and line)."""


# --------------------------------------------------------------------------- the spec

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
            "noise": {"label": self.noise_label, "sigma_scale_mm": self.noise.sigma_scale_mm,
                      "sigma_servo_rad": self.noise.sigma_servo_rad},
            "truth": {"label": self.truth_label, "values": self.truth_user,
                      "units": {k: r.errors[k].user_unit for k in self.truth_user}},
            "params": list(self.params), "seed": study.seed, "stream": self.stream, "chunk": study.chunk,
        })


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
        return f"{self.path}:{line}" if line else self.path


def _slug(s: str) -> str:
    s = re.sub(r"[^A-Za-z0-9.+-]+", "-", str(s)).strip("-.")
    return s or "x"


def _is_int(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(float(v))


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
            out.append((v, NoiseModel.named(v)))
        elif _is_num(v):
            if v < 0:
                raise StudySpecError(f"noise factor {v!r} must be >= 0", where=where("noise"))
            out.append((f"x{float(v):g}", NoiseModel.paper(float(v), float(v))))
        elif isinstance(v, dict):
            bad = [k for k in v if k not in ("scale", "servo")]
            vals = [v.get("scale", 1.0), v.get("servo", 1.0)]
            if bad or not all(_is_num(x) and x >= 0 for x in vals):
                raise StudySpecError(f"noise table {v!r}: keys scale and servo, factors >= 0 of the paper's "
                                     "two noise terms", where=where("noise"))
            out.append((f"scale{float(vals[0]):g}-servo{float(vals[1]):g}", NoiseModel.paper(*map(float, vals))))
        else:
            raise StudySpecError(f"noise level {v!r}: a name or a number", where=where("noise"))
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


def _design_poses(tab, robot, base, wk):
    """(label, poses) of one [[design]] table for one robot."""
    from zerocal_sym.cli._common import check_scheme, scheme_poses
    from zerocal_sym.io.poses import load_poses

    if "poses" in tab:
        p = Path(tab["poses"]) if Path(tab["poses"]).is_absolute() else base / tab["poses"]
        try:
            P = load_poses(p, robot)
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


def load_spec(path) -> Study:
    """Read and validate a study spec (TOML); every cell is built (robots loaded, poses checked).

    Raises
    ------
    StudySpecError
        Naming the spec file and the line.
    """
    from zerocal_sym.cli._common import parse_named_values
    from zerocal_sym.model import kinematics as kin

    path = Path(path)
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise StudySpecError("study spec not found", where=str(path)) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise StudySpecError(f"cannot read the study spec: {exc}", where=str(path)) from None
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        m = re.search(r"line (\d+)", str(exc))
        raise StudySpecError(f"not valid TOML: {exc}", where=f"{path}:{m.group(1)}" if m else str(path)) from None
    where = _Where(path, text)
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
    if not _is_int(chunk) or chunk < 1:
        raise StudySpecError(f"chunk must be a positive integer, got {chunk!r}", where=where("chunk"))
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
        if not isinstance(tabs, list) or not tabs or not all(isinstance(t, dict) for t in tabs):
            raise StudySpecError(f"at least one [[{key}]] table is needed", where=where(key))
    study = Study(path=path, name=name, seed=seed, trials=trials, chunk=chunk, params=params, streams=streams)
    labels = list(robots)
    for rl, robot in robots.items():
        try:
            names = robot.errors.resolve(params)
        except ValueError as exc:
            raise StudySpecError(f"params for robot {rl!r}: {exc}", where=where("params")) from None
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
                          ("label", lambda v: isinstance(v, str) and v), ("n", lambda v: _is_int(v) and v >= 2)):
                if k in dt and not ok(dt[k]):
                    raise StudySpecError(f"{k} = {dt[k]!r}: expected "
                                         + ("an integer >= 2" if k == "n" else "a string"), where=wd(k))
            flt = _filter(dt, labels, wd)
            if flt is not None and rl not in flt:
                continue
            dlabel, P = _design_poses(dt, robot, base, wd)
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
                for k, v in values.items():
                    if not _is_num(v):
                        raise StudySpecError(f"{k} = {v!r}: expected a finite number (deg for angles, mm otherwise)",
                                             where=wt(k))
                try:
                    user = parse_named_values([f"{k}={v}" for k, v in values.items()], robot, "truth")
                except ZerocalError as exc:
                    bad = next((k for k in values if k not in robot.errors.names), None)
                    raise StudySpecError(f"robot {rl!r}: {exc.message}", where=wt(bad)) from None
                for nl, noise in noises:
                    cid = "_".join(_slug(x) for x in (rl, dlabel, nl, tlabel))
                    stream = 0 if streams == "common" else int.from_bytes(
                        hashlib.sha256(cid.encode()).digest()[:4], "little")
                    if any(c.id == cid for c in study.cells):
                        raise StudySpecError(f"two cells named {cid!r}: give the [[design]]/[[truth]] tables "
                                             "distinct labels/names", where=wt("name") if "name" in tt else wd(None))
                    study.cells.append(Cell(cid, robot, rl, dlabel, P, theta, nl, noise, tlabel,
                                            robot.errors.from_user(user), user, names, stream))
    if not study.cells:
        raise StudySpecError("no cell: every [[design]] or [[truth]] is filtered out for every robot",
                             where=str(path))
    return study


# --------------------------------------------------------------------------- chunk files

def chunk_path(out, cell, k) -> Path:
    return Path(out) / cell.id / f"chunk-{k}.npz"


def write_chunk(path, cols: dict, params) -> None:
    """One chunk's columns to ``path`` (npz, one array per column), atomically."""
    from zerocal_sym.io.files import atomic_write_bytes

    arrays = {"trial": cols["trial"]}
    for j, n in enumerate(params):
        arrays[f"est_{n}"] = cols["estimate"][:, j]
    for j, n in enumerate(params):
        arrays[f"std_{n}"] = cols["std"][:, j]
    arrays.update(chi2=cols["chi2"], success=cols["success"], confirmed=cols["confirmed"],
                  time_s=np.asarray(cols.get("time_s", 0.0)))
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    atomic_write_bytes(path, buf.getvalue())


def read_chunk(path, params, start, stop, columns: bool = True):
    """The columns of a chunk file if it holds exactly trials ``start .. stop-1`` of these parameters, else None.

    ``columns=False``: only check (reads the ``trial`` column alone) and return True or None.
    """
    need = ["trial", "chi2", "success", "confirmed"] + [f"est_{n}" for n in params] + [f"std_{n}" for n in params]
    try:
        with np.load(path) as z:
            if any(k not in z.files for k in need) or not np.array_equal(z["trial"], np.arange(start, stop)):
                return None
            return {k: z[k] for k in z.files} if columns else True
    except (OSError, ValueError, EOFError, KeyError):
        return None


def _cell_json(out, cell, study, check_only=False):
    """Write (or check) ``OUT/<cell>/cell.json``; a different existing one is an error."""
    from zerocal_sym.io.files import atomic_write_text

    p = Path(out) / cell.id / "cell.json"
    want = cell.settings(study)
    if p.exists():
        try:
            have = json.loads(p.read_text())
        except (OSError, ValueError):
            have = None
        if have != json.loads(json.dumps(want)):
            diff = sorted(k for k in want if have is None or have.get(k) != json.loads(json.dumps(want[k])))
            raise ZerocalError(f"this cell was run with other settings ({', '.join(diff) or 'unreadable'}): use "
                               "another output directory or remove the cell's directory", where=str(p))
        return
    if not check_only:
        atomic_write_text(p, json.dumps(want, indent=1) + "\n")


# --------------------------------------------------------------------------- running

def plan(study: Study, out) -> tuple:
    """``(todo, on_disk)``: the chunks to run ``[(cell, k, start, stop)]`` and how many are already done."""
    todo, done = [], 0
    for cell in study.cells:
        for k, (a, b) in enumerate(chunk_ranges(study.trials, study.chunk)):
            p = chunk_path(out, cell, k)
            if p.exists() and read_chunk(p, cell.params, a, b, columns=False) is not None:
                done += 1
            else:
                todo.append((cell, k, a, b))
    return todo, done


def run_study(study: Study, out, workers: int = 1, scheduler=None, progress=None, log=None,
              make_progress=None) -> dict:
    """Run the chunks not on disk yet, then summarise.

    Parameters
    ----------
    out : path
        Output directory (created).
    workers, scheduler : see :func:`~zerocal_sym.identify.parallel.run_chunks`
    progress : callable, optional
        ``progress(done)`` with the trials done in this run.  A ``KeyboardInterrupt``
        (Ctrl-C, or raised by it) stops the run: the chunks written so far stay
        (complete files), nothing partial is left, no summary is written.
    log : callable, optional
        ``log(text)`` for the one-line account of what is on disk and what runs.
    make_progress : callable, optional
        ``make_progress(total) -> progress`` (total: the trials to run), instead of ``progress``.

    Returns
    -------
    dict
        The summary (:func:`summarize`), also written to ``OUT/summary.json``.
    """
    from zerocal_sym.io.files import write_json

    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ZerocalError("the study output must be a directory", where=str(out))
    for cell in study.cells:
        _cell_json(out, cell, study, check_only=True)
    todo, on_disk = plan(study, out)
    total = on_disk + len(todo)
    if log:
        log(f"study {study.name}: {len(study.cells)} cells x {study.chunks_per_cell} chunks of <= {study.chunk} "
            f"trials: {on_disk} of {total} chunks already on disk, {len(todo)} to run "
            f"({sum(b - a for _, _, a, b in todo)} identifications)")
    if make_progress is not None:
        progress = make_progress(sum(b - a for *_, a, b in todo))
    t0 = time.perf_counter()
    for cell in {c.id: c for c, *_ in todo}.values():
        _cell_json(out, cell, study)
    tasks = [OneShotTask(c.robot, c.theta, c.truth, c.noise, c.params, study.seed, c.stream, a, b)
             for c, k, a, b in todo]

    def save(i, cols):
        cell, k, a, b = todo[i]
        write_chunk(chunk_path(out, cell, k), cols, cell.params)
        return float(cols.get("time_s", 0.0))

    times = run_chunks(one_shot_chunk, tasks, [b - a for *_, a, b in todo], workers, scheduler, progress,
                       on_result=save)
    wall = time.perf_counter() - t0
    summary = summarize(study, out)
    n_run = sum(b - a for *_, a, b in todo)
    summary["run"] = {"chunks_on_disk_before": on_disk, "chunks_run": len(todo), "identifications": n_run,
                      "wall_s": wall, "identifications_per_s": n_run / wall if n_run and wall > 0 else None,
                      "identification_time_s": float(sum(t for t in times if t is not None)),
                      "workers": workers, "scheduler": describe_scheduler(scheduler)}
    write_json(out / "summary.json", summary)
    return summary


# --------------------------------------------------------------------------- summary

def _crlb(cell):
    from zerocal_sym.identify import fisher

    if cell.noise.is_zero:
        return None
    try:
        return np.sqrt(np.diag(fisher.crlb(cell.robot, cell.theta, cell.params, cell.noise, err0=cell.truth)))
    except (ZerocalError, np.linalg.LinAlgError, ValueError):
        return None


def summarize(study: Study, out) -> dict:
    """Merge the chunk files on disk into per-cell statistics (errors in deg for angles, mm otherwise).

    Cells with missing chunks are summarised over what is there (``trials_done``).
    """
    out = Path(out)
    cells = []
    for cell in study.cells:
        _cell_json(out, cell, study, check_only=True)  # chunks of other settings are not merged
        errors = cell.robot.errors
        names = cell.params
        conv = np.array([math.degrees(1.0) if errors[n].unit == "rad" else 1.0 for n in names])
        true = errors.take(cell.truth, names)
        St, Ss = Stats(len(names)), Stats(len(names), keep=False)
        fail = unconf = chunks = n_done = 0
        chi2_sum, t_id = 0.0, 0.0
        for k, (a, b) in enumerate(chunk_ranges(study.trials, study.chunk)):
            p = chunk_path(out, cell, k)
            cols = read_chunk(p, names, a, b) if p.exists() else None
            if cols is None:
                continue
            chunks += 1
            n_done += b - a
            ok = cols["success"].astype(bool)
            fail += int(np.sum(~ok))
            unconf += int(np.sum(~cols["confirmed"].astype(bool)))
            est = np.column_stack([cols[f"est_{n}"] for n in names])[ok]
            std = np.column_stack([cols[f"std_{n}"] for n in names])[ok]
            St.merge(Stats.of((est - true) * conv))
            Ss.merge(Stats.of(std * conv, keep=False))
            chi2_sum += float(np.sum(cols["chi2"][ok]))
            t_id += float(cols.get("time_s", 0.0))
        crlb = _crlb(cell)
        crlb_u = None if crlb is None else crlb * conv
        q = St.quantiles()

        def by_name(v):
            return None if v is None else {n: float(x) for n, x in zip(names, v)}

        rms = St.rms
        cells.append({
            "id": cell.id, "robot": cell.robot_label, "mechanism": cell.robot.mechanism_name,
            "design": cell.design_label, "K": int(cell.poses.shape[0]), "noise": cell.noise_label,
            "truth": cell.truth_label, "truth_values": cell.truth_user,
            "params": list(names), "units": {n: errors[n].user_unit for n in names},
            "trials": study.trials, "trials_done": n_done, "chunks_done": chunks,
            "chunks": study.chunks_per_cell, "identified": St.count, "failures": fail,
            "unconfirmed_in_batch": unconf,
            "bias": by_name(St.mean), "rms": by_name(rms), "std": by_name(St.std),
            "crlb": by_name(crlb_u),
            "rms_crlb_ratio": by_name(None if rms is None or crlb_u is None else rms / crlb_u),
            **{k: by_name(None if q is None else q[k]) for k in QUANTILES},
            "mean_reported_std": by_name(Ss.mean),
            "chi2_per_dof": (chi2_sum / St.count / (cell.poses.shape[0] - 1 - len(names))
                             if St.count and cell.poses.shape[0] - 1 > len(names) else None),
            "identification_time_s": t_id,
        })
    return {"study": study.name, "spec": str(study.path), "seed": study.seed, "trials": study.trials,
            "chunk": study.chunk, "streams": study.streams, "cells": cells}


def format_summary(s: dict) -> str:
    """The summary as text: one block per cell, one row per parameter."""
    lines = [f"study {s['study']}: {len(s['cells'])} cells, {s['trials']} trials each (chunks of {s['chunk']}, "
             f"seed {s['seed']}, {s['streams']} random streams)"]
    for c in s["cells"]:
        lines.append("")
        lines.append(f"{c['id']}: robot {c['robot']}, design {c['design']} (K = {c['K']}), noise {c['noise']}, "
                     f"truth {c['truth']}; {c['trials_done']}/{c['trials']} trials on disk, "
                     f"{c['failures']} failed" + (f", chi2/dof {c['chi2_per_dof']:.3f}" if c["chi2_per_dof"] else ""))
        if not c["identified"]:
            lines.append("  no identification on disk")
            continue
        lines.append(f"  {'param':8s} {'unit':4s} {'bias':>10s} {'RMS':>10s} {'CRLB':>10s} {'RMS/CRLB':>8s} "
                     f"{'5%':>10s} {'median':>10s} {'95%':>10s} {'mean std':>10s}")
        for n in c["params"]:
            def f(key, spec="10.4g"):
                v = c[key]
                return format(v[n], spec) if v is not None and v.get(n) is not None else "-".rjust(10)

            ratio = c["rms_crlb_ratio"]
            lines.append(f"  {n:8s} {c['units'][n]:4s} {f('bias', '+10.4g')} {f('rms')} {f('crlb')} "
                         f"{(format(ratio[n], '8.3f') if ratio else '-'.rjust(8))} {f('q05', '+10.4g')} "
                         f"{f('median', '+10.4g')} {f('q95', '+10.4g')} {f('mean_reported_std')}")
    r = s.get("run")
    if r:
        ips = r["identifications_per_s"]
        lines.append("")
        lines.append(f"this run: {r['chunks_run']} chunks ({r['identifications']} identifications) in "
                     f"{r['wall_s']:.1f} s" + (f", {ips:.0f} identifications/s" if ips else "")
                     + f"; {r['chunks_on_disk_before']} chunks were on disk")
    return "\n".join(lines)


def log_stderr(text: str) -> None:
    print(text, file=sys.stderr, flush=True)
