"""Compiled CasADi Functions, cached on disk: the fast tier of the hot loops.

CasADi evaluates an SX Function in its virtual machine (about 10-20 ns per
instruction here); the same Function generated as C and compiled runs 6-8x
faster (``benchmarks/bench_nlls.py`` prints both).  This module turns a set of
Functions into one shared library and loads them back as ``external``
Functions with the same names, inputs and outputs:

* the C source comes from ``casadi.CodeGenerator``; the library is built with
  the system C compiler (``$CC``, else ``cc``/``gcc``) with ``-O1
  -ffp-contract=off`` (no fused multiply-add: the compiled Functions return
  the interpreted ones' numbers, bit for bit on this machine - a test);
* libraries are cached under ``$ZEROCAL_CACHE`` (default
  ``~/.cache/zerocal_sym``), named by a hash of the serialized Functions,
  the CasADi version, the compiler and its flags: a cached library is never
  stale, because any change of the Functions changes their serialization;
  built by a job in a temporary folder and moved into place (a rename), one
  build per library across processes (a lock file), so concurrent processes
  can share the cache;
* ``ZEROCAL_COMPILE`` decides when: ``auto`` (default) -- the caller compiles
  the Functions it calls many times (a Monte Carlo, a batch, a loop of
  identifications; :class:`Tier`): a library already in the cache is loaded
  at once, else one is built in a background thread and used when ready
  (one-shot commands never pay for either); ``always`` --
  compile when first asked, and wait; ``never`` -- interpreted only.
  Anything that goes wrong (no compiler, a failed build, an unloadable
  library) leaves the interpreted Functions in place and is recorded in
  :func:`status`: compilation is an optimisation, never a requirement.
"""
from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
import subprocess
import tempfile
import threading
import time
from pathlib import Path

#: compiler flags (no FMA contraction: the same arithmetic as CasADi's virtual machine)
CFLAGS = ("-O1", "-fPIC", "-shared", "-ffp-contract=off")
#: modes of ZEROCAL_COMPILE
MODES = ("auto", "always", "never")
#: a Tier compiles after this many calls (mode "auto")
HOT_CALLS = 25

_LOG: list = []          # (time, key, event) of this process, newest last
_LOG_LOCK = threading.Lock()


def mode() -> str:
    """``ZEROCAL_COMPILE`` (``auto`` if unset); an unknown value is a user error naming the allowed ones."""
    m = os.environ.get("ZEROCAL_COMPILE", "auto").strip().lower() or "auto"
    aliases = {"0": "never", "off": "never", "no": "never", "false": "never",
               "1": "always", "on": "always", "yes": "always", "true": "always"}
    m = aliases.get(m, m)
    if m not in MODES:
        from zerocal_sym.errors import ZerocalError

        raise ZerocalError(f"ZEROCAL_COMPILE={os.environ.get('ZEROCAL_COMPILE')!r}: expected one of "
                         f"{', '.join(MODES)}")
    return m


def cache_dir() -> Path:
    """Where compiled libraries are kept (``$ZEROCAL_CACHE``, else ``~/.cache/zerocal_sym``)."""
    d = os.environ.get("ZEROCAL_CACHE")
    if d:
        return Path(os.path.expanduser(d))
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "zerocal_sym"


def compiler() -> str | None:
    """The C compiler: ``$CC`` if set (None when it is not found), else ``cc`` or ``gcc`` on the PATH."""
    cc = os.environ.get("CC")
    if cc:
        return shutil.which(cc)
    return shutil.which("cc") or shutil.which("gcc")


def _log(key, event):
    with _LOG_LOCK:
        _LOG.append((time.time(), key, event))
        del _LOG[:-200]


def _fell_back(key, reason):
    """Record a fallback; with ``ZEROCAL_COMPILE=always`` (compiling was asked for) also warn."""
    _log(key, reason)
    if mode() == "always":
        import warnings

        warnings.warn(f"ZEROCAL_COMPILE=always, but {key} runs interpreted: {reason}", RuntimeWarning, stacklevel=3)


def status() -> list:
    """What the compiled tier did in this process: ``[(unix time, key, event), ...]``, newest last."""
    with _LOG_LOCK:
        return list(_LOG)


