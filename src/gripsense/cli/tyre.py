"""``gripsense tyre``: evaluate Magic Formula models and fit them to measurements."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from gripsense.cli._common import Columns, Overwrite, console, fail, say
from gripsense.cli._help import QuickGroup
from gripsense.cli._numbers import finite_numbers
from gripsense.errors import GripsenseError, InputError

if TYPE_CHECKING:
    import numpy as np

EVAL_COLUMNS = ["fz_N", "kappa", "gamma_deg", "alpha_deg", "fx_N", "fy_N"]
"""Columns of ``gripsense tyre eval -o``."""

tyre_app = typer.Typer(
    cls=QuickGroup,
    no_args_is_help=True,
    rich_markup_mode=None,
    help="Magic Formula tyre models: evaluate and fit.",
)


def parse_range(text: str, what: str) -> np.ndarray:
    """``"-12:12:0.5"`` (start:stop:step, stop included), ``"2000,4000"`` or ``"4000"``; every
    number finite.
    """
    import numpy as np

    finite_numbers(text, f"--{what}", sep=",:")  # nan, inf: one line naming the option
    try:
        if ":" in text:
            parts = [float(p) for p in text.split(":")]
            if len(parts) != 3 or parts[2] == 0:
                raise ValueError
            start, stop, step = parts
            n = int(np.floor((stop - start) / step + 1e-9)) + 1
            if n < 1 or n > 1_000_000:
                raise ValueError
            return start + step * np.arange(n)
        return np.array([float(p) for p in text.split(",")])
    except ValueError:
        raise InputError(
            f"--{what}: {text!r} is not a value, a list a,b,c or a range start:stop:step"
        ) from None


def resolve_model(model: Path) -> Path:
    """A tyre model file: the path given, else a bundled tyre of that name (the names
    ``gripsense simulate`` takes, e.g. ``PacejkaBook_Defaults.tir``).

    Parameters
    ----------
    model : Path
        Path or bundled file name.

    Returns
    -------
    Path
        The file.
    """
    if model.exists() or model.parent != Path("."):
        return model
    from gripsense.data import path as data_path

    bundled = data_path("tyres")
    if (bundled / model.name).is_file():
        return bundled / model.name
    names = sorted(p.name for p in bundled.iterdir() if p.suffix.lower() in (".tir", ".json"))
    raise InputError(
        f"{model}: no such file, nor a bundled tyre; bundled: {', '.join(names)} (or give a path)"
    )


def _clipped(tm, grids: dict[str, np.ndarray]) -> str | None:
    """One line saying which grid values lie outside the file's limits (clipped to them)."""
    import numpy as np

    units = {
        "fz": ("Fz", 1.0, " N", "{:.0f}"),
        "alpha": ("α", 180 / np.pi, "°", "{:.1f}"),
        "gamma": ("γ", 180 / np.pi, "°", "{:.1f}"),
        "kappa": ("κ", 1.0, "", "{:.2f}"),
    }
    parts, n_out = [], np.zeros(next(iter(grids.values())).shape, bool)
    for key, (lo, hi) in tm.limits.items():
        v = grids[key]
        out = (v < lo) | (v > hi)
        if out.any():
            sym, scale, unit, fmt = units[key]
            rng = "…".join(fmt.format(x * scale) if np.isfinite(x) else "∞" for x in (lo, hi))
            parts.append(f"{sym} {rng}{unit} ({int(np.unique(v[out]).size)} value(s) beyond)")
            n_out |= out
    if not parts:
        return None
    return (
        f"note: {n_out.sum()} of {n_out.size} points lie outside the file's limits "
        f"({'; '.join(parts)}) and are evaluated at the limit, as MFeval does; "
        "--no-limits evaluates the formula beyond them"
    )


