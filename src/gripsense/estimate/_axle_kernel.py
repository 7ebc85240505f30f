"""Compiled core of ``axle-window``: the profile likelihood of μ for a set of bins of one axle,
nuisances profiled by Levenberg–Marquardt on their linearisation (no nuisance grids).

Per bin k (means over ~1 s) and wheel w ∈ {L, R} (``docs/physics.md`` §15):

    α_eff = α_wk − c − δ_k + κ a_k + ς δ_s,k    slip offsets (heading error), camber thrust,
                                                steering-channel scale error (front axle)
    Fz'_w = Fz_wk ∓ λ ΔFz_k                             load-transfer error (axle sum unchanged)
    C'_w  = s C_wk (Fz'_w/Fz_wk)^p0 (Fz'_w/Fz_static)^q  stiffness scale, load-sensitivity error
    x_w   = C'_w tan|α_eff| / (μ_w Fz'_w)
    μ_w   = μ (Fz'_w/F̄z')^−η · ΣFz' / Σ Fz'_v (Fz'_v/F̄z')^−η  load sensitivity of the friction
    F_model = Σ_w −sign(α_eff) μ_w Fz'_w f(x_w; shape)
    r_k  = F_k (1 + ε) cos^d δ_k − F_model
    v_k  = σ_F,k² + m_k² + (Σ_w ∂F_w/∂α)² (σ_α,k² + (0.35 s_α,k)²) + (Σ_w ½ |F_w''| s_α,k²)²

(cos^d δ turns the body-axis force of a steered axle into the wheels' lateral force: d = −1
when the axle is not driven, +1 when it is and the drive force balances the drag of the turn)

where s_α,k is the slip's spread within the bin beyond its noise (a transient: the mean of the
force is not the force at the mean slip — by the Jensen gap ½ F'' s², zero where the curve is
straight — and force and slip are ~0.1 s apart within the bin: 0.35 F' s) and m_k the force no
curve of the family represents. F_model is bracketed: a measured force between the force at the
mean slip and the two-point mean ½ [F(α − s) + F(α + s)] (s at most |α|) leaves r_k = 0, outside
it r_k is measured from the nearer one (a turn-in's slip sweeping the peak; §15.8).
θ = [ln s, κ, λ, q, ε, c, ς, η, d] is shared by every bin, with Gaussian priors (c: the offset left
by the heading calibration). The slip offset δ_k of each bin follows the receiver's slowly
varying heading error: a Gauss–Markov process (variance σ_δ²,
correlation ρ_k = exp(−Δt/τ) to the next bin, 0 across gaps), whose precision matrix is
tridiagonal. The normal equations are solved with the δ block eliminated by a tridiagonal
(Thomas) solve, so the cost is O(bins) whatever the number of bins or nuisances. The profile
over the curve's shape is the minimum over the shapes allowed.

Speed: the functions that run for every (μ, shape) minimisation and every Levenberg–Marquardt
step never allocate (work arrays come from :func:`workspace`) and are compiled with numba's
``_nrt=False``: without the runtime, taking a row of a work array or passing an array to a
function costs no atomic reference-count update (with it, ``NRT_incref``/``NRT_decref`` took a
quarter of the profile's time). A rejected step keeps the current point's residuals (no second
evaluation). A window of one bin — most windows of steady cornering, whose bins merge into one
point — solves its step by Sherman–Morrison in O(NG) (:func:`_step_one_bin`), a window of
2..NFEW bins by Woodbury with n × n systems (:func:`_step_few_bins`), instead of the NG × NG
Cholesky factorisation: the same step to rounding.
"""

from __future__ import annotations

import numpy as np
from numba import njit


def _no_runtime() -> dict:
    """Numba's ``_nrt=False`` where the installed numba has it (a private option of its CPU
    target, checked here rather than assumed; without it the kernels compute the same, only
    with reference counting).
    """
    try:
        from numba.core.cpu import CPUTargetOptions
    except ImportError:  # pragma: no cover - a numba without the module
        return {}
    return {"_nrt": False} if hasattr(CPUTargetOptions, "_nrt") else {}


_NO_RT = _no_runtime()
SKIP_MARGIN = 15.0  # −log L units; a deviance of 30 above the best
STOP_ABOVE = 30.0  # −log L units above the profile's minimum (or an upper bound of it): a
# deviance of 60, nine times the highest interval level (χ²₁ 99 %: 6.63)
DROP_ABOVE = 13.0  # −log L units above an upper bound of the minimum: a deviance of 26, above
# every stored one (a curve caps at 25.5, DEVIANCE_CAP) and four times the 99 % level
TOL_NLL = 1e-4  # −log L units: a step that gains less ends the minimisation
TOL_NLL_FEW = 1e-3  # the same for windows of up to NFEW bins: a deviance of 0.002, a fiftieth of
# a stored curve's step (DEVIANCE_STEP); each (μ, shape) of them starts one grid step from its
# minimum and converges in two steps, the third only moved it by less (10-15 % of their time)
TIMING_SPREAD = 0.35  # of a bin's slip spread: force and slip ~0.1 s apart in a 1 s bin
# (receiver latency, lag, yaw-acceleration smoothing) move the force by F' α̇ 0.1 s ≈ 0.35 F' s_α
NG = 9  # ln s, κ, λ, q, ε, c (slip offset), ς (steer scale), η (μ load sensitivity), d (drive)


@njit(cache=True, nogil=True, inline="always")
def _lookup(tab_f, tab_df, shape, inv_dx, x):
    """Table lookup: f and f' of shape ``shape`` at x ≥ 0 (linear interpolation; the tables
    are indexed in place — a row view would cost two reference-count updates per lookup).
    """
    u = x * inv_dx
    n = tab_f.shape[1]
    if u >= n - 1:
        return tab_f[shape, n - 1], 0.0
    i = int(u)
    w = u - i
    f0 = tab_f[shape, i]
    d0 = tab_df[shape, i]
    return f0 + w * (tab_f[shape, i + 1] - f0), d0 + w * (tab_df[shape, i + 1] - d0)