def source(functions: dict, name: str) -> str:
    """The C source of ``functions`` (name -> casadi.Function) in one translation unit."""
    import casadi as ca

    cg = ca.CodeGenerator(name + ".c", {"with_header": False, "verbose": False})
    for f in functions.values():
        cg.add(f)
    return cg.dump()


def library_path(functions: dict, cc: str, tag: str) -> Path:
    """The cache path of the library of ``functions`` built with ``cc`` and :data:`CFLAGS`."""
    import casadi as ca

    h = hashlib.sha256("\0".join([os.path.basename(cc), " ".join(CFLAGS), ca.__version__]).encode())
    for k in sorted(functions):
        h.update(b"\0" + k.encode() + b"\0" + functions[k].serialize().encode())
    safe = "".join(c if c.isalnum() or c in "-_" else "_" for c in tag)[:60]
    return cache_dir() / f"{safe}-{h.hexdigest()[:20]}.so"


#: the build job: compile in its own folder (the compiler's temporary files there too), move the library into
#: place, remove the folder -- it completes by itself if this process ends first
_BUILD_SH = ('cd "$ZC_TMP" && "$@" -o out.so -lm 2> err.txt && mv -f out.so "$ZC_OUT" '
             '&& cd / && rm -rf "$ZC_TMP"')


def build(src: str, path: Path, cc: str) -> None:
    """Compile ``src`` into ``path``: a build job in a temporary folder beside it, then an atomic move.

    The job (``sh``, its own process group) finishes by itself when this
    process ends or is killed first, so the work lands in the cache;
    :func:`stop_builds` stops it (Ctrl-C of a command).
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    for old in path.parent.glob(".build-*"):  # left by a job that was stopped or failed
        try:
            if time.time() - old.stat().st_mtime > 3600:
                shutil.rmtree(old, ignore_errors=True)
        except OSError:
            pass
    tmp = tempfile.mkdtemp(dir=path.parent, prefix=".build-")
    try:
        (Path(tmp) / "src.c").write_text(src)
        env = dict(os.environ, ZC_TMP=tmp, ZC_OUT=str(path), TMPDIR=tmp)
        proc = subprocess.Popen(["sh", "-c", _BUILD_SH, "zerocal-build", cc, *CFLAGS, "src.c"], env=env,
                                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                start_new_session=True)  # its own group: Ctrl-C of the command does not reach it
        with _RUNNING_LOCK:
            _RUNNING[proc] = tmp
        try:
            proc.wait()
        finally:
            with _RUNNING_LOCK:
                _RUNNING.pop(proc, None)
        if proc.returncode != 0 or not path.exists():
            try:
                err = (Path(tmp) / "err.txt").read_text().strip()[-400:]
            except OSError:
                err = ""
            raise RuntimeError(f"{cc} failed ({proc.returncode}): {err}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


_RUNNING: dict = {}     # build jobs of this process: Popen -> its folder
_RUNNING_LOCK = threading.Lock()


def stop_builds() -> None:
    """Stop the build jobs of this process (the compiler and its passes; their folders go with them).

    The CLI calls it when a command is interrupted; at a normal exit the jobs
    finish by themselves and their libraries land in the cache.
    """
    with _RUNNING_LOCK:
        jobs = list(_RUNNING.items())
    for proc, tmp in jobs:
        try:
            os.killpg(proc.pid, 9)  # the shell, the compiler driver and the passes it started
            proc.wait(timeout=5)
        except Exception:  # noqa: BLE001 - already gone
            pass
        shutil.rmtree(tmp, ignore_errors=True)


@contextlib.contextmanager
def _build_lock(path: Path):
    """An exclusive advisory lock on ``path``'s lock file (no-op where ``fcntl`` is missing)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        import fcntl
    except ImportError:  # not POSIX: concurrent builds are only wasteful (the final rename keeps them safe)
        yield
        return
    with open(path.with_suffix(".lock"), "a") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def load(functions: dict, path: Path) -> dict:
    """``external`` Functions of the same names from the library at ``path``."""
    import casadi as ca

    return {k: ca.external(f.name(), str(path)) for k, f in functions.items()}


