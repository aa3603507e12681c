"""Controller exports (``zerocal compensate --format klipper|rrf``, zerocal_sym/io/controllers.py) of a linear Delta.

Each export is read back by the small parsers below (written here, independently of the writer): the offsets
come back to the digits written; the towers map to the controller's by their azimuth; and a model of each
firmware, built from the exported text alone (Klipper's and RRF's delta kinematics and homing as their sources
state them), puts the effector where it is commanded once the endstops are corrected -- and does not before.
"""
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym.cli import main
from zerocal_sym.errors import ZerocalError
from zerocal_sym.io import controllers
from zerocal_sym.io.results import ResultFile
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.robot import load_robot

ROOT = Path(__file__).resolve().parents[1]
LINEAR = ROOT / "examples" / "linear_delta.toml"
DELTA_S = np.array([0.8, -0.5, 0.3])  # mm, joint order s1, s2, s3: the simulated round's
#: offsets of the unit tests: more digits than either format writes, so that the rounding is exercised
FINE_S = np.array([0.8123456789, -0.4987654321, 0.3011223344])
#: the controllers' default tower angles (deg), by tower name: Klipper's a, b, c and RRF's X, Y, Z
DEFAULT_ANGLES = {"a": 210.0, "b": 330.0, "c": 90.0, "X": 210.0, "Y": 330.0, "Z": 90.0}
#: azimuths (deg) of s1, s2, s3: the robot file's defaults, permuted, off the defaults, rotated by 30 deg
AZIMUTHS = [(90, 210, 330), (210, 330, 90), (330, 90, 210), (95.54321, 204.12345, 333.00067), (0, 120, 240),
            (90, 330, 210)]


def linear_robot(tmp_path, phi=None, extra=""):
    """The example linear Delta with tower azimuths ``phi`` (deg) and ``extra`` geometry lines."""
    text = LINEAR.read_text()
    lines = "".join(f"phi{i + 1} = {p}\n" for i, p in enumerate(phi or ())) + extra
    text = text.replace("[geometry]\n", "[geometry]\n" + lines, 1)
    for alias in ("R", "l"):  # per-tower values replace the file's one for all towers
        if f"{alias}1 =" in extra:
            text = re.sub(rf"(?m)^{alias} = .*\n", "", text)
    p = tmp_path / f"robot_{abs(hash((tuple(phi or ()), extra)))}.toml"
    p.write_text(text)
    return load_robot(p)


def result(offsets=FINE_S, std=(0.009, 0.0093, 0.0089), estimate=None):
    off = np.asarray(offsets, float)
    est = dict(estimate or {})
    est.update({f"s{i + 1}": float(v) for i, v in enumerate(off)})
    return ResultFile(off, np.asarray(std, float), np.zeros(3), "nlls", "converged", True, None, {}, "r.json",
                      mechanism="delta_linear", estimate=est)


# --------------------------------------------------------------------------- the parsers (of the lines we write)

def parse_klipper(text):
    """``{section: {key: float | str}}`` of the value lines, and ``{section: d}`` of the ``<current> +- d``
    comments."""
    sections, corrections, cur = {}, {}, None
    for line in text.splitlines():
        s = line.strip()
        m = re.fullmatch(r"\[(\w+)\]", s)
        if m:
            cur = m.group(1)
            sections[cur] = {}
            continue
        m = re.fullmatch(r"# position_endstop: <current> ([+-]) (\d+\.\d+)", s)
        if m:
            corrections[cur] = float(m.group(1) + m.group(2))
            continue
        if not s or s.startswith("#"):
            continue
        key, value = (v.strip() for v in s.split(":", 1))
        try:
            sections[cur][key] = float(value)
        except ValueError:
            sections[cur][key] = value
    return sections, corrections


def parse_gcode_words(line):
    """``M665 L300:301:302 R120 X0.5`` -> ``{"L": [300, 301, 302], "R": [120], "X": [0.5]}``."""
    words = line.split()[1:]
    return {w[0]: [float(v) for v in w[1:].split(":")] for w in words}


