"""Files checked for what they claim: a hand-edited result or data file is refused, not silently half-read.

A results file holds several copies of one value (``zero_offsets_deg``,
``estimate``, the ``compensation`` block; ``std_zero_offsets_deg``, ``std``,
``compensation.std_deg``; the robot hash three times): an edit of one copy is
an error naming the key and its line.  Standard deviations are >= 0 or null;
hashes are 64 hexadecimal digits; a data file has one value per metadata key
zerocal reads; what docs/data-format.md calls enough (``zero_offsets_deg``
alone) is enough.  And the messages say what is wrong: a negative H in a robot
file, a byte-order mark, an implausible MAEMM in the result verify applies.
"""
import json
import re
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym.cli import main
from zerocal_sym.errors import DataFileError
from zerocal_sym.io.results import load_result

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """A round, its result (tsvd, noise-free) and a second round compensated with it."""
    d = tmp_path_factory.mktemp("claims")
    data, res, data2 = d / "d.csv", d / "r.json", d / "d2.csv"
    assert main(["simulate", "--group", "1", "--noise", "none", "--out", str(data)]) == 0
    assert main(["identify", str(data), "--method", "tsvd", "--noise", "none", "--out", str(res)]) == 0
    off = json.loads(res.read_text())["zero_offsets_deg"]
    assert main(["simulate", "--group", "1", "--noise", "none", "--seed", "1", "--compensation", *map(str, off),
                 "--out", str(data2)]) == 0
    return {"data": data, "result": res, "data2": data2, "obj": json.loads(res.read_text())}


def edited(made, tmp_path, change) -> Path:
    obj = json.loads(json.dumps(made["obj"]))
    change(obj)
    p = tmp_path / "edited.json"
    p.write_text(json.dumps(obj, indent=2))
    return p


def refused(capsys, argv, pattern):
    rc = main([str(a) for a in argv])
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, (rc, err)
    assert re.search(pattern, err), err
    return err


def line_of(path: Path, key: str) -> int:
    return next(i for i, ln in enumerate(path.read_text().splitlines(), 1) if f'"{key}":' in ln)


# --------------------------------------------------------------------------- copies of one value

@pytest.mark.parametrize("key, change", [
    ("offset_deg", lambda o: o["compensation"].__setitem__("offset_deg", [5.0, 5.0])),
    ("estimate", lambda o: o["estimate"].__setitem__("theta1", 3.0)),
    ("estimate", lambda o: o["estimate"].__setitem__("rMx", 9.0)),
    ("std", lambda o: o["std"].__setitem__("theta2", 7.0)),
    ("std_deg", lambda o: o["compensation"].__setitem__("std_deg", [0.5, 0.5])),
])
def test_an_edited_copy_of_a_value_is_refused(capsys, tmp_path, made, key, change):
    """compensate does not use one copy and ignore the other: exit 2, the key and its line, nothing written."""
    p = edited(made, tmp_path, change)
    out = tmp_path / "table.csv"
    err = refused(capsys, ["compensate", p, "--out", out], rf"key '{key}': .* disagrees with .*one of the two copies")
    assert f"{p}:{line_of(p, key)}:" in err
    assert not out.exists()


def test_an_edited_offset_with_every_copy_edited_alike_is_read(tmp_path, made):
    """The check compares copies: the same edit everywhere is a (hand-made) result, read as it says."""
    def change(o):
        o["zero_offsets_deg"] = o["compensation"]["offset_deg"] = [0.5, -0.25]
        o["estimate"]["theta1"], o["estimate"]["theta2"] = 0.5, -0.25
    r = load_result(edited(made, tmp_path, change))
    np.testing.assert_array_equal(r.zero_offsets_deg, [0.5, -0.25])


@pytest.mark.parametrize("key, change", [
    ("sign_convention", lambda o: o["compensation"].__setitem__("sign_convention", "theta_cmd = IK(P) + offset_deg")),
    ("joints", lambda o: o["compensation"].__setitem__("joints", ["theta2", "theta1"])),
    ("joint_names", lambda o: o.__setitem__("joint_names", ["theta2", "theta1"])),
    ("mechanism", lambda o: o["robot"].__setitem__("mechanism", "delta_rotary")),
    ("units", lambda o: o["units"].__setitem__("rMx", "deg")),
])
def test_a_claim_that_contradicts_the_rest_is_refused(tmp_path, made, key, change):
    p = edited(made, tmp_path, change)
    with pytest.raises(DataFileError, match=re.escape(key)) as ei:
        load_result(p)
    assert ei.value.where.startswith(f"{p}:")


# --------------------------------------------------------------------------- standard deviations