@njit(cache=True, nogil=True, inline="always", **_NO_RT)
def _two_point(tab_f, tab_df, shape, inv_dx, x, hx, f, df, dfx):
    """The curve's two-point mean over a bin's slip spread *hx* around *x* (both normalised):
    f, f' and x f' as the means at x ± h (h = min(hx, x): slips of one sign), and the bend
    |f'(x + hx) − f'(x − hx)| from which the caller takes the Jensen gap two points leave out
    (docs/physics.md §15.8). Without a spread, the values at x (*f*, *df*, *dfx*). Inlined
    into :func:`_residuals`.
    """
    if not hx > 0.0:
        return f, df, dfx, 0.0
    h2 = min(hx, x)
    f_p, df_p = _lookup(tab_f, tab_df, shape, inv_dx, x + h2)
    f_m, df_m = _lookup(tab_f, tab_df, shape, inv_dx, x - h2)
    f2 = 0.5 * (f_p + f_m)
    df2 = 0.5 * (df_p + df_m)
    dfx2 = 0.5 * (df_p * (x + h2) + df_m * (x - h2))
    _, df_p = _lookup(tab_f, tab_df, shape, inv_dx, x + hx)
    _, df_m = _lookup(tab_f, tab_df, shape, inv_dx, max(x - hx, 0.0))
    return f2, df2, dfx2, abs(df_p - df_m)


@njit(cache=True, nogil=True, **_NO_RT)
def _residuals(mu, th, dl, shape, tab_f, tab_df, inv_dx, b, pre, p0, r_out, v_out, j_out, jd_out):
    """Residual, variance and Jacobian (globals; the bin's slip offset) of every bin (``pre``:
    the bins' constants, :func:`workspace`).
    """
    ln_s, kap, lam, q, eps, c_off, st_sc, eta = (
        th[0],
        th[1],
        th[2],
        th[3],
        th[4],
        th[5],
        th[6],
        th[7],
    )
    d_drive = th[8]
    n = b.shape[0]
    for k in range(n):
        ay = b[k, 10]
        dfz = 0.5 * (b[k, 3] - b[k, 2])
        # loads after the load-transfer error; the friction of each wheel falls with its load
        # (Fz/F̄z)^−η, normalised so that μ stays the axle's load-weighted friction (two
        # wheels: scalars, no arrays, so a call allocates nothing)
        fzp0 = max(b[k, 2] - lam * dfz, 1.0)
        fzp1 = max(b[k, 3] + lam * dfz, 1.0)
        fbar = 0.5 * (fzp0 + fzp1)
        ln0, ln1 = np.log(fzp0), np.log(fzp1)  # the only logarithms of a bin (the rest: pre)
        ln_bar = np.log(fbar)
        lr0 = ln0 - ln_bar
        lr1 = ln1 - ln_bar
        g0 = np.exp(-eta * lr0)
        g1 = np.exp(-eta * lr1)
        den = fzp0 * g0 + fzp1 * g1
        dden = fzp0 * g0 * lr0 + fzp1 * g1 * lr1
        mw0 = mu * g0 * (fzp0 + fzp1) / den
        mw1 = mu * g1 * (fzp0 + fzp1) / den
        fm = 0.0  # at the mean slip
        g_sum = 0.0
        gap = 0.0
        d_lns = 0.0
        d_lam = 0.0
        d_q = 0.0
        d_eta = 0.0
        fm2 = 0.0  # the two-point mean over the bin's slip spread
        g_sum2 = 0.0
        d_lns2 = 0.0
        d_lam2 = 0.0
        d_q2 = 0.0
        d_eta2 = 0.0
        for w in range(2):
            sgn_load = -1.0 if w == 0 else 1.0
            fzw = fzp0 if w == 0 else fzp1
            lrw = lr0 if w == 0 else lr1
            m_w = mw0 if w == 0 else mw1
            ae = b[k, w] - dl[k] - c_off + kap * ay + st_sc * b[k, 12]
            t = abs(np.tan(ae))
            ln_fzw = ln0 if w == 0 else ln1
            ln_fs = ln_fzw - pre[_PRE_LN_FZS, k]
            lnc = ln_s + pre[_PRE_LN_C + w, k] + p0 * (ln_fzw - pre[_PRE_LN_FZ + w, k]) + q * ln_fs
            cp = np.exp(lnc)
            x = cp * t / (m_w * fzw)
            sg = -1.0 if ae > 0 else 1.0
            # the bin's mean force is the curve's mean over the bin's slips, not necessarily the
            # force at the mean slip: where the slip sweeps the bend within the bin (a turn-in
            # through the peak) it lies below it by the Jensen gap. Two forces bracket it: f(x)
            # (the slip steady) and the two-point mean ½ [f(x − h) + f(x + h)] (h the slip's
            # spread in x, at most x: slips of one sign); a measured force between them is
            # explained (docs/physics.md §15.8).
            f, df = _lookup(tab_f, tab_df, shape, inv_dx, x)
            dfx = df * x
            hx = cp * (1.0 + t * t) * b[k, 13] / (m_w * fzw)
            f2, df2, dfx2, bend = _two_point(tab_f, tab_df, shape, inv_dx, x, hx, f, df, dfx)
            if hx > 0.0:  # the Jensen gap ½ F'' s², from f' at x ± h (none where f is straight)
                gap += m_w * fzw * bend * hx * 0.25
            fm += sg * m_w * fzw * f
            g_sum += cp * df * (1.0 + t * t)  # |∂F_w/∂α|
            d_lns += sg * m_w * fzw * dfx
            d_lam += sg * m_w * (f + dfx * (p0 + q - 1.0)) * sgn_load * dfz
            d_q += sg * m_w * fzw * dfx * ln_fs
            # ∂F/∂μ_w = Fz (f − x f'),  ∂ln μ_w/∂η = −ln(Fz/F̄z) + Σ Fz g ln(Fz/F̄z) / Σ Fz g
            d_eta += sg * fzw * (f - dfx) * m_w * (-lrw + dden / den)
            fm2 += sg * m_w * fzw * f2
            g_sum2 += cp * df2 * (1.0 + t * t)
            d_lns2 += sg * m_w * fzw * dfx2
            d_lam2 += sg * m_w * (f2 + dfx2 * (p0 + q - 1.0)) * sgn_load * dfz
            d_q2 += sg * m_w * fzw * dfx2 * ln_fs
            d_eta2 += sg * fzw * (f2 - dfx2) * m_w * (-lrw + dden / den)
        ln_cos = pre[_PRE_LN_COS, k]
        fk = b[k, 6] * np.exp(d_drive * ln_cos)  # cos^d δ
        # the variance's slope term at the mean slip; the residual to the nearer of the two
        # forces, none between them (and no pull on the nuisances there)
        v_slope = g_sum
        on = 1.0
        if (fk * (1.0 + eps) - fm) * (fk * (1.0 + eps) - fm2) <= 0.0:
            on = 0.0
        elif abs(fk * (1.0 + eps) - fm2) < abs(fk * (1.0 + eps) - fm):
            fm, g_sum, d_lns, d_lam, d_q, d_eta = fm2, g_sum2, d_lns2, d_lam2, d_q2, d_eta2
        r_out[k] = on * (fk * (1.0 + eps) - fm)
        v_out[k] = (
            b[k, 7] ** 2
            + b[k, 14] ** 2
            + v_slope**2 * (b[k, 8] ** 2 + (TIMING_SPREAD * b[k, 13]) ** 2)
            + gap * gap
            + 1e-6
        )
        j_out[k, 0] = -on * d_lns
        j_out[k, 1] = on * g_sum * ay
        j_out[k, 2] = -on * d_lam
        j_out[k, 3] = -on * d_q
        j_out[k, 4] = on * fk
        j_out[k, 5] = -on * g_sum
        j_out[k, 6] = on * g_sum * b[k, 12]
        j_out[k, 7] = -on * d_eta
        j_out[k, 8] = on * fk * (1.0 + eps) * ln_cos
        jd_out[k] = -on * g_sum
    return 0