@tyre_app.command("eval")
def tyre_eval(
    model: Annotated[
        Path,
        typer.Argument(
            help=".tir (MF 5.2/6.1/6.2), PAC89 .json or fit .json; or a bundled tyre's name "
            "(PacejkaBook_Defaults.tir …)"
        ),
    ],
    fz: Annotated[
        str, typer.Option("--fz", help="Load(s) [N]: 4000 or 2000,4000 or 2000:6000:1000")
    ],
    alpha_deg: Annotated[
        str, typer.Option("--alpha-deg", help="Slip angle(s) [deg], e.g. -12:12:0.5")
    ] = "0",
    gamma_deg: Annotated[str, typer.Option("--gamma-deg", help="Camber angle(s) [deg]")] = "0",
    kappa: Annotated[str, typer.Option("--kappa", help="Longitudinal slip ratio(s) [-]")] = "0",
    side: Annotated[
        str | None, typer.Option(help="Mounting side left/right (mirrors by TYRESIDE)")
    ] = None,
    output: Annotated[Path | None, typer.Option("-o", "--output", help="Write CSV here")] = None,
    plot: Annotated[
        Path | None, typer.Option(help="PNG of Fy (and Fx) against slip angle per load/camber")
    ] = None,
    limits: Annotated[
        bool,
        typer.Option(
            "--limits/--no-limits",
            help="Clip load, slip and camber to the .tir file's limits (FZMAX, ALPMIN/ALPMAX, "
            "CAMMIN/CAMMAX, KPUMIN/KPUMAX) as MFeval does, saying so when a value lies "
            "outside; --no-limits evaluates the formula beyond them",
        ),
    ] = True,
    lenient: Annotated[
        bool, typer.Option(help="Read unknown .tir keys with a warning (vendor files)")
    ] = False,
    overwrite: Overwrite = False,
) -> None:
    """Evaluate a tyre model on a grid of load, slip angle, camber and slip ratio (ISO-W, SI).

    The model's version is the file's (a .tir's FITTYP: 61 is MF 6.1). A value outside a
    .tir file's limits is clipped to them as MFeval does, with one line saying so.
    """
    from gripsense.config.tyre_files import load_tyre_model
    from gripsense.io.output_folder import check_output_file

    try:
        model = resolve_model(model)
        if output is not None:
            check_output_file(
                output, "tyre-eval", overwrite=overwrite, inputs=[model], header=EVAL_COLUMNS
            )
        if plot is not None:
            if plot.suffix.lower() != ".png":
                raise InputError(f"--plot {plot}: give a .png file name")
            check_output_file(plot, "tyre-eval", overwrite=overwrite, inputs=[model])
        tm = load_tyre_model(model, lenient=lenient)
        for w in tm.warnings:
            say(f"warning: {w}")
        desc = tm.description
        out = _eval_grid(tm, fz, kappa, gamma_deg, alpha_deg, side, limits)
    except (GripsenseError, ValueError) as e:
        fail(e)
    if plot is not None:
        _write_eval_plot(out, plot, desc + ("" if limits else ", no limits"))
    if output is not None:
        _write_eval_csv(out, output, desc)
        return
    if plot is not None:
        return
    _print_eval(out, desc)


def _eval_grid(tm, fz: str, kappa: str, gamma_deg: str, alpha_deg: str, side, limits: bool):
    """The model on the grid of the options (every combination), one row per point in the
    columns of :data:`EVAL_COLUMNS`; a line says which points lie outside the file's limits.
    """
    import numpy as np
    import pandas as pd

    grids = np.meshgrid(
        parse_range(fz, "fz"),
        parse_range(kappa, "kappa"),
        parse_range(gamma_deg, "gamma-deg"),
        parse_range(alpha_deg, "alpha-deg"),
        indexing="ij",
    )
    fzv, kv, gv, av = (x.ravel() for x in grids)
    kwargs: dict = {"side": side} if side else {}
    if tm.limits:
        kwargs["limits"] = limits
        note = _clipped(
            tm, {"fz": fzv, "kappa": kv, "gamma": np.deg2rad(gv), "alpha": np.deg2rad(av)}
        )
        if note and limits:
            say(note)
    fx, fy = tm.forces(fzv, kv, np.deg2rad(av), np.deg2rad(gv), **kwargs)
    return pd.DataFrame(
        {
            "fz_N": fzv,
            "kappa": kv,
            "gamma_deg": gv,
            "alpha_deg": av,
            "fx_N": np.broadcast_to(fx, fzv.shape),
            "fy_N": fy,
        }
    )


def _write_eval_plot(out, plot: Path, title: str) -> None:
    """``--plot``: Fy (and Fx) against slip angle per load and camber."""
    from gripsense.io.output_folder import write_file_atomic
    from gripsense.report.figures import save_png
    from gripsense.report.tyre_figures import eval_figure

    fig = eval_figure(out, title=title)
    try:
        write_file_atomic(plot, lambda tmp: save_png(fig, tmp, "tyre-eval", dpi=110))
    except GripsenseError as e:
        fail(e)
    say(f"wrote {plot}")


def _write_eval_csv(out, output: Path, desc: str) -> None:
    """``-o``: the points as CSV under a comment line naming the model."""
    from gripsense.io.output_folder import write_file_atomic

    def write(tmp):
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(f"# {desc}; written by gripsense tyre eval\n")
            out.to_csv(fh, index=False)

    try:
        write_file_atomic(output, write)
    except GripsenseError as e:
        fail(e)
    say(f"{desc}: {len(out)} points written to {output}")


