"""The measurement format at the API level: round trip, the example file, and
every kind of bad input (message names file, line and column)."""
import importlib.util
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym.io import measurements as data
from zerocal_sym.io.compensation import compensated_commands, format_compensation
from zerocal_sym.io.poses import load_poses
from zerocal_sym.io.results import load_result
from zerocal_sym.model import kinematics
from zerocal_sym.paper import scheme
from zerocal_sym.errors import DataFileError
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.paper.tables import table2_errors

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "measurements_example.csv"
HEADER = "pose,theta1_deg,theta2_deg,reading_mm,x_mm,y_mm"
HL = 4  # header line of the files written by format_measurements(good_meas): format, mechanism, robot_sha256


@pytest.fixture(scope="module")
def good_meas():
    from zerocal_sym.model.robot import paper_robot

    robot = paper_robot()
    P = scheme.paper_poses(robot, 3)
    th = kinematics.ik(robot, P)
    s = VirtualPlant(robot, table2_errors(1)).measure(th, NoiseModel.paper(), 7)
    return Measurements(th, s, P, {"robot_sha256": robot.sha256})


@pytest.fixture
def good_text(good_meas):
    return data.format_measurements(good_meas)


def write(tmp_path, text, name="m.csv"):
    p = tmp_path / name
    if isinstance(text, bytes):
        p.write_bytes(text)
    else:
        p.write_text(text, encoding="utf-8")
    return p


def lines_of(text):
    return text.split("\n")


def replace_line(text, lineno, new):
    ls = lines_of(text)
    ls[lineno - 1] = new
    return "\n".join(ls)


def data_line(text, pose):
    """1-based line number of the data row of ``pose``."""
    for i, ln in enumerate(lines_of(text), 1):
        if ln.startswith(f"{pose},"):
            return i
    raise AssertionError(pose)


def expect(tmp_path, text, pattern, line=None, robot=None, **kw):
    p = write(tmp_path, text)
    with pytest.raises(DataFileError) as ei:
        data.load_measurements(p, robot=robot, **kw)
    msg = str(ei.value)
    assert "\n" not in msg
    assert msg.startswith(str(p)), msg
    if line is not None:
        assert ei.value.where == f"{p}:{line}", msg
    assert re.search(pattern, msg), msg
    return msg


# --------------------------------------------------------------------------- round trip and example

def test_round_trip_exact(tmp_path, good_meas, robot):
    p = tmp_path / "m.csv"
    data.write_measurements(p, good_meas)
    m = data.load_measurements(p, robot=robot)
    # degrees in the file: exact to the last bit or two of the radians
    np.testing.assert_allclose(m.theta_cmd, good_meas.theta_cmd, rtol=1e-15, atol=0)
    assert np.array_equal(m.readings, good_meas.readings)
    assert np.array_equal(m.target, good_meas.target)
    assert m.meta["robot_sha256"] == robot.sha256
    assert m.K == 6 and m.changes.shape == (5,)
    assert m.lines == [data_line(p.read_text(), k) for k in range(6)]
    assert lines_of(p.read_text())[:HL] == [data.FORMAT_LINE, "# mechanism: planar_2dof",
                                            f"# robot_sha256: {robot.sha256}", HEADER]
    assert m.mechanism == "planar_2dof" and m.meta_lines["mechanism"] == 2


def test_without_targets_and_any_column_order(tmp_path, good_meas, robot):
    deg = np.degrees(good_meas.theta_cmd)
    text = "reading_mm,theta2_deg,pose,theta1_deg\n" + "".join(
        f"{float(good_meas.readings[k])!r},{float(deg[k, 1])!r},{k},{float(deg[k, 0])!r}\n" for k in range(6))
    m = data.load_measurements(write(tmp_path, text), robot=robot)
    assert m.target is None
    np.testing.assert_allclose(m.theta_cmd, good_meas.theta_cmd, rtol=0, atol=1e-15)


