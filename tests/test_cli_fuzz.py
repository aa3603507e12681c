"""Hypothesis fuzz of the command line: whatever the files hold, never a traceback.

Robot files, measurement files, results files and study specs, for both
mechanisms (the paper's planar robot and the rotary Delta), are mutated --
values replaced by hostile ones (huge, tiny, negative, not finite, of the
wrong type, nested thousands deep), keys and lines deleted or repeated,
measurement rows shuffled, reversed, dropped, made cumulative -- and run
through the ``zerocal`` commands that read them, in this process, through
:func:`zerocal_sym.cli.main`.  The command must return an exit status (0 or
1; 2 with exactly one line on stderr) and never let any exception but
``SystemExit`` (argparse) escape: any other is a traceback for the user.

The CI form runs a few examples of each (about a minute of CPU); the long
form (``slow``) many more.
"""
import contextlib
import copy
import io
import json
import math
import os
import random
import shutil
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from zerocal_sym.cli import main

ROOT = Path(__file__).resolve().parents[1]
PAPER_TOML = (ROOT / "examples" / "paper_robot.toml").read_text()
DELTA_TOML = (ROOT / "examples" / "delta.toml").read_text()

#: examples per fuzz test: the CI form, the long form
QUICK, LONG = 80, 300

# hostile TOML values for any key
TOML_VALUES = ["0", "-1", "-0.0", "1e308", "-1e308", "1e-308", "5e-324", "DIGITS", "nan", "inf", "-inf",
               "1e30", "-1e30", "1e6", "-1e6", "1e-12", '"x"', '""', "true", "[1, 2]", "[]", "{a = 1}",
               "1979-05-27", "DEEP", "DEEP200", "0x7fffffffffffffff",
               "-9223372036854775808", "[1e308, 1e308, 1e308]", "[nan, 1, 2]", "99999999999999999999",
               # the study spec's lists and counts
               "[1e308]", '["paper", 1e6]', "[{scale = 1e308, servo = 0}]", "[1e3]", "[0]", "1000000000000",
               "100000", '["paper"]', '["delta.toml", "delta.toml"]', '["paper", "nonexistent.toml"]']
# hostile CSV cells
CELLS = ["", "nan", "inf", "-inf", "1e308", "-1e308", "1e-320", "0", "-0", "1e30", "x", "1" + "0" * 400,
         "180", "-180", "360", "720", "1e6", "0.0000001"]


@contextlib.contextmanager
def _fd_captured():
    """What C code writes to the file descriptors 1 and 2 (LAPACK's complaints, Ipopt's banner), as a list."""
    got = []
    with tempfile.TemporaryFile() as tmp:
        saved = [os.dup(1), os.dup(2)]
        try:
            for fd in (1, 2):
                os.dup2(tmp.fileno(), fd)
            yield got
        finally:
            for fd, old in zip((1, 2), saved):
                os.dup2(old, fd)
                os.close(old)
        tmp.seek(0)
        got.append(tmp.read().decode(errors="replace"))


def run(argv) -> tuple:
    """``zerocal argv`` in this process: (status, stdout, stderr, what C code printed); an exception other than
    SystemExit escaping fails the test (it would be a traceback)."""
    out, err = io.StringIO(), io.StringIO()
    with _fd_captured() as raw, contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = main([str(a) for a in argv])
        except SystemExit as exc:  # argparse's own errors
            rc = exc.code
    return rc, out.getvalue(), err.getvalue(), raw[0]


def check(argv, record: bool = True) -> int:
    rc, out, err, raw = run(argv)
    assert "Traceback" not in err and "Traceback" not in out, (argv, err)
    assert raw == "", (argv, raw)  # nothing printed past Python (it would land in the JSON on stdout)
    assert rc in (0, 1, 2), (argv, rc, err)
    if rc == 2:
        lines = err.strip().splitlines()
        assert len(lines) == 1, (argv, err)
    if record:  # (--hypothesis-show-statistics: how far the cases get)
        event(f"zerocal {argv[0]}: exit {rc}")
    return rc


