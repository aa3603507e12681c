"""Mergeable statistics of Monte Carlo results (:class:`Stats`).

Per quantity: count, sum, sum of squares and the samples themselves (for
quantiles); merging two is addition and concatenation, so the statistics of
chunks (:mod:`zerocal_sym.identify.parallel`) combine into those of the whole
run, bit-identically when merged in the same order.
"""
from __future__ import annotations

import numpy as np

#: quantiles reported (5 %, median, 95 %)
QUANTILES = {"q05": 0.05, "median": 0.5, "q95": 0.95}


class Stats:
    """Mergeable statistics of row vectors of width ``w``.

    ``count``, ``sum`` (w,), ``sumsq`` (w,) and the samples (for quantiles);
    :meth:`merge` adds and concatenates, so statistics of chunks combine into
    those of the whole run.  Merged in the same order, the same chunks give
    bit-identical results.
    """

    __slots__ = ("width", "count", "sum", "sumsq", "parts", "keep")

    def __init__(self, width: int, keep: bool = True):
        self.width = int(width)
        self.count = 0
        self.sum = np.zeros(self.width)
        self.sumsq = np.zeros(self.width)
        self.parts = []
        self.keep = keep  # keep the samples (quantiles); False: moments only

    @classmethod
    def of(cls, rows, width: int | None = None, keep: bool = True) -> "Stats":
        """Statistics of the rows of ``rows`` (shape (N, w); (N,) is one column)."""
        a = np.asarray(rows, float)
        if a.ndim == 1:
            a = a.reshape(-1, 1) if width in (None, 1) else a.reshape(-1, width)
        if a.size == 0:
            a = a.reshape(0, a.shape[1] if a.ndim == 2 and a.shape[1] else (width or 1))
        st = cls(a.shape[1], keep)
        st.count = a.shape[0]
        if st.count:
            st.sum = np.sum(a, axis=0)
            st.sumsq = np.sum(a * a, axis=0)
            st.parts = [a] if keep else []
        return st

    def merge(self, other: "Stats") -> "Stats":
        """Add ``other`` to this (in place); returns self."""
        if other.count:
            if self.count and other.width != self.width:
                raise ValueError(f"cannot merge statistics of width {other.width} into width {self.width}")
            if not self.count:
                self.width = other.width
                self.sum = np.zeros(self.width)
                self.sumsq = np.zeros(self.width)
            self.count += other.count
            self.sum = self.sum + other.sum
            self.sumsq = self.sumsq + other.sumsq
            if self.keep:
                self.parts.extend(other.parts)
        return self

    def __getstate__(self):
        return {k: getattr(self, k) for k in self.__slots__}

    def __setstate__(self, st):
        for k, v in st.items():
            setattr(self, k, v)

    @property
    def samples(self) -> np.ndarray:
        """All rows, shape (count, w), in merge order."""
        return np.concatenate(self.parts, axis=0) if self.parts else np.zeros((0, self.width))

    @property
    def mean(self):
        """ndarray (w,), or None without samples."""
        return self.sum / self.count if self.count else None

    @property
    def rms(self):
        """Root mean square, ndarray (w,), or None."""
        return np.sqrt(self.sumsq / self.count) if self.count else None

    @property
    def std(self):
        """Sample standard deviation (ddof = 1), ndarray (w,), or None for fewer than 2 samples."""
        if self.count < 2:
            return None
        var = (self.sumsq - self.sum**2 / self.count) / (self.count - 1)
        return np.sqrt(np.maximum(var, 0.0))

    def quantiles(self, qs=QUANTILES) -> dict | None:
        """``{name: ndarray (w,)}`` of the quantiles ``qs`` (name -> fraction), or None."""
        if not self.count or not self.keep:
            return None
        S = self.samples
        return {k: np.quantile(S, q, axis=0) for k, q in qs.items()}

    def max(self):
        return np.max(self.samples, axis=0) if self.count and self.keep else None
