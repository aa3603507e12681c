"""Every bad input through the command line: one line on stderr naming file,
line (and column where there is one), exit status 2, no output file."""
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from zerocal_sym.cli import main

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = (ROOT / "examples" / "measurements_example.csv").read_text()
ROBOT_TOML = (ROOT / "examples" / "paper_robot.toml").read_text()
LINES = EXAMPLE.split("\n")
HL = next(i for i, ln in enumerate(LINES, 1) if ln.startswith("pose,"))  # header line


def row(k):
    """(line number, cells) of pose k in the example."""
    i = HL + k  # pose k is on line HL + 1 + k
    return i + 1, LINES[i].split(",")


def edit(k, j, value):
    ln, cells = row(k)
    cells[j] = value
    ls = list(LINES)
    ls[ln - 1] = ",".join(cells)
    return "\n".join(ls), ln


def run_cli(capsys, argv):
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


def check_error(capsys, tmp_path, argv, pattern, where=None, command="identify"):
    outfile = tmp_path / "out.file"
    rc, out, err = run_cli(capsys, argv + ["--out", str(outfile)])
    assert rc == 2, (rc, out, err)
    lines = err.strip().split("\n")
    assert len(lines) == 1, err
    assert lines[0].startswith(f"zerocal {command}: error: "), err
    assert "Traceback" not in err
    if where is not None:
        assert f"{where}: " in lines[0], err
    assert re.search(pattern, lines[0]), err
    assert not outfile.exists(), "an output file was written"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out.file")], "temporary file left behind"
    return lines[0]


def data_file(tmp_path, text, name="d.csv"):
    p = tmp_path / name
    if isinstance(text, bytes):
        p.write_bytes(text)
    else:
        p.write_text(text)
    return p


# --------------------------------------------------------------------------- measurement files via identify

CASES = {
    "missing column": (lambda: ("\n".join(ln.replace(",reading_mm", "") if ln.startswith("pose,") else ln
                                          for ln in LINES), HL), r"missing column\(s\): reading_mm"),
    "extra column": (lambda: ("\n".join(ln.replace("y_mm", "y_mm,z_mm") if ln.startswith("pose,") else ln
                                        for ln in LINES), HL), r"unexpected column\(s\): 'z_mm' \(column 7"),
    "NaN": (lambda: edit(2, 1, "nan"), r"column 'theta1_deg' \(field 2\): nan is not a finite number"),
    "inf": (lambda: edit(3, 3, "inf"), r"column 'reading_mm' \(field 4\): inf is not a finite number"),
    "non-numeric": (lambda: edit(4, 2, "12,5".replace(",", ".") + "deg"),
                    r"column 'theta2_deg' \(field 3\): '12.5deg' is not a number"),
    "empty cell": (lambda: edit(1, 3, ""), r"column 'reading_mm' \(field 4\): empty cell"),
    "ragged row": (lambda: (EXAMPLE.replace(LINES[HL + 2], LINES[HL + 2] + ",1"), HL + 3),
                   r"7 fields, expected 6"),
    "pose numbering": (lambda: edit(3, 0, "4"), r"column 'pose' \(field 1\): expected 3, got 4"),
    "duplicated pose number": (lambda: edit(3, 0, "2"), r"pose 2 appears twice"),
    "duplicated pose": (lambda: (lambda t: (t, row(3)[0]))(
        "\n".join(LINES[:HL + 3] + [",".join(["3"] + row(1)[1][1:3] + ["0.5", "100", "700"])] + LINES[HL + 4:])),
        r"duplicated pose: pose 3 repeats the commanded joint angles of pose 1"),
    "target outside workspace": (lambda: edit(4, 5, "790"), r"target \(x_mm, y_mm\) pose .* is outside the workspace"),
    "commanded pose outside workspace": (lambda: edit(2, 1, "60"), r"commanded pose .* is outside the workspace"),
    "first reading": (lambda: edit(0, 3, "1.5"), r"the reading at pose 0 must be 0"),
    "header only": (lambda: ("\n".join(LINES[:HL]), HL), r"no data rows after the header"),
    "semicolons": (lambda: ("\n".join(ln.replace(",", ";") if not ln.startswith("#") else ln for ln in LINES), HL),
                   r"separator must be a comma"),
}


@pytest.mark.parametrize("case", list(CASES))
def test_bad_measurement_file(capsys, tmp_path, case):
    make, pattern = CASES[case]
    text, line = make()
    p = data_file(tmp_path, text)
    check_error(capsys, tmp_path, ["identify", str(p), "--method", "tsvd", "--json"], pattern, where=f"{p}:{line}")


def test_too_few_poses(capsys, tmp_path):
    p = data_file(tmp_path, "\n".join(LINES[:HL + 4]))
    check_error(capsys, tmp_path, ["identify", str(p)], r"too few poses: 4 \(at least 5", where=str(p))