@njit(cache=True, nogil=True, **_NO_RT)
def _prior_delta(rho, sd, pd, pe):
    """Tridiagonal precision of a Gauss–Markov sequence: diagonal pd, off-diagonal pe."""
    n = pd.size
    s2 = sd * sd
    for k in range(n):
        a = rho[k - 1] if k > 0 else 0.0
        c = rho[k] if k < n - 1 else 0.0
        pd[k] = (1.0 - a * a * c * c) / ((1.0 - a * a) * (1.0 - c * c) * s2)
        if k < n - 1:
            pe[k] = -c / ((1.0 - c * c) * s2)
    return 0


@njit(cache=True, nogil=True, **_NO_RT)
def _objective(mu, th, dl, ctx, r, v, jg, jd):
    """−log L at (θ, δ); ``ctx`` = (shape, f table, f' table, 1/dx, bins, the bins' constants,
    p0, prior mean, prior sd, δ prior diagonal, δ prior off-diagonal); fills r, v and the
    Jacobians.
    """
    shape, tab_f, tab_df, inv_dx, b, pre, p0, prior_m, prior_s, pd, pe = ctx
    _residuals(mu, th, dl, shape, tab_f, tab_df, inv_dx, b, pre, p0, r, v, jg, jd)
    n = b.shape[0]
    nll = 0.0
    for k in range(n):
        nll += 0.5 * r[k] * r[k] / v[k]
        nll += 0.5 * pd[k] * dl[k] * dl[k]
        if k < n - 1:
            nll += pe[k] * dl[k] * dl[k + 1]
    for i in range(NG):
        z = (th[i] - prior_m[i]) / prior_s[i]
        nll += 0.5 * z * z
    return nll


@njit(cache=True, nogil=True, **_NO_RT)
def _cholesky_solve(a, x):
    """Solve a y = x in place (x ← y) for a small symmetric positive-definite a (overwritten
    by its Cholesky factor); a tiny ridge keeps a numerically semi-definite a solvable. Only
    the lower triangle of a is read; the factor's diagonal is kept as its reciprocal (one
    division per row instead of one per element).
    """
    m = a.shape[0]
    for j in range(m):
        d = a[j, j]
        for k in range(j):
            d -= a[j, k] * a[j, k]
        inv_d = 1.0 / np.sqrt(max(d, 1e-300))
        a[j, j] = inv_d
        for i in range(j + 1, m):
            acc = a[i, j]
            for k in range(j):
                acc -= a[i, k] * a[j, k]
            a[i, j] = acc * inv_d
    for i in range(m):
        acc = x[i]
        for k in range(i):
            acc -= a[i, k] * x[k]
        x[i] = acc * a[i, i]
    for i in range(m - 1, -1, -1):
        acc = x[i]
        for k in range(i + 1, m):
            acc -= a[k, i] * x[k]
        x[i] = acc * a[i, i]
    return 0


_PRE = 16 + 2 * NG  # the first row of the bins' constants in the per-bin work array
_PRE_LN_C, _PRE_LN_FZ, _PRE_LN_FZS, _PRE_LN_COS = 0, 2, 4, 5  # ln C_L, ln C_R; ln Fz_L, ln Fz_R


@njit(cache=True, nogil=True)
def workspace(b):
    """Work arrays of :func:`profile_nll` for the bins *b* (per-bin rows, small matrices, and
    the Jacobians with their bins along the first axis, C-contiguous for the inner loops).

    The per-bin rows end with the bins' constants, computed here once rather than at every
    evaluation of the objective: ln C_w, ln Fz_w, ln Fz_static and ln cos δ.
    """
    n = b.shape[0]
    m = max(n, 1)
    ws = np.zeros((_PRE + 6, m))
    for k in range(n):
        for w in range(2):
            ws[_PRE + _PRE_LN_C + w, k] = np.log(b[k, 4 + w])
            ws[_PRE + _PRE_LN_FZ + w, k] = np.log(b[k, 2 + w])
        ws[_PRE + _PRE_LN_FZS, k] = np.log(b[k, 11])
        ws[_PRE + _PRE_LN_COS, k] = np.log(np.cos(b[k, 12]))
    return ws, np.zeros((4 + 2 * NG, NG + 1)), np.zeros((3, m, NG))