def parse_rrf(text):
    """The words of the M665 and M666 lines and the ``M666 X<current> +- d ...`` comment, by letter."""
    m665 = m666 = None
    corrections = {}
    for line in text.splitlines():
        if line.startswith("M665 "):
            m665 = parse_gcode_words(line)
        elif line.startswith("M666 "):
            m666 = {k: v[0] for k, v in parse_gcode_words(line).items()}
        elif line.startswith("; M666 ") and "<current>" in line:
            for name, sign, d in re.findall(r"(\w)<current> ([+-]) (\d+\.\d+)", line):
                corrections[name] = float(sign + d)
    return m665, m666, corrections


def joint_at(robot, azimuth_deg, within=1e-5):
    """The joint whose tower stands at ``azimuth_deg`` (the physical tower), to ``within`` deg."""
    phis = [math.degrees(robot.param(f"phi{j + 1}")) for j in range(3)]
    j = int(np.argmin([abs((p - azimuth_deg + 180) % 360 - 180) for p in phis]))
    assert abs((phis[j] - azimuth_deg + 180) % 360 - 180) < within, (phis, azimuth_deg)
    return j


def tol(fmt):
    """Half the last digit written, and the round-off of the sum of two written values."""
    return 10.0 ** -controllers.FORMATS[fmt].digits


# --------------------------------------------------------------------------- declarations

def test_formats_of_each_mechanism():
    from zerocal_sym.model.mechanism import get_mechanism

    assert controllers.formats_for(get_mechanism("delta_linear")) == ["csv", "klipper", "rrf"]
    for name in ("planar_2dof", "delta_rotary", "hexapod"):
        assert controllers.formats_for(get_mechanism(name)) == ["csv"], name
    why = controllers.KLIPPER.refusal(get_mechanism("delta_rotary"))
    assert "revolute" in why
    assert "6 joints" in controllers.RRF.refusal(get_mechanism("hexapod"))


# --------------------------------------------------------------------------- round trips

@pytest.mark.parametrize("phi", AZIMUTHS)
@pytest.mark.parametrize("endstop", [None, (300.0,), (300.1, 299.9, 300.3)])
def test_klipper_round_trip(tmp_path, phi, endstop):
    robot = linear_robot(tmp_path, phi)
    text = controllers.format_klipper(robot, result(), None if endstop is None else np.broadcast_to(endstop, 3))
    sections, corrections = parse_klipper(text)
    assert sections["printer"]["kinematics"] == "delta"
    assert sections["printer"]["delta_radius"] == pytest.approx(150 - 30, abs=tol("klipper"))
    seen = []
    for k, name in enumerate("abc"):
        st = sections[f"stepper_{name}"]
        j = joint_at(robot, st["angle"])  # the tower at the stepper's angle ...
        d = abs((st["angle"] - DEFAULT_ANGLES[name] + 180) % 360 - 180)
        assert d < 60, (name, st["angle"])  # ... is the one nearest the stepper's default angle
        assert st["arm_length"] == pytest.approx(300, abs=tol("klipper"))
        if endstop is None:
            assert "position_endstop" not in st
            got = corrections[f"stepper_{name}"]
        else:
            assert f"stepper_{name}" not in corrections
            got = st["position_endstop"] - np.broadcast_to(endstop, 3)[k]
        assert got == pytest.approx(FINE_S[j], abs=tol("klipper")), (name, j)
        seen.append(j)
    assert sorted(seen) == [0, 1, 2]


@pytest.mark.parametrize("phi", AZIMUTHS)
@pytest.mark.parametrize("endstop", [None, (0.0,), (0.12, -0.3, 0.05)])
def test_rrf_round_trip(tmp_path, phi, endstop):
    robot = linear_robot(tmp_path, phi)
    text = controllers.format_rrf(robot, result(), None if endstop is None else np.broadcast_to(endstop, 3),
                                  homed_height_mm=None if endstop is None else 250.0)
    m665, m666, corrections = parse_rrf(text)
    assert m665["R"] == [pytest.approx(120, abs=tol("rrf"))] and m665["L"] == [pytest.approx(300, abs=tol("rrf"))]
    assert ("H" in m665) == (endstop is not None)
    seen = []
    for k, name in enumerate("XYZ"):
        azimuth = DEFAULT_ANGLES[name] + m665[name][0]  # RRF: tower X at 210 + X deg, Y at 330 + Y, Z at 90 + Z
        assert abs(m665[name][0]) < 60
        j = joint_at(robot, azimuth, within=tol("rrf"))
        if endstop is None:
            assert m666 is None
            got = corrections[name]
        else:
            got = m666[name] - np.broadcast_to(endstop, 3)[k]
        assert got == pytest.approx(FINE_S[j], abs=tol("rrf")), (name, j)
        seen.append(j)
    assert sorted(seen) == [0, 1, 2]