class _Inputs(dict):
    def __repr__(self):  # (hypothesis shows the arguments of a failing case: not the files' texts)
        return "<the fuzz's valid inputs>"


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    """Valid inputs of both mechanisms: robot files, a simulated round each, a result each, a study spec."""
    d = tmp_path_factory.mktemp("fuzz")
    (d / "paper.toml").write_text(PAPER_TOML)
    (d / "delta.toml").write_text(DELTA_TOML)
    files = _Inputs()
    for mech, robot, sets in (("paper", d / "paper.toml", ["theta1=1", "theta2=-0.5", "rMx=0.5"]),
                              ("delta", d / "delta.toml", ["theta1=2", "theta2=-1", "theta3=0.5", "rMz=0.3"])):
        data, res = d / f"{mech}.csv", d / f"{mech}.json"
        assert check(["simulate", "--robot", robot, *sum((["--set", s] for s in sets), []),
                      "--out", data], record=False) == 0
        assert check(["identify", data, "--robot", robot, "--out", res], record=False) == 0
        data2 = d / f"{mech}2.csv"  # a second round, measured with the result's compensation (for verify)
        offsets = [f"{v:.12g}" for v in json.loads(res.read_text())["zero_offsets_deg"]]
        assert check(["simulate", "--robot", robot, *sum((["--set", s] for s in sets), []), "--seed", "1",
                      "--compensation", *offsets, "--out", data2], record=False) == 0
        files[mech] = {"robot": robot, "data_text": data.read_text(), "data2_text": data2.read_text(),
                       "result_text": res.read_text(), "data": data, "data2": data2, "result": res}
    files["dir"] = d
    return files


@contextlib.contextmanager
def workdir(base):
    """A fresh directory with the robot files in it (the study spec names them relatively)."""
    with tempfile.TemporaryDirectory(dir=base["dir"]) as t:
        t = Path(t)
        for name in ("paper.toml", "delta.toml"):
            shutil.copy(base["dir"] / name, t / name)
        yield t


def fuzz(examples):
    return settings(suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow,
                                           HealthCheck.data_too_large], deadline=None, max_examples=examples)


# --------------------------------------------------------------------------- mutations of a "key = value" file

#: tokens that stand for values too long to show (expanded when the file is written)
LONG_VALUES = {"DEEP": "[" * 3000 + "]" * 3000, "DEEP200": "[" * 200 + "1" + "]" * 200, "DIGITS": "1" + "0" * 400}


@st.composite
def toml_edits(draw):
    """One to three edits of a TOML file: a value replaced, a line deleted/repeated, a key or table added.

    Drawn as small tuples (shown when a case fails); :func:`apply_toml_edits` makes the text."""
    edits = []
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(["value", "value", "float", "nudge", "nudge", "delete", "repeat", "add",
                                     "header"]))
        pick, at = draw(st.integers(0, 10**6)), draw(st.integers(0, 10**6))
        if kind == "nudge":  # a number scaled: a file that still loads, of another (maybe odd) robot or study
            value = draw(st.sampled_from(["0.5", "0.9", "0.99", "1.01", "1.1", "2", "10", "-1", "0", "1e-6"]))
        elif kind == "float":
            value = repr(draw(st.floats(allow_nan=False, allow_infinity=False)))
        elif kind == "header":
            value = draw(st.sampled_from(["[geometry]", "[workspace]", "[[design]]", "[[truth]]", "[design]", "[x]",
                                          "[[geometry]]"]))
        elif kind == "add":
            value = (draw(st.sampled_from(["home", "singularity_margin", "mechanism", "units", "n", "poses", "x",
                                           "theta1", "rMx", "L", "phi1", "z1", "chunk", "seed", "label", "scheme"]))
                     + " = " + draw(st.sampled_from(TOML_VALUES)))
        else:
            value = draw(st.sampled_from(TOML_VALUES))
        edits.append((kind, pick, at, value))
    return edits


def _number(line):
    """The number a ``key = number  # comment`` line sets, or None."""
    try:
        v = float(line.split("=", 1)[1].split("#", 1)[0])
    except (IndexError, ValueError):
        return None
    return v if math.isfinite(v) and abs(v) < 1e300 else None