@njit(cache=True, nogil=True, inline="always", **_NO_RT)
def _copy(dst, src):
    """Copy src into dst (1-D), element by element: no temporary, no reference counting."""
    for i in range(dst.shape[0]):
        dst[i] = src[i]
    return 0


@njit(cache=True, nogil=True, inline="always")
def _thomas_factor(lo, di, up, cp, inv_den):
    """Factor a tridiagonal matrix (sub-diagonal lo[k] = A[k+1, k], super up[k] = A[k, k+1])
    once for :func:`_thomas_solve` (Thomas algorithm: the reciprocal pivots and the ratios cp).
    """
    n = di.size
    inv_den[0] = 1.0 / di[0]
    cp[0] = up[0] * inv_den[0] if n > 1 else 0.0
    for k in range(1, n):
        inv_den[k] = 1.0 / (di[k] - lo[k - 1] * cp[k - 1])
        cp[k] = up[k] * inv_den[k] if k < n - 1 else 0.0
    return 0


@njit(cache=True, nogil=True, inline="always")
def _thomas_solve(lo, cp, inv_den, rhs, out, dp):
    """Solve the factored tridiagonal system for one right-hand side (O(n), no division)."""
    n = inv_den.size
    dp[0] = rhs[0] * inv_den[0]
    for k in range(1, n):
        dp[k] = (rhs[k] - lo[k - 1] * dp[k - 1]) * inv_den[k]
    out[n - 1] = dp[n - 1]
    for k in range(n - 2, -1, -1):
        out[k] = dp[k] - cp[k] * out[k + 1]
    return 0


@njit(cache=True, nogil=True, inline="always", **_NO_RT)
def _step_one_bin(th, dl, r, v, jg, jd, pd, prior_m, prior_s, lam, g_g, g_d, dth, trial_th,
                  trial_dl, inv_e):  # fmt: skip
    """The damped Gauss–Newton step of :func:`profile_nll` for a single bin, in O(NG).

    With one residual the δ-eliminated normal matrix is a diagonal plus a rank-one term,
    A = diag(e) + c j jᵀ with e_a = (1 + λ)/σ_a² + λ w j_a² and c = w − (w j_δ)²/d_δ (w = 1/v,
    d_δ the damped δ diagonal), so Sherman–Morrison solves it exactly — the same step as the
    general path's Cholesky factorisation (to rounding), without the NG³ work
    (``docs/physics.md`` §15.3, "Why profile, not marginalise").
    """
    wk = 1.0 / v[0]
    jd0 = jd[0]
    dd0 = (jd0 * jd0 * wk + pd[0]) * (1.0 + lam)
    gd0 = jd0 * r[0] * wk + pd[0] * dl[0]
    g_d[0] = gd0
    c = wk - (wk * jd0) * (wk * jd0) / dd0
    s1 = 0.0
    s2 = 0.0
    for a in range(NG):
        ja = jg[0, a]
        ps = 1.0 / (prior_s[a] * prior_s[a])
        g_g[a] = ja * r[0] * wk + (th[a] - prior_m[a]) * ps
        inv_e[a] = 1.0 / ((1.0 + lam) * ps + lam * wk * ja * ja)
        dth[a] = -g_g[a] + wk * ja * jd0 * gd0 / dd0  # right-hand side, then the step
        s1 += ja * inv_e[a] * dth[a]
        s2 += ja * ja * inv_e[a]
    fac = c * s1 / (1.0 + c * s2)
    acc = gd0
    for a in range(NG):
        dth[a] = inv_e[a] * (dth[a] - jg[0, a] * fac)
        trial_th[a] = th[a] + dth[a]
        acc += wk * jg[0, a] * jd0 * dth[a]
    trial_dl[0] = dl[0] - acc / dd0
    return 0


NFEW = 4  # windows of 2..NFEW bins step by Woodbury (:func:`_step_few_bins`)


@njit(cache=True, nogil=True, inline="always", **_NO_RT)
def _gauss_solve(a, n, ncols):
    """Solve a[:n, :n] x = a[:n, n:ncols] in place by Gaussian elimination with partial
    pivoting (tiny dense systems: n ≤ NFEW); the solutions replace the right-hand sides.
    """
    for i in range(n):
        p = i
        for k in range(i + 1, n):
            if abs(a[k, i]) > abs(a[p, i]):
                p = k
        if p != i:
            for c in range(i, ncols):
                t = a[i, c]
                a[i, c] = a[p, c]
                a[p, c] = t
        inv = 1.0 / a[i, i]
        for k in range(i + 1, n):
            f = a[k, i] * inv
            if f != 0.0:
                for c in range(i, ncols):
                    a[k, c] -= f * a[i, c]
    for i in range(n - 1, -1, -1):
        inv = 1.0 / a[i, i]
        for c in range(n, ncols):
            acc = a[i, c]
            for k in range(i + 1, n):
                acc -= a[i, k] * a[k, c]
            a[i, c] = acc * inv
    return 0


