"""Nonlinear least squares with bounds and nonlinear inequality constraints (Gauss–Newton SQP).

Each iteration linearises the residuals (exact Jacobian from the model) and the constraints and
solves the quadratic sub-problem

    min_d ½ dᵀ (JᵀWJ + λ diag(JᵀWJ)) d + (JᵀWr)ᵀ d   s.t.  c(x) + A d ≥ 0,  lb ≤ x + d ≤ ub

(Levenberg–Marquardt damping λ; W = IRLS weights of a robust loss). The sub-problem has as many
variables as coefficients, so it is cheap whatever the number of data points; it is solved with
SLSQP on unit-scaled variables. A step is accepted when an ℓ1 merit function (cost + ν·violation)
decreases; λ adapts as in Levenberg–Marquardt. This is the classic Gauss–Newton/SQP combination
(Nocedal & Wright, *Numerical Optimization*, 2nd ed., §18.1 and §10.3): Gauss–Newton curvature
gives quadratic-like convergence near a small-residual solution, where a quasi-Newton SQP such as
plain SLSQP needs many more iterations, each with a full gradient.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

__all__ = ["LSQResult", "loss_weights", "solve_constrained_lsq"]


@dataclass
class LSQResult:
    """Result of :func:`solve_constrained_lsq`.

    Attributes
    ----------
    x : numpy.ndarray
        Solution.
    cost : float
        ½ Σ ρ(r²) at x (ρ = identity for the linear loss) [unit of r^2].
    residuals : numpy.ndarray
        Residuals at x.
    jacobian : numpy.ndarray
        Jacobian of the residuals at x.
    constraint_values : numpy.ndarray
        c(x), ≥ 0 when satisfied.
    success : bool
        Whether the solver converged.
    message : str
        Why it stopped.
    nit : int
        Iterations.
    nfev : int
        Residual evaluations.
    """

    x: np.ndarray
    cost: float  #: ½ Σ ρ(r²) at x (ρ = identity for the linear loss) [unit of r^2]
    residuals: np.ndarray
    jacobian: np.ndarray
    constraint_values: np.ndarray  #: c(x) (≥ 0 when satisfied)
    success: bool
    message: str
    nit: int
    nfev: int


def loss_weights(r: np.ndarray, loss: str, f_scale: float) -> tuple[np.ndarray, float]:
    """IRLS weights ρ'(z) and cost ½ f² Σ ρ(z), z = (r/f)², for ``linear``, ``soft_l1``, ``huber``
    and ``cauchy`` (the definitions of :func:`scipy.optimize.least_squares`).

    Parameters
    ----------
    r : ndarray
        Residuals [any unit].
    loss : str
        Loss name.
    f_scale : float
        Soft margin between inlier and outlier residuals [unit of r].

    Returns
    -------
    weights : ndarray
    cost : float
    """
    if loss == "linear":
        return np.ones_like(r), 0.5 * float(r @ r)
    z = (r / f_scale) ** 2
    if loss == "soft_l1":
        rho = 2.0 * (np.sqrt(1.0 + z) - 1.0)
        w = 1.0 / np.sqrt(1.0 + z)
    elif loss == "huber":
        rho = np.where(z <= 1, z, 2.0 * np.sqrt(z) - 1.0)
        w = np.where(z <= 1, 1.0, 1.0 / np.sqrt(np.maximum(z, 1e-300)))
    elif loss == "cauchy":
        rho = np.log1p(z)
        w = 1.0 / (1.0 + z)
    else:
        raise ValueError(f"loss must be linear, soft_l1, huber or cauchy, not {loss!r}")
    return w, 0.5 * f_scale**2 * float(rho.sum())


def _active_set_qp(
    h: np.ndarray,
    g: np.ndarray,
    gmat: np.ndarray,
    hvec: np.ndarray,
    z: np.ndarray,
    max_iter: int = 500,
) -> np.ndarray | None:
    """Primal active-set method for the convex QP min ½zᵀHz + gᵀz s.t. G z ≥ h from a feasible z
    (Nocedal & Wright, Algorithm 16.3). Returns None if it does not finish.
    """
    n = g.size
    slack = gmat @ z - hvec
    work = [i for i in np.where(np.abs(slack) <= 1e-12)[0]]
    # keep a linearly independent working set
    indep: list[int] = []
    for i in work:
        cand = gmat[[*indep, i]]
        if np.linalg.matrix_rank(cand) == len(indep) + 1:
            indep.append(i)
    work = indep
    for _ in range(max_iter):
        m = len(work)
        aw = gmat[work]
        kkt = np.zeros((n + m, n + m))
        kkt[:n, :n] = h
        kkt[:n, n:] = -aw.T
        kkt[n:, :n] = aw
        rhs = np.concatenate([-(h @ z + g), np.zeros(m)])
        try:
            sol = np.linalg.solve(kkt, rhs)
        except np.linalg.LinAlgError:
            return None
        p, lam = sol[:n], sol[n:]
        if np.linalg.norm(p) <= 1e-12 * (1 + np.linalg.norm(z)):
            if m == 0 or lam.min() >= -1e-12:
                return z
            work.pop(int(np.argmin(lam)))
            continue
        gp = gmat @ p
        slack = gmat @ z - hvec
        entering = [i for i in np.where(gp < -1e-15)[0] if i not in work]
        alpha, block = 1.0, None
        for i in entering:
            a_i = -slack[i] / gp[i]
            if a_i < alpha:
                alpha, block = max(a_i, 0.0), i
        z = z + alpha * p
        if block is not None:
            work.append(int(block))
    return None


def _qp(
    h: np.ndarray, g: np.ndarray, c0: np.ndarray, a: np.ndarray, lo: np.ndarray, hi: np.ndarray
) -> np.ndarray:
    """Min ½dᵀHd + gᵀd s.t. c0 + A d ≥ 0, lo ≤ d ≤ hi, on variables scaled to unit diagonal."""
    s = 1.0 / np.sqrt(np.maximum(np.diag(h), 1e-300))
    hs = h * s[:, None] * s[None, :]
    gs = g * s
    as_ = a * s[None, :]
    bounds = list(zip(lo / s, hi / s, strict=True))
    # unconstrained Newton step as the start when it is feasible; else zero
    try:
        z0 = np.linalg.solve(hs, -gs)
    except np.linalg.LinAlgError:
        z0 = np.zeros_like(gs)
    if np.all(z0 > lo / s) and np.all(z0 < hi / s) and (not c0.size or np.all(c0 + as_ @ z0 >= 0)):
        return z0 * s  # the Newton step is feasible: it solves the QP exactly
    z0 = np.clip(z0, lo / s, hi / s)
    if c0.size and np.any(c0 + as_ @ z0 < 0):
        z0 = np.zeros_like(gs)
    # rows G z >= h: linearised constraints and finite bounds
    rows = [as_] if c0.size else []
    rhs = [-c0] if c0.size else []
    eye = np.eye(gs.size)
    fin_lo, fin_hi = np.isfinite(lo), np.isfinite(hi)
    rows += [eye[fin_lo], -eye[fin_hi]]
    rhs += [(lo / s)[fin_lo], -(hi / s)[fin_hi]]
    gmat, hvec = np.vstack(rows), np.concatenate(rhs)
    zs = np.zeros_like(gs)
    if np.all(gmat @ zs - hvec >= -1e-12):
        z = _active_set_qp(hs, gs, gmat, hvec, zs)
        if z is not None:
            return z * s
    cons = (
        [{"type": "ineq", "fun": lambda z: c0 + as_ @ z, "jac": lambda z: as_}] if c0.size else []
    )
    res = minimize(
        lambda z: 0.5 * z @ hs @ z + gs @ z,
        z0,
        jac=lambda z: hs @ z + gs,
        bounds=bounds,
        constraints=cons,
        method="SLSQP",
        options={"maxiter": 200, "ftol": 1e-14},
    )
    return res.x * s


def solve_constrained_lsq(
    fun: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
    x0: np.ndarray,
    *,
    lb: np.ndarray,
    ub: np.ndarray,
    constraints: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None = None,
    loss: str = "linear",
    f_scale: float = 1.0,
    max_iter: int = 200,
    ftol: float = 1e-8,
    xtol: float = 1e-8,
) -> LSQResult:
    """Minimise ½ Σ ρ(rᵢ(x)²) subject to lb ≤ x ≤ ub and c(x) ≥ 0.

    Parameters
    ----------
    fun : callable
        ``x -> (r, J)``: residuals (n,) and Jacobian (n, p).
    x0 : ndarray
        Start; clipped into the bounds. It should satisfy c(x0) ≥ 0.
    lb, ub : ndarray
        Bounds (may be ±inf).
    constraints : callable, optional
        ``x -> (c, A)``: constraint values (m,) that must be ≥ 0, and their Jacobian (m, p).
    loss, f_scale : str, float
        Robust loss (see :func:`loss_weights`).
    max_iter : int
        Maximum accepted + rejected iterations.
    ftol, xtol : float
        Stop when the relative cost decrease or the relative step falls below these.

    Returns
    -------
    LSQResult
    """
    x = np.clip(np.asarray(x0, float), lb, ub)
    nfev = 0

    def cons(x):
        if constraints is None:
            return np.zeros(0), np.zeros((0, x.size))
        return constraints(x)

    r, j = fun(x)
    nfev += 1
    w, cost = loss_weights(r, loss, f_scale)
    c, a = cons(x)
    viol = float(np.sum(np.maximum(-c, 0.0)))
    lam = 1e-3
    grow = 2.0
    message = "maximum number of iterations reached"
    success = False
    it = 0
    history = [cost]
    for it in range(1, max_iter + 1):  # noqa: B007 - it is reported
        jw = j * w[:, None]
        h = j.T @ jw
        g = jw.T @ r
        dh = np.maximum(np.diag(h), 1e-12 * max(float(np.max(np.diag(h))), 1e-300))
        d = _qp(h + lam * np.diag(dh), g, c, a, lb - x, ub - x)
        xn = np.clip(x + d, lb, ub)
        cn, an = cons(xn)
        for _ in range(3):  # second-order correction back onto curved constraints
            if not cn.size or np.all(cn >= -1e-12):
                break
            xn = np.clip(xn + _qp(np.diag(dh), np.zeros_like(x), cn, an, lb - xn, ub - xn), lb, ub)
            cn, an = cons(xn)
        violn = float(np.sum(np.maximum(-cn, 0.0)))
        dd = xn - x
        pred = -(g @ dd + 0.5 * dd @ h @ dd)
        rn, jn = fun(xn)
        nfev += 1
        wn, costn = loss_weights(rn, loss, f_scale)
        better = np.isfinite(costn) and (
            (violn <= max(viol, 1e-10) and costn < cost) or violn < 0.5 * viol
        )
        if better:
            rho = (cost - costn) / pred if pred > 0 else 0.0
            step_small = np.linalg.norm(dd) <= xtol * (np.linalg.norm(x) + xtol)
            f_small = 0 <= (cost - costn) <= ftol * max(cost, 1e-300)
            x, r, j, w, cost, c, a, viol = xn, rn, jn, wn, costn, cn, an, violn
            lam = max(lam * max(1 / 3, 1 - (2 * rho - 1) ** 3), 1e-12) if rho > 0 else lam
            grow = 2.0
            if (step_small or f_small) and viol <= 1e-9:
                message = "converged"
                success = True
                break
            history.append(cost)
            if (
                len(history) > 10
                and viol <= 1e-9
                and history[-11] - cost <= 1e-6 * max(history[-11], 1e-300)
            ):
                message = (
                    "converged (cost flat over 10 iterations: a direction the data "
                    "do not determine)"
                )
                success = True
                break
        else:
            lam *= grow
            grow *= 2.0
            if lam > 1e12:
                message = "converged (no further decrease possible)"
                success = viol <= 1e-9
                break
    return LSQResult(
        x=x,
        cost=cost,
        residuals=r,
        jacobian=j,
        constraint_values=c,
        success=success,
        message=message,
        nit=it,
        nfev=nfev,
    )