def _print_eval(out, desc: str) -> None:
    """The points as a table (the first 200)."""
    from rich.table import Table
    from rich.text import Text

    table = Table(title=Text(desc))
    for c in out.columns:
        table.add_column(c, justify="right")
    for row in out.head(200).itertuples(index=False):
        table.add_row(*(f"{v:.6g}" for v in row))
    console.print(table)
    if len(out) > 200:
        console.print(f"({len(out) - 200} more rows; use -o FILE.csv)")


@tyre_app.command("fit")
def tyre_fit(
    data: Annotated[
        Path,
        typer.Argument(
            help="CSV/Parquet with alpha, gamma, fz, fy (or the friction run's wheels.parquet)"
        ),
    ],
    model: Annotated[
        str, typer.Option(help="pac94 (a0..a17 of Toyota CRDL R&D Review 1999) or mf61")
    ] = "pac94",
    constraints: Annotated[str, typer.Option(help="none, shape, symmetric, camber or all")] = "all",
    output: Annotated[
        Path | None, typer.Option("-o", "--output", help="fit.json, or fit.tir for mf61")
    ] = None,
    plot: Annotated[Path | None, typer.Option(help="PNG of measured vs identified curves")] = None,
    columns: Columns = None,
    variant: Annotated[str, typer.Option(help="PAC94 shifts: published or seed")] = "published",
    loss: Annotated[
        str | None,
        typer.Option(
            help="linear, soft_l1, huber or cauchy (default: soft_l1 for a wheels table — "
            "motion-derived forces have outliers —, linear for measured points)"
        ),
    ] = None,
    fnomin: Annotated[
        float | None, typer.Option(help="MF 6.1 nominal load [N] (default median)")
    ] = None,
    wheel: Annotated[
        str | None,
        typer.Option(
            help="Wheel or axle of a wheels table (front, rear, rear_left …; needed when it "
            "holds both axles)"
        ),
    ] = None,
    template: Annotated[
        Path | None,
        typer.Option(help="Existing .tir to take the other sections from (mf61 -o .tir)"),
    ] = None,
    compare: Annotated[
        bool, typer.Option(help="Also fit without constraints and show both")
    ] = False,
    max_iter: Annotated[
        int, typer.Option("--max-iter", help="Iterations of the solver at most", min=1)
    ] = 200,
    force: Annotated[
        bool,
        typer.Option(
            "--force",
            help="Write and plot a fit that did not converge (it is refused otherwise, exit 2)",
        ),
    ] = False,
    overwrite: Overwrite = False,
) -> None:
    """Fit Magic Formula lateral coefficients in one step (Toyota CRDL R&D Review 34(3),
    1999), with constraints.

    A fit that stops before converging (the iteration limit, a constraint it cannot meet) is
    not written: one line says why and how to go on (--max-iter, --force).
    """
    from gripsense.identify.tyre_fit import fit_tyre_table
    from gripsense.io.output_folder import check_output_file
    from gripsense.io.table import describe_columns
    from gripsense.io.tyres.tyre_table import read_tyre_table

    try:
        _check_fit_args(model, output, fnomin)
        ins = [data] + ([template] if template else [])
        for out in (output, plot):
            if out is not None:
                check_output_file(out, "tyre-fit", overwrite=overwrite, inputs=ins)
        table, info = read_tyre_table(data, columns)
        if "columns" in info:
            say(f"{data.name}: columns {describe_columns(info['columns'])}")
        kw = _fit_options(model, constraints, loss, info, max_iter, variant, fnomin)
        fit = fit_tyre_table(table, info, model=model, wheel=wheel, **kw)
        unconverged = _check_converged(fit, data, force, written=output or plot)
        _check_usable(fit, data)
        free_fit = None
        if compare:
            free_fit = fit_tyre_table(table, info, model=model, wheel=wheel,
                                      **{**kw, "constraints": "none"})  # fmt: skip
        if info["source"] == "wheels":
            info = {
                "rows": info["rows"],
                "rows_used": fit.extra["rows_used"],
                "rejected": fit.extra["rows_rejected"],
            }
        _write_fit_files(fit, free_fit, table, data, output, plot, template, wheel)
    except GripsenseError as e:
        fail(e)
    _print_fit(fit, info, data, free_fit)
    if unconverged:
        say(f"warning: {unconverged}; written anyway (--force)")
    if output is not None:
        say(f"wrote {output}")
    if plot is not None:
        say(f"wrote {plot}")


