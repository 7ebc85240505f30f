"""``gripsense ingest``: an NMEA log into the epoch table, with its line accounting."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.table import Table
from rich.text import Text

from gripsense.cli._common import console, fail, say
from gripsense.errors import GripsenseError
from gripsense.io import NmeaLog, read_nmea

__all__ = ["ingest", "print_ingest", "write_table"]


def print_ingest(log: NmeaLog) -> None:
    """Print the line accounting and a summary of an ingested log.

    Parameters
    ----------
    log : NmeaLog
        The ingested log.
    """
    rep = log.report
    table = Table(title=Text(f"Line accounting — {Path(rep.source).name}"))
    table.add_column("bucket")
    table.add_column("type / reason")
    table.add_column("lines", justify="right")
    for row in rep.to_frame().itertuples(index=False):
        if row.bucket == "rejected" and row.lines == 0:
            continue
        table.add_row(row.bucket, Text(str(row.kind)), str(row.lines))
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
        say(f"  line {r.line}: {r.reason} — {r.detail}")
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
        say(f"duration {dur:.2f} s{start}, median rate {rate:.1f} Hz")
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
            say(f"{col}: " + ", ".join(f"{k} {v}" for k, v in vc.items()))


def write_table(df, out: Path) -> None:
    """Write an epoch table to Parquet or CSV (chosen by the file suffix).

    Parameters
    ----------
    df : pandas.DataFrame
        The table.
    out : Path
        ``.parquet`` or ``.csv`` file.
    """
    suffix = out.suffix.lower()
    if suffix == ".parquet":
        df.to_parquet(out, index=False)
    elif suffix == ".csv":
        df.to_csv(out, index=False)
    else:
        raise GripsenseError(f"{out}: unknown output format {suffix!r}; use .parquet or .csv")


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
            say(f"wrote {len(nlog.epochs)} epochs to {output}")
    except GripsenseError as e:
        fail(e)
