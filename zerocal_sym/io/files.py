"""Writing outputs: all-or-nothing, and the rules for an output's path.

The rules (``docs/data-format.md``, "Output files"):

* **All or nothing.**  A file is written to a temporary file beside its
  target and renamed into place when complete; a command that fails leaves no
  half-written file and no temporary one.  An error names the user's path,
  never the temporary one.
* **Permissions.**  A new file gets ``0o666 & ~umask`` (as ``>`` in a shell);
  a regular file that is replaced keeps its permission bits.
* **A symbolic link** given as the output is written through: its target is
  replaced (atomically, beside the target) and the link is kept.
* **Not a regular file.**  An existing directory given for a file, a block
  device or a socket is an error; a character device (``/dev/null``, a
  terminal) or a FIFO (a pipe, ``>(...)`` in bash) -- and a link under
  ``/dev/`` or ``/proc/`` (``/dev/stdout``, ``/dev/fd/3``) -- is written to
  as a stream, never replaced.
* **An empty name** is an error.
* **An input is never an output**: :func:`check_outputs` refuses, before any
  work, an output that is one of the command's inputs (the same file however
  named: a symlink, ``./``, ``..``, a hard link; compared by device and
  inode) or another of its outputs.
* **Directories of outputs** (``--plot DIR``, ``reproduce --out DIR``) are
  filled in a temporary directory beside them and moved into place when the
  command has succeeded (:func:`staged_directory`); a failed command leaves
  no directory it created.
"""
from __future__ import annotations

import contextlib
import json
import os
import shutil
import stat
import tempfile
from pathlib import Path

import numpy as np

from zerocal_sym.errors import ZerocalError

#: a symbolic link under these prefixes is written as a stream (/dev/stdout, /dev/fd/3, /proc/self/fd/1)
STREAM_PREFIXES = ("/dev/", "/proc/")


class OutputError(ZerocalError):
    """An output path that cannot or must not be written (empty, an input, a directory, a device)."""


