"""``gripsense simulate`` and ``gripsense demo``: drives with known friction, and the demo job."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from gripsense.cli._common import Overwrite, command_line, console, fail, say
from gripsense.errors import GripsenseError
from gripsense.io.results import ResultWriter, check_output_folder

__all__ = ["demo", "simulate"]


def simulate(
    scenario: Annotated[Path, typer.Argument(help="scenario TOML (see gripsense.sim.scenario)")],
    outdir: Annotated[Path, typer.Option("-o", "--outdir", help="output folder")] = Path("sim-out"),
    overwrite: Overwrite = False,
) -> None:
    """Simulate drives with known friction and emulate the receiver (logs, truth, vehicle)."""
    from rich.progress import Progress

    from gripsense.sim.scenario import run_scenario

    try:
        with Progress(console=console, transient=True) as prog:
            task = prog.add_task("simulating", total=None)

            def tick(i, n, cid):
                prog.update(task, total=n, completed=i, description=f"simulating {cid}")

            cases = run_scenario(
                scenario, outdir, progress=tick, overwrite=overwrite, command=command_line()
            )
    except GripsenseError as e:
        fail(e)
    say(
        f"simulated {len(cases)} cases into {outdir}/ "
        f"(median {cases['realtime_factor'].median():.0f}× real time); index: "
        f"{outdir / 'cases.csv'}"
    )


def demo(
    outdir: Annotated[
        Path, typer.Option("-o", "--outdir", help="folder for the demo's output")
    ] = Path("demo-report"),
    overwrite: Annotated[
        bool,
        typer.Option(
            "--overwrite/--no-overwrite",
            help="replace an earlier demo output in OUTDIR (never other files)",
        ),
    ] = True,
) -> None:
    """Friction on the bundled simulated drives (dry μ 0.9, wet μ 0.5), estimate next to truth."""
    from rich.progress import Progress

    from gripsense.demo import demo_dir, run_demo

    folder = demo_dir()
    try:
        check_output_folder(outdir, "demo", overwrite=overwrite)
    except GripsenseError as e:
        fail(e)
    console.print(
        f"[bold]gripsense demo[/] — {folder.name}: thesis-2018-like circles "
        "(20–50 km/h × R 20–40 m) on a dry and a wet road, emulated V100-like compass"
    )
    with Progress(console=console, transient=True) as prog:
        task = prog.add_task("ingest → friction", total=None)

        def tick(i, n, cid):
            prog.update(task, total=n, completed=i, description=f"ingest → friction {cid}")

        df = run_demo(folder, progress=tick)
    from rich import box

    table = Table(
        title="Estimated vs true μ (rear wheels; n/o = not observable)",
        box=box.SIMPLE_HEAD,
        pad_edge=False,
    )
    for col in ("case", "v", "R", "true μ", "a_y/μg", "rear left", "rear right", "in"):
        table.add_column(col, no_wrap=True)
    for case, g in df.groupby("case", sort=False):
        cells = []
        marks = []
        for rec in g.to_dict("records"):
            if rec.get("observable"):
                cells.append(f"{rec['mu']:.2f} [{rec['mu_low']:.2f}–{rec['mu_high']:.2f}]")
                marks.append("✓" if rec["covered"] else "✗")
            else:
                cells.append(f"n/o  ≥ {rec['mu_lower_bound']:.2f}")
        first = g.iloc[0]
        v, r = first["name"].split()[1:3]
        table.add_row(
            case,
            v[2:-4],
            r[2:-1],
            f"{first['mu_true']:.1f}",
            f"{g['utilisation_true'].mean():.2f}",
            *cells,
            "".join(marks),
        )
    console.print(table)
    obs = df[df["observable"] == True]  # noqa: E712 - pandas element-wise
    n_cov = int(obs["covered"].sum())
    console.print(
        f"{len(obs)} of {len(df)} wheel-cases observable (n/o = not observable: only the "
        f"lower bound is reported); truth inside the 90 % interval in {n_cov} of {len(obs)}; "
        f"lower bound ≤ truth (+0.05) in {int(df['bound_holds'].sum())} of {len(df)}."
    )
    from gripsense.demo import write_demo_report

    try:
        with ResultWriter(outdir, "demo", overwrite=overwrite, command=command_line()) as tmp:
            df.to_csv(tmp / "demo_results.csv", index=False)
            write_demo_report(df, folder, tmp / "report.html")
    except GripsenseError as e:
        fail(e)
    say(f"wrote {outdir / 'demo_results.csv'}")
    say(f"report: {outdir / 'report.html'}")
