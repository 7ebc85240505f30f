"""The ``gripsense`` command line: a thin layer over the library."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console
from rich.table import Table

from gripsense.errors import GripsenseError
from gripsense.io import NmeaLog, read_nmea

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="gripsense: tyre-road friction, tyre and steering parameters from how a vehicle moves.",
)
console = Console()
err_console = Console(stderr=True, soft_wrap=True)


def _fail(err: Exception) -> None:
    err_console.print(f"[bold red]error:[/] {err}", markup=True, highlight=False)
    raise typer.Exit(2)


def print_ingest(log: NmeaLog) -> None:
    """Print the line accounting and a summary of an ingested log."""
    rep = log.report
    table = Table(title=f"Line accounting — {Path(rep.source).name}")
    table.add_column("bucket")
    table.add_column("type / reason")
    table.add_column("lines", justify="right")
    for row in rep.to_frame().itertuples(index=False):
        if row.bucket == "rejected" and row.lines == 0:
            continue
        table.add_row(row.bucket, row.kind, str(row.lines))
    table.add_row("[bold]total[/]", "", f"[bold]{rep.total_lines}[/]")
    console.print(table)
    ok = "[green]yes[/]" if rep.balanced else "[red]NO[/]"
    console.print(
        f"parsed {rep.n_parsed} + ignored {rep.n_ignored} + rejected {rep.n_rejected} "
        f"= {rep.total_lines} lines; balanced: {ok}"
    )
    if rep.junk_prefix_lines:
        console.print(
            f"{rep.junk_prefix_lines} sentences recovered after non-NMEA bytes on their line"
        )
    for r in rep.first_rejects[:5]:
        console.print(f"  line {r.line}: {r.reason} — {r.detail}")
    ep = log.epochs
    t = ep["t_s"].to_numpy()
    timed = t[~np.isnan(t)]
    console.print(f"\n[bold]{len(ep)} epochs[/] ({rep.epochs_without_time} without time)")
    if timed.size >= 2:
        dur = float(timed.max() - timed.min())
        dt = np.diff(np.sort(timed))
        dt = dt[dt > 0]
        rate = 1.0 / float(np.median(dt)) if dt.size else float("nan")
        first = ep["time_utc"].dropna()
        start = f", from {first.iloc[0]}" if len(first) else " (no date in log)"
        console.print(f"duration {dur:.2f} s{start}, median rate {rate:.1f} Hz")
    present = []
    for col in (
        "lat_deg",
        "speed_mps",
        "course_deg",
        "heading_deg",
        "pitch_deg",
        "rot_deg_per_min",
        "yaw_rate_rps",
    ):
        n = int(ep[col].notna().sum())
        if n:
            present.append(f"{col} {n}")
    console.print("present: " + (", ".join(present) if present else "nothing usable"))
    for col in ("heading_source", "yaw_rate_source"):
        vc = ep[col].value_counts()
        vc = vc[vc > 0]
        if len(vc):
            console.print(f"{col}: " + ", ".join(f"{k} {v}" for k, v in vc.items()))


def write_table(df, out: Path) -> None:
    """Write an epoch table to Parquet or CSV (chosen by the file suffix)."""
    suffix = out.suffix.lower()
    if suffix == ".parquet":
        df.to_parquet(out, index=False)
    elif suffix == ".csv":
        df.to_csv(out, index=False)
    else:
        raise GripsenseError(f"{out}: unknown output format {suffix!r}; use .parquet or .csv")


@app.command()
def ingest(
    log: Annotated[Path, typer.Argument(help="NMEA log (plain or .gz)")],
    output: Annotated[
        Path | None, typer.Option("-o", "--output", help="write epochs to .parquet or .csv")
    ] = None,
    strict: Annotated[
        bool, typer.Option("--strict", help="stop at the first rejected line")
    ] = False,
) -> None:
    """Read an NMEA log into the epoch table and print its line accounting."""
    try:
        nlog = read_nmea(log, strict=strict)
        print_ingest(nlog)
        if output is not None:
            write_table(nlog.epochs, output)
            console.print(f"wrote {len(nlog.epochs)} epochs to {output}")
    except GripsenseError as e:
        _fail(e)


@app.command()
def demo(
    outdir: Annotated[
        Path, typer.Option("-o", "--outdir", help="folder for the demo's output")
    ] = Path("demo-report"),
) -> None:
    """Run gripsense on the bundled sample data, show what it finds and write it to OUTDIR."""
    import json

    from gripsense.data import sample_path

    path = sample_path("rst39.log")
    console.print(f"[bold]gripsense demo[/] — ingest of a bundled real log: {path.name}")
    nlog = read_nmea(path)
    print_ingest(nlog)
    outdir.mkdir(parents=True, exist_ok=True)
    write_table(nlog.epochs, outdir / "epochs.csv")
    (outdir / "ingest.json").write_text(json.dumps(nlog.report.to_dict(), indent=2) + "\n")
    console.print(f"\nwrote {outdir / 'epochs.csv'} and {outdir / 'ingest.json'}")
    cols = [
        "t_s",
        "lat_deg",
        "lon_deg",
        "speed_mps",
        "course_deg",
        "heading_deg",
        "heading_source",
        "yaw_rate_rps",
        "yaw_rate_source",
    ]
    console.print(nlog.epochs[cols].head(12).to_string(index=False), soft_wrap=True)


def main() -> None:
    """Console-script entry point."""
    app()


if __name__ == "__main__":
    main()
