"""The ``.tir`` an MF 6.1 lateral fit is written as: a template's other sections kept, or a
minimal file that gripsense and MFeval can read.
"""

from __future__ import annotations

from pathlib import Path

from gripsense.errors import InputError
from gripsense.io.tyres.tir import TirFile, read_tir, write_tir

__all__ = ["fit_to_tir"]


def fit_to_tir(fit, path: str | Path, template: str | Path | None = None) -> Path:
    """Write *fit* (an MF 6.1 :class:`~gripsense.identify.tyre_fit.TyreFit`) as a ``.tir``.

    Parameters
    ----------
    fit : TyreFit
        An MF 6.1 lateral fit.
    path : str or Path
        Output file.
    template : str or Path, optional
        Existing ``.tir`` whose other sections are kept.

    Returns
    -------
    Path
        The file written.
    """
    if fit.model != "mf61":
        raise InputError(
            "to_tir: only MF 6.1 fits can be written as .tir; write PAC94 coefficients with to_json"
        )
    if template is not None:
        tir = read_tir(template)
        for k, v in fit.coefficients.items():
            tir.set(k, float(v), section="LATERAL_COEFFICIENTS")
        tir.set("FNOMIN", float(fit.extra["FNOMIN"]), section="VERTICAL")
        tir.prepend_comment("lateral coefficients identified by gripsense tyre-fit")
    else:
        fz_lo, fz_hi = fit.ranges["fz_N"]
        a_lo, a_hi = fit.ranges["alpha_rad"]
        g_lo, g_hi = fit.ranges["gamma_rad"]
        tir = TirFile.from_sections(
            {
                "MDI_HEADER": {"FILE_TYPE": "tir", "FILE_VERSION": 3.0, "FILE_FORMAT": "ASCII"},
                "UNITS": {
                    "LENGTH": "meter",
                    "FORCE": "newton",
                    "ANGLE": "radians",
                    "MASS": "kg",
                    "TIME": "second",
                },
                "MODEL": {"FITTYP": 61, "TYRESIDE": "LEFT", "LONGVL": 16.7, "VXLOW": 1.0},
                "DIMENSION": {"UNLOADED_RADIUS": float(fit.extra.get("UNLOADED_RADIUS", 0.3))},
                "OPERATING_CONDITIONS": {"INFLPRES": 220000.0, "NOMPRES": 220000.0},
                "VERTICAL": {"FNOMIN": float(fit.extra["FNOMIN"])},
                "VERTICAL_FORCE_RANGE": {"FZMIN": float(fz_lo), "FZMAX": float(fz_hi)},
                "SLIP_ANGLE_RANGE": {"ALPMIN": float(a_lo), "ALPMAX": float(a_hi)},
                "INCLINATION_ANGLE_RANGE": {"CAMMIN": float(g_lo), "CAMMAX": float(g_hi)},
                "SCALING_COEFFICIENTS": {
                    "LFZO": 1.0,
                    "LCY": 1.0,
                    "LMUY": 1.0,
                    "LEY": 1.0,
                    "LKY": 1.0,
                    "LKYC": 1.0,
                    "LHY": 1.0,
                    "LVY": 1.0,
                },
                "LONGITUDINAL_COEFFICIENTS": {"PCX1": 1.65, "PDX1": 1.0, "PKX1": 20.0},
                "LATERAL_COEFFICIENTS": {k: float(v) for k, v in fit.coefficients.items()},
            },
            header=[
                "Magic Formula 6.1 pure lateral coefficients identified by gripsense",
                f"constraints: {fit.constraints}; n = {fit.n}; "
                f"rms residual {fit.residual_rms_N:.1f} N",
                "longitudinal coefficients are placeholders (not identified)",
            ],
        )
    return write_tir(tir, path)