def _check_fit_args(model: str, output: Path | None, fnomin: float | None) -> None:
    """A known model, an output suffix a reader knows, a nominal load in range."""
    from gripsense.identify.tyre_fit import FITTERS

    if model not in FITTERS:
        raise InputError(f"--model {model!r}: use pac94 or mf61")
    if output is not None and output.suffix.lower() == ".tir" and model != "mf61":
        raise InputError("-o .tir needs --model mf61; PAC94 coefficients are written as .json")
    if output is not None and output.suffix.lower() not in (".json", ".tir"):
        raise InputError(  # tyre eval and a vehicle's tyre_file know a model by its suffix
            f"-o {output}: give a .json (or .tir with --model mf61) file name, the suffixes "
            "tyre eval and a vehicle's tyre_file read"
        )
    if fnomin is not None and not 100.0 <= fnomin <= 1e6:
        raise InputError(f"--fnomin {fnomin:g}: a nominal load is 100–1e6 N")


def _fit_options(
    model: str,
    constraints: str,
    loss: str | None,
    info: dict,
    max_iter: int,
    variant: str,
    fnomin: float | None,
) -> dict:
    """The fitter's options of the command line (the loss by default: soft_l1 for a wheels
    table, linear for measured points).
    """
    if loss is None:
        loss = "soft_l1" if info["source"] == "wheels" else "linear"
    kw = {"constraints": constraints, "loss": loss, "max_iter": max_iter}
    if model == "pac94":
        kw["variant"] = variant
    elif fnomin is not None:
        kw["fnomin"] = fnomin
    return kw


def _write_fit_files(fit, free_fit, table, data: Path, output, plot, template, wheel) -> None:
    """``-o``: the fit file (read back before it is installed); ``--plot``: measured points
    against the identified curves.
    """
    from gripsense.identify.tyre_fit.from_wheels import wheel_fit_points
    from gripsense.io.output_folder import write_file_atomic
    from gripsense.report.figures import save_png

    if output is not None:
        write_file_atomic(output, lambda tmp: _write_fit(fit, tmp, output, template))
    if plot is not None:
        from gripsense.report.tyre_figures import fit_figure

        # the points the fit used (a wheels table's other wheels and unsteady rows are
        # not: their loads lie outside the range the fit is valid for)
        pts = wheel_fit_points(table, wheel) if "alpha_rad" not in table.columns else table
        fig = fit_figure(
            fit,
            pts,
            title=data.name,
            extra_fits={"no constraints": free_fit} if free_fit else None,
        )
        write_file_atomic(plot, lambda tmp: save_png(fig, tmp, "tyre-fit", dpi=110))


def _write_fit(fit, tmp: Path, output: Path, template: Path | None) -> None:
    """Write the fit to *tmp* and read it back with the reader ``tyre eval`` and a vehicle's
    ``tyre_file`` use: a file that reader refuses is never installed.
    """
    from gripsense.config.tyre_files import TYRE_FILE_TYPES

    suffix = output.suffix.lower()
    if suffix == ".tir":
        fit.to_tir(tmp, template=template)
    else:
        fit.to_json(tmp)
    try:
        TYRE_FILE_TYPES[suffix](Path(tmp), False)
    except InputError as e:
        raise InputError(
            f"{output}: not written: the fit would not read back as a tyre model "
            f"({str(e).replace(str(tmp), output.name)})"
        ) from None


def _check_usable(fit, data: Path) -> None:
    """Refuse a fit that explains nothing (no coefficient determined, or a flat curve): it would
    otherwise be written and plotted as if it were a tyre.
    """
    import numpy as np

    determined = any(fit.determined.values())
    lo, hi = fit.ranges["alpha_rad"]
    fz = float(np.mean(fit.ranges["fz_N"]))
    curve = fit.predict(np.full(41, fz), np.linspace(lo, hi, 41))
    flat = not np.all(np.isfinite(curve)) or np.ptp(curve) < 0.02 * fz * max(hi - lo, 1e-6)
    if not determined or flat:
        raise InputError(
            f"{data.name}: the fit determines no tyre (rms residual {fit.residual_rms_N:.0f} N"
            f"{', flat curve' if flat else ''}, {fit.n} points); give data that spans slip "
            "angles on both sides, one axle of a wheels table (--wheel front|rear), or fewer "
            "free coefficients (--constraints all)"
        )