@pytest.mark.parametrize("key, change", [
    ("std_zero_offsets_deg", lambda o: o.__setitem__("std_zero_offsets_deg", [-1.0, 0.1])),
    ("std", lambda o: o["std"].__setitem__("rMy", -0.1)),
    ("std_deg", lambda o: o["compensation"].__setitem__("std_deg", [0.1, -0.1])),
])
def test_a_negative_standard_deviation_is_refused(capsys, tmp_path, made, key, change):
    p = edited(made, tmp_path, change)
    refused(capsys, ["compensate", p], rf"{p}:{line_of(p, key)}: key '{key}': .*standard deviation.* must be >= 0")


@pytest.mark.parametrize("change, known", [
    (lambda o: o.__setitem__("std_zero_offsets_deg", None), True),  # the copy in std fills it
    (lambda o: o.__setitem__("std_zero_offsets_deg", [None, None]), True),
    (lambda o: o.__setitem__("std", None), True),
    (lambda o: [o.pop(k) for k in ("std_zero_offsets_deg", "std", "compensation")], False),
])
def test_a_null_standard_deviation_means_unknown(capsys, tmp_path, made, change, known):
    """null where the docs allow it (a list of nulls or the key itself) is read as unknown; a known copy fills it."""
    p = edited(made, tmp_path, change)
    r = load_result(p)
    if known:
        np.testing.assert_allclose(r.std_zero_offsets_deg, made["obj"]["std_zero_offsets_deg"], rtol=1e-12)
    else:
        assert np.all(np.isnan(r.std_zero_offsets_deg))
    assert main(["compensate", str(p)]) == 0, capsys.readouterr().err


def test_only_the_offsets_are_enough(capsys, tmp_path, made):
    """docs/data-format.md: only zero_offsets_deg is required: compensate and verify take such a file."""
    off = made["obj"]["zero_offsets_deg"]
    p = tmp_path / "bare.json"
    p.write_text(json.dumps({"zero_offsets_deg": off}))
    out = tmp_path / "table.csv"
    assert main(["compensate", str(p), "--out", str(out)]) == 0, capsys.readouterr().err
    rows = [ln.split(",") for ln in out.read_text().splitlines() if ln.startswith("theta")]
    assert [float(r[1]) for r in rows] == off and [r[2] for r in rows] == ["", ""]
    rc = main(["verify", str(p), str(made["data2"])])
    assert rc in (0, 1) and "error" not in capsys.readouterr().err


# --------------------------------------------------------------------------- robot hashes

@pytest.mark.parametrize("value", [5, "ab", "g" * 64, "2eaac3c7", True])
@pytest.mark.parametrize("where", ["robot_sha256", "robot.sha256"])
def test_a_robot_hash_of_the_wrong_form_is_refused(capsys, tmp_path, made, value, where):
    """A hash that is not 64 hex digits is an error (robot_sha256: 5 no longer skips the check)."""
    def change(o):
        if where == "robot_sha256":
            o["robot_sha256"] = value
        else:
            o["robot"]["sha256"] = value
    p = edited(made, tmp_path, change)
    refused(capsys, ["compensate", p], rf"key '{re.escape(where)}' must be the robot's SHA-256, 64 hexadecimal digits")


def test_two_robot_hashes_that_disagree_are_refused(capsys, tmp_path, made):
    p = edited(made, tmp_path, lambda o: o["robot"].__setitem__("sha256", "0" * 64))
    refused(capsys, ["compensate", p], r"name different robots")


def test_a_result_of_another_robot_is_refused_with_a_valid_hash(capsys, tmp_path, made):
    other = "0" * 64
    def change(o):
        o["robot_sha256"] = o["robot"]["sha256"] = other
    p = edited(made, tmp_path, change)
    refused(capsys, ["compensate", p], r"identified on another robot")


# --------------------------------------------------------------------------- data-file metadata

def with_lines(made, tmp_path, *lines) -> Path:
    text = made["data"].read_text().splitlines()
    p = tmp_path / "d.csv"
    p.write_text("\n".join(text[:2] + list(lines) + text[2:]) + "\n")
    return p


@pytest.mark.parametrize("line, pattern", [
    ("# mechanism: delta_rotary", r"'# mechanism:' given twice with different values \(lines 2 and 3\)"),
    ("# robot_sha256: " + "0" * 64, r"'# robot_sha256:' given twice with different values"),
    ("# compensation_deg: 1, 2", r"'# compensation_deg:' given twice with different values \(lines 3 and \d+\)"),
])
def test_a_metadata_key_has_one_value(capsys, tmp_path, made, line, pattern):
    p = with_lines(made, tmp_path, line)
    refused(capsys, ["identify", p, "--method", "tsvd"], rf"{p}:\d+: {pattern}")


