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
* **Where a path lands** (:func:`landing`): the absolute path with ``..``
  and symbolic links resolved as the system resolves them once missing
  directories are made (``nosuch/../d.csv`` is ``d.csv``, ``link/..`` the
  parent of the link's target).  Every check and every write uses it.
* **A file name is a file name**: an output file whose name ends in ``/``
  (or ``.``, ``..``) names a directory and is refused.
* **An input is never an output**: :func:`check_outputs` refuses, before any
  work, an output that lands on one of the command's inputs (the same file
  however named: ``./``, ``..`` through missing directories or symbolic
  links, a symlink, a hard link -- compared by device and inode when the
  file exists) or on another of its outputs; a directory of outputs is
  refused if a file it would write there is an input.
* **Short temporary names**: the temporary file is ``.<up to 32 characters of
  the name>.<random>.tmp``, so any name the file system accepts can be
  written.
* **Directories of outputs** (``--plot DIR``, ``reproduce --out DIR``) are
  filled in a temporary directory beside them and moved into place when the
  command has succeeded (:func:`staged_directory`); a failed command leaves
  no directory it created.
"""
from __future__ import annotations

import contextlib
import fnmatch
import glob
import json
import os
import shutil
import signal
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
    st = _stat(landing(p)) if st is None else st
    return st is not None and (stat.S_ISCHR(st.st_mode) or stat.S_ISFIFO(st.st_mode))


def landing(path) -> str:
    """Where writing ``path`` lands: absolute, ``..`` and symbolic links resolved (the module's rules).

    Components that exist are resolved as the system resolves them (a
    symbolic link to a directory, then ``..``, is the parent of its target);
    a missing directory followed by ``..`` cancels out, as it does once a
    writer has made the directory (``nosuch/../d.csv`` is ``d.csv``).  A
    symbolic link as the last component is resolved too: a write goes through
    it.
    """
    return os.path.realpath(os.fspath(path))


def names_a_directory(path) -> bool:
    """Whether a file name ends in ``/``, ``/.`` or ``/..`` (or is ``.``, ``..``): a directory, not a file."""
    p = os.fspath(path)
    return p.endswith(os.sep) or (os.altsep is not None and p.endswith(os.altsep)) or \
        os.path.basename(p) in (".", "..")


def _temp_prefix(name: str) -> str:
    """``.<name, at most 32 characters>.``: a temporary name any file system accepts beside a valid name."""
    return f".{name[:32]}."


def _created_parents(parent: Path) -> list:
    """Create ``parent`` (and missing ancestors); return the directories created, deepest first."""
    missing = []
    p = parent
    while not p.exists() and p != p.parent:
        missing.append(p)
        p = p.parent
    parent.mkdir(parents=True, exist_ok=True)
    return missing


@contextlib.contextmanager
def _stops_held():
    """Ctrl-C and SIGTERM held (blocked: they stay pending) while a temporary file or directory is made and its
    name recorded for the cleanup; a stop that arrives meanwhile acts as the block ends, when the cleanup knows
    the name.  (Without it, a signal between the file's creation and the assignment of its name left a hidden
    ``.NAME.*.tmp`` behind: seen on a loaded machine.)"""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _remove_dirs(dirs) -> None:
    for d in dirs:  # deepest first; only if still empty
        try:
            os.rmdir(d)
        except OSError:
            break


def atomic_write_bytes(path, data: bytes) -> None:
    """Write ``data`` to ``path`` all-or-nothing (the module's rules).

    The file written is :func:`landing` of ``path`` (missing parent
    directories are made, and removed again if the write fails).

    Raises
    ------
    OutputError
        An empty name, a name ending in ``/``, a block device or a socket.
    OSError
        With ``filename`` the user's ``path``: a directory given, no
        permission, a full disk, ...
    """
    p = os.fspath(path)
    if p == "":
        raise OutputError("empty output file name")
    if names_a_directory(p):
        raise OutputError("ends in a directory separator or '.': a file name is expected", where=p)
    target = Path(landing(p))
    try:
        st = _stat(os.fspath(target))
    except OSError as exc:
        raise OSError(exc.errno, exc.strerror, p) from None
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
    mode = (st.st_mode & 0o777) if st is not None else (0o666 & ~current_umask())
    created, tmp, done = [], None, False
    try:
        if not os.path.islink(p):  # a dangling link: its directory is not made
            created = _created_parents(target.parent)
        with _stops_held():
            fd, tmp = tempfile.mkstemp(prefix=_temp_prefix(target.name), suffix=".tmp", dir=target.parent)
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
    if kind == "file" and names_a_directory(path):
        raise OutputError(f"{option}: ends in a directory separator or '.', which names a directory: give a file "
                          "name", where=path)
    land = landing(path)
    try:
        st = _stat(land)
    except OSError as exc:
        raise OutputError(f"{option}: {exc.strerror}", where=path) from None
    if st is None:
        parent = os.path.dirname(land)
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


def _matches(rel: str, pattern: str) -> bool:
    """Whether the relative path ``rel`` matches ``pattern`` level by level (``*`` does not cross ``/``)."""
    parts, pats = rel.split(os.sep), pattern.split("/")
    return len(parts) == len(pats) and all(fnmatch.fnmatchcase(a, b) for a, b in zip(parts, pats))


def _written_in(directory: str, names) -> list:
    """``[(landing, user path)]`` of the files an output directory would hold: its literal names, and the existing
    files that match its patterns."""
    out = []
    for name in names:
        if not any(c in name for c in "*?["):
            user = os.path.join(directory, *name.split("/"))
            out.append((landing(user), user))
            continue
        land = landing(directory)
        if os.path.isdir(land):
            for found in glob.glob(os.path.join(glob.escape(land), *name.split("/"))):
                out.append((landing(found), os.path.join(directory, os.path.relpath(found, land))))
    return out


def check_outputs(outputs, inputs=()) -> None:
    """Refuse, before any work, outputs that cannot be written or would overwrite an input.

    Parameters
    ----------
    outputs : iterable of (option, path[, names])
        ``path`` None is skipped.  Without ``names`` the output is a file;
        with ``names`` (file names or ``fnmatch`` patterns, ``/`` between
        levels) it is a directory that will hold those files.
    inputs : iterable of (label, path)
        The command's input files (``"the measurement file"``, ...); None
        paths are skipped.

    Raises
    ------
    OutputError
        An empty name; a name ending in ``/`` given for a file; a directory
        given for a file, or a file for a directory; a block device or
        socket; an output that lands on an input (:func:`landing`, and the
        same device and inode) or on another output.
    """
    ins, by_land, by_inode = [], {}, {}
    for label, path in inputs:
        if path is None or os.fspath(path) == "":
            continue
        path = os.fspath(path)
        land = landing(path)
        try:
            st = _stat(land)
        except OSError:  # unreadable: its loader says so
            continue
        if st is not None and stat.S_ISREG(st.st_mode):
            ins.append((label, path, land))
            by_land[land] = by_inode[(st.st_dev, st.st_ino)] = (label, path)
    files = []  # (option, user path, landing)
    for item in outputs:
        option, path = item[0], item[1]
        if path is None:
            continue
        path = os.fspath(path)
        names = item[2] if len(item) > 2 else None
        _check_one(option, path, "file" if names is None else "dir")
        if names is None:
            if not is_stream(path):
                files.append((option, path, landing(path)))
            continue
        files += [(option, user, land) for land, user in _written_in(path, names)]
        dland = landing(path)
        for label, ipath, iland in ins:  # an input below the directory, under a name it writes
            rel = os.path.relpath(iland, dland)
            if rel != os.pardir and not rel.startswith(os.pardir + os.sep) and any(_matches(rel, pat)
                                                                                for pat in names):
                raise OutputError(f"{option} would overwrite {ipath}, {label}: an input is never overwritten; "
                                  "write the output elsewhere", where=path)
    seen_land, seen_inode = {}, {}  # of the outputs: -> (option, user path)
    for option, user, land in files:
        try:
            st = _stat(land)
        except OSError as exc:
            raise OutputError(f"{option}: {exc.strerror}", where=user) from None
        inode = None if st is None else (st.st_dev, st.st_ino)
        hit = by_land.get(land) or by_inode.get(inode)
        if hit is not None:
            raise OutputError(f"{option} would overwrite {hit[1]}, {hit[0]}: an input is never overwritten; "
                              "write the output elsewhere", where=user)
        other = seen_land.get(land) or seen_inode.get(inode)
        if other is not None and other[0] != option:
            raise OutputError(f"{option} and {other[0]} name the same file ({other[1]}): give two different "
                              "outputs", where=user)
        seen_land.setdefault(land, (option, user))
        if inode is not None:
            seen_inode.setdefault(inode, (option, user))


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
    out = Path(landing(p))
    try:
        st = _stat(os.fspath(out))
    except OSError as exc:
        raise OSError(exc.errno, exc.strerror, p) from None
    if st is not None and not stat.S_ISDIR(st.st_mode):
        raise OutputError(f"is {_kind(st.st_mode)}, not a directory", where=p)
    created, tmp = [], None

    def users(name):  # the user's name of a path inside the temporary directory
        if name is None:
            return p
        rel = os.path.relpath(os.fspath(name), tmp)
        return p if rel == "." else (os.path.join(p, rel) if not rel.startswith("..") else os.fspath(name))

    try:
        try:
            with _stops_held():
                if st is None:
                    created = _created_parents(out.parent)
                    tmp = Path(tempfile.mkdtemp(prefix=_temp_prefix(out.name), suffix=".tmp", dir=out.parent))
                else:
                    tmp = Path(tempfile.mkdtemp(prefix=".zerocal.", suffix=".tmp", dir=out))
        except OSError as exc:
            raise OSError(exc.errno, exc.strerror, p) from None
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
        if tmp is not None:
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