def test_default_azimuths_map_s1_to_c_and_z(tmp_path):
    """The robot file's towers 90, 210, 330 deg: s1 is Klipper's c and RRF's Z, s2 a / X, s3 b / Y."""
    robot = linear_robot(tmp_path)
    for fmt in ("klipper", "rrf"):
        desc = controllers.describe(fmt, robot)
        assert [t.joint_name for t in desc.towers] == ["s2", "s3", "s1"]


def test_per_tower_rod_lengths(tmp_path):
    robot = linear_robot(tmp_path, extra="l1 = 301\nl2 = 302\nl3 = 303\n")
    sections, _ = parse_klipper(controllers.format_klipper(robot, result()))
    assert [sections[f"stepper_{n}"]["arm_length"] for n in "abc"] == [302, 303, 301]
    m665, _, _ = parse_rrf(controllers.format_rrf(robot, result()))
    assert m665["L"] == [302, 303, 301]


def test_other_identified_errors_are_named_not_exported(tmp_path):
    robot = linear_robot(tmp_path)
    text = controllers.format_klipper(robot, result(estimate={"l1": 0.25, "rMx": 0.1}))
    line = next(ln for ln in text.splitlines() if "not exported" in ln)
    assert "l1 +0.25 mm" in line and "rMx" not in line
    assert parse_klipper(text)[0]["stepper_c"]["arm_length"] == 300  # the nominal rod, not 300.25


# --------------------------------------------------------------------------- the firmware: the sign, checked

POSES = np.array([[0.0, 0.0, 120.0], [60.0, -40.0, 40.0], [-70.0, 25.0, 200.0], [10.0, 90.0, 80.0]])


def _effector(robot, carriages_by_joint):
    return kin.fk(robot, np.asarray(carriages_by_joint, float)[None, :])[0]


def klipper_effector(robot, text, P, true_home):
    """Where the effector goes when Klipper, configured by ``text``, is commanded to ``P``.

    Klipper's delta kinematics: the tower of stepper k at ``delta_radius (cos angle, sin angle)``; the
    carriage for P at ``z + sqrt(arm^2 - |xy - tower|^2)``; after homing it believes the carriage at
    ``position_endstop + sqrt(arm^2 - delta_radius^2)``, where the carriage of tower j truly is ``true_home[j]``.
    """
    sec, _ = parse_klipper(text)
    radius = sec["printer"]["delta_radius"]
    actual = np.zeros(3)
    for name in "abc":
        st = sec[f"stepper_{name}"]
        a, arm = math.radians(st["angle"]), st["arm_length"]
        j = joint_at(robot, st["angle"])
        cmd = P[2] + math.sqrt(arm**2 - (P[0] - radius * math.cos(a))**2 - (P[1] - radius * math.sin(a))**2)
        believed_home = st["position_endstop"] + math.sqrt(arm**2 - radius**2)
        actual[j] = cmd + true_home[j] - believed_home
    return _effector(robot, actual)


