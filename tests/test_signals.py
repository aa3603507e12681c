"""Signals: Ctrl-C while the command line starts, SIGTERM, a signal after the outputs, workers that die with
the command.

Ctrl-C (SIGINT) and SIGTERM stop a command at any point after its code has
started -- while the command line is imported too -- with one line on stderr
and status 130 / 143; SIGTERM cleans up as Ctrl-C does (the temporary
directory of a plot or ``reproduce --out`` is removed).  A signal that comes
once the outputs are written does not change the status.  The worker
processes of ``--workers N`` (and multiprocessing's resource tracker) end
when the command ends, however it ends: SIGTERM, or SIGKILL, which no
process can handle.
"""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from zerocal_sym.cli import _interrupt, main

ROOT = Path(__file__).resolve().parents[1]
LINUX = sys.platform.startswith("linux") and Path("/proc/self/status").exists()
needs_proc = pytest.mark.skipif(not LINUX, reason="reads /proc (Linux)")


def zerocal(*argv, cwd=None, stderr=subprocess.PIPE):
    return subprocess.Popen([sys.executable, "-m", "zerocal_sym", *map(str, argv)], stdout=subprocess.DEVNULL,
                            stderr=stderr, text=True, cwd=cwd or ROOT)


def catches(pid, sig) -> bool:
    """Whether process ``pid`` has a handler for ``sig`` (/proc/PID/status, SigCgt)."""
    try:
        with open(f"/proc/{pid}/status") as fh:
            for line in fh:
                if line.startswith("SigCgt:"):
                    return bool(int(line.split()[1], 16) >> (sig - 1) & 1)
    except OSError:
        pass
    return False


def descendants(pid) -> list:
    """The processes below ``pid`` (children, theirs, ...), from /proc."""
    out, todo = [], [pid]
    while todo:
        q = todo.pop()
        try:
            tasks = os.listdir(f"/proc/{q}/task")
        except OSError:
            continue
        for t in tasks:
            try:
                with open(f"/proc/{q}/task/{t}/children") as fh:
                    kids = [int(x) for x in fh.read().split()]
            except OSError:
                continue
            for k in kids:
                if k not in out:
                    out.append(k)
                    todo.append(k)
    return out


def running(pid) -> bool:
    """Whether ``pid`` exists and is not a zombie."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def cmdline(pid) -> str:
    try:
        with open(f"/proc/{pid}/cmdline") as fh:
            return fh.read().replace("\0", " ")
    except OSError:
        return ""


def wait_until(cond, timeout, step=0.0005):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if cond():
            return True
        time.sleep(step)
    return cond()


# --------------------------------------------------------------------------- while the command line starts

@needs_proc
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_signal_while_the_command_line_starts(tmp_path, sig):
    """From the first line of zerocal's own code on (the command line's imports, tens of ms, included): one
    line, 130 or 143, no traceback.  Before, a Ctrl-C in the first 30 ms was a traceback from an import or
    death by SIGINT.  The signal is sent at several short delays after the process has its handlers (it then
    catches SIGTERM, which Python does not by default: zerocal_sym.__main__.console has started)."""
    status, word = _interrupt.EXIT_STATUS[sig], _interrupt.WORDS[sig]
    for delay in (0.0, 0.002, 0.005, 0.01, 0.02, 0.04, 0.08, 0.15):
        p = zerocal("compare", "--trials", "100000", "--quiet", "--out", tmp_path / "c.json")
        assert wait_until(lambda: catches(p.pid, signal.SIGTERM) or p.poll() is not None, 30.0)
        time.sleep(delay)
        p.send_signal(sig)
        _, err = p.communicate(timeout=60)
        assert p.returncode == status, (delay, p.returncode, err)
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].endswith(word) and "Traceback" not in err, (delay, err)
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------- SIGTERM cleans up

def test_sigterm_in_process_is_143_and_writes_nothing(tmp_path, capsys, monkeypatch):
    """SIGTERM during a command (here raised by the progress callback): the Monte Carlo stops, nothing is
    written, one line "terminated", status 143."""
    from zerocal_sym.identify.progress import Progress

    monkeypatch.setattr(Progress, "__call__", lambda self, done: signal.raise_signal(signal.SIGTERM))
    out = tmp_path / "c.json"
    assert main(["compare", "--trials", "20", "--methods", "tsvd", "--out", str(out)]) == 143
    assert capsys.readouterr().err.strip().splitlines()[-1] == "zerocal compare: terminated"
    assert list(tmp_path.iterdir()) == []
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL  # the handler was the command's only


@needs_proc
def test_sigterm_removes_the_temporary_directory(tmp_path):
    """SIGTERM while ``reproduce --out DIR`` fills its temporary directory (.DIR.*.tmp, beside DIR): it is
    removed, nothing is written, status 143.  Before, SIGTERM left the hidden directory."""
    p = zerocal("reproduce", "--trials", "3", "--out", tmp_path / "rep")
    assert wait_until(lambda: any(tmp_path.glob(".rep.*.tmp")) or p.poll() is not None, 120.0, step=0.01)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 143, err
    assert err.strip().splitlines()[-1] == "zerocal reproduce: terminated" and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("what", ["directory", "file"])
def test_a_stop_right_after_the_temporary_is_made_leaves_nothing(tmp_path, monkeypatch, what):
    """A Ctrl-C that arrives just as the temporary directory or file is made -- before its name is recorded for
    the cleanup -- acts once the name is known: nothing is left (the race behind a hidden .rep.*.tmp after
    SIGTERM on a loaded machine).  The signal is raised inside tempfile's call, deterministically."""
    import tempfile

    from zerocal_sym.io import files

    name = "mkdtemp" if what == "directory" else "mkstemp"
    real = getattr(tempfile, name)

    def then_a_stop(*args, **kwargs):
        out = real(*args, **kwargs)
        signal.raise_signal(signal.SIGINT)  # Python's default handler: KeyboardInterrupt at the next check
        return out

    monkeypatch.setattr(tempfile, name, then_a_stop)
    with pytest.raises(KeyboardInterrupt):
        if what == "directory":
            with files.staged_directory(tmp_path / "out") as d:
                (d / "a.txt").write_text("a")
        else:
            files.atomic_write_text(tmp_path / "out.txt", "a")
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------- a signal after the outputs