def test_tolerated_variations(tmp_path, good_text, robot):
    """BOM, CRLF, blank lines, comments between rows, spaces around cells."""
    text = "\ufeff" + good_text.replace("\n", "\r\n")
    m = data.load_measurements(write(tmp_path, text), robot=robot)
    assert m.K == 6
    ls = lines_of(good_text)
    ls.insert(data_line(good_text, 2), "   ")
    ls.insert(data_line(good_text, 4), "# a comment between rows")
    ls = [ln.replace(",", " , ") if ln and ln[0].isdigit() else ln for ln in ls]
    m2 = data.load_measurements(write(tmp_path, "\n".join(ls), "v.csv"), robot=robot)
    np.testing.assert_array_equal(m2.readings, m.readings)


def test_example_file_is_valid_and_reproducible(robot, tmp_path):
    m = data.load_measurements(EXAMPLE, robot=robot)
    assert m.K == 6 and m.meta["robot_sha256"] == robot.sha256
    np.testing.assert_allclose(m.target, scheme.paper_poses(robot, 3))
    spec = importlib.util.spec_from_file_location("make_measurements_example",
                                                  ROOT / "examples" / "make_measurements_example.py")
    mk = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mk)
    assert data.format_measurements(mk.make_example()) == EXAMPLE.read_text()


def test_template_round_trip(tmp_path, good_meas, robot):
    text = data.format_template(good_meas.theta_cmd, good_meas.target)
    p = write(tmp_path, text)
    with pytest.raises(DataFileError, match=r"column 'reading_mm' \(field 4\): empty cell \(fill in"):
        data.load_measurements(p, robot=robot)
    # filling it in gives a valid file
    ls = lines_of(text)
    for k in range(1, 6):
        i = data_line(text, k) - 1
        cells = ls[i].split(",")
        cells[3] = repr(float(good_meas.readings[k]))
        ls[i] = ",".join(cells)
    m = data.load_measurements(write(tmp_path, "\n".join(ls), "f.csv"), robot=robot)
    np.testing.assert_array_equal(m.readings, good_meas.readings)


# --------------------------------------------------------------------------- bad input: columns

def test_missing_column(tmp_path, good_text):
    text = good_text.replace(HEADER, HEADER.replace("reading_mm", "x_reading"))
    expect(tmp_path, text, r"unexpected column\(s\): 'x_reading' \(column 4", line=HL)
    cols = HEADER.split(",")
    ls = [",".join(c for j, c in enumerate(ln.split(",")) if j != 3) if ln and not ln.startswith("#") else ln
          for ln in lines_of(good_text)]
    expect(tmp_path, "\n".join(ls), r"missing column\(s\): reading_mm", line=HL)
    assert cols[3] == "reading_mm"


def test_extra_column(tmp_path, good_text):
    ls = [ln + ",1" if ln and not ln.startswith("#") else ln for ln in lines_of(good_text)]
    ls[HL - 1] = HEADER + ",temperature_C"
    expect(tmp_path, "\n".join(ls), r"unexpected column\(s\): 'temperature_C' \(column 7\)", line=HL)


def test_misspelt_column_hint(tmp_path, good_text):
    text = good_text.replace("theta1_deg", "Theta1_deg")
    expect(tmp_path, text, r"'Theta1_deg' \(column 2; did you mean 'theta1_deg'\?\)", line=HL)


def test_duplicated_column(tmp_path, good_text):
    text = good_text.replace("x_mm,y_mm", "x_mm,x_mm")
    expect(tmp_path, text, r"duplicated column\(s\): x_mm", line=HL)


def test_x_without_y(tmp_path, good_text):
    ls = [",".join(ln.split(",")[:5]) if ln and not ln.startswith("#") else ln for ln in lines_of(good_text)]
    expect(tmp_path, "\n".join(ls), r"x_mm and y_mm go together", line=HL)