@njit(cache=True, nogil=True, inline="always", **_NO_RT)
def _step_few_bins(n, th, dl, r, v, jg, jd, pd, pe, prior_m, prior_s, lam, g_g, g_d, dth,
                   trial_th, trial_dl, wm, u, y, z, sv):  # fmt: skip
    """The damped Gauss–Newton step of :func:`profile_nll` for 2 ≤ n ≤ NFEW bins, in
    O(n² NG + n³).

    With δ eliminated, the damped normal matrix of θ is A = diag(e) + Jᵀ C J: e_a =
    (1 + λ)/σ_a² + λ Σ_k w_k j_ka², C = W − W J_δ T⁻¹ J_δ W (n × n; T the damped tridiagonal δ
    block). Woodbury, A⁻¹ = E − E Jᵀ C (I + J E Jᵀ C)⁻¹ J E (E = diag(e)⁻¹), solves it with
    n × n systems only — the same step as the general path's Cholesky factorisation, to
    rounding (``docs/physics.md`` §15.3). Scratch: rows 4–20 of ``wm``; u, y, z, sv: n each.
    """
    inv_e = wm[4]
    xm = wm[5 : 5 + NFEW]  # X = T⁻¹ diag(w j_δ)
    cm = wm[9 : 9 + NFEW]  # C
    mm = wm[13 : 13 + NFEW]  # M = J E Jᵀ
    ga = wm[17 : 17 + NFEW]  # augmented systems
    for a in range(NG):
        ps = 1.0 / (prior_s[a] * prior_s[a])
        g_g[a] = (th[a] - prior_m[a]) * ps
        inv_e[a] = (1.0 + lam) * ps
    for k in range(n):
        wk = 1.0 / v[k]
        for a in range(NG):
            g_g[a] += jg[k, a] * r[k] * wk
            inv_e[a] += lam * wk * jg[k, a] * jg[k, a]
        g_d[k] = jd[k] * r[k] * wk + pd[k] * dl[k]
        if k > 0:
            g_d[k] += pe[k - 1] * dl[k - 1]
        if k < n - 1:
            g_d[k] += pe[k] * dl[k + 1]
    for a in range(NG):
        inv_e[a] = 1.0 / inv_e[a]
    # T [X | u] = [diag(w j_δ) | g_δ]
    for k in range(n):
        wk = 1.0 / v[k]
        for c in range(2 * n + 1):
            ga[k, c] = 0.0
        ga[k, k] = (jd[k] * jd[k] * wk + pd[k]) * (1.0 + lam)
        if k > 0:
            ga[k, k - 1] = pe[k - 1]
        if k < n - 1:
            ga[k, k + 1] = pe[k]
        ga[k, n + k] = wk * jd[k]
        ga[k, 2 * n] = g_d[k]
    _gauss_solve(ga, n, 2 * n + 1)
    for k in range(n):
        wk = 1.0 / v[k]
        u[k] = ga[k, 2 * n]
        for m in range(n):
            xm[k, m] = ga[k, n + m]
            cm[k, m] = -wk * jd[k] * ga[k, n + m]
        cm[k, k] += wk
    # right-hand side −g_θ + H_θδ T⁻¹ g_δ, then q = J E rhs and M = J E Jᵀ
    for a in range(NG):
        acc = -g_g[a]
        for k in range(n):
            acc += jg[k, a] * jd[k] * u[k] / v[k]
        dth[a] = acc
    for k in range(n):
        acc = 0.0
        for a in range(NG):
            acc += jg[k, a] * inv_e[a] * dth[a]
        y[k] = acc
        for m in range(k + 1):
            acc = 0.0
            for a in range(NG):
                acc += jg[k, a] * inv_e[a] * jg[m, a]
            mm[k, m] = acc
            mm[m, k] = acc
    # (I + M C) y = q, z = C y
    for k in range(n):
        for m in range(n):
            acc = 0.0
            for i in range(n):
                acc += mm[k, i] * cm[i, m]
            ga[k, m] = acc + (1.0 if k == m else 0.0)
        ga[k, n] = y[k]
    _gauss_solve(ga, n, n + 1)
    for k in range(n):
        acc = 0.0
        for m in range(n):
            acc += cm[k, m] * ga[m, n]
        z[k] = acc
    for a in range(NG):
        acc = dth[a]
        for k in range(n):
            acc -= jg[k, a] * z[k]
        dth[a] = inv_e[a] * acc
        trial_th[a] = th[a] + dth[a]
    # δ step: −T⁻¹ (g_δ + H_δθ Δθ) = −(u + X J Δθ)
    for k in range(n):
        acc = 0.0
        for a in range(NG):
            acc += jg[k, a] * dth[a]
        sv[k] = acc
    for k in range(n):
        acc = u[k]
        for m in range(n):
            acc += xm[k, m] * sv[m]
        trial_dl[k] = dl[k] - acc
    return 0


@njit(cache=True, nogil=True, inline="always", **_NO_RT)
def _step_many_bins(n, th, dl, r, v, jg, jd, pd, pe, prior_m, prior_s, lam, g_g, g_d, rhs,
                    trial_th, trial_dl, h_gg, h_gd, a_mat, dd, ud, cp, piv, dp, rhs_tmp,
                    out_tmp, sol):  # fmt: skip
    """One damped Gauss–Newton step of :func:`profile_nll` over more than ``NFEW`` bins: the
    per-bin slips δ eliminated from the normal equations by their tridiagonal block (Thomas,
    O(n)) and the NG shared nuisances solved from the Schur complement (Cholesky). Writes the
    gradient (*g_g*, *g_d*) and the trial point (*trial_th*, *trial_dl*); inlined into the
    caller, so the split costs nothing.
    """
    h_gg[:, :] = 0.0
    g_g[:] = 0.0
    for k in range(n):
        wk = 1.0 / v[k]
        for a in range(NG):
            g_g[a] += jg[k, a] * r[k] * wk
            h_gd[k, a] = jg[k, a] * jd[k] * wk
            for c in range(a + 1):  # lower triangle: all the Cholesky factor reads
                h_gg[a, c] += jg[k, a] * jg[k, c] * wk
        dd[k] = (jd[k] * jd[k] * wk + pd[k]) * (1.0 + lam)
        g_d[k] = jd[k] * r[k] * wk + pd[k] * dl[k]
        if k > 0:
            g_d[k] += pe[k - 1] * dl[k - 1]
        if k < n - 1:
            g_d[k] += pe[k] * dl[k + 1]
            ud[k] = pe[k]
    for a in range(NG):
        h_gg[a, a] += 1.0 / prior_s[a] ** 2
        g_g[a] += (th[a] - prior_m[a]) / prior_s[a] ** 2
        h_gg[a, a] *= 1.0 + lam
    # eliminate δ: T⁻¹ on the NG coupling columns and on the gradient (Thomas, O(n))
    _thomas_factor(ud, dd, ud, cp, piv)  # one factorisation for the NG + 1 solves
    for a in range(NG):
        for k in range(n):
            rhs_tmp[k] = h_gd[k, a]
        _thomas_solve(ud, cp, piv, rhs_tmp, out_tmp, dp)
        _copy(sol[a], out_tmp)
    _thomas_solve(ud, cp, piv, g_d, out_tmp, dp)
    _copy(sol[NG], out_tmp)
    for a in range(NG):
        _copy(a_mat[a], h_gg[a])
    for a in range(NG):
        rhs[a] = -g_g[a]
    for a in range(NG):
        for k in range(n):
            rhs[a] += h_gd[k, a] * sol[NG, k]
        for c in range(a + 1):
            acc = 0.0
            for k in range(n):
                acc += h_gd[k, a] * sol[c, k]
            a_mat[a, c] -= acc
    _cholesky_solve(a_mat, rhs)  # the Schur complement is symmetric positive definite
    for a in range(NG):
        trial_th[a] = th[a] + rhs[a]
    for k in range(n):
        acc = sol[NG, k]
        for a in range(NG):
            acc += sol[a, k] * rhs[a]
        trial_dl[k] = dl[k] - acc


