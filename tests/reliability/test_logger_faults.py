"""Model-free numbers robust to logger faults (docs/reliability.md, docs/physics.md §14): a
logger that writes every epoch twice, repeats sentences, or holds its last value at new time
stamps adds no measurement, so the measured grip and its bound stay those of the unique data —
never higher — and the copies are counted."""

from __future__ import annotations

import functools

import numpy as np
import pandas as pd
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gripsense import FrictionRun
from gripsense.estimate.noise import NoiseModel
from gripsense.io import read_nmea
from gripsense.sim.drives import limit_speed, simulate_drive, truth_vehicle, user_vehicle


@functools.cache
def _drive(mu: float, u: float):
    """A simulated circle near the limit: its NMEA lines and the vehicle as declared."""
    d = simulate_drive(
        "sedan", "mf-book", None, mu, seed=3, circle=(limit_speed(mu, 40.0, u), 40.0)
    )
    return tuple(d.lines), user_vehicle(truth_vehicle("sedan"), "mf-book")


def _blocks(lines) -> list[list[str]]:
    """The log's epochs as blocks of sentences (each starts with the heading sentence)."""
    out: list[list[str]] = []
    for line in lines:
        if line.startswith("$GPHDT") or not out:
            out.append([])
        out[-1].append(line)
    return out


def _bounds(lines, vehicle):
    run = FrictionRun(vehicle, method="axle-window", noise=NoiseModel.for_vehicle(vehicle, "v100"))
    log = read_nmea(list(lines))
    res = run.run(log.epochs)
    s = res.summary.set_index("axle")
    return s["grip_used"], s["grip_used_lower"], res.meta, log.report


@settings(max_examples=8, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])  # fmt: skip
@given(
    mu=st.sampled_from([0.5, 0.9]),
    u=st.sampled_from([0.8, 1.05]),
    epoch_share=st.floats(0.0, 1.0),
    sentence_share=st.floats(0.0, 1.0),
    copies=st.integers(1, 3),
    seed=st.integers(0, 10_000),
)
def test_duplicated_epochs_and_sentences_never_raise_the_bound(
    mu, u, epoch_share, sentence_share, copies, seed
):
    lines, vehicle = _drive(mu, u)
    grip0, bound0, _, _ = _bounds(lines, vehicle)
    rng = np.random.default_rng(seed)
    faulty = []
    for block in _blocks(lines):
        # some sentences written twice in a row, some epochs written again after themselves
        b = [x for line in block for x in [line] * (1 + copies * (rng.random() < sentence_share))]
        faulty += b * (1 + copies * (rng.random() < epoch_share))
    grip, bound, meta, report = _bounds(faulty, vehicle)
    assert (bound <= bound0 + 1e-9).all(), (bound.to_dict(), bound0.to_dict())
    assert (grip <= grip0 + 1e-9).all()
    extra = len(faulty) - len(lines)
    if extra:  # the copies are counted: in the log's notes or the run's
        said = meta.get("epochs_collapsed", "") + " ".join(report.notes)
        assert "each counted once" in said or "counts once" in said, (meta, report.notes)


def test_held_epochs_at_new_time_stamps_are_collapsed():
    """A logger resampling its 10 Hz input to 20 Hz by holding the last value: every second
    epoch repeats the one before at a new time stamp. The bound is the clean log's."""
    lines, vehicle = _drive(0.9, 1.05)
    run = FrictionRun(vehicle, method="axle-window", noise=NoiseModel.for_vehicle(vehicle, "v100"))
    ep = read_nmea(list(lines)).epochs
    clean = run.run(ep)
    held = ep.copy()
    held["t_s"] = held["t_s"] + 0.05
    if "time_utc" in held:
        held["time_utc"] = held["time_utc"] + pd.Timedelta(milliseconds=50)
    twice = pd.concat([ep, held]).sort_values("t_s", kind="stable").reset_index(drop=True)
    faulty = run.run(twice)
    a = clean.summary.set_index("axle")["grip_used_lower"]
    b = faulty.summary.set_index("axle")["grip_used_lower"]
    assert np.allclose(a, b, rtol=0, atol=1e-12), (a.to_dict(), b.to_dict())
    assert faulty.meta["epochs_held"] == len(ep)  # every copy
    assert "counts once" in faulty.meta["epochs_collapsed"]


def test_without_the_collapse_the_copies_would_raise_the_bound():
    """The test above can fail: the same copies, each given a time of its own and a heading
    nudged below the receiver's resolution so that nothing collapses, raise the bound (the
    noise averaged over twice the samples)."""
    lines, vehicle = _drive(0.9, 1.05)
    run = FrictionRun(vehicle, method="axle-window", noise=NoiseModel.for_vehicle(vehicle, "v100"))
    ep = read_nmea(list(lines)).epochs
    clean = run.run(ep).summary.set_index("axle")["grip_used_lower"]
    held = ep.copy()
    held["t_s"] = held["t_s"] + 0.05
    held["heading_deg"] = held["heading_deg"] + 1e-6
    twice = pd.concat([ep, held]).sort_values("t_s", kind="stable").reset_index(drop=True)
    raised = run.run(twice).summary.set_index("axle")["grip_used_lower"]
    assert (raised > clean + 0.002).any(), (clean.to_dict(), raised.to_dict())