def rrf_effector(robot, text, P, true_home):
    """Where the effector goes when RRF, configured by ``text``, is commanded to ``P``.

    RRF's linear-delta kinematics: towers from R and the angle corrections (``Recalc``), the carriage for P at
    ``sqrt(L^2 - |xy - tower|^2) + z``, after homing believed at ``H + sqrt(L^2 - R^2) + adjustment``.
    """
    m665, m666, _ = parse_rrf(text)
    R, H = m665["R"][0], m665["H"][0]
    L = m665["L"] * 3 if len(m665["L"]) == 1 else m665["L"]
    cx, cy, cz = (math.radians(m665[n][0]) for n in "XYZ")
    towers = [(-R * math.cos(math.radians(30) + cx), -R * math.sin(math.radians(30) + cx)),
              (R * math.cos(math.radians(30) - cy), -R * math.sin(math.radians(30) - cy)),
              (-R * math.sin(cz), R * math.cos(cz))]
    actual = np.zeros(3)
    for k, name in enumerate("XYZ"):
        tx, ty = towers[k]
        j = joint_at(robot, math.degrees(math.atan2(ty, tx)) % 360, within=tol("rrf"))
        cmd = math.sqrt(L[k]**2 - (P[0] - tx)**2 - (P[1] - ty)**2) + P[2]
        believed_home = H + math.sqrt(L[k]**2 - R**2) + m666[name]
        actual[j] = cmd + true_home[j] - believed_home
    return _effector(robot, actual)


@pytest.mark.parametrize("phi", [(90, 210, 330), (95.54321, 204.12345, 333.00067), (330, 90, 210)])
def test_corrected_klipper_puts_the_effector_where_commanded(tmp_path, phi):
    """The truth: measured with position_endstop pe0, the carriage of tower j stood Δs_j higher than Klipper
    believed (actual = commanded + offset).  With the export's position_endstop the poses are reached, to the
    rounding of the 6 decimals written (5e-7 mm a carriage)."""
    robot = linear_robot(tmp_path, phi)
    pe0 = np.array([300.1, 299.9, 300.3])  # a, b, c
    nominal = controllers.format_klipper(robot, result(np.zeros(3)), pe0)
    sec, _ = parse_klipper(nominal)
    true_home = np.zeros(3)
    for name in "abc":  # Klipper's belief with pe0, plus the offset of the tower at the stepper's angle
        st = sec[f"stepper_{name}"]
        j = joint_at(robot, st["angle"])
        true_home[j] = st["position_endstop"] + math.sqrt(st["arm_length"]**2 - sec["printer"]["delta_radius"]**2) \
            + FINE_S[j]
    corrected = controllers.format_klipper(robot, result(), pe0)
    for P in POSES:
        np.testing.assert_allclose(klipper_effector(robot, corrected, P, true_home), P, rtol=0, atol=1e-5)
        # the uncorrected configuration misses by the offsets' size: the check can fail
        assert np.linalg.norm(klipper_effector(robot, nominal, P, true_home) - P) > 0.1


@pytest.mark.parametrize("phi", [(90, 210, 330), (95.54321, 204.12345, 333.00067), (330, 90, 210)])
def test_corrected_rrf_puts_the_effector_where_commanded(tmp_path, phi):
    """As Klipper's, with RRF's M666 adjustments; to the rounding of the 3 decimals written (5e-4 mm a carriage,
    5e-4 deg a tower: 1e-6 mm at R = 120 mm)."""
    robot = linear_robot(tmp_path, phi)
    adj0 = np.array([0.12, -0.3, 0.05])  # X, Y, Z
    H = 250.0
    nominal = controllers.format_rrf(robot, result(np.zeros(3)), adj0, H)
    m665, m666, _ = parse_rrf(nominal)
    R = m665["R"][0]
    desc = controllers.describe("rrf", robot)
    true_home = np.zeros(3)
    for k, t in enumerate(desc.towers):
        true_home[t.joint] = H + math.sqrt(t.rod_mm**2 - R**2) + adj0[k] + FINE_S[t.joint]
    corrected = controllers.format_rrf(robot, result(), adj0, H)
    for P in POSES:
        np.testing.assert_allclose(rrf_effector(robot, corrected, P, true_home), P, rtol=0, atol=5e-3)
        assert np.linalg.norm(rrf_effector(robot, nominal, P, true_home) - P) > 0.1


# --------------------------------------------------------------------------- robots a format cannot describe

@pytest.mark.parametrize("phi", [(30, 150, 270), (60, 120, 270)])
def test_ambiguous_azimuths_refused(tmp_path, phi):
    """30, 150, 270 deg: each tower 60 deg from two of the controller's; 60 and 120 deg: both nearest c."""
    robot = linear_robot(tmp_path, phi)
    for fmt, towers in (("klipper", "a, b, c"), ("rrf", "X, Y, Z")):
        with pytest.raises(ZerocalError, match=rf"do not match .*towers {towers} at 210, 330, 90 deg one to one"):
            controllers.describe(fmt, robot)


