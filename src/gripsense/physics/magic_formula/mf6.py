"""Magic Formula 5.2 / 6.1 / 6.2 steady-state forces from ``.tir`` parameters (ISO-W axes, SI).

Equations: Pacejka, *Tire and Vehicle Dynamics*, 3rd ed. (2012), §4.3.2 eqs. (4.E1)–(4.E67), as
implemented by MFeval 4.0 (Furlan Tassara; validated there against TNO MF-Tyre). What is covered:

* pure slip Fx0 (4.E9–E18) and Fy0 (4.E19–E30), with load, camber and inflation-pressure effects;
* combined slip Fx = Gxα Fx0 (4.E50–E57) and Fy = Gyκ Fy0 + SVyκ (4.E58–E67);
* MFeval's "use mode 1x1": limit checks (inputs clipped to the file's FZMAX, ALPMIN/MAX, CAMMIN/MAX,
  KPUMIN/MAX, PRESMIN/MAX; E ≤ 1), low-speed reductions below VXLOW, no α* (tan α) substitution,
  no turn slip;
* MF 5.2-family files (FITTYP 5, 6, 21 and PAC2002 files without FITTYP): the MF-Tyre 5.2 camber
  terms (SHy with PHY3, SVy camber part, Kyγ0 from PHY3); missing 6.1-only coefficients are 0,
  missing PKY4 is 2 (the 5.2 form sin(2 atan ...)), and LKYC takes LGAY when absent.

* the aligning moment (:meth:`MFTyre.aligning_moment`): pure slip Mz0 (4.E31–E47, with MFeval's
  paper forms A58/A60 for Bt and Dt) and combined slip Mz = −t Fy' + Mzr + s Fx (4.E71–E76,
  A54–A56; the MF 5.2 form −t (Fy − SVyκ) for 5.2-family files), the pneumatic trail t and the
  residual moment Mzr as MFeval 4.0 returns them.

Not covered: Mx, My, loaded radius, relaxation lengths, turn slip, transient modes,
the ``FE_METHOD`` friction-ellipse option of some MF-Tyre 5.0 files.

Sign convention: ISO-W (x forward, y left, z up; positive α gives Fy < 0 for PKY1 < 0).
``side`` mirrors a tyre measured on one side for use on the other (TYRESIDE):
Fy(α, γ) → −Fy(−α, −γ), Fx(κ, α, γ) → Fx(κ, −α, −γ).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gripsense.errors import InputError

__all__ = ["MFForces", "MFMoment", "MFTyre"]

_EPS = 1e-6  # MFeval / Pacejka (4.E6a) singularity guard

_MANDATORY_LATERAL = ("PCY1", "PDY1", "PKY1", "PKY2")
_MANDATORY_LONGITUDINAL = ("PCX1", "PDX1", "PKX1")
_MANDATORY = ("FNOMIN", "UNLOADED_RADIUS")
_SCALING = (
    "LFZO",
    "LCX",
    "LMUX",
    "LEX",
    "LKX",
    "LHX",
    "LVX",
    "LCY",
    "LMUY",
    "LEY",
    "LKY",
    "LKYC",
    "LHY",
    "LVY",
    "LXAL",
    "LYKA",
    "LVYKA",
    "LTR",
    "LRES",
    "LS",
    "LKZC",
)


def _sign(x: np.ndarray) -> np.ndarray:
    """sign() with sign(0) = +1, as MFeval uses to avoid 0/0."""
    return np.where(x < 0, -1.0, 1.0)


@dataclass(frozen=True)
class MFForces:
    """Forces of :meth:`MFTyre.forces` (arrays broadcast to the inputs' shape; SI, ISO-W).

    Attributes
    ----------
    fx : numpy.ndarray
        Combined-slip longitudinal force [N].
    fy : numpy.ndarray
        Combined-slip lateral force [N].
    fx0 : numpy.ndarray
        Pure-slip longitudinal force [N].
    fy0 : numpy.ndarray
        Pure-slip lateral force [N].
    mux : numpy.ndarray
        Longitudinal peak friction coefficient [-].
    muy : numpy.ndarray
        Lateral peak friction coefficient [-] (signed, as PDY1).
    kxk : numpy.ndarray
        Longitudinal slip stiffness [N].
    kya : numpy.ndarray
        Cornering stiffness [N/rad].
    """

    fx: np.ndarray  #: combined-slip longitudinal force [N]
    fy: np.ndarray  #: combined-slip lateral force [N]
    fx0: np.ndarray  #: pure-slip longitudinal force [N]
    fy0: np.ndarray  #: pure-slip lateral force [N]
    mux: np.ndarray  #: longitudinal peak friction coefficient [-]
    muy: np.ndarray  #: lateral peak friction coefficient [-] (signed, as PDY1)
    kxk: np.ndarray  #: longitudinal slip stiffness [N]
    kya: np.ndarray  #: cornering stiffness [N/rad]


@dataclass(frozen=True)
class MFMoment:
    """Aligning moment of :meth:`MFTyre.aligning_moment` (arrays; SI, ISO-W).

    Attributes
    ----------
    mz : numpy.ndarray
        Combined-slip aligning moment [N m].
    trail : numpy.ndarray
        Pneumatic trail t [m] (the lever of the lateral force, 4.E73).
    mzr : numpy.ndarray
        Residual moment Mzr [N m] (4.E75).
    fy : numpy.ndarray
        Combined-slip lateral force at the same point [N].
    """

    mz: np.ndarray  #: combined-slip aligning moment [N m]
    trail: np.ndarray  #: pneumatic trail [m]
    mzr: np.ndarray  #: residual moment [N m]
    fy: np.ndarray  #: combined-slip lateral force [N]


@dataclass(frozen=True)
class _Inputs:
    """Inputs after MFeval's limit checks (use mode 1xx) and the quantities derived from them."""

    fz: np.ndarray
    fz_low: np.ndarray  # Fz clipped below at FZMIN (used by the moments)
    kappa: np.ndarray
    alpha: np.ndarray
    gamma: np.ndarray
    vx: np.ndarray
    dfz: np.ndarray
    dpi: np.ndarray
    low: np.ndarray
    smooth: np.ndarray
    mirror: bool


@dataclass(frozen=True)
class MFTyre:
    """A Magic Formula 5.2/6.1/6.2 tyre.

    Parameters
    ----------
    params : dict
        ``{KEY: value}`` in SI (as from :meth:`gripsense.io.tyres.tir.TirFile.parameters`; build
        one from a file with :func:`gripsense.config.tyre_files.load_mf_tyre`).
    name : str
        Used in messages.
    """

    params: dict[str, Any]  # as read (TYRESIDE is a word); SI floats after __post_init__
    name: str = "<tyre>"
    version: str = field(init=False)
    _side: str = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        p = {k.upper(): v for k, v in self.params.items()}
        missing = [k for k in _MANDATORY if not isinstance(p.get(k), (int, float))]
        if missing:
            raise InputError(
                f"{self.name}: missing mandatory key {missing[0]} "
                "([VERTICAL] FNOMIN, [DIMENSION] UNLOADED_RADIUS); add it to the file"
            )
        fittyp = p.get("FITTYP")
        fmt = str(p.get("PROPERTY_FILE_FORMAT") or "").upper()
        if fittyp in (61, 62):
            version = "6.1" if fittyp == 61 else "6.2"
        elif fittyp in (5, 6, 21) or (fittyp is None and fmt in ("PAC2002", "MF_05", "MF_52")):
            version = "5.2"
        else:
            raise InputError(
                f"{self.name}: FITTYP = {fittyp!r} (PROPERTY_FILE_FORMAT {fmt!r}) is not "
                "a Magic Formula 5.2/6.1/6.2 file; set [MODEL] FITTYP to 6, 61 or 62"
            )
        q: dict[str, float] = {}
        for k, v in p.items():
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                q[k] = float(v)
        for k in _SCALING:
            q.setdefault(k, 1.0)
        if version == "5.2":
            q.setdefault("PKY4", 2.0)
            if "LKYC" not in p and "LGAY" in q:
                q["LKYC"] = q["LGAY"]
        q.setdefault("NOMPRES", 220000.0)  # MFeval readTIR default; no effect without PP* terms
        q.setdefault("INFLPRES", q["NOMPRES"])
        object.__setattr__(self, "params", q)
        object.__setattr__(self, "version", version)
        object.__setattr__(self, "_side", str(p.get("TYRESIDE") or "").upper())

    def _p(self, key: str) -> float:
        return self.params.get(key, 0.0)

    def _require(self, keys: tuple[str, ...]) -> None:
        for k in keys:
            if k not in self.params:
                raise InputError(
                    f"{self.name}: missing mandatory key {k}; the force cannot be "
                    "evaluated without it"
                )

    # ------------------------------------------------------------------ public
    def forces(
        self,
        fz,
        kappa=0.0,
        alpha=0.0,
        gamma=0.0,
        *,
        vx=None,
        pressure=None,
        combined: bool = True,
        limits: bool = True,
        side: str | None = None,
    ) -> MFForces:
        """Steady-state tyre forces.

        Parameters
        ----------
        fz : array_like
            Vertical load [N] (negative is set to 0).
        kappa : array_like
            Longitudinal slip ratio [-].
        alpha : array_like
            Slip angle [rad], ISO-W.
        gamma : array_like
            Inclination (camber) angle [rad], ISO-W.
        vx : array_like, optional
            Forward speed of the wheel centre [m/s]; default the file's LONGVL.
        pressure : array_like, optional
            Inflation pressure [Pa]; default the file's INFLPRES (else NOMPRES).
        combined : bool
            Combined-slip reduction (True) or pure-slip forces only.
        limits : bool
            Apply the file's validity limits and the low-speed model (MFeval use mode 1xx).
        side : {"left", "right"}, optional
            Side the tyre is mounted on; mirrors when it differs from the file's TYRESIDE.

        Returns
        -------
        MFForces
        """
        q = self._prepare(fz, kappa, alpha, gamma, vx, pressure, limits, side)
        r, _ = self._solve(q, limits, combined)
        fy, fy0 = (-r.fy, -r.fy0) if q.mirror else (r.fy, r.fy0)
        return dataclasses.replace(r, fy=fy, fy0=fy0)

    def _solve(self, q: _Inputs, limits: bool, combined: bool = True) -> tuple[MFForces, tuple]:
        """The forces at prepared inputs, in the file's own side (not mirrored), and the pure
        lateral force's shifts and factors (S_Hy, S_Vy, B_y, C_y) the aligning moment needs.
        """
        self._require(_MANDATORY_LATERAL + _MANDATORY_LONGITUDINAL)
        fz, kappa, alpha, gamma, vx = q.fz, q.kappa, q.alpha, q.gamma, q.vx
        dfz, dpi, low, smooth = q.dfz, q.dpi, q.low, q.smooth
        fx0, mux, kxk = self._fx0(fz, kappa, gamma, vx, dfz, dpi, low, smooth, limits)
        fy0, muy, kya, shifts = self._fy0(fz, alpha, gamma, dfz, dpi, low, smooth, limits)
        if combined:
            fx = self._gxa(kappa, alpha, gamma, dfz, limits) * fx0
            gyk, svyk = self._gyk(fz, kappa, alpha, gamma, dfz, muy, low, smooth, limits)
            fy = gyk * fy0 + svyk
        else:
            fx, fy = fx0, fy0
        forces = MFForces(fx=fx, fy=fy, fx0=fx0, fy0=fy0, mux=mux, muy=muy, kxk=kxk, kya=kya)
        return forces, shifts

    def _prepare(self, fz, kappa, alpha, gamma, vx, pressure, limits, side) -> _Inputs:
        """Broadcast the inputs and apply the file's limits and the low-speed model (MFeval
        ``parseInputs``/``calculateBasic`` for use mode 1xx).
        """
        p = self._p
        vx = p("LONGVL") if vx is None else vx
        pr = p("INFLPRES") if pressure is None else pressure
        fz, kappa, alpha, gamma, vx, pr = np.broadcast_arrays(
            *(np.asarray(v, dtype=float) for v in (fz, kappa, alpha, gamma, vx, pr))
        )
        mirror = self._mirror(side)
        if mirror:
            alpha, gamma = -alpha, -gamma
        fz = np.maximum(fz, 0.0)
        alpha = alpha.copy()
        kappa = kappa.copy()
        gamma = gamma.copy()
        pr = pr.copy()
        low = np.zeros(fz.shape, bool)
        smooth = np.ones(fz.shape)
        fz_low = fz
        if limits:
            vxlow = p("VXLOW")
            low = np.abs(vx) <= vxlow
            if np.any(low):
                smooth = np.where(low, 1 - 0.5 * (1 + np.cos(np.pi * vx / vxlow)), 1.0)
                kappa = np.where(low, kappa * np.abs(vx / vxlow), kappa)
            vsy = np.tan(alpha) * vx
            ssum = np.abs(vx) + np.abs(vsy)
            alpha = np.where(ssum < vxlow, alpha * ssum / vxlow, alpha)
            alpha = np.clip(alpha, *self._range("ALPMIN", "ALPMAX"))
            gamma = np.clip(gamma, *self._range("CAMMIN", "CAMMAX"))
            if "FZMAX" in self.params:
                fz = np.minimum(fz, p("FZMAX"))
            fz_low = np.where(fz > 0, np.maximum(fz, self.params.get("FZMIN", 0.0)), 0.0)
            pr = np.clip(pr, *self._range("PRESMIN", "PRESMAX"))
            kappa = np.clip(kappa, *self._range("KPUMIN", "KPUMAX"))
        fz0p = p("LFZO") * p("FNOMIN")
        dfz = (fz - fz0p) / fz0p
        dpi = (pr - p("NOMPRES")) / p("NOMPRES")
        return _Inputs(fz, fz_low, kappa, alpha, gamma, vx, dfz, dpi, low, smooth, mirror)

    def aligning_moment(
        self,
        fz,
        kappa=0.0,
        alpha=0.0,
        gamma=0.0,
        *,
        vx=None,
        pressure=None,
        limits: bool = True,
        side: str | None = None,
    ) -> MFMoment:
        """Steady-state aligning moment, pneumatic trail and residual moment.

        Pacejka (2012) (4.E31)–(4.E47) and (4.E71)–(4.E76) as MFeval 4.0 evaluates them: Bt, Dt
        from the MF-Tyre paper's (A58), (A60); α_t,eq and α_r,eq from (A54), (A55); s from (A56);
        t scaled by LFZO; Fy' = Gyκ(γ = 0) Fy0(γ = 0) (4.E74); MF 5.2 files use
        Mz = −t (Fy − SVyκ) + Mzr + s Fx. No turn slip.

        Parameters as :meth:`MFTyre.forces` (always combined slip).

        Returns
        -------
        MFMoment
        """
        p = self._p
        q = self._prepare(fz, kappa, alpha, gamma, vx, pressure, limits, side)
        r, (shy, svy, by, cy) = self._solve(q, limits)
        fx, fy, kxk, kya = r.fx, r.fy, r.kxk, r.kya
        fz, kappa, alpha, gamma, vx = q.fz, q.kappa, q.alpha, q.gamma, q.vx
        dfz, dpi, low, smooth = q.dfz, q.dpi, q.low, q.smooth
        # at γ = 0 (4.E32, 4.E74); Gyκ keeps γ as MFeval 4.0 does (its note: closer to TNO)
        zero = np.zeros_like(gamma)
        fy0_0, muy_0, _, _ = self._fy0(fz, alpha, zero, dfz, dpi, low, smooth, limits)
        gyk_0, svyk_0 = self._gyk(fz, kappa, alpha, gamma, dfz, muy_0, low, smooth, limits)

        r0 = p("UNLOADED_RADIUS")
        fz0p = p("LFZO") * p("FNOMIN")
        fzl = q.fz_low
        lmuy = p("LMUY")
        cos_ap = vx / (np.hypot(vx, np.tan(alpha) * np.abs(vx)) + _EPS)  # cos α' (4.E6)
        sht = p("QHZ1") + p("QHZ2") * dfz + (p("QHZ3") + p("QHZ4") * dfz) * gamma  # (4.E35)
        kya_p = kya + _EPS * _sign(kya)  # (4.E39)
        alphar = alpha + shy + svy / kya_p  # (4.E37, 4.E38)
        alphat = alpha + sht  # (4.E34)
        dt = (
            (p("QDZ1") + p("QDZ2") * dfz)
            * (1 - p("PPZ1") * dpi)
            * (1 + p("QDZ3") * gamma + p("QDZ4") * gamma**2)
            * fzl
            * (r0 / fz0p)
            * p("LTR")
        )  # (A60)
        bt = (
            (p("QBZ1") + p("QBZ2") * dfz + p("QBZ3") * dfz**2)
            * (1 + p("QBZ4") * gamma + p("QBZ5") * np.abs(gamma))
            * p("LKY")
            / lmuy
        )  # (A58)
        ct = p("QCZ1")  # (4.E41)
        et = (p("QEZ1") + p("QEZ2") * dfz + p("QEZ3") * dfz**2) * (
            1 + (p("QEZ4") + p("QEZ5") * gamma) * (2 / np.pi) * np.arctan(bt * ct * alphat)
        )  # (4.E44)
        if limits:
            et = np.minimum(et, 1.0)
        dr = (
            fzl
            * r0
            * (
                (p("QDZ6") + p("QDZ7") * dfz) * p("LRES")
                + (
                    (p("QDZ8") + p("QDZ9") * dfz) * (1 + p("PPZ2") * dpi)
                    + (p("QDZ10") + p("QDZ11") * dfz) * np.abs(gamma)
                )
                * gamma
                * p("LKZC")
            )
            * lmuy
            * np.sign(vx)
            * np.cos(alpha)
        )  # (4.E47)
        br = p("QBZ9") * p("LKY") / lmuy + p("QBZ10") * by * cy  # (4.E45)
        ratio = (kxk / kya_p) ** 2 * kappa**2
        # (A54), (A55), with MATLAB's sign(0) = 0
        alphar_eq = np.arctan(np.sqrt(np.tan(alphar) ** 2 + ratio)) * np.sign(alphar)
        alphat_eq = np.arctan(np.sqrt(np.tan(alphat) ** 2 + ratio)) * np.sign(alphat)
        s = (
            r0
            * (p("SSZ1") + p("SSZ2") * (fy / p("FNOMIN")) + (p("SSZ3") + p("SSZ4") * dfz) * gamma)
            * p("LS")
        )  # (A56)
        mzr = dr * np.cos(np.arctan(br * alphar_eq))  # (4.E75), Cr = 1 without turn slip
        x = bt * alphat_eq
        t = dt * np.cos(ct * np.arctan(x - et * (x - np.arctan(x)))) * cos_ap  # (4.E73)
        t = t * p("LFZO")
        if np.any(low):
            t = np.where(low, t * smooth, t)
            mzr = np.where(low, mzr * smooth, mzr)
        if self.version == "5.2":
            mz = -t * (fy - svyk_0) + mzr + s * fx
        else:
            mz = -t * (gyk_0 * fy0_0) + mzr + s * fx  # (4.E71, 4.E72)
        if q.mirror:
            mz, mzr, fy = -mz, -mzr, -fy
        return MFMoment(mz=mz, trail=t, mzr=mzr, fy=fy)

    # ------------------------------------------------------------------ pieces
    def _mirror(self, side: str | None) -> bool:
        if side is None:
            return False
        s = side.strip().upper()
        if s not in ("LEFT", "RIGHT"):
            raise ValueError(f"side must be 'left' or 'right', not {side!r}")
        return self._side in ("LEFT", "RIGHT") and s != self._side

    def _range(self, lo: str, hi: str) -> tuple[float, float]:
        return self.params.get(lo, -np.inf), self.params.get(hi, np.inf)

    def _fx0(self, fz, kappa, gamma, vx, dfz, dpi, low, smooth, limits):
        """Pure longitudinal force, Pacejka (2012) (4.E9)–(4.E18)."""
        p = self._p
        cx = p("PCX1") * p("LCX")
        mux = (
            (p("PDX1") + p("PDX2") * dfz)
            * (1 + p("PPX3") * dpi + p("PPX4") * dpi**2)
            * (1 - p("PDX3") * gamma**2)
            * p("LMUX")
        )
        mux = np.where(fz == 0, 0.0, mux)
        dx = mux * fz
        kxk = (
            fz
            * (p("PKX1") + p("PKX2") * dfz)
            * np.exp(p("PKX3") * dfz)
            * (1 + p("PPX1") * dpi + p("PPX2") * dpi**2)
            * p("LKX")
        )
        bx = kxk / (cx * dx + _EPS * _sign(dx))
        shx = (p("PHX1") + p("PHX2") * dfz) * p("LHX")
        svx = fz * (p("PVX1") + p("PVX2") * dfz) * p("LVX") * p("LMUX")
        shx = np.where(low, shx * smooth, shx)
        svx = np.where(low, svx * smooth, svx)
        kx = kappa + shx
        ex = (
            (p("PEX1") + p("PEX2") * dfz + p("PEX3") * dfz**2)
            * (1 - p("PEX4") * np.sign(kx))
            * p("LEX")
        )
        if limits:
            ex = np.minimum(ex, 1.0)
        fx0 = dx * np.sin(cx * np.arctan(bx * kx - ex * (bx * kx - np.arctan(bx * kx)))) + svx
        fx0 = np.where(vx < 0, -fx0, fx0)
        return fx0, mux, kxk

    def _fy0(self, fz, alpha, gamma, dfz, dpi, low, smooth, limits):
        """Pure lateral force, Pacejka (2012) (4.E19)–(4.E30); MF 5.2 camber terms per TNO."""
        p = self._p
        fz0p = p("LFZO") * p("FNOMIN")
        kya = (
            p("PKY1")
            * fz0p
            * (1 + p("PPY1") * dpi)
            * (1 - p("PKY3") * np.abs(gamma))
            * np.sin(
                p("PKY4")
                * np.arctan(
                    (fz / fz0p) / ((p("PKY2") + p("PKY5") * gamma**2) * (1 + p("PPY2") * dpi))
                )
            )
            * p("LKY")
        )
        svyg = fz * (p("PVY3") + p("PVY4") * dfz) * gamma * p("LKYC") * p("LMUY")
        if self.version == "5.2":
            shy = (p("PHY1") + p("PHY2") * dfz) * p("LHY") + p("PHY3") * gamma * p("LKYC")
        else:
            kyg0 = fz * (p("PKY6") + p("PKY7") * dfz) * (1 + p("PPY5") * dpi) * p("LKYC")
            shy = (p("PHY1") + p("PHY2") * dfz) * p("LHY") + (kyg0 * gamma - svyg) / (
                kya + _EPS * _sign(kya)
            )
        svy = fz * (p("PVY1") + p("PVY2") * dfz) * p("LVY") * p("LMUY") + svyg
        svy = np.where(low, svy * smooth, svy)
        shy = np.where(low, shy * smooth, shy)
        ay = alpha + shy
        cy = p("PCY1") * p("LCY")
        muy = (
            (p("PDY1") + p("PDY2") * dfz)
            * (1 + p("PPY3") * dpi + p("PPY4") * dpi**2)
            * (1 - p("PDY3") * gamma**2)
            * p("LMUY")
        )
        dy = muy * fz
        ey = (
            (p("PEY1") + p("PEY2") * dfz)
            * (1 + p("PEY5") * gamma**2 - (p("PEY3") + p("PEY4") * gamma) * _sign(ay))
            * p("LEY")
        )
        if limits:
            ey = np.minimum(ey, 1.0)
        by = kya / (cy * dy + _EPS * _sign(dy))
        fy0 = dy * np.sin(cy * np.arctan(by * ay - ey * (by * ay - np.arctan(by * ay)))) + svy
        muy = np.where(fz == 0, 0.0, muy)
        return fy0, muy, kya, (shy, svy, by, cy)

    def _gxa(self, kappa, alpha, gamma, dfz, limits):
        """Combined-slip weighting of Fx, Pacejka (2012) (4.E51)–(4.E57)."""
        p = self._p
        cxa = p("RCX1")
        exa = p("REX1") + p("REX2") * dfz
        if limits:
            exa = np.minimum(exa, 1.0)
        shxa = p("RHX1")
        bxa = (p("RBX1") + p("RBX3") * gamma**2) * np.cos(np.arctan(p("RBX2") * kappa)) * p("LXAL")
        a_s = alpha + shxa
        g0 = np.cos(cxa * np.arctan(bxa * shxa - exa * (bxa * shxa - np.arctan(bxa * shxa))))
        return np.cos(cxa * np.arctan(bxa * a_s - exa * (bxa * a_s - np.arctan(bxa * a_s)))) / g0

    def _gyk(self, fz, kappa, alpha, gamma, dfz, muy, low, smooth, limits):
        """Combined-slip Fy weighting and κ-induced side force, Pacejka (2012) (4.E58)–(4.E67)."""
        p = self._p
        dvyk = (
            muy
            * fz
            * (p("RVY1") + p("RVY2") * dfz + p("RVY3") * gamma)
            * np.cos(np.arctan(p("RVY4") * alpha))
        )
        svyk = dvyk * np.sin(p("RVY5") * np.arctan(p("RVY6") * kappa)) * p("LVYKA")
        shyk = p("RHY1") + p("RHY2") * dfz
        eyk = p("REY1") + p("REY2") * dfz
        if limits:
            eyk = np.minimum(eyk, 1.0)
        cyk = p("RCY1")
        byk = (
            (p("RBY1") + p("RBY4") * gamma**2)
            * np.cos(np.arctan(p("RBY2") * (alpha - p("RBY3"))))
            * p("LYKA")
        )
        ks = kappa + shyk
        g0 = np.cos(cyk * np.arctan(byk * shyk - eyk * (byk * shyk - np.arctan(byk * shyk))))
        gyk = np.cos(cyk * np.arctan(byk * ks - eyk * (byk * ks - np.arctan(byk * ks)))) / g0
        svyk = np.where(low, svyk * smooth, svyk)
        return gyk, svyk