def test_trailing_comma_in_header(tmp_path, good_text):
    expect(tmp_path, good_text.replace(HEADER, HEADER + ","), r"column 7 of the header has no name", line=HL)


def test_semicolon_separator(tmp_path, good_text):
    ls = [ln.replace(",", ";") if ln and not ln.startswith("#") else ln for ln in lines_of(good_text)]
    expect(tmp_path, "\n".join(ls), r"separator must be a comma, found ';'", line=HL)


def test_no_header(tmp_path, good_text):
    text = good_text.replace(HEADER + "\n", "")
    expect(tmp_path, text, r"no header line", line=HL)


# --------------------------------------------------------------------------- bad input: cells

@pytest.mark.parametrize("bad,pattern", [
    ("nan", r"column 'theta2_deg' \(field 3\): nan is not a finite number"),
    ("inf", r"column 'theta2_deg' \(field 3\): inf is not a finite number"),
    ("-Infinity", r"column 'theta2_deg' \(field 3\): -Infinity is not a finite number"),
    ("12.3.4", r"column 'theta2_deg' \(field 3\): '12.3.4' is not a number"),
    ("abc", r"column 'theta2_deg' \(field 3\): 'abc' is not a number"),
    ("", r"column 'theta2_deg' \(field 3\): empty cell"),
])
def test_bad_cell(tmp_path, good_text, bad, pattern):
    ln = data_line(good_text, 3)
    cells = lines_of(good_text)[ln - 1].split(",")
    cells[2] = bad
    expect(tmp_path, replace_line(good_text, ln, ",".join(cells)), pattern, line=ln)


def test_nan_reading(tmp_path, good_text):
    ln = data_line(good_text, 5)
    cells = lines_of(good_text)[ln - 1].split(",")
    cells[3] = "NaN"
    expect(tmp_path, replace_line(good_text, ln, ",".join(cells)), r"column 'reading_mm' \(field 4\): NaN", line=ln)


@pytest.mark.parametrize("delta,pattern", [(-1, r"5 fields, expected 6"), (+1, r"7 fields, expected 6 .*is extra")])
def test_ragged_rows(tmp_path, good_text, delta, pattern):
    ln = data_line(good_text, 2)
    row = lines_of(good_text)[ln - 1]
    row = ",".join(row.split(",")[:-1]) if delta < 0 else row + ",9"
    expect(tmp_path, replace_line(good_text, ln, row), pattern, line=ln)


def test_malformed_quotes(tmp_path, good_text):
    ln = data_line(good_text, 1)
    expect(tmp_path, replace_line(good_text, ln, '1,"2"x,3,4,5,6'), r"malformed CSV line", line=ln)


# --------------------------------------------------------------------------- bad input: poses

def test_pose_numbering(tmp_path, good_text):
    ln = data_line(good_text, 3)
    row = lines_of(good_text)[ln - 1]
    expect(tmp_path, replace_line(good_text, ln, "7" + row[1:]), r"column 'pose' \(field 1\): expected 3, got 7",
           line=ln)
    expect(tmp_path, replace_line(good_text, ln, "2.5" + row[1:]), r"'2.5' is not a whole number", line=ln)


def test_pose_numbering_from_one(tmp_path, good_text):
    ls = lines_of(good_text)
    ls = [str(int(ln.split(",")[0]) + 1) + ln[ln.index(","):] if ln[:1].isdigit() else ln for ls_ in [ls]
          for ln in ls_]
    expect(tmp_path, "\n".join(ls), r"expected 0, got 1 \(numbering starts at 0\)", line=data_line(good_text, 0))


def test_duplicated_pose_number(tmp_path, good_text):
    l2, l3 = data_line(good_text, 2), data_line(good_text, 3)
    row = lines_of(good_text)[l3 - 1]
    expect(tmp_path, replace_line(good_text, l3, "2" + row[1:]), rf"pose 2 appears twice \(lines {l2} and {l3}\)",
           line=l3)