@njit(cache=True, nogil=True, **_NO_RT)
def profile_nll(
    mu,
    shape,
    b,
    rho,
    prior_m,
    prior_s,
    prior_d,
    tab_f,
    tab_df,
    inv_dx,
    p0,
    th0,
    dl0,
    iters,
    th_out,
    dl_out,
    ws,
    wm,
    wj,
    stop_above,
):
    """Minimise ½Σr²/v + ½ priors over the nuisances for one (μ, shape) by Levenberg–Marquardt
    (Gauss–Newton steps, damped when a step does not lower the objective).

    A minimisation still above ``stop_above`` after a step ends there (the caller sets it far
    above every interval level, where the exact value does not matter; ``np.inf``: never).

    Returns the minimum (the variances v are re-evaluated at each point: the effective-variance
    method, without a log-variance term); ``th_out``/``dl_out`` receive the nuisances. ``ws``,
    ``wm`` and ``wj`` are work arrays (:func:`workspace` of the same bins *b*: ``ws`` also
    holds their constants), so a call allocates nothing.
    """
    n = b.shape[0]
    tol = TOL_NLL_FEW if n <= NFEW else TOL_NLL
    th = wm[0, :NG]
    dl = ws[0]
    _copy(th, th0)
    _copy(dl, dl0)
    r, v, jd, pd, pe = ws[1], ws[2], ws[3], ws[4], ws[5]
    jg, jg_t, h_gd = wj[0, :n], wj[1, :n], wj[2, :n]
    _prior_delta(rho, prior_d, pd, pe)
    ctx = (shape, tab_f, tab_df, inv_dx, b, ws[_PRE:], p0, prior_m, prior_s, pd, pe)
    best = _objective(mu, th, dl, ctx, r, v, jg, jd)
    _copy(th_out, th)
    _copy(dl_out, dl)
    lam = 1e-3
    trial_th = wm[1, :NG]
    g_g = wm[2, :NG]
    rhs = wm[3, :NG]
    h_gg = wm[4 : 4 + NG, :NG]
    a_mat = wm[4 + NG : 4 + 2 * NG, :NG]
    trial_dl, dd, ud, g_d, cp, dp, rhs_tmp, out_tmp = (
        ws[6 + NG], ws[7 + NG], ws[8 + NG], ws[9 + NG], ws[10 + NG], ws[11 + NG], ws[12 + NG],
        ws[13 + NG],
    )  # fmt: skip
    sol = ws[14 + NG : 15 + 2 * NG]
    # the trial point's residuals, variances and Jacobians: kept apart from the current
    # point's, so a rejected step needs no second evaluation at the current point
    r_t, v_t, jd_t, piv = ws[15 + 2 * NG], ws[6], ws[7], ws[8]
    for _ in range(2 * iters):
        if n == 1:
            _step_one_bin(th, dl, r, v, jg, jd, pd, prior_m, prior_s, lam, g_g, g_d, rhs,
                          trial_th, trial_dl, wm[4])  # fmt: skip
        elif n <= NFEW:
            _step_few_bins(n, th, dl, r, v, jg, jd, pd, pe, prior_m, prior_s, lam, g_g, g_d,
                           rhs, trial_th, trial_dl, wm, cp, dp, rhs_tmp, out_tmp)  # fmt: skip
        else:
            _step_many_bins(n, th, dl, r, v, jg, jd, pd, pe, prior_m, prior_s, lam, g_g, g_d,
                            rhs, trial_th, trial_dl, h_gg, h_gd, a_mat, dd, ud, cp, piv, dp,
                            rhs_tmp, out_tmp, sol)  # fmt: skip
        # keep the step physical: stiffness scale within e^±2, load-transfer error > −0.95
        trial_th[0] = min(max(trial_th[0], -2.0), 2.0)
        trial_th[2] = max(trial_th[2], -0.95)
        trial_th[7] = min(max(trial_th[7], -0.5), 1.0)
        trial_th[8] = min(max(trial_th[8], -2.0), 2.0)
        # the decrease the quadratic model predicts for this step: at the minimum it is below
        # the tolerance, and a step that rounding would reject is not tried again and again
        pred = 0.0
        for a in range(NG):
            pred -= g_g[a] * (trial_th[a] - th[a])
        for k in range(n):
            pred -= g_d[k] * (trial_dl[k] - dl[k])
        if 0.5 * pred < tol:
            break
        val = _objective(mu, trial_th, trial_dl, ctx, r_t, v_t, jg_t, jd_t)
        if val < best:
            improvement = best - val
            _copy(th, trial_th)
            _copy(dl, trial_dl)
            _copy(r, r_t)
            _copy(v, v_t)
            _copy(jd, jd_t)
            for k in range(n):
                _copy(jg[k], jg_t[k])
            best = val
            _copy(th_out, th)
            _copy(dl_out, dl)
            lam = max(lam * 0.1, 1e-6)
            if improvement < tol:
                break
        else:
            lam *= 10.0
        if best > stop_above:
            break
    return best


