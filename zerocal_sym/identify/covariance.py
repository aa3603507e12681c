"""The covariance of the K-1 measured changes (:class:`ChangeCovariance`): bands, and the revisits' low-rank part.

The bands: ``sigma_m^2 I + D diag(v) D^T`` is tridiagonal, whitened by its
lower-bidiagonal Cholesky factor (:mod:`~zerocal_sym.identify.banded`), O(K).

The revisited poses' shared error: a low-rank update of the bands.

A pose's systematic error of the measured length ``u_g ~ N(0, sigma_r^2)``
(:class:`~zerocal_sym.model.noise.NoiseModel` ``sigma_revisit_mm``) is shared
by every visit of pose ``g``.  The lengths then have the covariance
``diag(v) + sigma_r^2 Z Z^T`` (``Z`` (K, poses) the indicator of each visit's
pose), and the K - 1 changes::

    C = T + B B^T,   T = sigma_m^2 I + D diag(v + sigma_r^2 [visited once]) D^T,   B = sigma_r D Z_r,

``T`` tridiagonal (a pose visited once carries its ``u`` as one more
independent error), ``Z_r`` the columns of the G revisited poses, ``B``
(K-1, G).  When the revisits are not consecutive, ``B B^T`` reaches beyond
the band: ``C`` is no longer tridiagonal.  Everything is kept exact through
``T = L L^T`` (bidiagonal ``L``) and the G x G problem of ``W = L^-1 B``:
with ``W^T W = V diag(lam) V^T`` and ``Q = W V diag(lam)^-1/2`` (orthonormal
columns)::

    C = L (I + Q diag(lam) Q^T) L^T,
    whitening  S L^-1,  S = (I + W W^T)^-1/2 = I + Q diag((1 + lam)^-1/2 - 1) Q^T   (symmetric),
    C^-1 = L^-T (I + Q diag(1 / (1 + lam) - 1) Q^T) L^-1,
    log det C = 2 sum log l + sum log(1 + lam)          (Woodbury, the determinant lemma).

Cost O(K G) time and memory beyond the bands (O(K (p + G)) for a (K-1, p)
right-hand side): linear in K for a fixed number of revisited poses (a
design's support points); nothing is (K-1) x (K-1).  :class:`SharedPart`
holds ``B`` and these factors; :class:`ChangeCovariance` uses it.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.identify import banded
from zerocal_sym.model.revisits import shared_design

#: eigenvalues of W^T W below this fraction of the largest are a revisited pose the changes do not see (all
#: visits at one pose: a common offset of the lengths)
LAMBDA_RTOL = 1e-14


def shared_terms(var_rho, labels, sigma_revisit_mm: float):
    """``(v, B)``: the lengths' independent variances with the once-visited poses' shared error added, shape
    (K,), and ``B = sigma_r D Z_r`` (K-1, G) of the revisited poses (None when there are none)."""
    v = np.array(var_rho, float)
    tau2 = float(sigma_revisit_mm) ** 2
    if tau2 == 0:
        return v, None
    singles, groups = shared_design(labels)
    v[singles] += tau2
    if not groups:
        return v, None
    K = v.size
    Z = np.zeros((K, len(groups)))
    for g, rows in enumerate(groups):
        Z[rows, g] = 1.0
    return v, float(sigma_revisit_mm) * np.diff(Z, axis=0)


class SharedPart:
    """``B B^T`` of :func:`shared_terms` and its factors against a bidiagonal ``L`` (module docstring).

    Attributes
    ----------
    B : ndarray, shape (K-1, G)
    """

    def __init__(self, B):
        self.B = np.asarray(B, float)
        self._fact = None

    @property
    def G(self) -> int:
        return self.B.shape[1]

    def factor(self, l, b):
        """``(Q, lam)`` of ``W = L^-1 B``: Q (K-1, r) orthonormal, lam (r,) > 0 (cached per factor)."""
        if self._fact is None or self._fact[0] is not l:
            W = banded.forward(l, b, self.B)
            lam, V = np.linalg.eigh(W.T @ W)
            keep = lam > LAMBDA_RTOL * max(float(lam.max(initial=0.0)), 1e-300)
            Q = (W @ V[:, keep]) / np.sqrt(lam[keep])
            self._fact = (l, Q, lam[keep])
        return self._fact[1], self._fact[2]

    def take(self, keep) -> "SharedPart":
        return SharedPart(self.B[np.asarray(keep, int)])


def apply(Q, c, Y):
    """``(I + Q diag(c) Q^T) Y`` for Y (n,) or (n, k)."""
    if Y.ndim == 1:
        return Y + Q @ (c * (Q.T @ Y))
    return Y + Q @ (c[:, None] * (Q.T @ Y))


class ChangeCovariance:
    """``Cov(s) = sigma_m^2 I + D diag(v) D^T (+ B B^T)`` of the K-1 measured changes, kept as two bands.

    Tridiagonal, (K-1) x (K-1): diagonal ``sigma_m^2 + v_k + v_{k+1}``,
    sub-diagonal ``-v_{k+1}`` (consecutive changes share a pose), ``v_k`` the
    variance of ``rho_k`` from the servo error.  Its Cholesky factor ``L`` is
    lower bidiagonal (diagonal ``l``, sub-diagonal ``b``); whitening ``L^-1 A``
    is a forward substitution.  Memory and time O(K) (O(K p) for a (K-1, p)
    matrix): nothing here is (K-1) x (K-1) unless :meth:`dense` is asked for.

    With ``shared`` (``B`` (K-1, G), the revisited poses' shared error:
    :mod:`zerocal_sym.identify.covariance`) the covariance is the bands
    plus ``B B^T``, no longer tridiagonal; every method below stays exact
    (Woodbury, O(K G) more) and :meth:`cholesky` is the bands' factor.

    Attributes
    ----------
    diag : ndarray, shape (K-1,)
    off : ndarray, shape (K-2,)
        ``C[k+1, k] = C[k, k+1]``.
    shared : SharedPart or None
    """

    def __init__(self, diag, off, shared=None):
        self.diag = np.asarray(diag, float).ravel()
        self.off = np.asarray(off, float).ravel()
        if self.off.size != max(self.diag.size - 1, 0):
            raise ValueError(f"off-diagonal of length {self.off.size} for a diagonal of {self.diag.size}")
        if shared is not None and not isinstance(shared, SharedPart):
            shared = SharedPart(shared)
        if shared is not None and shared.B.shape[0] != self.diag.size:
            raise ValueError(f"shared part of {shared.B.shape[0]} rows for {self.diag.size} changes")
        self.shared = shared
        self._chol = None

    @classmethod
    def from_variances(cls, sigma_scale_mm: float, var_rho, labels=None,
                       sigma_revisit_mm: float = 0.0) -> "ChangeCovariance":
        """From ``sigma_m`` (mm) and ``v`` (K,), the variance of each pose's distance (mm^2); with ``labels``
        (K,) the pose of each visit and ``sigma_revisit_mm`` the shared error of its revisits."""
        B = None
        if labels is not None and sigma_revisit_mm > 0:
            var_rho, B = shared_terms(var_rho, labels, sigma_revisit_mm)
        v = np.asarray(var_rho, float).ravel()
        return cls(sigma_scale_mm**2 + v[:-1] + v[1:], -v[1:-1], B)

    @property
    def n(self) -> int:
        return self.diag.size

    @property
    def is_zero(self) -> bool:
        return not (np.any(self.diag) or np.any(self.off))

    @property
    def banded(self) -> bool:
        """Whether ``C`` is the tridiagonal bands alone (no shared revisit part)."""
        return self.shared is None

    def _low(self):
        """``(Q, lam)`` of the shared part against the bands' factor."""
        return self.shared.factor(*self.cholesky())

    def dense(self) -> np.ndarray:
        """The full matrix, shape (K-1, K-1) (small problems and tests only)."""
        C = np.diag(self.diag)
        if self.n > 1:
            i = np.arange(self.n - 1)
            C[i + 1, i] = C[i, i + 1] = self.off
        if self.shared is not None:
            C += self.shared.B @ self.shared.B.T
        return C

    def std(self) -> np.ndarray:
        """Standard deviation of each change, shape (K-1,)."""
        d = self.diag if self.shared is None else self.diag + np.sum(self.shared.B**2, axis=1)
        return np.sqrt(d)

    def cholesky(self):
        """``(l, b)``: the bands ``T = L L^T`` with ``L`` lower bidiagonal (``L[k, k] = l[k]``, ``L[k+1, k] = b[k]``).

        Raises
        ------
        numpy.linalg.LinAlgError
            ``T`` is not positive definite (a zero noise model).
        """
        if self._chol is None:
            l, b, ok = banded.cholesky(self.diag, self.off)
            if not ok:
                raise np.linalg.LinAlgError("the covariance of the changes is not positive definite")
            self._chol = (l, b)
        return self._chol

    def whiten(self, A) -> np.ndarray:
        """``W A`` with ``W^T W = C^-1`` (identity covariance), shape of ``A``: (K-1,) or (K-1, p); O(K p).

        ``W = L^-1`` (bands alone), ``S L^-1`` with the shared part."""
        l, b = self.cholesky()
        Y = band_forward(l, b, A)
        if self.shared is None:
            return Y
        Q, lam = self._low()
        return apply(Q, 1.0 / np.sqrt(1.0 + lam) - 1.0, Y)

    def whiten_transpose(self, V) -> np.ndarray:
        """``W^T V`` (the transpose of :meth:`whiten`'s ``W``), ``V`` (K-1,) or (K-1, p)."""
        l, b = self.cholesky()
        V = np.asarray(V, float)
        if self.shared is not None:
            Q, lam = self._low()
            V = apply(Q, 1.0 / np.sqrt(1.0 + lam) - 1.0, V)
        return banded.backward(l, b, V)

    def factor_times(self, A) -> np.ndarray:
        """``A L_C`` with ``C = L_C L_C^T``, ``A`` shape (p, K-1): then ``A C A^T = (A L_C)(A L_C)^T``."""
        l, b = self.cholesky()
        A = np.asarray(A, float)
        out = A * l
        if self.n > 1:
            out[:, :-1] += A[:, 1:] * b
        if self.shared is not None:
            Q, lam = self._low()
            out = out + ((out @ Q) * (np.sqrt(1.0 + lam) - 1.0)) @ Q.T
        return out

    def sandwich(self, A) -> np.ndarray:
        """``A C A^T`` for ``A`` (p, K-1), O(K p^2) (works for a singular C too)."""
        A = np.asarray(A, float)
        out = (A * self.diag) @ A.T
        if self.n > 1:
            X = (A[:, 1:] * self.off) @ A[:, :-1].T
            out += X + X.T
        if self.shared is not None:
            AB = A @ self.shared.B
            out += AB @ AB.T
        return out

    def whitener(self) -> np.ndarray:
        """``W`` dense, shape (K-1, K-1) (small problems only)."""
        return self.whiten(np.eye(self.n))

    def solve(self, V) -> np.ndarray:
        """``C^-1 V``, ``V`` shape (K-1,) or (K-1, p); O(K p)."""
        l, b = self.cholesky()
        if self.shared is None:
            return banded.solve(l, b, V)
        Q, lam = self._low()
        return banded.backward(l, b, apply(Q, 1.0 / (1.0 + lam) - 1.0, banded.forward(l, b, V)))

    def inverse_diagonal(self) -> np.ndarray:
        """The diagonal of ``C^-1``, shape (K-1,); O(K) (O(K G) with the shared part)."""
        out = banded.inverse_diagonal(*self.cholesky())
        if self.shared is not None:
            Q, lam = self._low()
            Y = banded.backward(*self.cholesky(), Q)
            out = out + (Y * Y) @ (1.0 / (1.0 + lam) - 1.0)
        return out

    def logdet(self) -> float:
        """``log det C``."""
        l, _ = self.cholesky()
        out = 2.0 * float(np.sum(np.log(l)))
        if self.shared is not None:
            out += float(np.sum(np.log1p(self._low()[1])))
        return out

    def take(self, keep) -> "ChangeCovariance":
        """The covariance of the changes ``keep`` (sorted indices), the others marginalised out (bands again,
        and the shared part's rows)."""
        return ChangeCovariance(*banded.submatrix(self.diag, self.off, keep),
                                None if self.shared is None else self.shared.take(keep))

    def plus_diagonal(self, x) -> "ChangeCovariance":
        """``C + diag(x)``, ``x`` shape (K-1,)."""
        return ChangeCovariance(self.diag + np.asarray(x, float), self.off, self.shared)


def band_forward(l, b, A) -> np.ndarray:
    """Solve ``L Y = A`` for lower-bidiagonal ``L`` (diagonal ``l`` (n,), sub-diagonal ``b`` (n-1,)).

    The recurrence ``y_k = (a_k - b_{k-1} y_{k-1}) / l_k`` evaluated as a
    parallel prefix (log2 n vectorised steps of ``y_k = alpha_k y_{k-1} +
    beta_k``), O(n p log n) flops, O(n p) memory.
    """
    A = np.asarray(A, float)
    return banded.forward(np.ravel(np.asarray(l, float)), np.ravel(np.asarray(b, float)), A.reshape(A.shape[0], -1)
                          ).reshape(A.shape)