@pytest.mark.parametrize("content,pattern", [
    ("", r"empty file: no header line and no data"),
    ("# just a comment\n\n", r"empty file"),
])
def test_empty_file(capsys, tmp_path, content, pattern):
    p = data_file(tmp_path, content)
    check_error(capsys, tmp_path, ["identify", str(p)], pattern, where=str(p))


def test_missing_file(capsys, tmp_path):
    check_error(capsys, tmp_path, ["identify", str(tmp_path / "nope.csv")], r"file not found",
                where=str(tmp_path / "nope.csv"))


def test_non_utf8(capsys, tmp_path):
    ln, cells = row(2)
    p = data_file(tmp_path, EXAMPLE.encode().replace(cells[1].encode(), b"\xe9" + cells[1].encode()))
    check_error(capsys, tmp_path, ["identify", str(p)], r"not UTF-8 text: byte 0xe9 at column 3", where=f"{p}:{ln}")


def test_binary_file(capsys, tmp_path):
    p = data_file(tmp_path, bytes(range(256)))
    check_error(capsys, tmp_path, ["identify", str(p)], r"binary data|not UTF-8", where=f"{p}:1")


def test_data_of_another_robot(capsys, tmp_path):
    toml = ROBOT_TOML.replace("L = 375", "L = 380")
    r = tmp_path / "other.toml"
    r.write_text(toml)
    p = data_file(tmp_path, EXAMPLE)
    sha_line = next(i for i, ln in enumerate(LINES, 1) if ln.startswith("# robot_sha256:"))
    check_error(capsys, tmp_path, ["identify", str(p), "--robot", str(r)], r"measured on another robot",
                where=f"{p}:{sha_line}")


def test_bom_and_crlf_are_accepted(capsys, tmp_path):
    p = data_file(tmp_path, ("\ufeff" + EXAMPLE.replace("\n", "\r\n")).encode())
    out = tmp_path / "r.json"
    rc, stdout, err = run_cli(capsys, ["identify", str(p), "--method", "tsvd", "--out", str(out)])
    assert rc == 0, err
    assert json.loads(out.read_text())["method"] == "tsvd"


# --------------------------------------------------------------------------- robot files

ROBOT_CASES = {
    "wrong units": (lambda t: t.replace('units = "mm"', 'units = "m"'), "units",
                    r"units = 'm' is not supported: robot files are in mm"),
    "unknown key": (lambda t: t.replace("dy = 51\n", "dy = 51\nwheelbase = 3\n"), "wheelbase",
                    r"unknown key 'wheelbase'"),  # (among the top-level keys, before the [tolerances] table)
    "missing key": (lambda t: t.replace("cy = 79\n", ""), None, r"missing key\(s\): cy"),
    "not a number": (lambda t: t.replace("H = 632", 'H = "632"'), "H", r"key 'H' must be a number"),
    "metres": (lambda t: "\n".join(ln for ln in t.split("\n") if not ln.startswith("units")).replace(
        "L = 375", "L = 0.375").replace("l = 825", "l = 0.825"), "L", r"look like metres"),
    "not TOML": (lambda t: t.replace("ex = 80", "ex == 80"), "ex", r"not valid TOML"),  # the line named
}


def _robot_where(path, text, key):
    if key is None:
        return str(path)
    ln = next(i for i, s in enumerate(text.split("\n"), 1) if re.match(rf"\s*{key}\s*=", s))
    return f"{path}:{ln}"


@pytest.mark.parametrize("case", list(ROBOT_CASES))
@pytest.mark.parametrize("command", ["identify", "robot", "compensate"])
def test_bad_robot_file(capsys, tmp_path, case, command):
    mutate, key, pattern = ROBOT_CASES[case]
    text = mutate(ROBOT_TOML)
    r = tmp_path / "bad.toml"
    r.write_text(text)
    where = _robot_where(r, text, key)
    if command == "identify":
        argv = ["identify", str(data_file(tmp_path, EXAMPLE)), "--robot", str(r)]
    elif command == "robot":
        argv = ["robot", "--robot", str(r)]
        rc, out, err = run_cli(capsys, argv)
        assert rc == 2 and len(err.strip().split("\n")) == 1 and f"{where}: " in err and re.search(pattern, err), err
        return
    else:
        argv = ["compensate", "--scheme", "paper", "--template", "--robot", str(r)]
    check_error(capsys, tmp_path, argv, pattern, where=where, command=command)


# --------------------------------------------------------------------------- results files via compensate

def _result(tmp_path, **over):
    d = {"method": "tsvd", "status": "ok", "success": True, "zero_offsets_deg": [-2.0, 1.0],
         "std_zero_offsets_deg": [0.5, 0.5], "maemm_mm": [1.0, -0.5]}
    d.update(over)
    p = tmp_path / "r.json"
    p.write_text(json.dumps(d, indent=2))
    return p