def test_repeated_lines_that_agree_or_are_not_read_are_accepted(capsys, tmp_path, made):
    sha = next(ln for ln in made["data"].read_text().splitlines() if ln.startswith("# robot_sha256:"))
    p = with_lines(made, tmp_path, sha, "# note: first", "# note: second")
    assert main(["identify", str(p), "--method", "tsvd", "--noise", "none"]) == 0, capsys.readouterr().err


@pytest.mark.parametrize("line, pattern", [
    ("# robot_sha256: 5", r"'# robot_sha256:' must be the robot's SHA-256, 64 hexadecimal digits"),
    ("# compensation_deg: 1, x", r"'# compensation_deg:' must be 2 finite angles in deg, one per joint"),
    ("# compensation_deg: 1", r"'# compensation_deg:' must be 2 finite angles"),
])
def test_a_metadata_value_of_the_wrong_form_is_refused(capsys, tmp_path, made, line, pattern):
    key = line.split(":")[0]
    text = [ln for ln in made["data"].read_text().splitlines() if not ln.startswith(key + ":")]
    p = tmp_path / "d.csv"
    p.write_text("\n".join(text[:2] + [line] + text[2:]) + "\n")
    refused(capsys, ["identify", p, "--method", "tsvd"], rf"{p}:3: {pattern}")


# --------------------------------------------------------------------------- messages that say what is wrong

@pytest.mark.parametrize("example, old, new", [
    ("paper_robot.toml", "H = 632", "H = -632"),
    ("delta.toml", "H = 700", "H = -700"),
])
def test_a_negative_workspace_distance_is_named(capsys, tmp_path, example, old, new):
    text = (ROOT / "examples" / example).read_text()
    assert old in text
    p = tmp_path / "r.toml"
    p.write_text(text.replace(old, new))
    line = next(i for i, ln in enumerate(p.read_text().splitlines(), 1) if ln.startswith(new))
    err = refused(capsys, ["robot", "--robot", p], rf"{p}:{line}: workspace distance H must be positive, got -")
    assert "kinematics disagree" not in err


def test_a_byte_order_mark_is_accepted_in_toml_files(capsys, tmp_path, made):
    """A robot file and a tolerance file saved with a UTF-8 BOM read as without; line numbers stay right."""
    text = (ROOT / "examples" / "paper_robot.toml").read_text()
    p = tmp_path / "bom.toml"
    p.write_bytes(b"\xef\xbb\xbf" + text.encode())
    assert main(["robot", "--robot", str(p)]) == 0, capsys.readouterr().err
    assert "sha256: 2eaac3c73911d104959ab1b225bfaeb012037cfd07e148fe53251fcc3cea7b04" in capsys.readouterr().out
    p.write_bytes(b"\xef\xbb\xbf" + text.replace("name = ", "nam = ").encode())
    refused(capsys, ["robot", "--robot", p], rf"{p}:2: unknown key 'nam'")
    tol = tmp_path / "tol.toml"
    tol.write_bytes(b"\xef\xbb\xbfL1 = 0.01\n")
    assert main(["identify", str(made["data"]), "--method", "tsvd", "--noise", "none", "--tolerance-file",
                 str(tol)]) == 0, capsys.readouterr().err


def test_verify_names_an_implausible_maemm_of_the_applied_result(capsys, tmp_path, made):
    """A huge MAEMM in the result verify applies is that result's problem, not a rank problem of the data."""
    def change(o):
        o["maemm_mm"] = [1e12, 1e12]
        o["estimate"]["rMx"] = o["estimate"]["rMy"] = 1e12
    p = edited(made, tmp_path, change)
    rc = main(["verify", str(p), str(made["data2"]), "--out", str(tmp_path / "new.json")])
    err = capsys.readouterr().err
    assert rc == 1 and err.startswith(f"zerocal verify: refused {p}: MAEMM |rM| = 1.414e+12 mm is beyond"), err
    assert "rank" not in err and not (tmp_path / "new.json").exists()


def test_identify_names_an_implausible_maemm_prior(capsys, made):
    """A MAEMM prior that --max-maemm-mm would refuse is named as such before any work, not left to the fit."""
    refused(capsys, ["identify", made["data"], "--method", "tsvd", "--maemm-prior", "300", "0"],
            r"--maemm-prior 300 0: \|rM\| = 300 mm is beyond --max-maemm-mm 50")
    assert main(["identify", str(made["data"]), "--method", "tsvd", "--noise", "none", "--maemm-prior", "300", "0",
                 "--max-maemm-mm", "400"]) in (0, 1)
