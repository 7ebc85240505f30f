"""Contact length versus wheel mass: least-squares fit of the thesis's l–m model.

l = a √m + b m, linear in (a, b) (seed 000 eq. 6.23, Table 18; docs/physics.md §5).
"""

from __future__ import annotations

import numpy as np

from gripsense._arrays import as_float_array
from gripsense.errors import InputError

__all__ = ["fit_contact_length"]


def fit_contact_length(mass_kg, length_m) -> tuple[dict[str, float], dict[str, float]]:
    """Fit l = a √m + b m by linear least squares.

    Parameters
    ----------
    mass_kg : array_like
        Mass carried by the wheel [kg] (>= 0).
    length_m : array_like
        Measured contact length [m].

    Returns
    -------
    params : dict
        ``a`` [m/kg^0.5], ``b`` [m/kg] — keyword arguments of
        :func:`gripsense.physics.contact.contact_length_lm`.
    stats : dict
        ``n``; ``r2``; ``rmse_m`` = √(SSE/n) (the thesis's "0.29", which is in cm, not %);
        ``rmse_dof_m`` = √(SSE/(n − 2)) (MATLAB cftool's definition); ``m_peak_kg`` = (a/2|b|)²,
        where the model stops growing (only for b < 0).

    Examples
    --------
    Thesis Table 18 gives a = 0.010398, b = −1.0172e-4, RMSE 0.286 cm (docs/physics.md §5).
    """
    m = as_float_array(mass_kg, "mass_kg").ravel()
    y = as_float_array(length_m, "length_m").ravel()
    if m.shape != y.shape:
        raise InputError(f"fit_contact_length: {m.size} masses but {y.size} lengths")
    ok = np.isfinite(m) & np.isfinite(y)
    if (m[ok] < 0).any():
        raise InputError("fit_contact_length: mass_kg has negative values; give masses in kg")
    m, y = m[ok], y[ok]
    if m.size < 3:
        raise InputError(f"fit_contact_length: {m.size} usable rows; need at least 3")
    X = np.column_stack([np.sqrt(m), m])
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    a, b = float(coef[0]), float(coef[1])
    res = y - X @ coef
    sse = float(res @ res)
    sst = float(((y - y.mean()) ** 2).sum())
    stats = {
        "n": int(m.size),
        "r2": 1.0 - sse / sst if sst > 0 else float("nan"),
        "rmse_m": float(np.sqrt(sse / m.size)),
        "rmse_dof_m": float(np.sqrt(sse / (m.size - 2))),
        "m_peak_kg": (a / (2.0 * abs(b))) ** 2 if b < 0 else float("inf"),
    }
    return {"a": a, "b": b}, stats