@pytest.mark.parametrize("over,pattern,line", [
    ({"zero_offsets_deg": [1.0]}, r"key 'zero_offsets_deg' must be a list of 2 numbers", 5),
    ({"zero_offsets_deg": [1.0, "x"]}, r"must be a list of 2 finite numbers", 5),
    ({"robot_sha256": "0" * 64}, r"identified on another robot", None),
])
def test_bad_result_file(capsys, tmp_path, over, pattern, line):
    p = _result(tmp_path, **over)
    where = f"{p}:{line}" if line else str(p)
    check_error(capsys, tmp_path, ["compensate", str(p)], pattern, where=where, command="compensate")


@pytest.mark.parametrize("over,pattern", [
    ({"success": False, "status": "Ipopt: Infeasible_Problem_Detected"}, "not a calibration: Ipopt: Infeasible"),
    ({"zero_offsets_deg": [45.0, 1.0]}, "theta1 = +45 deg is beyond the plausible 10 deg"),
])
def test_implausible_result_refused(capsys, tmp_path, over, pattern):
    """A failed or implausible result: compensate refuses it (exit 1, one line with the reasons), writes nothing."""
    p = _result(tmp_path, **over)
    out = tmp_path / "table.csv"
    rc = main(["compensate", str(p), "--out", str(out)])
    o, err = capsys.readouterr()
    assert rc == 1 and not out.exists() and len(err.strip().splitlines()) == 1 and pattern in err, err


def test_result_not_json(capsys, tmp_path):
    p = tmp_path / "r.json"
    p.write_text('{\n  "zero_offsets_deg": [1, 2],\n  "method": tsvd\n}\n')
    check_error(capsys, tmp_path, ["compensate", str(p)], r"not valid JSON: Expecting value \(column 13\)",
                where=f"{p}:3", command="compensate")


def test_pose_file_outside_workspace(capsys, tmp_path):
    p = data_file(tmp_path, "pose,x_mm,y_mm\n0,-240,632\n1,0,600\n", "poses.csv")
    check_error(capsys, tmp_path, ["compensate", str(_result(tmp_path)), "--poses", str(p)],
                r"pose 1 \(0, 600\) mm is outside the workspace", where=f"{p}:3", command="compensate")


def test_compensate_needs_result_or_template(capsys, tmp_path):
    check_error(capsys, tmp_path, ["compensate"], r"give RESULT.json", command="compensate")


def test_scheme_with_too_small_n(capsys, tmp_path):
    check_error(capsys, tmp_path, ["compensate", str(_result(tmp_path)), "--scheme", "paper", "--n", "1"],
                r"n >= 2", command="compensate")


def test_existing_output_untouched_on_error(capsys, tmp_path):
    out = tmp_path / "r.json"
    out.write_text("previous\n")
    p = data_file(tmp_path, edit(2, 1, "nan")[0])
    rc = main(["identify", str(p), "--out", str(out)])
    capsys.readouterr()
    assert rc == 2 and out.read_text() == "previous\n"


def test_console_script_exit_status(tmp_path):
    """The installed entry point itself: status 2, one line, no traceback."""
    p = data_file(tmp_path, edit(2, 1, "nan")[0])
    r = subprocess.run([sys.executable, "-m", "zerocal_sym", "identify", str(p)], capture_output=True, text=True)
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and "Traceback" not in r.stderr
    assert f"{p}:{row(2)[0]}: column 'theta1_deg' (field 2): nan is not a finite number" in r.stderr


# --------------------------------------------------------------------------- verify and unwritable outputs

def test_verify_bad_data(capsys, tmp_path):
    p = data_file(tmp_path, edit(2, 1, "inf")[0])
    check_error(capsys, tmp_path, ["verify", str(_result(tmp_path)), str(p)], r"inf is not a finite number",
                where=f"{p}:{row(2)[0]}", command="verify")


def test_verify_bad_result(capsys, tmp_path):
    p = data_file(tmp_path, EXAMPLE)
    check_error(capsys, tmp_path, ["verify", str(_result(tmp_path, success=False)), str(p)],
                r"the identification failed", command="verify")


def test_verify_bad_mu0(capsys, tmp_path):
    p = data_file(tmp_path, EXAMPLE)
    check_error(capsys, tmp_path, ["verify", str(_result(tmp_path)), str(p), "--mu0", "-1"],
                r"--mu0 must be a positive number", command="verify")


@pytest.mark.parametrize("command", ["compensate", "verify"])
def test_output_is_a_directory(capsys, tmp_path, command):
    argv = (["compensate", str(_result(tmp_path))] if command == "compensate"
            else ["verify", str(_result(tmp_path)), str(data_file(tmp_path, EXAMPLE))])
    rc, out, err = run_cli(capsys, argv + ["--out", str(tmp_path)])
    assert rc == 2 and err.count("\n") == 1 and str(tmp_path) in err, err
    assert "cannot write the output" in err or "is a directory" in err, err