def test_duplicated_pose_angles(tmp_path, good_text):
    l1, l4 = data_line(good_text, 1), data_line(good_text, 4)
    c1 = lines_of(good_text)[l1 - 1].split(",")
    c4 = lines_of(good_text)[l4 - 1].split(",")
    c4[1:3] = c1[1:3]
    c4[4:6] = ["100", "700"]
    expect(tmp_path, replace_line(good_text, l4, ",".join(c4)),
           rf"duplicated pose: pose 4 repeats the commanded joint angles of pose 1 \(line {l1}\)", line=l4)


def test_duplicated_target(tmp_path, good_text):
    l1, l4 = data_line(good_text, 1), data_line(good_text, 4)
    c1 = lines_of(good_text)[l1 - 1].split(",")
    c4 = lines_of(good_text)[l4 - 1].split(",")
    c4[4:6] = c1[4:6]
    expect(tmp_path, replace_line(good_text, l4, ",".join(c4)), r"pose 4 repeats the target", line=l4)


def test_too_few_poses(tmp_path, good_text):
    ls = lines_of(good_text)
    text = "\n".join(ls[:data_line(good_text, 3)])
    expect(tmp_path, text, r"too few poses: 4 \(at least 5")
    assert data.load_measurements(write(tmp_path, text, "ok.csv"), min_poses=3).K == 4


def test_first_reading_not_zero(tmp_path, good_text):
    ln = data_line(good_text, 0)
    cells = lines_of(good_text)[ln - 1].split(",")
    cells[3] = "0.5"
    expect(tmp_path, replace_line(good_text, ln, ",".join(cells)), r"reading at pose 0 must be 0", line=ln)


def test_pose_outside_workspace(tmp_path, good_meas, robot):
    P = good_meas.target.copy()
    P[2] = (400.0, 700.0)   # reachable, outside the 480 x 150 rectangle
    th = kinematics.ik(robot, P)
    text = data.format_measurements(Measurements(th, good_meas.readings, None))
    msg = expect(tmp_path, text, r"commanded pose \(400.000, 700.000\) mm is outside the workspace",
                 line=data_line(text, 2), robot=robot)
    assert "x in [-240, 240]" in msg
    # without a robot, the geometry is not checked
    assert data.load_measurements(write(tmp_path, text, "n.csv")).K == 6


def test_target_outside_workspace(tmp_path, good_text, robot):
    ln = data_line(good_text, 5)
    cells = lines_of(good_text)[ln - 1].split(",")
    cells[5] = "790"
    expect(tmp_path, replace_line(good_text, ln, ",".join(cells)),
           r"target \(x_mm, y_mm\) pose \(240.000, 790.000\) mm is outside", line=ln, robot=robot)


def test_commanded_angles_far_off(tmp_path, good_text, robot):
    """(Every pair of angles is an assembly of the paper's robot: 2 l > 2 ex + 2 L.)"""
    ln = data_line(good_text, 2)
    cells = lines_of(good_text)[ln - 1].split(",")
    cells[1:3] = ["90", "-90"]
    expect(tmp_path, replace_line(good_text, ln, ",".join(cells)), r"commanded pose \(.*\) mm is outside the "
           r"workspace", line=ln, robot=robot)


def test_unassemblable_pose(tmp_path, good_text):
    """A robot whose distal links cannot always close: the angles are no assembly (first bad pose named)."""
    from dataclasses import replace

    from zerocal_sym.model.robot import paper_robot

    r = paper_robot()
    short = replace(r, geometry=r.geometry * np.array([1, 1, 1, 1, 1, 1, 0.35, 0.35, 1, 1, 1, 1]))
    ln = data_line(good_text, 2)
    cells = lines_of(good_text)[ln - 1].split(",")
    cells[1:3] = ["-90", "270"]
    text = replace_line(good_text, ln, ",".join(cells)).replace("# robot_sha256", "# other")
    expect(tmp_path, text, r"commanded joint angles \(22.7339, 207.807\) deg are not an assembly of the robot",
           line=data_line(good_text, 0), robot=short)