def compile_functions(functions: dict, tag: str, cached_only: bool = False, memo: dict | None = None) -> dict | None:
    """The compiled twins of ``functions`` (name -> casadi.Function), or None.

    Builds the library unless it is in the cache (``cached_only``: only a
    cached library, never a build).  None when there is no compiler, the
    build or the load failed (recorded in :func:`status`).  ``memo``: a dict
    the caller keeps for these Functions, so that their library path (a
    serialization of every Function) is computed once per compiler.
    """
    if len({f.name() for f in functions.values()}) != len(functions):
        raise ValueError(f"{tag}: the Functions to compile need distinct names")
    cc = compiler()
    if cc is None:
        _fell_back(tag, "no C compiler (set CC): interpreted")
        return None
    try:
        path = memo.get(cc) if memo is not None else None
        if path is None:
            path = library_path(functions, cc, tag)
            if memo is not None:
                memo[cc] = path
        if not path.exists() and cached_only:
            return None
        for attempt in (0, 1):
            if not path.exists():
                with _build_lock(path):  # another process building the same library: wait for it, then load
                    if not path.exists():
                        t = time.perf_counter()
                        build(source(functions, "zc_" + path.stem.rsplit("-", 1)[-1]), path, cc)
                        _log(tag, f"compiled in {time.perf_counter() - t:.1f} s: {path}")
            try:
                out = _checked(functions, load(functions, path))
                break
            except Exception as exc:  # noqa: BLE001 - a damaged cached library: remove it, build once more
                if attempt or cached_only:
                    raise
                _log(tag, f"cached library unusable ({type(exc).__name__}: {exc}): rebuilt")
                path.unlink(missing_ok=True)
        _log(tag, f"loaded {path.name}")
        return out
    except Exception as exc:  # noqa: BLE001 - compilation is an optimisation: fall back, say why
        _fell_back(tag, f"failed, interpreted: {type(exc).__name__}: {exc}")
        return None


def _checked(functions: dict, out: dict) -> dict:
    """``out`` if every compiled twin has its source Function's signature, else RuntimeError."""
    for k, f in functions.items():
        g = out[k]
        if (g.n_in(), g.n_out()) != (f.n_in(), f.n_out()) or any(
                g.sparsity_in(i) != f.sparsity_in(i) for i in range(f.n_in())) or any(
                g.sparsity_out(i) != f.sparsity_out(i) for i in range(f.n_out())):
            raise RuntimeError(f"compiled {k!r} does not match its source Function")
    return out


class Tier:
    """Interpreted Functions now, compiled twins when they are ready.

    ``tier.get()`` returns the current dict (name -> Function); callers
    rebuild what they derived from it when :attr:`version` changes.
    :meth:`hot` says the Functions will be called many times: in mode
    ``auto`` a background thread compiles them (a cached library loads at
    once), in ``always`` it compiles now, in ``never`` nothing happens.
    :meth:`touch` counts calls and declares the tier hot after
    :data:`HOT_CALLS`.
    """

    def __init__(self, functions: dict, tag: str):
        self.tag = tag
        self._interp = dict(functions)
        self._current = self._interp
        self.version = 0
        self.compiled = False
        self._calls = 0
        self._started = False
        self._lock = threading.Lock()
        self._thread = None
        self._memo = {}       # the library path per compiler (compile_functions)
        if mode() == "always":
            self._started = True  # tried once; hot() does not build again
            self._swap(self._compile())

    def _compile(self, cached_only: bool = False):
        return compile_functions(self._interp, self.tag, cached_only, self._memo)

    def get(self) -> dict:
        return self._current

    def _swap(self, out):
        if out is not None:
            with self._lock:
                self._current, self.compiled = out, True
                self.version += 1
        return out

    def hot(self, wait: bool = False) -> None:
        """The Functions will be called many times: use a cached library, else build one.

        Mode ``auto``: the build runs in a background thread (``wait``: in
        this one); ``always``: now; ``never``: nothing.
        """
        m = mode()
        if self.compiled or m == "never":
            return
        with self._lock:
            start, self._started = not self._started, True
        if start:
            if self._swap(self._compile(cached_only=True)) is not None:
                return
            if m == "always" or wait:
                self._swap(self._compile())
                return
            self._thread = threading.Thread(target=lambda: self._swap(self._compile()),
                                            name=f"compile {self.tag}", daemon=True)
            self._thread.start()
        if wait and self._thread is not None:
            self._thread.join()

    def touch(self) -> None:
        """One more call; the tier turns hot after :data:`HOT_CALLS`."""
        self._calls += 1
        if self._calls == HOT_CALLS:
            self.hot()
