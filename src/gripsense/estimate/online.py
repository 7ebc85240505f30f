"""``axle-window`` for live use: the window estimator fed sample by sample
(:class:`OnlineAxleWindow`), its answers equal to :func:`gripsense.estimate.axle_window.
estimate_windows` on the same samples.
"""

from __future__ import annotations

import itertools
from collections import deque

import numpy as np
import pandas as pd
from scipy.stats import norm

from gripsense.config import Vehicle
from gripsense.estimate.bins import axle_bins, axle_pairs
from gripsense.estimate.grip import bin_bound
from gripsense.estimate.noise import NoiseModel
from gripsense.estimate.options import WindowOptions
from gripsense.estimate.profile import ProfileCache, axle_priors, merge_bins
from gripsense.estimate.screen import resolvable

__all__ = ["OnlineAxleWindow"]


class OnlineAxleWindow:
    """``axle-window`` for live use: bins are kept as running sums, so adding a sample costs
    O(1) and an update one window's profile (independent of how long the drive is).

    Feed it the wheel-table rows of one axle as they become final (:meth:`push`), ask for the
    newest window (:meth:`estimate`). The answers equal :func:`estimate_windows` on the same
    samples (the bins are formed the same way).

    Parameters
    ----------
    vehicle : Vehicle
        Vehicle description.
    axle : str
        ``front`` or ``rear``.
    noise : NoiseModel, optional
        Measurement and parameter uncertainty.
    options : WindowOptions, optional
        Settings.
    """

    def __init__(
        self,
        vehicle: Vehicle,
        axle: str,
        *,
        noise: NoiseModel | None = None,
        options: WindowOptions | None = None,
    ):
        self.vehicle = vehicle
        self.axle = axle
        self.noise = noise or NoiseModel()
        self.o = options or WindowOptions()
        self._rows: list[dict[str, np.ndarray]] = []  # usable samples of the current bin
        self._k: int | None = None  # the current bin's index on the data clock
        self._bins: deque = deque(maxlen=max(round(self.o.window_s / self.o.bin_s), 1))
        self._pri = axle_priors(vehicle, axle, self.noise)
        self._reuse = ProfileCache()
        self._tail: dict[str, np.ndarray] | None = None
        self._tyre = vehicle.tyres[axle]  # its shapes: tyre_family, via ProfileCache.profile

    def push(self, rows: pd.DataFrame) -> None:
        """Add final wheel-table rows (both wheels of this axle, any number of epochs).

        Parameters
        ----------
        rows : pandas.DataFrame
            Rows of :func:`gripsense.estimate.friction.friction_from_motion`.
        """
        p = axle_pairs(rows, self.axle)
        k = np.floor(p["t_s_L"] / self.o.bin_s).astype(np.int64)
        cuts = np.concatenate([[0], np.flatnonzero(np.diff(k)) + 1, [k.size]])
        for i0, i1 in itertools.pairwise(cuts):
            if i1 <= i0:
                continue
            if self._k is not None and k[i0] != self._k:
                self._close()
            self._k = int(k[i0])
            self._rows.append({c: x[i0:i1] for c, x in p.items()})

    def _close(self) -> None:
        rows = {c: np.concatenate([r[c] for r in self._rows]) for c in self._rows[0]}
        k = self._k
        self._rows = []
        # the previous bin's samples give the relaxation-lag interpolation its context at the
        # bin's start, as in the batch (they form their own bin, which is not kept here)
        frame = (
            rows
            if self._tail is None or self._tail.keys() != rows.keys()
            else {c: np.concatenate([self._tail[c], x]) for c, x in rows.items()}
        )
        self._tail = rows
        ab = axle_bins(frame, self.axle, self.vehicle, self.noise, self.o.bin_s, 1)
        mine = np.flatnonzero(np.floor(ab.t0 / self.o.bin_s) == k)
        if mine.size and ab.n[mine[-1]] >= self.o.min_samples:
            i = mine[-1]
            self._bins.append((ab.t0[i], ab.t1[i], ab.n[i], ab.data[i], ab.grip_sigma[i], ab.p0,
                               ab.grip_proven[i]))  # fmt: skip

    def _screen(self, data: np.ndarray, gsig: np.ndarray) -> bool:
        """Whether the window of bins *data* passes the screen (``docs/physics.md`` §15.2)."""
        o = self.o
        return bool(resolvable(data[None], gsig[None], self.noise, o.screen_z,
                               o.screen_utilisation)[0])  # fmt: skip

    def estimate(self) -> dict | None:
        """The newest complete window (None until there is one).

        Returns
        -------
        dict or None
            The window row (keys as :func:`estimate_windows`' windows).
        """
        if len(self._bins) < (self._bins.maxlen or 1):
            return None
        t0 = np.array([b[0] for b in self._bins])
        t1 = np.array([b[1] for b in self._bins])
        data = np.array([b[3] for b in self._bins])
        gsig = np.array([b[4] for b in self._bins])
        proven = np.array([b[6] for b in self._bins])  # the bound's (docs/physics.md §14.1)
        z_w = float(norm.ppf(self.o.bound_level))
        lower = bin_bound(proven, gsig, z_w)
        row = {
            "axle": self.axle,
            "t_start": float(t0[0]),
            "t_end": float(t1[-1]),
            "n": int(sum(b[2] for b in self._bins)),
            "grip_used": float(np.max(proven)),
            "grip_used_lower": lower,
            "analysed": bool(self._screen(data, gsig)),
        }
        if row["analysed"]:
            n = np.array([b[2] for b in self._bins])
            mid, merged = merge_bins(t0, t1, n, data, self._pri, self.o)
            row.update(
                self._reuse.profile(
                    merged,
                    mid,
                    self._pri,
                    self._tyre,
                    self._bins[-1][5],
                    self.o,
                    lower,
                )
            )
        else:
            row.update(
                {
                    "mu": np.nan,
                    "mu_low": lower,
                    "mu_high": np.inf,
                    "observable": False,
                    "fit": "screened",
                }
            )
        return row