def apply_toml_edits(text, edits) -> str:
    lines = text.splitlines()
    for kind, pick, at, value in edits:
        value = " = ".join(LONG_VALUES.get(v, v) for v in value.split(" = ")) if kind == "add" else \
            LONG_VALUES.get(value, value)
        kv = [i for i, ln in enumerate(lines) if "=" in ln and not ln.lstrip().startswith("#")]
        if kind in ("value", "float") and kv:
            i = kv[pick % len(kv)]
            lines[i] = f"{lines[i].split('=', 1)[0]}= {value}"
        elif kind == "nudge":
            nums = [i for i in kv if _number(lines[i]) is not None]
            if nums:
                i = nums[pick % len(nums)]
                key, text = lines[i].split("=", 1)
                v = _number(lines[i]) * float(value)
                integer = not any(c in text.split("#", 1)[0] for c in ".eE") and v == int(v)
                lines[i] = f"{key}= {int(v) if integer else repr(v)}"
        elif kind == "delete" and lines:
            del lines[pick % len(lines)]
        elif kind == "repeat" and lines:
            lines.insert(at % (len(lines) + 1), lines[pick % len(lines)])
        elif kind in ("add", "header"):
            lines.insert(at % (len(lines) + 1), value)
    return "\n".join(lines) + "\n"


def _robot_case(base, edits, mech):
    with workdir(base) as t:
        robot = t / "r.toml"
        robot.write_text(apply_toml_edits(PAPER_TOML if mech == "paper" else DELTA_TOML, edits))
        if check(["robot", "--robot", robot]) != 0:
            return
        out = t / "d.csv"
        sets = ["theta1=1", "theta2=-1"]
        if check(["simulate", "--robot", robot, *sum((["--set", s] for s in sets), []), "--noise", "none",
                  "--out", out]) == 0:
            check(["identify", out, "--robot", robot, "--method", "tsvd"])
        check(["identify", base[mech]["data"], "--robot", robot])  # the file of the robot given: refused or fits


def _robot_strategy():
    return st.tuples(st.sampled_from(["paper", "delta"]), toml_edits())


@fuzz(QUICK)
@given(case=_robot_strategy())
def test_robot_files(base, case):
    _robot_case(base, case[1], case[0])


@pytest.mark.slow
@fuzz(LONG)
@given(case=_robot_strategy())
def test_robot_files_long(base, case):
    _robot_case(base, case[1], case[0])


# --------------------------------------------------------------------------- measurement files

#: edits of the rows (most keep the file loadable, so that the identification runs on wrong data)
ROW_EDITS = ("shuffle", "shuffle", "reverse", "reverse", "drop", "drop", "dropmany", "dup", "cumulative", "cumulative",
             "negate", "scale", "scale", "cell", "swap", "zero", "perturb", "perturb", "renumber_off")


@st.composite
def data_mutated(draw):
    mech = draw(st.sampled_from(["paper", "delta"]))
    return mech, draw(st.lists(st.sampled_from(ROW_EDITS), min_size=1, max_size=3)), draw(st.integers(0, 2**32 - 1)), \
        draw(st.sampled_from(CELLS)), draw(st.sampled_from(["tsvd", "nlls", "huber", "verify"]))


