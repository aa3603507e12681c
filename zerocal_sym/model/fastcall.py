"""Zero-copy calls of CasADi Functions.

Calling a CasADi ``Function`` from Python converts every numpy argument to a
``DM`` and every result back (about 0.1 ms per call here, more than the
evaluation of a small kinematics function); :class:`FastCall` evaluates it
through its buffer (``Function.buffer``) on preallocated arrays instead
(about 1 us of overhead).  :func:`mapped` caches a Function mapped over K
poses with its shared inputs not repeated, for the batched kinematics.
"""
from __future__ import annotations

import threading

import numpy as np


class FastCall:
    """Zero-copy evaluation of a CasADi Function through its buffer (no numpy <-> DM conversion).

    ``fc(*args)`` copies the arguments into preallocated arrays, runs the
    Function in place and returns views of its preallocated outputs (dense,
    column-major; matrices come back as ``(rows, cols)`` arrays).  The
    outputs are overwritten by the next call: copy what you keep.  One
    buffer per thread.
    """

    def __init__(self, f):
        self.f = f
        self._local = threading.local()
        self.out_shapes = [f.size_out(i) for i in range(f.n_out())]

    def _state(self):
        st = getattr(self._local, "st", None)
        if st is None:
            f = self.f
            buf, trigger = f.buffer()
            ins = [np.zeros(f.nnz_in(i)) for i in range(f.n_in())]
            outs = [np.zeros(f.nnz_out(i)) for i in range(f.n_out())]
            for i, a in enumerate(ins):
                buf.set_arg(i, memoryview(a))
            for i, a in enumerate(outs):
                buf.set_res(i, memoryview(a))
            st = self._local.st = (buf, trigger, ins, outs)
        return st

    def __call__(self, *args):
        st = getattr(self._local, "st", None)
        buf, trigger, ins, outs = self._state() if st is None else st
        for a, v in zip(ins, args):
            a[:] = v.ravel(order="F") if isinstance(v, np.ndarray) else np.ravel(v, order="F")
        trigger()
        return [o.reshape(s, order="F") if s[1] > 1 else o for o, s in zip(outs, self.out_shapes)]

    def stats(self) -> dict:
        return self._state()[0].stats()


_MAPPED: dict = {}
_MAPPED_LOCK = threading.Lock()


def _cached(key, f, make):
    """The object ``make()`` built for ``f`` under ``key`` (which starts with ``id(f)``), cached; the entry holds
    ``f`` too, so that its id is not reused by another Function while the entry lives."""
    hit = _MAPPED.get(key)
    if hit is None or hit[0] is not f:
        with _MAPPED_LOCK:
            hit = _MAPPED.get(key)
            if hit is None or hit[0] is not f:
                hit = _MAPPED[key] = (f, make())
    return hit[1]


def mapped(f, K: int, per_pose: tuple) -> FastCall:
    """``f`` mapped over K columns of the inputs flagged in ``per_pose`` (the others shared), cached."""
    per_pose = tuple(per_pose)
    return _cached((id(f), K, per_pose), f,
                   lambda: FastCall(f.map(K, [not m for m in per_pose], [False] * f.n_out(), {})))


def columns(f, per_pose: tuple) -> "Columns":
    """:class:`Columns` of ``f`` (the inputs flagged in ``per_pose`` per column, the others shared), cached."""
    per_pose = tuple(per_pose)
    return _cached((id(f), "columns", per_pose), f, lambda: Columns(f, per_pose))


#: chunk sizes of :class:`Columns`: powers of two from SMALLEST_CHUNK to LARGEST_CHUNK columns
SMALLEST_CHUNK, LARGEST_CHUNK = 8, 1024


class Columns:
    """``f`` (dense column-vector outputs) over any number N of columns of its per-pose inputs, zero-copy.

    A call splits the N columns into chunks of :data:`LARGEST_CHUNK`, then of the power of two that holds the
    rest if that pads it by at most an eighth (or :data:`SMALLEST_CHUNK` columns), else of the largest power of
    two within it; padding columns are copies of the chunk's last; each chunk
    runs through a :class:`FastCall` of ``f`` mapped over that size (the shared inputs not repeated), built once
    per size.  Every column is evaluated by ``f`` alone, as a call of ``f`` on the N columns would: the
    numbers are the same whatever the chunks.
    """

    def __init__(self, f, per_pose: tuple):
        self.f, self.per_pose = f, tuple(per_pose)
        self.rows = [f.nnz_out(i) for i in range(f.n_out())]
        if any(not f.sparsity_out(i).is_dense() or f.size2_out(i) != 1 for i in range(f.n_out())):
            raise ValueError(f"Columns: {f.name()} has an output that is not a dense column")
        self._maps = {}

    def _fc(self, B):
        fc = self._maps.get(B)
        if fc is None:
            fc = self._maps[B] = FastCall(self.f.map(B, [not m for m in self.per_pose], [False] * self.f.n_out(),
                                                     {}))
        return fc

    def __call__(self, *args):
        """``args``: the per-pose inputs as arrays (rows, N), the shared ones as vectors; returns the outputs as
        arrays (rows, N)."""
        args = [np.asarray(a, float) for a in args]
        N = next(a.shape[1] for a, pp in zip(args, self.per_pose) if pp)
        outs = [np.empty((r, N)) for r in self.rows]
        start = 0
        while start < N:
            r = N - start
            B = max(SMALLEST_CHUNK, 1 << (r - 1).bit_length())  # the power of two that holds the rest
            if B > LARGEST_CHUNK:
                B = LARGEST_CHUNK
            elif B - r > max(SMALLEST_CHUNK, r // 8):  # too much padding: the largest power of two within it
                B //= 2
            n = min(B, r)
            chunk = []
            for a, pp in zip(args, self.per_pose):
                if not pp:
                    chunk.append(a)
                    continue
                c = a[:, start:start + n]
                if n < B:
                    c = np.concatenate([c, np.repeat(c[:, -1:], B - n, axis=1)], axis=1)
                chunk.append(c)
            res = self._fc(B)(*chunk)
            for o, v, rows in zip(outs, res, self.rows):
                o[:, start:start + n] = np.reshape(v, (rows, B), order="F")[:, :n]
            start += n
        return outs
