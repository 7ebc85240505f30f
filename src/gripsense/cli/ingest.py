"""``gripsense ingest``: a log of any supported format into the epoch table, with its accounting."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from gripsense.cli._common import (
    LOG_COLUMNS_HELP,
    Dbc,
    Overwrite,
    TimeOffset,
    console,
    fail,
    log_options,
    say,
)
from gripsense.errors import GripsenseError

if TYPE_CHECKING:
    from gripsense.io import NmeaLog

__all__ = ["MAX_BYTES", "MAX_LINES", "check_table_output", "ingest", "print_ingest", "write_table"]

# the defaults of --max-lines and --max-bytes: gripsense.io.text's (a test keeps them equal),
# written here so that the help of the command line imports no reader (pandas, numba)
MAX_BYTES = 1 << 30
"""Default of ``--max-bytes``: :data:`gripsense.io.text.MAX_BYTES` [bytes]."""
MAX_LINES = 5_000_000
"""Default of ``--max-lines``: :data:`gripsense.io.text.MAX_LINES` [lines]."""


def print_ingest(log: NmeaLog) -> None:
    """Print the line accounting and a summary of an ingested log.

    Parameters
    ----------
    log : NmeaLog
        The ingested log.
    """
    import numpy as np
    from rich.table import Table
    from rich.text import Text

    from gripsense.io.logs.nmea.align import align_channels

    rep = log.report
    unit = rep.unit
    title = f"Accounting ({rep.format}, {unit}) — {Path(rep.source).name}"
    table = Table(title=Text(title))
    table.add_column("bucket")
    table.add_column("type / reason")
    table.add_column(unit, justify="right")
    for row in rep.to_frame().itertuples(index=False):
        if row.bucket == "rejected" and row.lines == 0:
            continue
        table.add_row(row.bucket, Text(str(row.kind)), str(row.lines))
    table.add_row("[bold]total[/]", "", f"[bold]{rep.total_lines}[/]")
    console.print(table)
    ok = "[green]yes[/]" if rep.balanced else "[red]NO[/]"
    console.print(
        f"parsed {rep.n_parsed} + ignored {rep.n_ignored} + rejected {rep.n_rejected} "
        f"= {rep.total_lines} {unit}; balanced: {ok}"
    )
    if rep.junk_prefix_lines:
        console.print(
            f"{rep.junk_prefix_lines} sentences recovered after non-NMEA bytes on their line"
        )
    for note in rep.notes:
        say(f"note: {note}")
    for r in rep.first_rejects[:5]:
        say(f"  {r.line}: {r.reason} — {r.detail}")
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
    if rep.channels:
        say("channels: " + ", ".join(f"{k} {v:g} Hz" for k, v in rep.channels.items()))
    if len(ep):
        say(align_channels(ep)[1].describe())


def _write_parquet(df, path: Path, kind: str) -> None:
    from gripsense.io.output_folder import write_parquet

    write_parquet(df, path, kind)


TABLE_WRITERS = {
    ".parquet": _write_parquet,
    ".csv": lambda df, p, kind: df.to_csv(p, index=False),
}
"""Output suffix → writer of a table."""


def check_table_output(out: Path, kind: str, columns: list[str], *, overwrite: bool, inputs=()):
    """Check a table output path before the work (suffix, existing file, inputs).

    Parameters
    ----------
    out : Path
        ``.parquet`` or ``.csv`` file.
    kind : str
        Output kind (:func:`gripsense.io.output_folder.is_own_file`).
    columns : list of str
        Columns of the table (how a CSV of this kind is recognised).
    overwrite : bool
        Replace an earlier output of this kind.
    inputs : iterable of Path
        The command's inputs (never written).
    """
    from gripsense.io.output_folder import check_output_file

    if out.suffix.lower() not in TABLE_WRITERS:
        raise GripsenseError(f"{out}: unknown output format {out.suffix!r}; use .parquet or .csv")
    check_output_file(out, kind, overwrite=overwrite, inputs=list(inputs), header=columns)


def write_table(df, out: Path, kind: str = "epochs") -> None:
    """Write a table to Parquet or CSV (chosen by the file suffix), atomically.

    Parameters
    ----------
    df : pandas.DataFrame
        The table.
    out : Path
        ``.parquet`` or ``.csv`` file.
    kind : str
        Output kind recorded in a Parquet file's metadata.
    """
    from gripsense.io.output_folder import write_file_atomic

    writer = TABLE_WRITERS.get(out.suffix.lower())
    if writer is None:
        raise GripsenseError(f"{out}: unknown output format {out.suffix!r}; use .parquet or .csv")
    write_file_atomic(out, lambda tmp: writer(df, tmp, kind))


def ingest(
    log: Annotated[
        Path,
        typer.Argument(
            help="log: NMEA, VBOX .vbo, UBX, NovAtel ASCII, MDF4, CAN BLF/ASC or a ROS bag "
            "(.bag, .db3, .mcap or its folder) (plain or .gz); a pipe, or - "
            "for standard input"
        ),
    ],
    output: Annotated[
        Path | None, typer.Option("-o", "--output", help="write epochs to .parquet or .csv")
    ] = None,
    strict: Annotated[
        bool, typer.Option("--strict", help="stop at the first rejected line")
    ] = False,
    max_lines: Annotated[
        int, typer.Option(help="read at most this many lines; the rest are counted (memory)")
    ] = MAX_LINES,
    max_bytes: Annotated[
        int,
        typer.Option(help="read at most this many bytes (decompressed); beyond: as --max-lines"),
    ] = MAX_BYTES,
    columns: Annotated[str | None, typer.Option("--columns", help=LOG_COLUMNS_HELP)] = None,
    dbc: Dbc = None,
    time_offset: TimeOffset = None,
    overwrite: Overwrite = False,
) -> None:
    """Read a log (format recognised from its content) into the epoch table and print its
    accounting: every line, frame or sample used, ignored or rejected with the reason.
    """
    from gripsense.io.logs import read_log
    from gripsense.io.logs.nmea.epochs import EPOCH_COLUMNS

    try:
        if output is not None:
            check_table_output(output, "epochs", EPOCH_COLUMNS, overwrite=overwrite, inputs=[log])
        opts = log_options(
            columns, dbc, time_offset, strict=strict, max_lines=max_lines, max_bytes=max_bytes
        )
        nlog = read_log(log, opts)
        print_ingest(nlog)
        if output is not None:
            write_table(nlog.epochs, output)
            say(f"wrote {len(nlog.epochs)} epochs to {output}")
    except GripsenseError as e:
        fail(e)