def mutate_rows(text, edits, seed, cell):
    """The measurement file with row edits (the pose column renumbered unless the edit is to break it)."""
    rng = random.Random(seed)
    lines = text.splitlines()
    head = [ln for ln in lines if not ln[:1].isdigit()]
    rows = [ln.split(",") for ln in lines if ln[:1].isdigit()]
    col = next(ln.split(",") for ln in head if ln.startswith("pose,")).index("reading_mm")
    renumber = True
    for e in edits:
        if e == "shuffle":
            rng.shuffle(rows)
        elif e == "reverse":
            rows.reverse()
        elif e == "drop" and rows:
            del rows[rng.randrange(len(rows))]
        elif e == "dropmany":
            rows = rows[: rng.randrange(0, len(rows) + 1)]
        elif e == "dup" and rows:
            i = rng.randrange(len(rows))
            rows.insert(i, list(rows[i]))
        elif e in ("cumulative", "negate", "scale", "zero"):
            acc, f = 0.0, rng.choice([10.0, 1e3, 1e6, 1e-6, 1e300])
            for r in rows:
                try:
                    v = float(r[col])
                except (ValueError, IndexError):
                    continue
                acc += v
                r[col] = repr(acc if e == "cumulative" else -v if e == "negate" else v * f if e == "scale" else 0.0)
        elif e == "cell" and rows:
            r = rows[rng.randrange(len(rows))]
            r[rng.randrange(1, len(r))] = cell
        elif e == "swap" and len(rows) > 1:
            i = rng.randrange(len(rows) - 1)
            rows[i], rows[i + 1] = rows[i + 1], rows[i]
        elif e == "perturb" and rows:
            r = rows[rng.randrange(len(rows))]
            j = rng.randrange(1, len(r))
            try:
                r[j] = repr(float(r[j]) + rng.choice([-1, 1]) * rng.choice([0.5, 5.0, 50.0, 500.0]))
            except ValueError:
                pass
        elif e == "renumber_off":
            renumber = False
    if renumber:  # the pose column and the first reading (0) as the loader wants them
        for i, r in enumerate(rows):
            r[0] = str(i)
        if rows and len(rows[0]) > col:
            rows[0][col] = "0"
    return "\n".join(head + [",".join(r) for r in rows]) + "\n"


def _data_case(base, case):
    mech, edits, seed, cell, how = case
    with workdir(base) as t:
        data = t / "d.csv"
        data.write_text(mutate_rows(base[mech]["data2_text" if how == "verify" else "data_text"], edits, seed, cell))
        robot = base[mech]["robot"]
        if how == "tsvd":
            check(["identify", data, "--robot", robot, "--method", "tsvd"])
        elif how == "nlls":
            check(["identify", data, "--robot", robot, "--json"])
        elif how == "huber":
            check(["identify", data, "--robot", robot, "--loss", "huber"])
        else:
            check(["verify", base[mech]["result"], data, "--robot", robot])
        assert sorted(p.name for p in t.iterdir()) == ["d.csv", "delta.toml", "paper.toml"]


@fuzz(2 * QUICK)
@given(case=data_mutated())
def test_measurement_files(base, case):
    _data_case(base, case)


@pytest.mark.slow
@fuzz(LONG)  # the suite's costliest test at 2 x LONG (142 s of CPU): CI's 15 minutes hold both versions' runs
@given(case=data_mutated())
def test_measurement_files_long(base, case):
    _data_case(base, case)


# --------------------------------------------------------------------------- results files

JSON_VALUES = [None, True, 0, -1, 1e308, -1e308, 5e-324, "DIGITS", "DEEP", "x", [], {}, [1e308] * 3, [0.0], "nan",
               [[1, 2], [3, 4]], [1, 2, 3, 4, 5, 6, 7], "delta_rotary", "planar_2dof", 1e30, 45.0, -720.0]


def _paths(obj, prefix=()):
    yield prefix
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(obj, list) and len(obj) <= 8:
        for i, v in enumerate(obj):
            yield from _paths(v, prefix + (i,))


@st.composite
def result_mutated(draw):
    mech = draw(st.sampled_from(["paper", "delta"]))
    return mech, draw(st.lists(st.tuples(st.integers(0, 10**6), st.sampled_from(JSON_VALUES + ["DELETE"])),
                               min_size=1, max_size=3)), draw(st.sampled_from(["compensate", "verify", "template"]))


def mutate_json(text, edits):
    obj = json.loads(text)
    for pick, value in edits:
        paths = [p for p in _paths(obj) if p]
        if not paths:
            break
        path = paths[pick % len(paths)]
        parent = obj
        for k in path[:-1]:
            parent = parent[k]
        if value == "DELETE":
            del parent[path[-1]]
        else:
            parent[path[-1]] = f"@{value}@" if isinstance(value, str) and value in LONG_VALUES else copy.deepcopy(value)
    text = json.dumps(obj)
    for key, long in LONG_VALUES.items():
        text = text.replace(f'"@{key}@"', long)
    return text


