"""Measurement logs with named channels (MDF4, CAN): mapped channels -> the epoch table.

Shared by :mod:`gripsense.io.logs.mdf` and :mod:`gripsense.io.logs.canlog`: the mapped channels
are put on the heading channel's time base (:func:`.channels.channels_to_epochs`), the time
made absolute (the file's start time, or ``--time-offset``) and every sample accounted
for.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from gripsense.errors import InputError
from gripsense.io.logs.channels import Channel, ChannelSpec, channels_to_epochs
from gripsense.io.logs.epoch_table import build_epochs
from gripsense.io.logs.nmea.accounting import IngestReport, RejectedLine
from gripsense.io.logs.nmea.reader import NmeaLog
from gripsense.io.logs.nmea.schema import MALFORMED, REASONS

__all__ = ["log_from_channels", "missing_channel"]


def log_from_channels(
    mapped: dict[str, ChannelSpec],
    found: dict[str, Channel],
    *,
    name: str,
    fmt: str,
    start_s: float | None,
    time_offset: float | None,
    strict: bool = False,
    ignored: dict[str, int] | None = None,
    rejected: dict[str, int] | None = None,
    first_rejects: list[RejectedLine] | None = None,
    notes: list[str] | None = None,
    unit: str = "samples",
) -> NmeaLog:
    """The epoch table and accounting of a log's mapped channels.

    Parameters
    ----------
    mapped : dict
        Key -> :class:`~gripsense.io.logs.channels.ChannelSpec` (``--columns``).
    found : dict
        Key -> decoded :class:`~gripsense.io.logs.channels.Channel`.
    name : str
        File, for messages.
    fmt : str
        Format name for the report.
    start_s : float or None
        Absolute time of the log's clock zero: seconds since 1970 UTC [s]; None when the file
        has none.
    time_offset : float or None
        ``--time-offset``: replaces *start_s* [s].
    strict : bool
        Raise at the first sample that is not a number.
    ignored, rejected : dict, optional
        Further accounting of the format (frames of unmapped messages, frames that did not
        decode).
    first_rejects : list of RejectedLine, optional
        The format's first rejects.
    notes : list of str, optional
        What else to say.
    unit : str
        What the accounting counts.

    Returns
    -------
    NmeaLog
    """
    rej = dict.fromkeys(REASONS, 0)
    for k, v in (rejected or {}).items():
        rej[k] = rej.get(k, 0) + v
    parsed: dict[str, int] = {}
    firsts = list(first_rejects or [])
    for key, ch in found.items():
        bad = ~(np.isfinite(ch.values) & np.isfinite(ch.t))
        nb = int(bad.sum())
        if nb:
            i = int(np.flatnonzero(bad)[0])
            detail = (
                f"channel {ch.name!r} ({key}): sample {i + 1} at t = {ch.t[i]} s is not a number"
            )
            if strict:
                raise InputError(f"{name}: {MALFORMED}: {detail} (strict mode)")
            rej[MALFORMED] += nb
            if len(firsts) < 20:
                firsts.append(RejectedLine(i + 1, MALFORMED, detail))
        parsed[f"{ch.name} ({key})"] = int(ch.values.size - nb)
    t, values = channels_to_epochs(mapped, found, name)
    offset = time_offset if time_offset is not None else start_s
    has_date = offset is not None
    seconds = t + (offset if offset is not None else 0.0)
    hsrc = "channel"
    ysrc = "channel" if "yaw_rate" in found else None
    epochs = build_epochs(values, seconds, has_date=has_date, heading_source=hsrc,
                          yaw_rate_source=ysrc)  # fmt: skip
    ign = dict(ignored or {})
    total = sum(parsed.values()) + sum(ign.values()) + sum(rej.values())
    report = IngestReport(
        source=name,
        total_lines=total,
        parsed=dict(sorted(parsed.items())),
        ignored=dict(sorted(ign.items())),
        rejected=rej,
        first_rejects=firsts[:20],
        n_epochs=len(epochs),
        epochs_without_time=0,
        has_date=has_date,
        notes=list(notes or []),
        format=fmt,
        unit=unit,
    )
    rows = {
        k: pd.DataFrame({"t_s": ch.t, "value": ch.values}, copy=False) for k, ch in found.items()
    }
    return NmeaLog(epochs=epochs, report=report, sentences=rows)


def missing_channel(name: str, spec: ChannelSpec, available: list[str]) -> InputError:
    """The error for a mapped channel the log does not have (names the close ones).

    Parameters
    ----------
    name : str
        File.
    spec : ChannelSpec
        The mapping.
    available : list of str
        The channels the log has.
    """
    import difflib

    close = difflib.get_close_matches(spec.channel, available, n=3, cutoff=0.5)
    hint = f" (did you mean {', '.join(close)}?)" if close else ""
    return InputError(
        f"{name}: no channel {spec.channel!r} for {spec.key} in --columns{hint}; the log has "
        f"{len(available)} channels: {', '.join(sorted(available)[:15])}"
        f"{' …' if len(available) > 15 else ''}"
    )
