"""``zerocal study`` and ``zerocal compare`` on damaged, foreign or impossible input: one line, exit 2, nothing written.

A damaged chunk file, another cell's chunk, a directory of another study, a
stale summary after an interrupted run, a truth-key typo, a parameter set the
poses cannot identify, ``--robot`` in study's help, the ``--set`` heading of
compare.  One small study is run once (module fixture) and copied per test.
"""
import io
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym.cli import main, study, study_chunks, study_spec
from zerocal_sym.errors import ZerocalError
from zerocal_sym.identify.progress import Progress

PAPER = "paper_paper3_paper_g1"
HALF = "paper_paper3_x0.5_g1"


def _spec(d: Path, name="t", truth="g1", trials=4, extra="", design="n = 3", file="spec.toml") -> Path:
    p = d / file
    p.write_text(f"""name = "{name}"
seed = 4
trials = {trials}
chunk = 2
robots = ["paper"]
noise = ["paper", 0.5]
{extra}
[[design]]
{design}

[[truth]]
name = "{truth}"
theta1 = 2
theta2 = -1
rMx = 1
""")
    return p


@pytest.fixture(scope="module")
def done(tmp_path_factory):
    """A complete study directory (2 cells x 2 chunks of 2 trials) and its spec."""
    d = tmp_path_factory.mktemp("study")
    spec = _spec(d)
    assert main(["study", str(spec), "--out", str(d / "out"), "--quiet"]) == 0
    return d


@pytest.fixture
def run(done, tmp_path):
    """A copy of the complete study: ``(spec, out)``."""
    shutil.copytree(done / "out", tmp_path / "out")
    return _spec(tmp_path), tmp_path / "out"


def _tree(d: Path) -> dict:
    return {str(p.relative_to(d)): p.read_bytes() for p in sorted(d.rglob("*")) if p.is_file()}


