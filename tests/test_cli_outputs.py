"""Output wiring of the CLI: plots written where asked, unwritable outputs a one-line error."""
import json

import pytest

from zerocal_sym.cli import main


@pytest.fixture(scope="module")
def data_csv(tmp_path_factory):
    p = tmp_path_factory.mktemp("d") / "d.csv"
    assert main(["simulate", "--group", "1", "--seed", "3", "--out", str(p)]) == 0
    return p


def test_identify_plot_dir(data_csv, tmp_path, capsys):
    out = tmp_path / "plots"
    assert main(["identify", str(data_csv), "--plot", str(out), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["success"] is True
    assert (out / "residuals.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("argv_tail", [["simulate", "--group", "1", "--out"], ["identify", "DATA", "--out"]])
def test_output_path_is_a_directory(data_csv, tmp_path, capsys, argv_tail):
    argv = [a if a != "DATA" else str(data_csv) for a in argv_tail] + [str(tmp_path)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "is a directory" in err[0] and str(tmp_path) in err[0]
    assert list(tmp_path.iterdir()) == [], "nothing written"