def test_just_within_60_degrees_accepted(tmp_path):
    robot = linear_robot(tmp_path, (31, 151, 271))
    assert [t.joint_name for t in controllers.describe("rrf", robot).towers] == ["s2", "s3", "s1"]


def test_unequal_tower_radii_refused(tmp_path):
    robot = linear_robot(tmp_path, extra="R1 = 150\nR2 = 151\nR3 = 150\n")
    for fmt in ("klipper", "rrf"):
        with pytest.raises(ZerocalError, match=r"one tower radius; the robot file's R1, R2, R3 differ"):
            controllers.describe(fmt, robot)


@pytest.mark.parametrize("text", ["abc", "1,2", "1,2,3,4", "nan", "", "1e9"])
def test_bad_endstop_values(text):
    with pytest.raises(ValueError, match="--endstop-mm"):
        controllers.parse_endstops(text, "klipper")


# --------------------------------------------------------------------------- the command

def zc(capsys, *argv, expect=0):
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert rc == expect, (argv, rc, out, err)
    return out, err


@pytest.fixture(scope="module")
def identified(tmp_path_factory):
    """A noise-free round of the example linear Delta with offsets DELTA_S, identified (nlls)."""
    d = tmp_path_factory.mktemp("ctl")
    sets = [a for i, v in enumerate(DELTA_S) for a in ("--set", f"s{i + 1}={v}")]
    assert main(["simulate", "--robot", str(LINEAR), "--scheme", "ring", "--n", "6", *sets, "--noise", "none",
                 "--out", str(d / "d.csv")]) == 0
    assert main(["identify", str(d / "d.csv"), "--robot", str(LINEAR), "--out", str(d / "r.json")]) == 0
    return d / "r.json"


def test_cli_klipper_and_rrf(capsys, tmp_path, identified):
    out = tmp_path / "printer.cfg"
    zc(capsys, "compensate", identified, "--robot", LINEAR, "--format", "klipper", "--endstop-mm", "300.1,299.9,300.3",
       "--out", out)
    sec, _ = parse_klipper(out.read_text())
    got = [sec[f"stepper_{n}"]["position_endstop"] - e for n, e in zip("abc", (300.1, 299.9, 300.3))]
    np.testing.assert_allclose(got, DELTA_S[[1, 2, 0]], atol=1e-5)  # a = s2, b = s3, c = s1
    text, _ = zc(capsys, "compensate", identified, "--robot", LINEAR, "--format", "rrf", "--endstop-mm", "0",
                 "--homed-height-mm", "250")
    m665, m666, _ = parse_rrf(text)
    np.testing.assert_allclose([m666[n] for n in "XYZ"], DELTA_S[[1, 2, 0]], atol=1e-3)
    assert m665["H"] == [250.0]
    summary, _ = zc(capsys, "compensate", identified, "--robot", LINEAR, "--format", "rrf", "--json")
    assert json.loads(summary)["format"] == "rrf"


def test_cli_csv_is_the_default_and_unchanged(capsys, identified):
    a, _ = zc(capsys, "compensate", identified, "--robot", LINEAR)
    b, _ = zc(capsys, "compensate", identified, "--robot", LINEAR, "--format", "csv")
    assert a == b and "joint,offset_mm,std_mm" in a


@pytest.mark.parametrize("robot", [None, ROOT / "examples" / "delta.toml", ROOT / "examples" / "hexapod.toml"])
@pytest.mark.parametrize("fmt", ["klipper", "rrf"])
def test_cli_other_mechanisms_refused(capsys, tmp_path, robot, fmt):
    res = tmp_path / "r.json"
    res.write_text("{}")  # refused for the mechanism before the result is read
    out = tmp_path / "x.cfg"
    argv = ["compensate", res, "--format", fmt, "--out", out] + ([] if robot is None else ["--robot", robot])
    _, err = zc(capsys, *argv, expect=2)
    assert len(err.strip().splitlines()) == 1 and "formats of" in err and err.strip().endswith(": csv"), err
    assert f"--format {fmt}" in err and not out.exists()