def _error(capsys, argv, *patterns):
    """Exit status 2, one line on stderr, containing every pattern; returns the line."""
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert rc == 2, (rc, out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    for p in patterns:
        assert p in lines[0], (p, lines[0])
    return lines[0]


def _numbers(summary):
    return [{k: v for k, v in c.items() if k != "identification_time_s"} for c in summary["cells"]]


# --------------------------------------------------------------------------- 1. damaged chunk files

def _truncated(p):
    p.write_bytes(p.read_bytes()[:100])


def _empty(p):
    p.write_bytes(b"")


def _text(p):
    p.write_text("not a chunk\n")


def _no_column(p):
    with np.load(p) as z:
        cols = {k: z[k] for k in z.files if k != "est_rMy"}
    np.savez(p, **cols)


def _short_column(p):
    with np.load(p) as z:
        cols = {k: z[k] for k in z.files}
    cols["chi2"] = cols["chi2"][:1]
    np.savez(p, **cols)


@pytest.mark.parametrize("damage", [_truncated, _empty, _text, _no_column, _short_column])
@pytest.mark.parametrize("mode", ["--summary", "--out"])
def test_damaged_chunk_is_refused_naming_it(run, capsys, damage, mode):
    spec, out = run
    bad = out / PAPER / "chunk-1.npz"
    damage(bad)
    before = _tree(out)
    line = _error(capsys, ["study", spec, mode, out, "--quiet"], str(bad), "delete it")
    assert "chunk" in line
    assert _tree(out) == before  # nothing written, the damaged file not replaced, summary.json kept


def test_several_damaged_chunks_counted(run, capsys):
    spec, out = run
    for cell in (PAPER, HALF):
        _empty(out / cell / "chunk-0.npz")
    _error(capsys, ["study", spec, "--out", out], str(out / PAPER / "chunk-0.npz"), "1 other chunk file")


def test_deleted_damaged_chunk_is_recomputed_to_the_same_summary(run, done, capsys):
    spec, out = run
    _truncated(out / PAPER / "chunk-1.npz")
    (out / PAPER / "chunk-1.npz").unlink()
    assert main(["study", str(spec), "--out", str(out), "--quiet", "--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    first = json.loads((done / "out" / "summary.json").read_text())
    assert _numbers(again) == _numbers(first) and again["run"]["chunks_run"] == 1


# --------------------------------------------------------------------------- 3. a chunk of another cell

def test_chunk_of_another_cell_is_refused(run, capsys):
    spec, out = run
    bad = out / PAPER / "chunk-1.npz"
    shutil.copyfile(out / HALF / "chunk-1.npz", bad)  # same trials, another cell
    before = _tree(out)
    for mode in ("--summary", "--out"):
        _error(capsys, ["study", spec, mode, out], str(bad), HALF, PAPER)
    assert _tree(out) == before


def test_chunk_of_other_trials_of_the_cell_is_refused(run, capsys):
    spec, out = run
    bad = out / PAPER / "chunk-1.npz"
    shutil.copyfile(out / PAPER / "chunk-0.npz", bad)
    _error(capsys, ["study", spec, "--out", out], str(bad), "holds trials 0..1", "trials 2..3")


def test_chunk_of_other_settings_is_refused(run, capsys):
    spec, out = run
    bad = out / PAPER / "chunk-1.npz"
    with np.load(bad) as z:
        cols = {k: z[k] for k in z.files}
    cols["cell_sha256"] = np.array("0" * 64)
    np.savez(bad, **cols)
    _error(capsys, ["study", spec, "--summary", out], str(bad), "other settings")


def test_chunk_records_its_cell(run):
    spec, out = run
    cell = study_spec.load_spec(spec).cells[0]
    with np.load(out / cell.id / "chunk-0.npz") as z:
        assert str(z["cell"]) == cell.id
        assert str(z["cell_sha256"]) == cell.digest(study_spec.load_spec(spec))


def test_chunk_without_cell_record_is_read_as_before(run):
    """A chunk written before the cell record existed: checked by its columns and trials."""
    spec, out = run
    s = study_spec.load_spec(spec)
    first = study.summarize(s, out)
    for p in out.rglob("chunk-*.npz"):
        with np.load(p) as z:
            cols = {k: z[k] for k in z.files if k not in ("cell", "cell_sha256")}
        np.savez(p, **cols)
    assert _numbers(study.summarize(s, out)) == _numbers(first)
    assert study.plan(s, out) == ([], 4)


# --------------------------------------------------------------------------- 2. another study's directory

def test_directory_of_another_study_is_refused(run, capsys, tmp_path):
    spec, out = run
    before = _tree(out)
    other = _spec(tmp_path, name="other", truth="g2", file="other.toml")  # another name, other cells
    _error(capsys, ["study", other, "--out", out], str(out), "'t'", "'other'", "another --out directory")
    renamed = _spec(tmp_path, name="other", file="renamed.toml")  # the same cells under another name
    _error(capsys, ["study", renamed, "--out", out], "holds the study 't'")
    _error(capsys, ["study", renamed, "--summary", out], "holds the study 't'")
    cells = _spec(tmp_path, truth="g2", file="cells.toml")  # the study's name, other cells
    _error(capsys, ["study", cells, "--out", out], str(out), PAPER, HALF, "another --out directory")
    assert _tree(out) == before


def test_summary_of_fewer_cells_and_a_new_cell_beside(run, capsys, tmp_path):
    spec, out = run
    one = tmp_path / "one.toml"
    one.write_text(spec.read_text().replace('noise = ["paper", 0.5]', 'noise = ["paper"]'))
    assert main(["study", str(one), "--summary", str(out), "--json"]) == 0
    assert [c["id"] for c in json.loads(capsys.readouterr().out)["cells"]] == [PAPER]
    more = tmp_path / "more.toml"
    more.write_text(spec.read_text().replace('noise = ["paper", 0.5]', 'noise = ["paper", 0.5, "none"]'))
    assert main(["study", str(more), "--out", str(out), "--quiet"]) == 0  # the same study, one cell more
    assert json.loads((out / "paper_paper3_none_g1" / "cell.json").read_text())["study"] == "t"


def test_directory_without_a_study_is_refused(tmp_path, capsys):
    spec, out = _spec(tmp_path), tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("mine\n")
    _error(capsys, ["study", spec, "--out", out], str(out), "holds no study")
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]


# --------------------------------------------------------------------------- 5. a summary that no longer describes the directory

def test_interrupted_run_leaves_no_stale_summary(run, capsys, monkeypatch):
    spec, out = run
    assert json.loads((out / "summary.json").read_text())["trials"] == 4
    spec.write_text(spec.read_text().replace("trials = 4", "trials = 40"))
    monkeypatch.setattr(Progress, "__call__", lambda self, done: (_ for _ in ()).throw(KeyboardInterrupt))
    assert main(["study", str(spec), "--out", str(out)]) == 130
    capsys.readouterr()
    assert not (out / "summary.json").exists()


def test_resume_without_work_keeps_the_summary(run):
    spec, out = run
    before = json.loads((out / "summary.json").read_text())
    again = study.run_study(study_spec.load_spec(spec), out)
    assert again["run"]["chunks_run"] == 0 and _numbers(again) == _numbers(before)


# --------------------------------------------------------------------------- 6. a truth-key typo

def test_truth_key_typo_is_an_unknown_source_error(tmp_path):
    p = _spec(tmp_path)
    p.write_text(p.read_text().replace('name = "g1"', 'nam = "g1"'))
    with pytest.raises(study_spec.StudySpecError, match="unknown source error 'nam'") as e:
        study_spec.load_spec(p)
    assert e.value.where == f"{p}:12"


# --------------------------------------------------------------------------- 4. parameters the poses cannot identify

def test_study_with_unidentifiable_params_is_refused(tmp_path, capsys):
    p = _spec(tmp_path, extra='params = "all"', design='scheme = "paper"\nn = 8')
    with pytest.raises(study_spec.StudySpecError, match=r"not identifiable.*rank 9 of 12") as e:
        study_spec.load_spec(p)
    assert e.value.where == f"{p}:8"  # the [[design]] table
    _error(capsys, ["study", p, "--out", tmp_path / "o", "--quiet"], f"{p}:8", "rank 9 of 12", "params = 'all'")
    assert not (tmp_path / "o").exists()
    ok = _spec(tmp_path, extra='params = "gauge_fixed"', design='scheme = "paper"\nn = 8')
    assert len(study_spec.load_spec(ok).cells) == 2  # the gauge fixed: identifiable


def test_compare_with_unidentifiable_params_is_refused(capsys, tmp_path):
    out = tmp_path / "c.json"
    _error(capsys, ["compare", "--params", "all", "--n", "8", "--trials", "5", "--quiet", "--out", out],
           "--params all", "rank 9 of 12", "--n 8")
    assert not out.exists()


# --------------------------------------------------------------------------- 7, 8: study --robot, compare --set

def test_study_help_does_not_offer_robot(capsys, tmp_path):
    with pytest.raises(SystemExit):
        main(["study", "--help"])
    assert "--robot" not in capsys.readouterr().out
    with pytest.raises(SystemExit):
        main(["compare", "--help"])
    assert "--robot FILE" in capsys.readouterr().out  # the shared option is untouched for the others
    _error(capsys, ["study", _spec(tmp_path), "--out", tmp_path / "o", "--robot", "x.toml"], "robots = [...]")
    assert not (tmp_path / "o").exists()


def test_compare_set_heading(capsys):
    assert main(["compare", "--set", "theta1=2", "--set", "theta2=-1", "--trials", "1", "--methods", "tsvd",
                 "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "group set: true offsets +2.000,-1.000 deg" in out and "set: set" not in out


def test_study_chunk_read_refuses_an_npy(tmp_path):
    p = tmp_path / "chunk-0.npz"
    buf = io.BytesIO()
    np.save(buf, np.arange(3))
    p.write_bytes(buf.getvalue())
    with pytest.raises(ZerocalError, match="not a readable chunk file"):
        study_chunks.read_chunk(p, "c", "d", ["theta1"], 0, 3)


# --------------------------------------------------------------------------- the new-user review

def test_bogus_compile_mode_writes_nothing(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("ZEROCAL_COMPILE", "bogus")
    out = tmp_path / "bogus"
    _error(capsys, ["study", _spec(tmp_path), "--out", out], "ZEROCAL_COMPILE='bogus'")
    assert not out.exists()
    with pytest.raises(ZerocalError, match="ZEROCAL_COMPILE"):
        study.run_study(study_spec.load_spec(_spec(tmp_path)), out)
    assert not out.exists()


def test_params_without_the_zero_offsets_is_refused(tmp_path, capsys):
    spec = _spec(tmp_path, extra='params = "base"', design="n = 8")
    _error(capsys, ["study", spec, "--out", tmp_path / "o"], f"{spec}:7:", "must contain the zero offsets theta1")
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("mode", ["--summary", "--out"])
def test_foreign_chunk_beyond_the_trials_is_refused(run, capsys, mode):
    spec, out = run
    bad = out / PAPER / "chunk-5.npz"
    shutil.copyfile(out / PAPER / "chunk-1.npz", bad)
    before = _tree(out)
    _error(capsys, ["study", spec, mode, out, "--quiet"], str(bad), "holds trials 2..3", "trials 10..11")
    assert _tree(out) == before


def test_own_chunk_beyond_the_trials_is_kept_and_not_summarised(run):
    spec, out = run
    s = study_spec.load_spec(spec)
    first = study.summarize(s, out)
    spec.write_text(spec.read_text().replace("trials = 4", "trials = 2"))
    s2 = study_spec.load_spec(spec)
    assert study.plan(s2, out) == ([], 2)  # chunk-1 is beyond the 1 chunk: checked, kept, not counted
    assert all(c["trials_done"] == 2 for c in study.summarize(s2, out)["cells"])
    assert _numbers(study.summarize(s, out)) == _numbers(first)


@pytest.mark.parametrize("text", ["", '{"format": "zerocal st'])
def test_unreadable_cell_json_says_delete_it_alone(run, done, capsys, text):
    spec, out = run
    bad = out / PAPER / "cell.json"
    bad.write_text(text)
    line = _error(capsys, ["study", spec, "--out", out], str(bad), "not a readable cell record", "cell.json alone")
    assert "other settings" not in line and "remove the cell's directory" not in line
    bad.unlink()
    assert main(["study", str(spec), "--out", str(out), "--quiet", "--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert json.loads(bad.read_text())["study"] == "t"  # written again, though no chunk was run
    assert again["run"]["chunks_run"] == 0
    assert _numbers(again) == _numbers(json.loads((done / "out" / "summary.json").read_text()))


def _rewrite(p, **change):
    with np.load(p) as z:
        cols = {k: z[k] for k in z.files}
    for k, f in change.items():
        cols[k] = f(cols[k])
    np.savez(p, **cols)


@pytest.mark.parametrize("change, words", [
    ({"est_theta1": lambda c: c.astype(str)}, ["column est_theta1", "not floating-point numbers"]),
    ({"trial": lambda c: c.astype(float)}, ["trial column holds float64", "not integers"]),
    ({"est_rMx": lambda c: np.where(np.arange(c.size) == 1, np.nan, c)}, ["row 1, trial 3", "est_rMx = nan"]),
])
def test_chunk_with_a_bad_column_says_what(run, capsys, change, words):
    spec, out = run
    bad = out / PAPER / "chunk-1.npz"
    _rewrite(bad, **change)
    for mode in ("--summary", "--out"):
        _error(capsys, ["study", spec, mode, out], str(bad), *words)


def test_text_chunk_is_not_a_chunk_file(run, capsys):
    spec, out = run
    _text(out / PAPER / "chunk-1.npz")
    line = _error(capsys, ["study", spec, "--summary", out], "not an npz archive")
    assert "pickle" not in line


@pytest.mark.parametrize("opt", [["--workers", "2"], ["--scheduler", "bad"], ["--workers", "1"]])
def test_summary_refuses_the_run_options(run, capsys, opt):
    spec, out = run
    _error(capsys, ["study", spec, "--summary", out, *opt], opt[0], "--summary")


def test_summary_of_a_file(tmp_path, capsys):
    spec = _spec(tmp_path)
    _error(capsys, ["study", spec, "--summary", spec], str(spec), "is a file (the spec?)", "output directory")


@pytest.mark.parametrize("edit, where, words", [
    (("[[truth]]", "[[truths]]"), 11, ["unknown key 'truths'"]),
    (("[[design]]", "[[designs]]"), 8, ["unknown key 'designs'"]),
    (("[[design]]", "[design]"), 8, ["[design] is a single table", "[[design]]"]),
    (("theta1 = 2", "theta1 = 200"), 13, ["theta1 = 200 deg", "plausible 10 deg"]),
])
def test_spec_messages_point_at_the_line(tmp_path, capsys, edit, where, words):
    spec = _spec(tmp_path)
    spec.write_text(spec.read_text().replace(*edit))
    _error(capsys, ["study", spec, "--out", tmp_path / "o"], f"{spec}:{where}:", *words)
    assert not (tmp_path / "o").exists()


def test_interrupted_inside_a_line_ends_it_first(run, capsys, monkeypatch):
    spec, out = run
    spec.write_text(spec.read_text().replace("trials = 4", "trials = 6"))

    def cut(self, done):  # Ctrl-C inside a progress line, before its newline
        self.stream.write("study [###")
        raise KeyboardInterrupt

    monkeypatch.setattr(Progress, "__call__", cut)
    assert main(["study", str(spec), "--out", str(out)]) == 130
    lines = capsys.readouterr().err.splitlines()
    assert lines[0].startswith("study t: 2 cells x 3 chunks") and lines[-1] == "zerocal study: interrupted", lines
