"""Hypothesis fuzz of the loaders: whatever the file holds, they return a valid
object or raise DataFileError -- never any other exception."""
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from zerocal_sym.io import measurements as data
from zerocal_sym.io.poses import load_poses
from zerocal_sym.io.results import load_result
from zerocal_sym.errors import DataFileError
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.mechanism import get_mechanism
from zerocal_sym.model.robot import paper_robot

ROOT = Path(__file__).resolve().parents[1]
VALID = (ROOT / "examples" / "measurements_example.csv").read_text()
ROBOT = paper_robot()
FUZZ = settings(suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow], deadline=None)

TOKENS = [",", "\n", "\r", "\r\n", " ", "#", '"', "'", ";", "\t", "\x00", "\ufeff", "\xb0", "é", "nan", "inf",
          "-inf", "1e999", "-", "+", "e", ".", "0", "1", "9", "-0", "1e-320", "1_0", "pose", "x_mm", "y_mm",
          "theta1_deg", "reading_mm", "# zerocal measurements v2", "# robot_sha256: x", "123456789012345678901234"]


def check_measurements(m):
    assert isinstance(m, Measurements)
    K = m.K
    assert K >= data.MIN_POSES
    mech = get_mechanism(m.mechanism)  # the file's, the robot's or the one its columns are
    assert m.theta_cmd.shape == (K, mech.m) and np.all(np.isfinite(m.theta_cmd))
    assert m.readings.shape == (K,) and np.all(np.isfinite(m.readings)) and m.readings[0] == 0
    assert m.target is None or (m.target.shape == (K, mech.n) and np.all(np.isfinite(m.target)))
    assert len(m.lines) == K and m.lines == sorted(set(m.lines))


def load_both(path):
    for robot in (None, ROBOT):
        try:
            m = data.load_measurements(path, robot=robot)
        except DataFileError as exc:
            assert "\n" not in str(exc) and str(exc).startswith(str(path))
        else:
            check_measurements(m)
            if robot is not None:
                assert m.mechanism == robot.mechanism_name


@FUZZ
@given(raw=st.binary(max_size=400))
def test_arbitrary_bytes(tmp_path, raw):
    p = tmp_path / "f.csv"
    p.write_bytes(raw)
    load_both(p)


@FUZZ
@given(text=st.text(max_size=300))
def test_arbitrary_text(tmp_path, text):
    p = tmp_path / "f.csv"
    p.write_bytes(text.encode("utf-8", "surrogatepass"))
    load_both(p)


@st.composite
def mutated(draw):
    """The valid example with a few edits: insert/delete/replace, line swaps, truncation."""
    text = VALID
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(["insert", "delete", "replace", "swap", "dup", "drop", "truncate", "cell"]))
        n = len(text)
        if kind == "insert":
            i = draw(st.integers(0, n))
            tok = draw(st.one_of(st.sampled_from(TOKENS), st.text(max_size=3)))
            text = text[:i] + tok + text[i:]
        elif kind == "delete" and n:
            i = draw(st.integers(0, n - 1))
            text = text[:i] + text[i + draw(st.integers(1, 5)):]
        elif kind == "replace" and n:
            i = draw(st.integers(0, n - 1))
            text = text[:i] + draw(st.sampled_from(TOKENS)) + text[i + 1:]
        elif kind in ("swap", "dup", "drop"):
            ls = text.split("\n")
            i, j = draw(st.integers(0, len(ls) - 1)), draw(st.integers(0, len(ls) - 1))
            if kind == "swap":
                ls[i], ls[j] = ls[j], ls[i]
            elif kind == "dup":
                ls.insert(j, ls[i])
            else:
                del ls[i]
            text = "\n".join(ls)
        elif kind == "truncate":
            text = text[:draw(st.integers(0, n))]
        elif kind == "cell":
            ls = text.split("\n")
            i = draw(st.integers(0, len(ls) - 1))
            cells = ls[i].split(",")
            j = draw(st.integers(0, len(cells) - 1))
            cells[j] = draw(st.one_of(st.sampled_from(TOKENS),
                                      st.floats(allow_nan=True, allow_infinity=True).map(repr)))
            ls[i] = ",".join(cells)
            text = "\n".join(ls)
    return text


@FUZZ
@given(text=mutated())
def test_mutated_valid_file(tmp_path, text):
    p = tmp_path / "f.csv"
    p.write_bytes(text.encode("utf-8", "surrogatepass"))
    load_both(p)


@FUZZ
@given(values=st.lists(st.floats(allow_nan=False, allow_infinity=False, width=64), min_size=12, max_size=12),
       readings=st.lists(st.floats(allow_nan=False, allow_infinity=False), min_size=5, max_size=5))
def test_any_numbers_in_a_well_formed_file(tmp_path, values, readings):
    """Well-formed files with arbitrary finite numbers: valid, or rejected with a DataFileError."""
    rows = "".join(f"{k},{values[2 * k]!r},{values[2 * k + 1]!r},{(0.0 if k == 0 else readings[k - 1])!r}\n"
                   for k in range(6))
    p = tmp_path / "f.csv"
    p.write_text("pose,theta1_deg,theta2_deg,reading_mm\n" + rows)
    load_both(p)


@FUZZ
@given(text=st.one_of(st.text(max_size=200), st.sampled_from(["{}", "[]", "null", '{"zero_offsets_deg": [1, 2]}',
                                                               '{"zero_offsets_deg": [1e400, 2]}',
                                                               '{"zero_offsets_deg": [true, 2], "success": 1}',
                                                               "[" * 5000 + "]" * 5000])))
def test_result_loader(tmp_path, text):
    p = tmp_path / "r.json"
    p.write_bytes(text.encode("utf-8", "surrogatepass"))
    try:
        r = load_result(p)
    except DataFileError:
        return
    mech = get_mechanism(r.mechanism)
    assert r.zero_offsets_deg.shape == (mech.m,) and np.all(np.isfinite(r.zero_offsets_deg))
    assert r.maemm_mm.shape == (mech.n,) and r.std_zero_offsets_deg.shape == (mech.m,)


@FUZZ
@given(text=st.text(alphabet=st.sampled_from(list("0123456789-.,e\n #xy_mposan")),
                    max_size=120), header=st.sampled_from(["", "x_mm,y_mm\n", "pose,x_mm,y_mm\n", "y_mm,x_mm\n", '{"poses": ', "{"]))
def test_pose_loader(tmp_path, text, header):
    p = tmp_path / "p.csv"
    p.write_text(header + text)
    try:
        P = load_poses(p, ROBOT)
    except DataFileError:
        return
    assert P.ndim == 2 and P.shape[1] == 2 and np.all(np.isfinite(P))
