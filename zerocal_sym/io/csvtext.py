"""Shared text handling of the data files: reading, CSV splitting, cell checks.

Used by the measurement file (:mod:`zerocal_sym.io.measurements`), the pose
file (:mod:`zerocal_sym.io.poses`), the results JSON
(:mod:`zerocal_sym.io.results`) and the compensation table
(:mod:`zerocal_sym.io.compensation`).  Columns may come in any order; the
separator is a comma; ``#`` starts a comment line; blank lines are ignored; a
UTF-8 byte-order mark is accepted.  Every error is a
:class:`~zerocal_sym.errors.DataFileError` naming the file, the line and,
where there is one, the column (by name and field number).

The columns of the data files come from the robot's mechanism
(:func:`joint_columns`, :func:`pose_columns`): ``theta1_deg, theta2_deg[,
theta3_deg]`` from its joint names, ``x_mm, y_mm[, z_mm]`` from its pose
names.  A file is read as the mechanism of the robot it is read for, else
as the one it names (``# mechanism:``, a results file's ``mechanism``), else
as the default mechanism (:func:`read_as`); it is never matched to a
mechanism by its columns or sizes (two mechanisms may share them), and
columns that do not fit are an error that says what the file was read as.
"""
from __future__ import annotations

import csv
import difflib
import json
import math
import re
from pathlib import Path

from zerocal_sym.errors import DataFileError

class ColumnMismatch(DataFileError):
    """A header whose columns are not the expected ones (unexpected or missing columns): maybe another
    mechanism's, so a reader says which mechanism it read the file as (:func:`with_reading_hint`)."""


#: metadata key naming the mechanism a file belongs to (``# mechanism: delta_rotary``)
MECHANISM_KEY = "mechanism"
#: the metadata keys zerocal reads: one value each (a second line with another value is an error); other
#: ``# key: value`` lines are kept and ignored, and may repeat
READ_META_KEYS = (MECHANISM_KEY, "robot_sha256", "compensation_deg", "compensation_mm", "true_errors", "revisits",
                  "region", "region_singularity_margin")
#: metadata key (a CSV's ``# revisits: allowed``, a JSON pose file's ``"revisits": "allowed"``) saying the file
#: revisits poses on purpose (a design's replicates); its one value
REVISITS_KEY, REVISITS_ALLOWED = "revisits", "allowed"
#: the option that allows revisits in a file without the line
ALLOW_REVISITS_OPTION = "--allow-revisits"

#: plausibility limits of the cells (anything beyond is a unit or typing error)
ANGLE_LIMIT_DEG = 3600.0
LENGTH_LIMIT_MM = 1e6


def _format_meta(meta: dict) -> str:
    out = []
    for k, v in meta.items():
        k, v = str(k).strip(), str(v).strip()
        if not k or ":" in k or "\n" in k + v or "\r" in k + v:
            raise ValueError(f"metadata key {k!r} / value {v!r} cannot be written on one '# key: value' line")
        out.append(f"# {k}: {v}\n")
    return "".join(out)