def test_radians_instead_of_degrees(tmp_path, good_meas, robot):
    deg = good_meas.theta_cmd.copy()
    text = data.format_measurements(Measurements(np.radians(deg), good_meas.readings, good_meas.target))
    expect(tmp_path, text, r"pose 0|not an assembly|outside the workspace|from the target", robot=robot,
           line=data_line(text, 0))


def test_swapped_target_columns(tmp_path, good_text, robot):
    ln = data_line(good_text, 1)
    cells = lines_of(good_text)[ln - 1].split(",")
    cells[4] = "-200"   # commanded angles reach (0, 632), target says (-200, 632)
    expect(tmp_path, replace_line(good_text, ln, ",".join(cells)), r"200.0 mm from the target", line=ln,
           robot=robot)


def test_robot_hash_mismatch(tmp_path, good_text, robot):
    text = good_text.replace(robot.sha256, "0" * 64)
    expect(tmp_path, text, r"measured on another robot", line=HL - 1, robot=robot)


# --------------------------------------------------------------------------- bad input: the file itself

def test_missing_file(tmp_path):
    with pytest.raises(DataFileError, match=r"m.csv: file not found"):
        data.load_measurements(tmp_path / "m.csv")


def test_directory(tmp_path):
    with pytest.raises(DataFileError, match=r"is a directory"):
        data.load_measurements(tmp_path)


@pytest.mark.parametrize("text", ["", "\n\n  \n", "# only a comment\n# zerocal measurements v1\n"])
def test_empty_file(tmp_path, text):
    expect(tmp_path, text, r"empty file: no header line and no data")


def test_header_only(tmp_path):
    expect(tmp_path, FORMAT_LINE_AND(HEADER), r"no data rows after the header", line=2)


def FORMAT_LINE_AND(header):
    return data.FORMAT_LINE + "\n" + header + "\n"


def test_non_utf8(tmp_path, good_text):
    raw = good_text.encode().replace(b"0,22.7", b"0,2\xb02.7")
    p = write(tmp_path, raw)
    ln = data_line(good_text, 0)
    with pytest.raises(DataFileError, match=rf"m.csv:{ln}: not UTF-8 text: byte 0xb0 at column 4"):
        data.load_measurements(p)


def test_utf16(tmp_path, good_text):
    p = write(tmp_path, good_text.encode("utf-16"))
    with pytest.raises(DataFileError, match=r"UTF-16 encoded: save it as UTF-8"):
        data.load_measurements(p)


def test_binary(tmp_path, good_text):
    p = write(tmp_path, good_text.encode()[:50] + b"\x00\x01\x02")
    with pytest.raises(DataFileError, match=r"m.csv:2: binary data \(NUL byte\)"):
        data.load_measurements(p)


def test_unsupported_version(tmp_path, good_text):
    expect(tmp_path, good_text.replace("measurements v1", "measurements v2"), r"unsupported format line", line=1)


# --------------------------------------------------------------------------- pose lists, results, compensation