def current_umask() -> int:
    """The process's umask (read without changing it for longer than the call)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _kind(mode) -> str:
    for test, name in ((stat.S_ISDIR, "a directory"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISREG, "a regular file")):
        if test(mode):
            return name
    return "not a regular file"


def _stat(path: str):
    """``os.stat`` (following links) or None if nothing is there (a dangling link included)."""
    try:
        return os.stat(path)
    except FileNotFoundError:
        return None
    except NotADirectoryError:
        raise OSError(20, "a component of the path is not a directory", path) from None
    except OSError as exc:
        raise OSError(exc.errno, exc.strerror, path) from None


def is_stream(path, st=None) -> bool:
    """Whether ``path`` is written as a stream: an existing character device or FIFO, or a link under /dev/, /proc/."""
    p = os.fspath(path)
    if os.path.abspath(p).startswith(STREAM_PREFIXES) and os.path.islink(p):
        return True
    st = _stat(p) if st is None else st
    return st is not None and (stat.S_ISCHR(st.st_mode) or stat.S_ISFIFO(st.st_mode))


def _created_parents(parent: Path) -> list:
    """Create ``parent`` (and missing ancestors); return the directories created, deepest first."""
    missing = []
    p = parent
    while not p.exists() and p != p.parent:
        missing.append(p)
        p = p.parent
    parent.mkdir(parents=True, exist_ok=True)
    return missing


def _remove_dirs(dirs) -> None:
    for d in dirs:  # deepest first; only if still empty
        try:
            os.rmdir(d)
        except OSError:
            break


def atomic_write_bytes(path, data: bytes) -> None:
    """Write ``data`` to ``path`` all-or-nothing (the module's rules).

    Raises
    ------
    OutputError
        An empty name, a block device or a socket.
    OSError
        With ``filename`` the user's ``path``: a directory given, no
        permission, a full disk, ...
    """
    p = os.fspath(path)
    if p == "":
        raise OutputError("empty output file name")
    st = _stat(p)
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise IsADirectoryError(21, "is a directory, expected a file name", p)
    if is_stream(p, st):
        try:
            with open(p, "wb") as fh:
                fh.write(data)
        except OSError as exc:
            raise OSError(exc.errno, exc.strerror, p) from None
        return
    if st is not None and not stat.S_ISREG(st.st_mode):
        raise OutputError(f"is {_kind(st.st_mode)}, not a regular file: not replaced", where=p)
    target = Path(os.path.realpath(p)) if os.path.islink(p) else Path(p)
    mode = (st.st_mode & 0o777) if st is not None else (0o666 & ~current_umask())
    created, tmp, done = [], None, False
    try:
        if not os.path.islink(p):
            created = _created_parents(target.parent)
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            os.fchmod(fh.fileno(), mode)
        os.replace(tmp, target)
        done = True
    except OSError as exc:  # report the user's path, not the temporary name
        raise OSError(exc.errno, exc.strerror, p) from None
    finally:
        if not done:
            if tmp is not None:
                with contextlib.suppress(OSError):
                    os.unlink(tmp)
            _remove_dirs(created)


def atomic_write_text(path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` all-or-nothing."""
    atomic_write_bytes(path, text.encode("utf-8"))


# --------------------------------------------------------------------------- checks before any work

def _check_one(option: str, path: str, kind: str) -> None:
    if path == "":
        raise OutputError(f"{option}: empty {'file' if kind == 'file' else 'directory'} name")
    st = _stat(path)
    if st is None:
        parent = os.path.dirname(os.path.abspath(path))
        while parent and not os.path.exists(parent):  # the nearest existing ancestor must be a directory
            up = os.path.dirname(parent)
            if up == parent:
                break
            parent = up
        if os.path.exists(parent) and not os.path.isdir(parent):
            raise OutputError(f"{option}: {parent} is not a directory", where=path)
        return
    if kind == "dir":
        if not stat.S_ISDIR(st.st_mode):
            raise OutputError(f"{option}: is {_kind(st.st_mode)}, not a directory", where=path)
        return
    if stat.S_ISDIR(st.st_mode):
        raise OutputError(f"{option}: is a directory, expected a file name", where=path)
    if not (stat.S_ISREG(st.st_mode) or stat.S_ISCHR(st.st_mode) or stat.S_ISFIFO(st.st_mode)):
        raise OutputError(f"{option}: is {_kind(st.st_mode)}, not a regular file: not written", where=path)


def check_outputs(outputs, inputs=()) -> None:
    """Refuse, before any work, outputs that cannot be written or would overwrite an input.

    Parameters
    ----------
    outputs : iterable of (option, path[, names])
        ``path`` None is skipped.  Without ``names`` the output is a file;
        with ``names`` (a list of file names) it is a directory that will hold
        those files.
    inputs : iterable of (label, path)
        The command's input files (``"the measurement file"``, ...); None
        paths are skipped.

    Raises
    ------
    OutputError
        An empty name; a directory given for a file, or a file for a
        directory; a block device or socket; an output that is an input (the
        same file however named: compared by device and inode) or another
        output.
    """
    ins = []
    for label, path in inputs:
        if path is None:
            continue
        st = _stat(os.fspath(path))
        if st is not None:
            ins.append((label, os.fspath(path), st))
    files = []  # (option, user path, path written)
    for item in outputs:
        option, path = item[0], item[1]
        if path is None:
            continue
        path = os.fspath(path)
        names = item[2] if len(item) > 2 else None
        _check_one(option, path, "file" if names is None else "dir")
        if names is None:
            files.append((option, path, path))
        else:
            files += [(option, path, os.path.join(path, name)) for name in names]
    seen = []
    for option, user, path in files:
        if is_stream(path):
            continue
        st = _stat(path)
        if st is not None:
            for label, ipath, ist in ins:
                if os.path.samestat(st, ist):
                    raise OutputError(f"{option} is {label} {ipath} (the same file): an input is never "
                                      "overwritten; write the output elsewhere", where=path)
        real = os.path.realpath(path)
        for other_option, other_path, other_real, other_st in seen:
            if real == other_real or (st is not None and other_st is not None and os.path.samestat(st, other_st)):
                raise OutputError(f"{option} and {other_option} name the same file ({other_path}): give two "
                                  "different outputs", where=path)
        seen.append((option, path, real, st))


@contextlib.contextmanager
def staged_directory(path):
    """A directory of outputs written all-or-nothing: yields a temporary directory, moved into place on success.

    If ``path`` does not exist, the temporary directory is made beside it and
    renamed to it (mode ``0o777 & ~umask``); if it is a directory, the files
    are made in a temporary directory inside it and each renamed into place
    (replacing files of the same name, keeping the others).  On any error
    (or Ctrl-C) the temporary directory and any parent directories this call
    created are removed; errors name the user's paths.

    Raises
    ------
    OutputError
        An empty name, or ``path`` exists and is not a directory.
    """
    p = os.fspath(path)
    if p == "":
        raise OutputError("empty directory name")
    out = Path(p)
    st = _stat(p)
    if st is not None and not stat.S_ISDIR(st.st_mode):
        raise OutputError(f"is {_kind(st.st_mode)}, not a directory", where=p)
    created = []
    try:
        if st is None:
            created = _created_parents(out.parent)
            tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".tmp", dir=out.parent))
        else:
            tmp = Path(tempfile.mkdtemp(prefix=".zerocal.", suffix=".tmp", dir=out))
    except OSError as exc:
        _remove_dirs(created)
        raise OSError(exc.errno, exc.strerror, p) from None

    def users(name):  # the user's name of a path inside the temporary directory
        if name is None:
            return p
        rel = os.path.relpath(os.fspath(name), tmp)
        return p if rel == "." else (os.path.join(p, rel) if not rel.startswith("..") else os.fspath(name))

    try:
        try:
            yield tmp
            if st is None:
                os.chmod(tmp, 0o777 & ~current_umask())
                os.rename(tmp, out)
            else:
                for name in sorted(os.listdir(tmp)):
                    os.replace(tmp / name, out / name)
                tmp.rmdir()
        except OSError as exc:
            raise OSError(exc.errno, exc.strerror, users(exc.filename)) from None
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        _remove_dirs(created)
        raise


# --------------------------------------------------------------------------- JSON

def _default(o):
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.bool_):
        return bool(o)
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def json_safe(obj):
    """``obj`` with non-finite floats replaced by None and numpy types by Python ones, recursively.

    JSON has no inf/NaN: an unbounded standard deviation (a parameter that is
    not identifiable) is written as ``null``.
    """
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return json_safe(obj.tolist())
    if isinstance(obj, (float, np.floating)):
        return float(obj) if np.isfinite(obj) else None
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    return obj


def to_json(obj, indent=2) -> str:
    """JSON text of ``obj`` (numpy arrays and scalars allowed)."""
    return json.dumps(obj, indent=indent, default=_default, allow_nan=False)


def write_json(path, obj) -> None:
    """Write ``obj`` as JSON, atomically."""
    atomic_write_text(path, to_json(obj) + "\n")