def _read_text(path, what="file") -> tuple[str, str]:
    """File text with BOM removed and newlines normalised; typed errors."""
    path = Path(path)
    src = str(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise DataFileError(f"{what} not found", where=src) from None
    except IsADirectoryError:
        raise DataFileError(f"{what} is a directory", where=src) from None
    except OSError as exc:
        raise DataFileError(f"cannot read {what}: {exc.strerror or exc}", where=src) from None
    if raw.startswith(b"\xef\xbb\xbf"):
        raw = raw[3:]
    elif raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise DataFileError("file is UTF-16 encoded: save it as UTF-8 (plain CSV)", where=f"{src}:1")
    nul = raw.find(b"\x00")
    if nul >= 0:
        line = raw.count(b"\n", 0, nul) + 1
        raise DataFileError("binary data (NUL byte) in a text file", where=f"{src}:{line}")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        before = raw[:exc.start]
        line = before.count(b"\n") + 1
        col = exc.start - (before.rfind(b"\n") + 1) + 1
        raise DataFileError(f"not UTF-8 text: byte 0x{raw[exc.start]:02x} at column {col} "
                            "(save the file as UTF-8 CSV)", where=f"{src}:{line}") from None
    return text.replace("\r\n", "\n").replace("\r", "\n"), src


def _split_csv(text: str, src: str, format_prefix: str | None = None, version: int | None = None):
    """Metadata lines, their line numbers and CSV rows (line number, stripped cells)."""
    meta, meta_lines, rows = {}, {}, []
    header_seen = False
    for lineno, line in enumerate(text.split("\n"), 1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            if format_prefix and stripped.startswith(format_prefix):
                m = re.fullmatch(re.escape(format_prefix) + r" v(\d+)", stripped)
                if not m or int(m.group(1)) != version:
                    raise DataFileError(f"unsupported format line {stripped[:60]!r} (this version reads "
                                        f"'{format_prefix} v{version}')", where=f"{src}:{lineno}")
            elif not header_seen and ":" in stripped:
                k, _, v = stripped[1:].partition(":")
                k, v = k.strip(), v.strip()
                if k in READ_META_KEYS and k in meta and meta[k] != v:
                    raise DataFileError(f"'# {k}:' given twice with different values (lines {meta_lines[k]} and "
                                        f"{lineno}): one value per key", where=f"{src}:{lineno}")
                meta[k] = v
                meta_lines[k] = lineno
            continue
        if '"' in line:  # quoting: the csv module (a line without quotes splits at every comma alike)
            try:
                cells = next(csv.reader([line], strict=True))
            except csv.Error as exc:
                raise DataFileError(f"malformed CSV line ({exc})", where=f"{src}:{lineno}") from None
        else:
            cells = line.split(",")
        rows.append((lineno, [c.strip() for c in cells]))
        header_seen = True
    return meta, meta_lines, rows


def _looks_numeric(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


def _check_header(header, header_line, src, allowed, required, example):
    where = f"{src}:{header_line}"
    if len(header) == 1 and (";" in header[0] or "\t" in header[0]):
        sep = "';'" if ";" in header[0] else "a tab"
        raise DataFileError(f"the separator must be a comma, found {sep} (header must be {example})", where=where)
    if any(_looks_numeric(c) for c in header if c):
        raise DataFileError(f"no header line: the first non-comment line must be the header {example}", where=where)
    for j, c in enumerate(header, 1):
        if c == "":
            raise DataFileError(f"column {j} of the header has no name (a trailing comma?)", where=where)
    dup = sorted({c for c in header if header.count(c) > 1})
    if dup:
        raise DataFileError(f"duplicated column(s): {', '.join(dup)}", where=where)
    extra = [c for c in header if c not in allowed]
    if extra:
        hints = []
        for c in extra:
            close = difflib.get_close_matches(c.lower(), allowed, n=1, cutoff=0.6)
            hints.append(f"'{c}' (column {header.index(c) + 1}" + (f"; did you mean '{close[0]}'?)" if close else ")"))
        missing = [c for c in required if c not in header]
        miss = f"; missing: {', '.join(missing)}" if missing else ""
        raise ColumnMismatch(f"unexpected column(s): {', '.join(hints)}{miss}; allowed: {', '.join(allowed)}",
                             where=where)
    missing = [c for c in required if c not in header]
    if missing:
        raise ColumnMismatch(f"missing column(s): {', '.join(missing)} (header must be {example})", where=where)


def _number(text: str, where: str, col: str, j: int) -> float:
    label = f"column '{col}' (field {j})"
    if text == "":
        hint = " (fill in the scale reading)" if col == "reading_mm" else ""
        raise DataFileError(f"{label}: empty cell{hint}", where=where)
    try:
        v = float(text)
    except ValueError:
        shown = text if len(text) <= 40 else text[:37] + "..."
        raise DataFileError(f"{label}: {shown!r} is not a number", where=where) from None
    if not math.isfinite(v):
        raise DataFileError(f"{label}: {text} is not a finite number", where=where)
    limit, unit = (ANGLE_LIMIT_DEG, "deg") if col.endswith("_deg") else (LENGTH_LIMIT_MM, "mm")
    if col != "pose" and abs(v) > limit:
        raise DataFileError(f"{label}: {v:g} is beyond the plausible range +-{limit:g} {unit}", where=where)
    return v


def _rows_to_records(rows, cols, src, int_cols=("pose",)):
    values, lines = [], []
    for lineno, cells in rows:
        where = f"{src}:{lineno}"
        if len(cells) != len(cols):
            more = "" if len(cells) < len(cols) else f" (field {len(cols) + 1} = {cells[len(cols)]!r} is extra)"
            raise DataFileError(f"{len(cells)} fields, expected {len(cols)} ({','.join(cols)}){more}", where=where)
        rec = {}
        for j, (c, cell) in enumerate(zip(cols, cells), 1):
            rec[c] = _number(cell, where, c, j)
            if c in int_cols and rec[c] != int(rec[c]):
                raise DataFileError(f"column '{c}' (field {j}): {cell!r} is not a whole number", where=where)
        values.append(rec)
        lines.append(lineno)
    return values, lines


def _rows_to_array(rows, cols, src, int_cols=("pose",)):
    """The cells as numbers, shape (N, len(cols)), and the line of each row; linear time.

    Every row is checked as :func:`_rows_to_records` checks it (the number of
    fields, numbers, finite, in the plausible range, whole numbers in
    ``int_cols``); the first row at fault is re-read by it for the message.
    """
    import numpy as np

    n = len(cols)
    V = np.empty((len(rows), n))
    lines = [lineno for lineno, _ in rows]
    for i, (_, cells) in enumerate(rows):
        try:
            if len(cells) != n:
                raise ValueError
            V[i] = [float(c) for c in cells]
        except ValueError:
            _rows_to_records([rows[i]], cols, src, int_cols)  # raises the message of this row
            raise
    limit = np.array([np.inf if c == "pose" else ANGLE_LIMIT_DEG if c.endswith("_deg") else LENGTH_LIMIT_MM
                      for c in cols])
    with np.errstate(invalid="ignore"):
        bad = ~(np.abs(V) <= limit)  # NaN and inf too
        for c in int_cols:
            if c in cols:
                j = cols.index(c)
                bad[:, j] |= V[:, j] != np.floor(V[:, j])
    first = np.flatnonzero(bad.any(axis=1))
    if first.size:
        _rows_to_records([rows[int(first[0])]], cols, src, int_cols)  # raises the message of this row
    return V, lines


def _check_pose_numbers(values, lines, src, col_index):
    """Poses numbered 0, 1, ... in file order; the first deviation is reported.

    ``values``: the records of :func:`_rows_to_records`, or the pose column (an array).
    """
    import numpy as np

    poses = (np.asarray(values, float) if not (len(values) and isinstance(values[0], dict))
             else np.array([rec["pose"] for rec in values], float))
    wrong = np.flatnonzero(poses != np.arange(len(poses)))
    if not wrong.size:
        return
    k = int(wrong[0])
    p = int(poses[k])
    if 0 <= p < k:  # the rows before k are numbered 0..k-1: p is one of them
        msg = f"pose {p} appears twice (lines {lines[p]} and {lines[k]})"
    else:
        msg = f"expected {k}, got {p}" + (" (numbering starts at 0)" if k == 0 and p == 1 else "")
    raise DataFileError(f"column 'pose' (field {col_index}): {msg}; poses are numbered 0, 1, ... in "
                        "visiting order, one row each", where=f"{src}:{lines[k]}")


def _reject_constant(c):
    raise ValueError(f"{c} is not allowed")


def _load_json(text: str, src: str):
    try:
        return json.loads(text, parse_constant=_reject_constant)
    except json.JSONDecodeError as exc:
        raise DataFileError(f"not valid JSON: {exc.msg} (column {exc.colno})", where=f"{src}:{exc.lineno}") from None
    except (ValueError, RecursionError) as exc:
        raise DataFileError(f"not valid JSON: {exc}", where=src) from None


def _json_line(text: str, key: str):
    m = re.search(rf'"{re.escape(key)}"\s*:', text)
    return text.count("\n", 0, m.start()) + 1 if m else None


def _where(text, key, src):
    """``src:line`` of ``key``'s first occurrence in the JSON ``text`` (``src`` alone when absent)."""
    line = _json_line(text, key)
    return f"{src}:{line}" if line else src


def _finite_number(x) -> bool:
    """A JSON number that is a finite float (not a bool; an integer of 400 digits is not)."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return False
    try:
        return math.isfinite(x)
    except OverflowError:  # an integer beyond any float
        return False


# --------------------------------------------------------------------------- columns from the mechanism

def get_mechanism_of(spec=None):
    """The :class:`~zerocal_sym.model.mechanism.Mechanism` of ``spec``.

    Parameters
    ----------
    spec : str, Mechanism, Robot or None
        A known mechanism's name (:func:`~zerocal_sym.model.mechanism.known_mechanisms`: the built-in ones,
        installed packages' and those a robot file registered), a mechanism, a robot (its mechanism), or
        None for the default mechanism.

    Raises
    ------
    ValueError
        An unknown mechanism name.
    """
    from zerocal_sym.model.mechanism import DEFAULT_MECHANISM, Mechanism, get_mechanism, is_known

    if spec is None:
        return get_mechanism(DEFAULT_MECHANISM)
    if isinstance(spec, Mechanism):
        return spec
    if not isinstance(spec, str):
        return spec.mechanism
    if not is_known(spec):
        raise ValueError(f"unknown mechanism {spec!r} (known: {', '.join(known_names())})")
    return get_mechanism(spec)


def known_names() -> list:
    """The names of the mechanisms known now (built in, installed, registered by a robot file)."""
    from zerocal_sym.model.mechanism import known_mechanisms

    return list(known_mechanisms())


def unknown_mechanism_message(name) -> str:
    """``unknown mechanism 'x' (known: ...)``, with how a mechanism of one's own becomes known."""
    return (f"unknown mechanism {name!r} (known: {', '.join(known_names())}; a mechanism of your own is known "
            "once its robot file is read: pass --robot)")


def joint_columns(mech, suffix: str | None = None) -> tuple:
    """``theta1_deg, ...`` (revolute joints) or ``s1_mm, ...`` (prismatic): one column per joint of ``mech`` (a
    name, Mechanism or Robot), the suffix its joints' unit."""
    mech = get_mechanism_of(mech)
    suffix = "_" + mech.joint_user_unit if suffix is None else suffix
    return tuple(j + suffix for j in mech.joint_names)


def pose_columns(mech) -> tuple:
    """``x_mm, y_mm[, z_mm]`` (and ``roll_deg, ...`` for orientations): one column per pose coordinate of
    ``mech`` (a name, Mechanism or Robot), the suffix its unit."""
    from zerocal_sym.model.units import pose_unit

    mech = get_mechanism_of(mech)
    return tuple(f"{p}_{pose_unit(mech, p)}" for p in mech.pose_names)


def read_as(robot, declared=None) -> tuple:
    """The mechanism a file is read as, and why (for messages): ``(Mechanism, reason)``.

    The robot's mechanism if there is a robot, else the one the file declares, else the default
    mechanism.  A file is never matched to a mechanism by its columns or its sizes: two mechanisms may
    have the same ones.
    """
    if robot is not None:
        return robot.mechanism, f"the robot's ({robot.source})"
    if declared is not None:
        return get_mechanism_of(declared), "the one it names"
    return get_mechanism_of(None), "the default one (no robot file given)"


def with_reading_hint(exc: DataFileError, mech, reason: str) -> DataFileError:
    """``exc`` with what the file was read as appended (a file without a mechanism line whose columns or
    sizes do not fit): one line, the same place."""
    return DataFileError(f"{exc.message}; the file names no mechanism and is read as mechanism {mech.name}, "
                         f"{reason}: pass the robot file of the measured robot (--robot)", where=exc.where)


def _go_together(names) -> str:
    """``columns x_mm and y_mm go together (both or neither)`` (``all or none`` for three or more)."""
    names = list(names)
    text = ", ".join(names[:-1]) + " and " + names[-1] if len(names) > 1 else names[0]
    return f"columns {text} go together ({'both or neither' if len(names) == 2 else 'all or none'})"