@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_signal_after_the_outputs_does_not_change_the_status(tmp_path, capsys, monkeypatch, sig):
    """A Ctrl-C or SIGTERM that arrives once the outputs are written (while the command reports) does not
    turn the success into 130/143: the file is there, the report complete, the status 0.  Before, a late
    SIGINT made the exit status 130 with the output written."""
    written = _interrupt.outputs_written

    def then_a_signal():
        written()
        signal.raise_signal(sig)

    monkeypatch.setattr(_interrupt, "outputs_written", then_a_signal)
    out = tmp_path / "d.csv"
    assert main(["simulate", "--group", "1", "--out", str(out)]) == 0
    o, e = capsys.readouterr()
    assert out.exists() and o.startswith("wrote 6 poses") and e == ""


def test_a_signal_before_the_outputs_stops_the_command(tmp_path, capsys, monkeypatch):
    """The other side: a SIGINT inside the command, before its outputs, stops it (130, nothing written)."""
    from zerocal_sym.cli import cmd_simulate

    real = cmd_simulate.run

    def run(args):
        signal.raise_signal(signal.SIGINT)
        return real(args)

    monkeypatch.setattr(cmd_simulate, "run", run)
    out = tmp_path / "d.csv"
    assert main(["simulate", "--group", "1", "--out", str(out)]) == 130
    assert capsys.readouterr().err == "zerocal simulate: interrupted\n" and not out.exists()


def test_the_handler_decides_by_where_the_command_is():
    """Inside the command's run the handler raises; in call() itself (the command not started yet, or just
    returned) it does not, and leaves the decision to its re-trip; after the command it does nothing.  Before,
    a SIGINT landing after run() had returned still made the status 130."""
    with _interrupt.installed() as guard:
        guard._kick = lambda: None  # (no re-trip: this test calls the handler itself)
        inside = []

        def run():
            inside.append(sys._getframe())
            return sys._getframe(1)  # call()'s own frame

        between = guard.call(run)
        assert between.f_code is _interrupt._CALL_CODE
        guard.done = False  # as if the command were still running
        with pytest.raises(KeyboardInterrupt):
            guard.handler(signal.SIGINT, inside[0])
        assert guard.handler(signal.SIGINT, between) is None  # at the boundary: no raise
        guard.done = True
        assert guard.handler(signal.SIGTERM, inside[0]) is None  # finished: nothing
        assert _interrupt.interrupt_status() == (143, "terminated")
    _interrupt.reset()
    assert _interrupt.interrupt_status() == (130, "interrupted")


# --------------------------------------------------------------------------- workers die with the command

def _workers_started(p, n=2, timeout=120.0):
    def up():
        return sum("spawn_main" in cmdline(k) for k in descendants(p.pid)) >= n or p.poll() is not None

    assert wait_until(up, timeout, step=0.05), "the workers did not start"
    assert p.poll() is None, "the command ended before it was signalled"
    time.sleep(0.5)  # into the Monte Carlo
    return descendants(p.pid)


COMMANDS = {
    "compare": ["compare", "--trials", "100000", "--workers", "2", "--quiet", "--out", "OUT/c.json"],
    "study": ["study", "SPEC", "--out", "OUT/s", "--workers", "2", "--quiet"],
}


@needs_proc
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
@pytest.mark.parametrize("command", list(COMMANDS))
def test_workers_end_with_the_command(tmp_path, command, sig):
    """``--workers 2``, the command signalled: within a few seconds none of its processes is left (the two
    workers, multiprocessing's resource tracker), and no temporary file in the output directory.  Before,
    after SIGTERM or SIGKILL the workers and the tracker waited on their pipes for good (alive 60 s later)."""
    spec = tmp_path / "spec.toml"
    spec.write_text('trials = 1000000\nchunk = 50\nrobots = ["paper"]\n[[design]]\nscheme = "auto"\n'
                    "[[truth]]\ntheta1 = 1\n")
    out = tmp_path / "out"
    out.mkdir()
    argv = [str(spec) if a == "SPEC" else a.replace("OUT", str(out)) for a in COMMANDS[command]]
    with open(tmp_path / "stderr.txt", "w") as err:  # (not a pipe: a worker left over would hold it open)
        p = zerocal(*argv, stderr=err)
        kids = _workers_started(p)
        try:
            assert len(kids) >= 2, kids
            p.send_signal(sig)
            p.wait(timeout=60)
            left = []
            assert wait_until(lambda: not [k for k in kids if running(k)], 10.0, step=0.05), \
                [(k, cmdline(k)) for k in kids if running(k)]
        finally:
            left = [k for k in kids if running(k)]
            for k in left:  # (only the processes this test started, by their ids)
                os.kill(k, signal.SIGKILL)
    text = (tmp_path / "stderr.txt").read_text()
    if sig == signal.SIGTERM:
        assert p.returncode == 143 and text.strip().splitlines()[-1] == f"zerocal {command}: terminated", text
        assert "Traceback" not in text
    else:
        assert p.returncode == -signal.SIGKILL
    assert [q.name for q in out.rglob(".*")] == []
    assert not (out / "c.json").exists() and not (out / "s" / "summary.json").exists()