def _check_converged(fit, data: Path, force: bool, written) -> str | None:
    """Refuse a fit that did not converge (unless *force*): its coefficients are where the
    solver stopped, not a least-squares answer. Returns the reason when forced.
    """
    if fit.success:
        return None
    why = (
        f"{data.name}: the fit did not converge ({fit.message}; {fit.nfev} evaluations, rms "
        f"residual {fit.residual_rms_N:.0f} N)"
    )
    if force:
        return why
    raise InputError(
        f"{why}; {'not written' if written else 'its coefficients are not an answer'}: give "
        "more iterations (--max-iter 1000), fewer free coefficients (--constraints all), or "
        "--force to keep it anyway"
    )


def _print_fit(fit, info, data, free_fit) -> None:
    import numpy as np
    from rich.table import Table

    rej = ", ".join(f"{k} {v}" for k, v in info.get("rejected", {}).items()) or "none"
    say(
        f"{data.name}: {info.get('rows_used', fit.n)} of {info['rows']} rows used (rejected: {rej})"
    )
    console.print(
        f"{fit.model} fit, constraints {fit.constraints}: {fit.message}; "
        f"rms residual {fit.residual_rms_N:.1f} N, n = {fit.n}, {fit.nfev} evaluations"
    )
    lo, hi = fit.ranges["fz_N"]
    a_lo, a_hi = np.rad2deg(fit.ranges["alpha_rad"])
    g_lo, g_hi = np.rad2deg(fit.ranges["gamma_rad"])
    console.print(
        f"valid for Fz {lo:.0f}–{hi:.0f} N, α {a_lo:.1f}–{a_hi:.1f}°, γ {g_lo:.1f}–{g_hi:.1f}°"
    )
    t = Table()
    for c in ("coefficient", "value", "1σ", "determined"):
        t.add_column(c, justify="right")
    for k, v in fit.coefficients.items():
        se = fit.stderr[k]
        det = fit.determined[k]
        t.add_row(
            k,
            f"{v:.6g}",
            "" if not np.isfinite(se) else f"{se:.3g}",
            "yes" if det else "[yellow]no[/]",
        )
    console.print(t)
    checks = fit.physical_checks()
    console.print(
        "physical checks: " + ", ".join(f"{k} {'ok' if v else 'FAILED'}" for k, v in checks.items())
    )
    if free_fit is not None:
        fc = free_fit.physical_checks()
        console.print(
            f"without constraints: rms {free_fit.residual_rms_N:.1f} N; "
            + ", ".join(f"{k} {'ok' if v else 'FAILED'}" for k, v in fc.items())
            + ("" if free_fit.success else f" (did not converge: {free_fit.message})")
        )


def contact_quantities() -> dict:
    """Keys of a contact-length table (mass on the wheel, contact-patch length).

    Returns
    -------
    dict
        Key → :class:`~gripsense.io.table.Quantity`.
    """
    from gripsense.io.table import Quantity

    return {
        "mass": Quantity("mass", ("mass", "m", "wheel_mass")),
        "length": Quantity("length", ("length", "l", "contact_length")),
    }


def fit_contact(
    table: Annotated[
        Path, typer.Argument(help="CSV with mass_kg and length_m (or length_cm, length_mm)")
    ],
    columns: Columns = None,
) -> None:
    """Fit the contact-length model l = a·√m + b·m (2018 Kochi University of Technology thesis,
    eq. 6.23) to measurements.
    """
    import numpy as np

    from gripsense.identify import fit_contact_length
    from gripsense.io.table import describe_columns, map_table, read_table

    try:
        df = read_table(table)
        v, used = map_table(
            df,
            table,
            contact_quantities(),
            columns,
            required=("mass", "length"),
            example="mass=Mass:kg,length=Length:cm",
        )
        say(f"{table.name}: columns {describe_columns(used)}")
        params, stats = fit_contact_length(v["mass"], v["length"])
    except GripsenseError as e:
        fail(e)
    say(f"l = a·√m + b·m fitted to {stats['n']} rows of {table.name}:")
    console.print(f"  a = {params['a']:.6g} m/kg^0.5")
    console.print(f"  b = {params['b']:.6g} m/kg")
    console.print(
        f"  R² = {stats['r2']:.4f}, RMSE = {stats['rmse_m'] * 100:.3f} cm "
        f"(√(SSE/(n−2)) = {stats['rmse_dof_m'] * 100:.3f} cm)"
    )
    if np.isfinite(stats["m_peak_kg"]):
        console.print(f"  the model stops growing at m = {stats['m_peak_kg']:.0f} kg")
    console.print(
        f"  vehicle file: contact_length = {{ a = {params['a']:.6g}, b = {params['b']:.6g} }}"
    )
