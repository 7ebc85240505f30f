"""The compiled scoring of a piecewise-linear fit with knots on a grid (``docs/physics.md``
§14.2): :func:`gripsense.estimate.wheels.receiver_epochs` tries ~200 grids (receiver rates ×
phases) on every log, and numpy's per-call overhead (bincounts and a banded LAPACK solve,
~0.2 ms a grid) made that search a fifth of a fleet task's time; compiled, a grid costs a few
microseconds.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["hat_score"]


@njit(cache=True, nogil=True)
def hat_score(t, y, period, phase, e_t, smooth):
    """The least-squares piecewise-linear fit of the columns *y* (n × m, in units of their
    tolerance) at the times *t* [s] with knots at ``phase + k period`` [s] (second differences
    of the knots weighted by *smooth*): per column the mean over the epochs of r²/v, v = 1 +
    (slope e_t)², the segment slope's largest of its own and its neighbours' (a stamp off by
    *e_t* [s]); returns the largest over the columns and the number of epochs beyond the knots
    they touch (the fit's free residuals). The same normal equations as
    :func:`gripsense.estimate.wheels._hat_fit`, solved by a banded Cholesky factorisation (they
    are positive definite).
    """
    n, m = y.shape
    k0 = int(np.floor((t[0] - phase) / period))
    k = np.empty(n, np.int64)
    w = np.empty(n)
    for i in range(n):
        s = (t[i] - phase) / period
        kk = int(np.floor(s))
        w[i] = s - kk
        k[i] = kk - k0
    n_k = int(k[n - 1]) + 2
    d0 = np.zeros(n_k)
    d1 = np.zeros(n_k)
    d2 = np.zeros(n_k)
    rhs = np.zeros((n_k, m))
    for i in range(n):
        a, b, kk = 1.0 - w[i], w[i], k[i]
        d0[kk] += a * a
        d0[kk + 1] += b * b
        d1[kk] += a * b
        for c in range(m):
            rhs[kk, c] += a * y[i, c]
            rhs[kk + 1, c] += b * y[i, c]
    ridge = 1e-12 * max(d0.max(), 1.0)
    if n_k >= 3:  # the second differences' penalty D^T D (rows 1, −2, 1)
        for j in range(n_k - 2):
            d0[j] += smooth
            d0[j + 1] += 4.0 * smooth
            d0[j + 2] += smooth
            d1[j] -= 2.0 * smooth
            d1[j + 1] -= 2.0 * smooth
            d2[j] += smooth
    for j in range(n_k):
        d0[j] += ridge
    # banded Cholesky L L^T (bandwidth 2): l0 diagonal, l1/l2 the first/second sub-diagonals
    l0 = np.zeros(n_k)
    l1 = np.zeros(n_k)
    l2 = np.zeros(n_k)
    for j in range(n_k):
        v = d0[j]
        if j >= 1:
            v -= l1[j - 1] ** 2
        if j >= 2:
            v -= l2[j - 2] ** 2
        l0[j] = np.sqrt(v)
        if j + 1 < n_k:
            u = d1[j]
            if j >= 1:
                u -= l1[j - 1] * l2[j - 1]
            l1[j] = u / l0[j]
        if j + 2 < n_k:
            l2[j] = d2[j] / l0[j]
    x = np.empty((n_k, m))
    for c in range(m):
        z = np.empty(n_k)
        for j in range(n_k):
            v = rhs[j, c]
            if j >= 1:
                v -= l1[j - 1] * z[j - 1]
            if j >= 2:
                v -= l2[j - 2] * z[j - 2]
            z[j] = v / l0[j]
        for j in range(n_k - 1, -1, -1):
            v = z[j]
            if j + 1 < n_k:
                v -= l1[j] * x[j + 1, c]
            if j + 2 < n_k:
                v -= l2[j] * x[j + 2, c]
            x[j, c] = v / l0[j]
    # segment slopes, each the largest of its own and its neighbours'
    n_s = n_k - 1
    seg = np.empty((n_s, m))
    for j in range(n_s):
        for c in range(m):
            seg[j, c] = abs(x[j + 1, c] - x[j, c]) / period
    best = 0.0
    for c in range(m):
        acc = 0.0
        for i in range(n):
            kk = k[i]
            fitted = (1.0 - w[i]) * x[kk, c] + w[i] * x[kk + 1, c]
            r = y[i, c] - fitted
            j = min(kk, n_s - 1)
            sl = seg[j, c]
            if j >= 1:
                sl = max(sl, seg[j - 1, c])
            else:
                sl = max(sl, seg[0, c])
            if j + 1 < n_s:
                sl = max(sl, seg[j + 1, c])
            else:
                sl = max(sl, seg[n_s - 1, c])
            acc += r * r / (1.0 + (sl * e_t) ** 2)
        best = max(best, acc / n)
    touched = np.zeros(n_k, np.bool_)
    for i in range(n):
        touched[k[i]] = True
        touched[k[i] + 1] = True
    return best, n - int(touched.sum())
