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
        buf, trigger, ins, outs = self._state()
        for a, v in zip(ins, args):
            a[:] = np.ravel(v, order="F")
        trigger()
        return [o.reshape(s, order="F") if s[1] > 1 else o for o, s in zip(outs, self.out_shapes)]

    def stats(self) -> dict:
        return self._state()[0].stats()


_MAPPED: dict = {}
_MAPPED_LOCK = threading.Lock()


def mapped(f, K: int, per_pose: tuple) -> FastCall:
    """``f`` mapped over K columns of the inputs flagged in ``per_pose`` (the others shared), cached."""
    key = (id(f), K, per_pose)
    fc = _MAPPED.get(key)
    if fc is None:
        with _MAPPED_LOCK:
            fc = _MAPPED.get(key)
            if fc is None:
                fc = _MAPPED[key] = FastCall(f.map(K, [not m for m in per_pose], [False] * f.n_out(), {}))
    return fc
