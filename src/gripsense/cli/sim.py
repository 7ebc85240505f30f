"""``gripsense simulate`` and ``gripsense demo``: drives with known friction, and the demo job."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from gripsense.cli._common import Overwrite, command_line, console, fail, say
from gripsense.errors import GripsenseError

__all__ = ["demo", "simulate"]


def simulate(
    scenario: Annotated[Path, typer.Argument(help="scenario TOML (see gripsense.sim.scenario)")],
    outdir: Annotated[Path, typer.Option("-o", "--outdir", help="output folder")] = Path("sim-out"),
    overwrite: Overwrite = False,
    receiver: Annotated[
        str | None,
        typer.Option(
            "--receiver",
            help="receiver of every case: v100 | white-0.3 | rtk | none | FILE.toml (a "
            "[receiver] table, as gripsense friction takes it; default: the scenario's)",
        ),
    ] = None,
    fmt: Annotated[
        str,
        typer.Option(
            "--format",
            help="format of the emulated logs: nmea | vbo (VBOX) | ubx (u-blox UBX with the "
            "NMEA sentences) | mf4 (MDF4) | rosbag2 (a ROS 2 bag folder, MCAP); vbo and mf4 carry "
            "the steering channel inside",
        ),
    ] = "nmea",
) -> None:
    """Simulate drives with known friction and emulate the receiver (logs, truth, vehicle)."""
    from rich.progress import Progress
    from rich.text import Text

    from gripsense.sim.scenario import run_scenario

    try:
        with Progress(console=console, transient=True) as prog:
            task = prog.add_task("simulating", total=None)

            def tick(i, n, cid):
                prog.update(task, total=n, completed=i, description=f"simulating {cid}")

            cases = run_scenario(
                scenario,
                outdir,
                progress=tick,
                overwrite=overwrite,
                command=command_line(),
                receiver=receiver,
                fmt=fmt,
                warn=lambda msg: prog.console.print(Text(f"warning: {msg}"), soft_wrap=True),
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
    """Friction on the bundled simulated drives (brush and Magic Formula tyres, two receivers,
    dry μ 0.9 and wet μ 0.5): what the data prove and what is estimated, next to the truth.
    """
    from rich.markup import escape
    from rich.progress import Progress
    from rich.table import Table

    from gripsense.demo import (
        DEMO_METHOD,
        demo_description,
        demo_dir,
        demo_estimate_text,
        demo_verdict,
        run_demo,
    )
    from gripsense.io.output_folder import ResultWriter, check_output_folder

    folder = demo_dir()
    try:
        check_output_folder(outdir, "demo", overwrite=overwrite)
    except GripsenseError as e:
        fail(e)
    console.print(
        f"[bold]gripsense demo[/] — {folder.name}: {escape(demo_description(folder))}; "
        f"method {DEMO_METHOD}"
    )
    with Progress(console=console, transient=True) as prog:
        task = prog.add_task("ingest → friction", total=None)

        def tick(i, n, cid):
            prog.update(task, total=n, completed=i, description=f"ingest → friction {cid}")

        df = run_demo(folder, progress=tick)
    from rich import box

    table = Table(
        title="Per axle: measured grip and estimated μ next to the truth (R 20 m)",
        box=box.SIMPLE_HEAD,
        pad_edge=False,
        padding=(0, 1),
        collapse_padding=True,
    )
    for col in (
        "case",
        "tyre",
        "rx",
        "km/h",
        "axle",
        "μ true",
        "μ ≥",
        "share",
        "estimate [90%]",
        "",
    ):
        table.add_column(col, no_wrap=True, min_width=len(col) if col != "estimate [90%]" else 17)
    for rec in df.to_dict("records"):
        v = rec["name"].split()[1]
        est = demo_estimate_text(rec)  # as the report's table says it
        mark = ("✓" if rec["covered"] else "✗") if rec["observable"] else ""
        table.add_row(
            rec["case"].removeprefix("case"),
            "MF" if rec["tyre"] != "brush" else "brush",
            rec["receiver"],
            v[2:-4],
            rec["axle"],
            f"{rec['mu_true']:.2f}",
            f"{rec['grip_used_lower']:.2f}" + ("" if rec["bound_holds"] else " ✗"),
            f"{rec['grip_used_lower'] / rec['mu_true']:.2f}",
            est,
            mark,
        )
    console.print(table)
    console.print(
        "μ ≥: the friction the axle used in its best 1 s, measured from the log less its "
        "uncertainty — the data prove μ ≥ this (model-free, level road assumed), so μ ≥ ≤ μ "
        "true on every row (✗ where not); share: μ ≥ ÷ μ true, a lower bound of how near its "
        "limit the axle went; estimate: μ under a tyre model whose shape is uncertain, given "
        "only where the data carry it (—: no value; ≤: the estimate's upper end)."
    )
    console.print(f"[bold]verdict:[/] {demo_verdict(df)}.")
    from gripsense.demo import write_demo_report

    try:
        with ResultWriter(outdir, "demo", overwrite=overwrite, command=command_line()) as tmp:
            df.to_csv(tmp / "demo_results.csv", index=False)
            write_demo_report(df, folder, tmp / "report.html")
    except GripsenseError as e:
        fail(e)
    say(f"wrote {outdir / 'demo_results.csv'}")
    say(f"report: {outdir / 'report.html'}")