def _result_case(base, case):
    mech, edits, how = case
    with workdir(base) as t:
        res = t / "r.json"
        res.write_text(mutate_json(base[mech]["result_text"], edits))
        robot = base[mech]["robot"]
        if how == "compensate":
            check(["compensate", res, "--robot", robot, "--out", t / "c.csv"])
        elif how == "template":
            check(["compensate", res, "--robot", robot, "--template", "--out", t / "c.csv"])
        else:
            check(["verify", res, base[mech]["data2"], "--robot", robot, "--out", t / "v.json"])


@fuzz(QUICK)
@given(case=result_mutated())
def test_result_files(base, case):
    _result_case(base, case)


@pytest.mark.slow
@fuzz(LONG)
@given(case=result_mutated())
def test_result_files_long(base, case):
    _result_case(base, case)


# --------------------------------------------------------------------------- pose files

POSES = {"paper": "x_mm,y_mm\n-240,632\n0,632\n240,632\n-240,782\n0,782\n240,782\n",
         "delta": "x_mm,y_mm,z_mm\n" + "".join(f"{x},{y},{z}\n" for x, y, z in (
             (150, 0, -750), (0, 150, -750), (-150, 0, -750), (0, -150, -750), (100, 100, -850),
             (-100, 100, -850), (-100, -100, -850), (100, -100, -850)))}


@st.composite
def poses_mutated(draw):
    mech = draw(st.sampled_from(["paper", "delta"]))
    edits = draw(st.lists(st.tuples(st.integers(0, 10**6), st.integers(0, 10**6), st.sampled_from(CELLS + [
        "-", "1e3", "5000", "0.001"])), min_size=1, max_size=3))
    return mech, edits, draw(st.booleans()), draw(st.sampled_from(["simulate", "template", "compare"]))


def _poses_case(base, case):
    mech, edits, as_json, how = case
    rows = [ln.split(",") for ln in POSES[mech].splitlines()]
    for i, j, value in edits:  # a cell replaced (the header too), or a row repeated / dropped
        r = rows[i % len(rows)]
        if value == "-" and j % 2:
            rows.insert(j % len(rows), list(r))
        elif value == "-":
            rows.remove(r)
        else:
            r[j % len(r)] = value
    with workdir(base) as t:
        f = t / ("p.json" if as_json else "p.csv")
        if as_json:
            f.write_text('{"poses": [' + ", ".join("[" + ", ".join(c or '""' for c in r) + "]" for r in rows[1:])
                         + "]}")
        else:
            f.write_text("\n".join(",".join(r) for r in rows) + "\n")
        robot = base[mech]["robot"]
        if how == "simulate":
            check(["simulate", "--robot", robot, "--poses", f, "--set", "theta1=1", "--out", t / "d.csv"])
        elif how == "template":
            check(["compensate", base[mech]["result"], "--robot", robot, "--poses", f, "--template", "--out",
                   t / "c.csv"])
        else:
            check(["compare", "--robot", robot, "--poses", f, "--trials", "2", "--methods", "tsvd", "--quiet"])


@fuzz(QUICK)
@given(case=poses_mutated())
def test_pose_files(base, case):
    _poses_case(base, case)


@pytest.mark.slow
@fuzz(LONG)
@given(case=poses_mutated())
def test_pose_files_long(base, case):
    _poses_case(base, case)


# --------------------------------------------------------------------------- study specs

#: a spec whose cells hold more poses x trials than this is only loaded (--summary), not run: a fuzz case
#: must stay a fraction of a second (trials = 100000 is a valid spec)
RUN_LIMIT = 2000


def _spec_case(base, edits):
    from zerocal_sym.cli.study_spec import load_spec
    from zerocal_sym.errors import ZerocalError

    with workdir(base) as t:
        spec = t / "s.toml"
        spec.write_text(apply_toml_edits(SPEC, edits))
        try:
            study = load_spec(spec)
            heavy = sum(c.poses.shape[0] for c in study.cells) * study.trials > RUN_LIMIT
        except ZerocalError:
            heavy = False  # refused as the command will refuse it
        if heavy:
            check(["study", spec, "--summary", t])
            return
        rc = check(["study", spec, "--out", t / "out", "--quiet"])
        if rc != 0:
            assert not (t / "out" / "summary.json").exists()
        left = [p.name for p in (t / "out").rglob(".*")] if (t / "out").exists() else []
        assert left == [], left