def test_load_poses(tmp_path, robot):
    p = write(tmp_path, "# my poses\nx_mm,y_mm\n-240,632\n0,700\n", "p.csv")
    np.testing.assert_array_equal(load_poses(p, robot), [[-240, 632], [0, 700]])
    p = write(tmp_path, "pose,x_mm,y_mm\n0,-240,632\n1,0,900\n", "p.csv")
    with pytest.raises(DataFileError, match=r"p.csv:3: pose 1 \(0, 900\) mm is outside the workspace"):
        load_poses(p, robot)
    p = write(tmp_path, "x_mm,z_mm\n1,2\n", "p.csv")
    with pytest.raises(DataFileError, match=r"p.csv:1: unexpected column"):
        load_poses(p)
    p = write(tmp_path, "x_mm,y_mm\n", "p.csv")
    with pytest.raises(DataFileError, match=r"p.csv:1: no data rows"):
        load_poses(p)
    # a design JSON (zerocal design --json)
    p = write(tmp_path, json.dumps({"K": 2, "poses": [[-240, 632], [240, 782.0]]}, indent=1), "d.json")
    np.testing.assert_array_equal(load_poses(p, robot), [[-240, 632], [240, 782]])
    p = write(tmp_path, json.dumps({"K": 2, "poses": [[-240, 632], [240]]}, indent=1), "d.json")
    with pytest.raises(DataFileError, match=r"d.json:3: key 'poses' must be a non-empty list of \[x_mm, y_mm\]"):
        load_poses(p, robot)


def _result_json(**over):
    d = {"method": "tsvd", "status": "ok", "success": True, "zero_offsets_deg": [2.0, -1.0],
         "std_zero_offsets_deg": [0.05, None], "maemm_mm": [1.0, 0.5]}
    d.update(over)
    return json.dumps(d, indent=2)


def test_load_result(tmp_path):
    r = load_result(write(tmp_path, _result_json(robot_sha256="AB" * 32), "r.json"))
    np.testing.assert_array_equal(r.zero_offsets_deg, [2.0, -1.0])
    assert r.std_zero_offsets_deg[0] == 0.05 and np.isnan(r.std_zero_offsets_deg[1])
    assert r.robot_sha256 == "ab" * 32 and r.method == "tsvd" and r.success


@pytest.mark.parametrize("text,pattern", [
    ('{"zero_offsets_deg": [1,', r"r.json:1: not valid JSON"),
    ("[1, 2]", r"a results file is a JSON object"),
    ('{"method": "tsvd"}', r"missing key 'zero_offsets_deg'"),
    (_result_json(zero_offsets_deg=[1.0]), r"r.json:5: key 'zero_offsets_deg' must be a list of 2 numbers"),
    (_result_json(zero_offsets_deg=[1.0, "x"]), r"must be a list of 2 finite numbers"),
    (_result_json().replace("-1.0", "NaN"), r"not valid JSON: NaN is not allowed"),
    (_result_json(success=False, status="rank 3"), r"r.json:4: the identification failed \(status: rank 3\)"),
    ("", r"empty results file"),
])
def test_bad_result(tmp_path, text, pattern):
    p = write(tmp_path, text, "r.json")
    with pytest.raises(DataFileError, match=pattern):
        load_result(p)


def test_compensated_commands_sign(robot):
    """Commanding IK(P) - offset on a plant with that offset reaches P."""
    P = scheme.paper_poses(robot, 3)
    err = np.zeros(12)
    err[:2] = np.radians([2.0, -1.0])
    nominal, cmd = compensated_commands(robot, P, [2.0, -1.0])
    np.testing.assert_allclose(np.degrees(nominal - cmd), np.broadcast_to([2.0, -1.0], (6, 2)), atol=1e-12)
    np.testing.assert_allclose(VirtualPlant(robot, err).actual_pose(cmd), P, atol=1e-8)
    assert np.max(np.linalg.norm(VirtualPlant(robot, err).actual_pose(nominal) - P, axis=1)) > 5


def test_compensation_table_states_the_sign(tmp_path):
    r = load_result(write(tmp_path, _result_json(), "r.json"))
    text = format_compensation(r)
    assert "theta_cmd = IK(P) - offset_deg" in text
    rows = [ln for ln in text.splitlines() if not ln.startswith("#")]
    assert rows == ["joint,offset_deg,std_deg", "theta1,2.0,0.05", "theta2,-1.0,"]


def test_runtime_module_has_no_heavy_imports():
    code = "import sys, zerocal_sym.io.measurements; assert 'matplotlib' not in sys.modules and 'sympy' not in sys.modules"
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0
