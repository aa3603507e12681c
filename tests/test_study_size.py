"""A study this machine cannot hold is refused before any work: one line naming the spec's line, exit 2,
nothing written (zerocal_sym/cli/study_size.py)."""
import collections
import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from zerocal_sym.cli import main, study, study_size
from zerocal_sym.cli._checks import MAX_N
from zerocal_sym.cli.study_spec import StudySpecError, load_spec


def _spec(d: Path, trials="4", chunk="chunk = 2", n=3) -> Path:
    p = d / "spec.toml"
    p.write_text(f"""name = "size"
seed = 1
trials = {trials}
{chunk}
robots = ["paper"]

[[design]]
n = {n}

[[truth]]
name = "g1"
theta1 = 2
theta2 = -1
""")
    return p


def _refused(capsys, spec, out, line, *words):
    assert main(["study", str(spec), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"{spec}:{line}:" in err, err
    for w in words:
        assert w in err, err
    assert not out.exists()
    return err


def test_n_beyond_the_cli_cap(tmp_path, capsys):
    """n = 1,000,000 made 2,000,000 poses before anything was said."""
    spec = _spec(tmp_path, n=1_000_000)
    _refused(capsys, spec, tmp_path / "out", 8, f"n = 1000000: expected an integer >= 2 and <= {MAX_N} (poses per "
             "boundary)")


def test_absurd_trials(tmp_path, capsys):
    """trials = 10^12 grew the memory of the plan (a list of its 10^8 chunks) without a word."""
    spec = _spec(tmp_path, trials="1000000000000", chunk="")
    _refused(capsys, spec, tmp_path / "out", 3, "100000000 chunk files per cell", f"at most {study_size.MAX_CHUNKS}")


def test_trials_whose_summary_does_not_fit(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(study_size, "machine_memory", lambda: 2**30)
    spec = _spec(tmp_path, trials="100000000", chunk="chunk = 10000")
    most = int(study_size.MEMORY_SHARE * 2**30 // (study_size.SUMMARY_COPIES * 8 * 4))
    _refused(capsys, spec, tmp_path / "out", 3, "trials = 100000000: the summary of a cell", "1 GB",
             f"at most {most} trials per cell")
    # what it allows runs
    assert load_spec(_spec(tmp_path, trials=str(most), chunk="chunk = 10000")).trials == most


def test_a_chunk_that_does_not_fit(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(study_size, "machine_memory", lambda: 2**30)
    spec = _spec(tmp_path, trials="5000", chunk="chunk = 5000", n=2000)
    err = _refused(capsys, spec, tmp_path / "out", 4, "chunk = 5000: identifying a chunk of a cell of 4000 poses")
    most = int(err.rsplit("at most ", 1)[1].split()[0])
    budget = study_size.MEMORY_SHARE * 2**30
    assert study_size.chunk_bytes(4000, most) <= budget < study_size.chunk_bytes(4000, most + 1)
    with pytest.raises(StudySpecError, match="not even one trial"):
        study_size.check_spec(load_spec(_spec(tmp_path, trials="1", chunk="chunk = 1", n=2000)),
                              lambda key=None: "spec", StudySpecError, memory=4000 * study_size.BYTES_PER_POSE)


def test_chunk_files_that_do_not_fit_on_the_disk(tmp_path, capsys, monkeypatch):
    usage = collections.namedtuple("usage", "total used free")
    monkeypatch.setattr(study_size.shutil, "disk_usage", lambda path: usage(10**6, 10**6 - 100, 100))
    spec = _spec(tmp_path)
    out = tmp_path / "out"
    assert main(["study", str(spec), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "the 2 chunk files to write need about" in err and str(out) in err
    assert not out.exists() or not any(out.rglob("*"))


def test_the_memory_model_bounds_what_a_chunk_uses(tmp_path):
    """The batched identification of a chunk (identify_batch) in a fresh process: its peak resident memory
    grows by less than study_size.chunk_bytes says."""
    code = textwrap.dedent("""
        import json, resource, sys
        import numpy as np
        from zerocal_sym.identify.batch import identify_batch
        from zerocal_sym.model import kinematics as kin
        from zerocal_sym.model.noise import NoiseModel, VirtualPlant
        from zerocal_sym.model.robot import paper_robot
        K, N = int(sys.argv[1]), int(sys.argv[2])
        robot = paper_robot()
        th = kin.ik(robot, robot.workspace.boundary_scheme(K // 2))
        plant = VirtualPlant(robot, robot.errors.from_user({"theta1": 1.0}))
        rng = np.random.default_rng(0)
        R = np.array([plant.measure(th, NoiseModel.paper(), rng) for _ in range(N)])
        before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        b = identify_batch(robot, th, R, "paper", noise=NoiseModel.paper())
        after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        print(json.dumps({"grew": (after - before) * 1024 + R.nbytes, "ok": float(b.success.mean())}))
    """)
    for K, N in ((12, 2000), (200, 300)):
        p = subprocess.run([sys.executable, "-c", code, str(K), str(N)], capture_output=True, text=True,
                           timeout=600)
        assert p.returncode == 0, p.stderr[-2000:]
        got = json.loads(p.stdout)
        assert got["ok"] > 0.9
        assert got["grew"] < study_size.chunk_bytes(K, N), (K, N, got, study_size.chunk_bytes(K, N))


def test_plan_is_checked_before_the_summary_goes(tmp_path, monkeypatch):
    """The disk check runs after the chunk files on disk are read and before the old summary is removed."""
    spec = _spec(tmp_path)
    out = tmp_path / "out"
    assert main(["study", str(spec), "--out", str(out), "--quiet"]) == 0
    (out / "paper_paper3_paper_g1" / "chunk-1.npz").unlink()
    usage = collections.namedtuple("usage", "total used free")
    monkeypatch.setattr(study_size.shutil, "disk_usage", lambda path: usage(10**6, 10**6 - 10, 10))
    with pytest.raises(study.ZerocalError, match="the 1 chunk files to write"):
        study.run_study(load_spec(spec), out)
    assert (out / "summary.json").exists()