@fuzz(QUICK)
@given(edits=toml_edits())
def test_study_specs(base, edits):
    _spec_case(base, edits)


@pytest.mark.slow
@fuzz(LONG)
@given(edits=toml_edits())
def test_study_specs_long(base, edits):
    _spec_case(base, edits)


SPEC = ('name = "fuzz"\nseed = 0\ntrials = 4\nchunk = 2\nrobots = ["paper.toml", "delta.toml"]\n'
        'noise = ["paper", 0.5]\nparams = "paper"\nstreams = "common"\n\n'
        '[[design]]\nscheme = "auto"\n\n[[design]]\nscheme = "auto"\nn = 4\nrobots = ["delta"]\nlabel = "ring4"\n\n'
        '[[truth]]\nname = "g1"\nrobots = ["paper"]\ntheta1 = 2\ntheta2 = -1\nrMx = 1\n\n'
        '[[truth]]\nname = "A"\nrobots = ["delta"]\ntheta1 = 2\ntheta2 = -1\ntheta3 = 0.5\nrMz = -0.5\n')


# --------------------------------------------------------------------------- the cases that were tracebacks

@pytest.mark.parametrize("edits, seed, how", [
    (["shuffle"], 1, "tsvd"), (["shuffle"], 1, "nlls"), (["shuffle"], 1, "huber"), (["shuffle"], 2, "nlls"),
    (["cumulative"], 0, "tsvd"), (["drop", "shuffle"], 3, "tsvd"),
], ids=lambda v: "+".join(v) if isinstance(v, list) else str(v))
def test_wrong_rows_are_refused_with_their_likely_cause(base, edits, seed, how):
    """Rows of a Delta round shuffled, cumulative or dropped: before, TSVD's report raised "the covariance of
    the changes is not positive definite" and Ipopt's (l2, huber) "SVD did not converge" (LAPACK printed
    "On entry to DLASCL" into the JSON on stdout).  Now: refused (exit 1), the fit check's paragraph on
    stderr, the JSON clean."""
    with workdir(base) as t:
        data = t / "d.csv"
        data.write_text(mutate_rows(base["delta"]["data_text"], edits, seed, ""))
        extra = {"tsvd": ["--method", "tsvd"], "nlls": [], "huber": ["--loss", "huber"]}[how]
        rc, out, err, raw = run(["identify", data, "--robot", base["delta"]["robot"], "--json", *extra])
        assert rc == 1 and raw == "" and "Traceback" not in err, (rc, raw, err)
        assert "no calibration written" in err and "Likely cause" in err, err
        result = json.loads(out)
        assert result["success"] is False and result["identifiability"]["K"] == result["data"]["K"]


def test_a_nonsense_estimate_is_not_accepted_despite_misfit(base):
    """--accept-misfit keeps a fit the noise model rejects, not an estimate where the model cannot even be
    evaluated (TSVD on shuffled rows ends at a MAEMM of metres): refused, exit 1, nothing written."""
    with workdir(base) as t:
        data = t / "d.csv"
        data.write_text(mutate_rows(base["delta"]["data_text"], ["shuffle"], 1, ""))
        rc, out, err, raw = run(["identify", data, "--robot", base["delta"]["robot"], "--method", "tsvd",
                                 "--accept-misfit", "--out", t / "r.json"])
        assert rc == 1 and raw == "" and "the exact model cannot be evaluated at the estimate" in err, err
        assert not (t / "r.json").exists()