@pytest.mark.parametrize("extra,pattern", [
    (("--format", "csv", "--endstop-mm", "300"), r"--endstop-mm: for a controller's configuration"),
    (("--homed-height-mm", "250"), r"RRF's M665 H: for --format rrf only"),
    (("--format", "klipper", "--homed-height-mm", "250"), r"RRF's M665 H: for --format rrf only"),
    (("--format", "klipper", "--scheme", "ring"), r"--scheme: not with --format klipper"),
    (("--format", "rrf", "--endstop-mm", "1,2"), r"--endstop-mm '1,2': one number .* \(X, Y, Z\)"),
    (("--format", "rrf", "--homed-height-mm", "-5"), r"--homed-height-mm must be a positive number"),
])
def test_cli_bad_options(capsys, tmp_path, identified, extra, pattern):
    out = tmp_path / "x.cfg"
    _, err = zc(capsys, "compensate", identified, "--robot", LINEAR, *extra, "--out", out, expect=2)
    assert len(err.strip().splitlines()) == 1 and re.search(pattern, err), err
    assert not out.exists()


@pytest.mark.parametrize("fmt", ["klipper", "rrf"])
@pytest.mark.parametrize("change,reason", [
    ("failed", "not a calibration"),
    ("implausible", "beyond the plausible 10 mm"),
])
def test_cli_failed_or_implausible_result_refused(capsys, tmp_path, identified, fmt, change, reason):
    d = json.loads(identified.read_text())
    if change == "failed":
        d["success"], d["status"] = False, "Ipopt: Infeasible_Problem_Detected"
    else:  # every copy of the offset
        d["zero_offsets_mm"][0] = d["estimate"]["s1"] = d["compensation"]["offset_mm"][0] = 20.0
    res = tmp_path / "r.json"
    res.write_text(json.dumps(d))
    out = tmp_path / "x.cfg"
    _, err = zc(capsys, "compensate", res, "--robot", LINEAR, "--format", fmt, "--endstop-mm", "0", "--out", out,
                expect=1)
    assert len(err.strip().splitlines()) == 1 and "refused" in err and reason in err, err
    assert not out.exists()


def test_cli_output_over_the_input_refused(capsys, identified):
    before = identified.read_text()
    _, err = zc(capsys, "compensate", identified, "--robot", LINEAR, "--format", "klipper", "--out", identified,
                expect=2)
    assert len(err.strip().splitlines()) == 1 and identified.read_text() == before


def test_the_documented_examples_read_back(tmp_path):
    """docs/data-format.md's pasted exports: each corrected value is the current one plus its tower's offset comment,
    and the file's towers are the robot file's by azimuth (a = s2, b = s3, c = s1)."""
    import docs_check  # the page's console blocks: each command with the output the page shows (the docs checker)

    page = docs_check.parse_page(ROOT / "docs" / "data-format.md")
    shown = {c.text: "\n".join(c.expected) + "\n" for it in page.items if it.kind == "block" for c in it.commands
             if c.expected}
    klipper = next(out for cmd, out in shown.items() if "--format klipper" in cmd)
    rrf = next(out for cmd, out in shown.items() if "--format rrf" in cmd)
    assert "[stepper_a]" in klipper and rrf.startswith("; zerocal")
    sec, _ = parse_klipper(klipper)
    offsets = {m.group(1): float(m.group(2)) for m in re.finditer(r"# tower (s\d): offset_mm (\S+)", klipper)}
    for name, joint in zip("abc", ("s2", "s3", "s1")):
        assert sec[f"stepper_{name}"]["position_endstop"] == pytest.approx(300 + offsets[joint], abs=tol("klipper"))
    m665, m666, _ = parse_rrf(rrf)
    current = dict(zip("XYZ", (0.12, -0.3, 0.05)))  # the documented --endstop-mm
    for name, joint in zip("XYZ", ("s2", "s3", "s1")):
        assert m666[name] == pytest.approx(current[name] + offsets[joint], abs=tol("rrf"))
    assert m665["H"] == [250.0] and m665["R"] == [120.0]