@njit(cache=True, nogil=True)
def merge_runs(t0, t1, n, data, tol, noise_cols, slip_z, drift_sd, tau_s, model_col):
    """The loop of :func:`gripsense.estimate.bins.merge_steady`: runs of bins whose
    measured grip (column 9) stays within *tol* of the run's first bin, and whose mean slip
    (columns 0, 1) stays within *slip_z* of its noise (the bins' white noise and the change of
    a Gauss–Markov drift of 1σ *drift_sd* and correlation time *tau_s* since the run's first
    bin), without a time gap, as count-weighted means; the columns in *noise_cols* combine as
    white noise of a mean, √(Σ nᵢ² σᵢ²) / Σ nᵢ. Sums in bin order, as ``np.bincount`` would.
    The model's fidelity (column *model_col*) is one error per level of force: the m merged
    points whose |grip| falls in one level *tol* wide (a plateau kept as points, a slalom's
    repeated visits of the same part of the curve) carry √m of it each, so together they weigh
    what one point weighs. Returns (mid, merged).
    """
    nb, nc = data.shape
    groups = np.zeros(nb, dtype=np.int64)
    g = 0
    i0 = 0  # first bin of the current point
    ir = 0  # first bin of the current run of steady force (the points it is split into)
    for k in range(1, nb):
        gap = t0[k] - t1[k - 1] > 1.5 * max(t1[k - 1] - t0[k - 1], 0.1)
        moved = False
        if slip_z < np.inf:
            d_slip = 0.5 * (data[k, 0] + data[k, 1] - data[i0, 0] - data[i0, 1])
            dt = 0.5 * (t0[k] + t1[k] - t0[i0] - t1[i0])
            var = data[k, 8] ** 2 + data[i0, 8] ** 2
            var += 2.0 * drift_sd**2 * (1.0 - np.exp(-abs(dt) / tau_s))
            moved = d_slip * d_slip > slip_z * slip_z * var
        force_moved = gap or abs(data[k, 9] - data[ir, 9]) > tol
        if force_moved or abs(data[k, 9] - data[i0, 9]) > tol or moved:
            g += 1
            i0 = k
            if force_moved:
                ir = k
        groups[k] = g
    noisy = np.zeros(nc, dtype=np.bool_)
    for c in noise_cols:
        noisy[c] = True
    sw = np.zeros(g + 1)
    out = np.zeros((g + 1, nc))
    mid = np.zeros(g + 1)
    for k in range(nb):
        w = n[k]
        j = groups[k]
        sw[j] += w
        for c in range(nc):
            x = w * data[k, c]
            out[j, c] += x * x if noisy[c] else x
        mid[j] += 0.5 * (t0[k] + t1[k]) * w
    for j in range(g + 1):
        for c in range(nc):
            out[j, c] = (np.sqrt(out[j, c]) if noisy[c] else out[j, c]) / sw[j]
        mid[j] /= sw[j]
    # the model's error is a function of the point of the curve, not of time: the m points at
    # one level of |grip| (levels *tol* wide) share it, so each carries √m of the fidelity
    if tol > 0.0:
        level = np.empty(g + 1, dtype=np.int64)
        for j in range(g + 1):
            level[j] = int(abs(out[j, 9]) / tol)
        per_level = np.zeros(np.max(level) + 1)
        for j in range(g + 1):
            per_level[level[j]] += 1.0
        for j in range(g + 1):
            out[j, model_col] *= np.sqrt(per_level[level[j]])
    return mid, out


@njit(cache=True, nogil=True, **_NO_RT)
def _grid_point(im, mu_grid, shapes, shape_pen, b, rho, prior_m, prior_s, prior_d, tab_f, tab_df,
                inv_dx, p0, iters, out_nll, out_th, out_dl, out_shape, floor, stop_margin, warm,
                warm_d, last, last_best, active, th, dl, ws, wm, wj):  # fmt: skip
    """One μ of :func:`profile_grid`: every shape still ``active`` minimised from its warm
    start (skipped where it was ``SKIP_MARGIN`` worse than the best at the previous μ, except at
    every fourth μ). Returns the best value (inf when no shape was minimised).
    """
    best = np.inf
    for si in range(shapes.size):
        if not active[si]:
            continue
        if im % 4 != 0 and last[si] > last_best + SKIP_MARGIN:
            continue
        stop = floor + stop_margin - shape_pen[si]
        nll = profile_nll(mu_grid[im], shapes[si], b, rho, prior_m, prior_s, prior_d, tab_f,
                          tab_df, inv_dx, p0, warm[si], warm_d[si], iters, th, dl, ws, wm, wj,
                          stop)  # fmt: skip
        if nll <= stop:
            _copy(warm[si], th)
            _copy(warm_d[si], dl)
        nll += shape_pen[si]
        last[si] = nll
        if nll < best:
            best = nll
            _copy(out_th[im], th)
            _copy(out_dl[im], dl)
            out_shape[im] = shapes[si]
    out_nll[im] = best
    return best


@njit(cache=True, nogil=True)
def _probe_shapes(probe, shapes, shape_pen, b, rho, prior_m, prior_s, prior_d, tab_f, tab_df,
                  inv_dx, p0, iters, warm, warm_d, probe_th, probe_d, probe_v, th, dl, ws, wm,
                  wj):  # fmt: skip
    """Every shape minimised at μ = *probe* from its start (*warm*, *warm_d*): the solutions
    into *probe_th*/*probe_d*, the values with each shape's penalty into *probe_v*. Returns the
    lowest (an upper bound of the profile's minimum).
    """
    floor = np.inf
    for si in range(shapes.size):
        nll = profile_nll(probe, shapes[si], b, rho, prior_m, prior_s, prior_d, tab_f, tab_df,
                          inv_dx, p0, warm[si], warm_d[si], iters, th, dl, ws, wm, wj,
                          np.inf)  # fmt: skip
        _copy(probe_th[si], th)
        _copy(probe_d[si], dl)
        probe_v[si] = nll + shape_pen[si]
        floor = min(floor, probe_v[si])
    return floor