def test_reversed_rows_of_a_small_ring(base):
    """The Delta's ring scheme with n = 4 (K = 8), rows reversed: the l2 fit and the huber loss end where the
    model is not finite; before, "SVD did not converge"."""
    with workdir(base) as t:
        data = t / "r4.csv"
        assert check(["simulate", "--robot", base["delta"]["robot"], "--scheme", "ring", "--n", "4", "--set",
                      "theta1=2", "--set", "theta2=-1", "--set", "theta3=0.5", "--out", data], record=False) == 0
        data.write_text(mutate_rows(data.read_text(), ["reverse"], 0, ""))
        for extra in ([], ["--loss", "huber"], ["--loss", "soft_l1"], ["--method", "tsvd"]):
            rc, out, err, raw = run(["identify", data, "--robot", base["delta"]["robot"], *extra])
            assert rc == 1 and raw == "" and "Traceback" not in err and "Likely cause" in err, (extra, err)
            assert out.strip().splitlines()[-1].startswith("verdict: rejected")


@pytest.mark.parametrize("key, value, words", [
    ("noise", "[1e308]", "noise factor 1e+308 must be >= 0 and at most 1000"),
    ("noise", "[{scale = 1, servo = 1e300}]", "factors >= 0 (at most 1000)"),
    ("chunk", "1000000000", "chunk must be a positive integer of at most 1000000"),
    ("trials", "1000000000000", "make 100000000 chunk files per cell"),
    ("n", "1000000000000", "n = 1000000000000: expected an integer >= 2 and <= 50000"),
    ("rMx", "1e308", "beyond the plausible |rM| <= 50 mm"),
    ("theta2", "1e308", "beyond the plausible 10 deg"),
])
def test_study_spec_values_out_of_range(base, key, value, words):
    """Study-spec values beyond their range: one line naming the spec's line, exit 2, nothing written.
    Before, noise = [1e308] was an OverflowError, n = 10^12 a MemoryError."""
    lines = SPEC.splitlines()
    if key == "trials":  # (with the default chunk)
        lines = [ln for ln in lines if not ln.startswith("chunk")]
    i = next(j for j, ln in enumerate(lines) if ln.startswith(f"{key} ="))
    lines[i] = f"{key} = {value}"
    with workdir(base) as t:
        spec = t / "s.toml"
        spec.write_text("\n".join(lines) + "\n")
        rc, out, err, raw = run(["study", spec, "--out", t / "out"])
        assert rc == 2 and len(err.strip().splitlines()) == 1, err
        assert f"s.toml:{i + 1}: " in err and words in err, err
        assert not (t / "out").exists()


@pytest.mark.parametrize("where", ["robot", "study", "tolerance"])
def test_arrays_nested_thousands_deep(base, where):
    """A value nested 3000 arrays deep: before, a RecursionError from the TOML (or JSON) parser."""
    deep = "[" * 3000 + "1" + "]" * 3000
    with workdir(base) as t:
        if where == "robot":
            f = t / "r.toml"
            f.write_text(PAPER_TOML.replace("L = 375", f"L = {deep}"))
            rc, _, err, _ = run(["robot", "--robot", f])
            line = PAPER_TOML.splitlines().index("L = 375") + 1
        elif where == "study":
            f = t / "s.toml"
            f.write_text(SPEC.replace('noise = ["paper", 0.5]', f"noise = {deep}"))
            rc, _, err, _ = run(["study", f, "--out", t / "out"])
            line = 6
        else:
            f = t / "tol.json"
            f.write_text('{"L1": ' + deep + "}")
            rc, _, err, _ = run(["identify", base["paper"]["data"], "--robot", base["paper"]["robot"],
                                 "--tolerance-file", f])
            line = None
        assert rc == 2 and len(err.strip().splitlines()) == 1 and "nested too deeply" in err, err
        if line is not None:
            assert f"{f.name}:{line}: " in err, err


@fuzz(8)
@given(case=result_mutated())
def test_result_files_in_the_report(base, case):
    """``zerocal report`` reads more of a results file than the others (the fit's record, the covariance, the
    residuals, the bias, an error budget): never a traceback either."""
    mech, edits, _ = case
    with workdir(base) as t:
        res = t / "r.json"
        res.write_text(mutate_json(base[mech]["result_text"], edits))
        check(["report", res, "--robot", base[mech]["robot"], "--data", base[mech]["data"], "--out", t / "r.html"])
