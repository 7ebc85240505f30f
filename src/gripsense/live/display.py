"""Live display (rich): μ per wheel or axle, interval, surface, bound, data-quality counters."""

from __future__ import annotations

import time

import numpy as np
from rich.console import Group
from rich.live import Live
from rich.table import Table
from rich.text import Text

__all__ = ["LiveDisplay"]


class LiveDisplay:
    """Context manager; call the instance with (summary, stats, ingest, source) to refresh."""

    def __init__(self, console=None, refresh_per_second: float = 4.0):
        self._live = Live(
            Text("waiting for data…"),
            console=console,
            refresh_per_second=refresh_per_second,
            transient=False,
        )

    def __enter__(self):
        self._live.__enter__()
        return self

    def __exit__(self, *exc):
        out = self._live.__exit__(*exc)
        if not self._live.console.is_terminal:  # a log file: the last frame's line ends too
            self._live.console.line()
        return out

    def __call__(self, summary, stats, ingest, source) -> None:
        """Show the latest summary, counters and source state."""
        self._live.update(render(summary, stats, ingest, source))


def render(summary, stats, ingest, source):
    """The display as a rich renderable (also used for a final print)."""
    rep = ingest.report
    el = max(time.monotonic() - stats.started, 1e-9)
    stale = stats.last_data is None or time.monotonic() - stats.last_data > 2.0
    rejected = sum(rep.rejected.values())
    head = Text.assemble(
        (f"{source.status}  ", "bold"),
        ("STALE  " if stale else "", "bold red"),
        f"{rep.total_lines} {rep.unit} ({rep.total_lines / el:.0f}/s), {stats.epochs} epochs, "
        f"{rejected} rejected, {len(stats.gaps)} gaps",
    )
    t = Table(expand=False)
    for c in (
        "unit",
        "μ estimate",
        "90 % interval",
        "surface",
        "slippery?",
        "measured: data prove μ ≥",
        "n valid",
    ):
        t.add_column(c, justify="right")
    if summary is None or len(summary) == 0:
        t.add_row("–", "no steady cornering yet", "", "", "", "", "")
    else:
        for r in summary.to_dict("records"):
            mu = r.get("mu", np.nan)
            if np.isfinite(mu):
                cells = (
                    f"{mu:.2f}",
                    Text(f"[{r.get('mu_low', np.nan):.2f}, {r.get('mu_high', np.nan):.2f}]"),
                    str(r.get("surface", "")),
                )
            else:
                cells = ("no value", "", str(r.get("surface", "undetermined")))
            lb = r.get("grip_used_lower", np.nan)
            t.add_row(
                str(r.get("unit")),
                *cells,
                str(r.get("slippery", "unknown")),
                f"{lb:.2f}" if np.isfinite(lb) else "",
                str(r.get("n_valid", "")),
            )
    parts = [head, t]
    if getattr(stats, "front_axle", ""):  # the front axle never disappears without a word
        parts.append(Text(stats.front_axle))
    return Group(*parts)