@njit(cache=True, nogil=True)
def probe_step(probe, mu_next, shapes, shape_pen, b, rho, prior_m, prior_s, prior_d, tab_f,
               tab_df, inv_dx, p0, iters, stop_margin):  # fmt: skip
    """The first step of :func:`profile_grid`'s upward sweep for the shape best at the probe:
    every shape minimised at μ = *probe* from the prior mean, then the best one at *mu_next*
    (the first grid μ ≥ *probe*) from its probe solution, with the stop the sweep gives it.

    The value is the one :func:`profile_grid` computes for that shape at that μ (the same
    starts, the same stop), so it is an upper bound of the minimum of the grid profile: a
    window that needs only to know the profile's minimum is below a level (the fit's
    consistency) learns it from ~ns + 1 minimisations instead of the grid's hundreds.
    """
    n = b.shape[0]
    ws, wm, wj = workspace(b)
    ns = shapes.size
    warm = np.empty((ns, NG))
    warm_d = np.zeros((ns, n))
    for si in range(ns):
        _copy(warm[si], prior_m)
    probe_th = np.empty((ns, NG))
    probe_d = np.zeros((ns, n))
    probe_v = np.empty(ns)
    th = np.empty(NG)
    dl = np.zeros(n)
    floor = _probe_shapes(probe, shapes, shape_pen, b, rho, prior_m, prior_s, prior_d, tab_f,
                          tab_df, inv_dx, p0, iters, warm, warm_d, probe_th, probe_d, probe_v,
                          th, dl, ws, wm, wj)  # fmt: skip
    s = int(np.argmin(probe_v))
    stop = floor + stop_margin - shape_pen[s]
    nll = profile_nll(mu_next, shapes[s], b, rho, prior_m, prior_s, prior_d, tab_f, tab_df,
                      inv_dx, p0, probe_th[s], probe_d[s], iters, th, dl, ws, wm, wj,
                      stop)  # fmt: skip
    return nll + shape_pen[s]


@njit(cache=True, nogil=True)
def profile_grid(
    mu_grid,
    shapes,
    shape_pen,
    b,
    rho,
    prior_m,
    prior_s,
    prior_d,
    tab_f,
    tab_df,
    inv_dx,
    p0,
    iters,
    out_nll,
    out_th,
    out_dl,
    out_shape,
    floor,
    probe,
    stop_margin,
):
    """Profile NLL(μ) over the allowed shapes for every μ of the grid (warm-started along μ);
    ``shape_pen[si]`` is the prior's −log weight of shape si. A shape that was worse than the
    best by more than ``SKIP_MARGIN`` at the previous μ is not refitted at the next one (the
    profile moves smoothly in μ), except at every fourth μ.

    μ too small to carry the measured force give values far above the profile's minimum; a
    minimisation still more than *stop_margin* (:data:`STOP_ABOVE`; ``np.inf``: never) above an
    upper bound of the minimum (*floor*, ``np.inf`` if none is known; the profile's value at
    μ = *probe* when it is positive; and the lowest value so far) after a step
    ends there, and its nuisances are not passed on as the next μ's start
    (``docs/physics.md`` §15.3).

    A window of up to ``NFEW`` bins with a *probe* is swept from the probe's minimisations (of
    every shape, from the prior mean) up the grid, then down it. A shape more than
    :data:`DROP_ABOVE` above the upper bound of the minimum (with *stop_margin* ``np.inf``:
    never) is not minimised further along that sweep: down, less grip carries the measured
    force still worse; up, a still more linear curve explains the data no better. A sweep ends
    when no shape is left, and the μ it did not reach get ``inf`` (points the profile excluded,
    far above every level). Windows of more than ``NFEW`` bins are minimised fully at every μ,
    up the grid from its first: their nuisances converge only along the warm-started path.
    """
    n = b.shape[0]
    ws, wm, wj = workspace(b)
    ns = shapes.size
    warm = np.empty((ns, NG))
    warm_d = np.zeros((ns, n))
    last = np.zeros(ns)
    active = np.ones(ns, dtype=np.bool_)
    th = np.empty(NG)
    dl = np.zeros(n)
    n_mu = mu_grid.size
    for si in range(ns):
        _copy(warm[si], prior_m)
    if n > NFEW or probe <= 0.0:  # long windows need the warm starts of every μ to converge
        stop_margin = np.inf if n > NFEW else stop_margin
        last_best = 0.0
        for im in range(n_mu):
            last_best = _grid_point(im, mu_grid, shapes, shape_pen, b, rho, prior_m, prior_s,
                                    prior_d, tab_f, tab_df, inv_dx, p0, iters, out_nll, out_th,
                                    out_dl, out_shape, floor, stop_margin, warm, warm_d, last,
                                    last_best, active, th, dl, ws, wm, wj)  # fmt: skip
            floor = min(floor, last_best)
        return 0
    # the probe's minimisation of every shape: an upper bound of the minimum, and the start of
    # both sweeps
    probe_th = np.empty((ns, NG))
    probe_d = np.zeros((ns, n))
    probe_v = np.empty(ns)
    floor = min(floor, _probe_shapes(probe, shapes, shape_pen, b, rho, prior_m, prior_s,
                                     prior_d, tab_f, tab_df, inv_dx, p0, iters, warm, warm_d,
                                     probe_th, probe_d, probe_v, th, dl, ws, wm, wj))  # fmt: skip
    drop = min(stop_margin, DROP_ABOVE) if stop_margin < np.inf else np.inf
    i0 = 0
    while i0 < n_mu and mu_grid[i0] < probe:
        i0 += 1
    for direction in (1, -1):
        for si in range(ns):
            _copy(warm[si], probe_th[si])
            _copy(warm_d[si], probe_d[si])
            last[si] = probe_v[si]
            active[si] = True
        last_best = floor
        im = i0 if direction > 0 else i0 - 1
        while 0 <= im < n_mu:
            if not active.any():
                out_nll[im] = np.inf
            else:
                best = _grid_point(im, mu_grid, shapes, shape_pen, b, rho, prior_m, prior_s,
                                   prior_d, tab_f, tab_df, inv_dx, p0, iters, out_nll, out_th,
                                   out_dl, out_shape, floor, stop_margin, warm, warm_d, last,
                                   last_best, active, th, dl, ws, wm, wj)  # fmt: skip
                for si in range(ns):  # a shape beyond every stored value stops here
                    if active[si] and last[si] > floor + drop:
                        active[si] = False
                last_best = best
                floor = min(floor, best)
            im += direction
    return 0
