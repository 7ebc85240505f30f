"""A fleet cell combines every pass's statement and obeys a drive's rule (``docs/fleet.md``).

Rows are written as the fleet's workers write them — each window's statement a deviance curve
made by the profile's own encoder (:func:`~gripsense.estimate.profile.deviance_curve`) — and the
aggregation (DuckDB and the combination) is the code under test. The reference for a combined
range is the brute-force product of the statements' likelihoods, its range read with the
profile's own scalar crossing (``profile._crossing``), not the vectorised reader under test."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gripsense.constants import CHI2_1_90
from gripsense.estimate.evidence import curve_grid
from gripsense.estimate.profile import DEVIANCE_STEP, _crossing, deviance_curve
from gripsense.fleet.aggregate import (
    STATUS_CONTRADICTION,
    STATUS_ESTIMATE,
    STATUS_INCONSISTENT,
    STATUS_MEASURED,
    STATUS_RANGE,
    aggregate_cells,
    cells_geojson,
)
from gripsense.fleet.tasks import ROW_COLUMNS

CELL = "8b2e6d9434b0fff"
GRID = curve_grid()


def statement(centre: float, width: float, *, lower: bool = True, upper: bool = True) -> bytes:
    """A window's curve: a profile-like deviance in log μ (90 % range ≈ centre·exp(±width)),
    one side flattened where the window does not state it — as the profile encodes it."""
    dev = (np.log(GRID / centre) / (width / np.sqrt(CHI2_1_90))) ** 2
    best = int(np.argmin(np.abs(np.log(GRID / centre))))
    dev = dev - dev[best]
    return deviance_curve(np.maximum(dev, 0.0), best, lower_trusted=lower, upper_trusted=upper)


def _rows(vehicle, log, curves, bounds, *, hour=10, mu=None, sigma=None, tyres=None):
    n = len(bounds)
    t = pd.Timestamp(f"2026-01-05T{hour:02d}:00:00Z") + pd.to_timedelta(np.arange(n), unit="s")
    mu = np.full(n, np.nan) if mu is None else np.asarray(mu, float)
    sigma = np.full(n, np.nan) if sigma is None else np.asarray(sigma, float)
    return pd.DataFrame(
        {
            "vehicle": vehicle,
            "log": log,
            "time_utc": t,
            "t_s": np.arange(n, dtype=float),
            "lat_deg": 33.62,
            "lon_deg": 133.72,
            "cell": CELL,
            "unit": "rear",
            "observable": np.isfinite(mu),
            "mu": mu,
            "mu_sigma": sigma,
            "mu_low": mu - 1.645 * sigma,
            "mu_high": mu + 1.645 * sigma,
            "grip_used": np.asarray(bounds, float) + 0.02,
            "grip_used_lower": np.asarray(bounds, float),
            "mu_deviance": list(curves),
            "receiver": "white-0.3",
            "calibration": "",
            "tyres": tyres or f"own tyres of {vehicle}",
        }
    )[ROW_COLUMNS]


def _write(folder, parts):
    for i, df in enumerate(parts):
        d = folder / "epochs" / f"vehicle={df['vehicle'].iloc[0]}"
        d.mkdir(parents=True, exist_ok=True)
        df.drop(columns="vehicle").to_parquet(d / f"log{i}.parquet", index=False)


def _cell(folder, parts):
    _write(folder, parts)
    c = aggregate_cells(folder)
    assert len(c) == 1
    return c.iloc[0]


def brute_force(statements: list[tuple[str, bytes]], bound: float) -> tuple[float, float]:
    """The combined 90 % range by brute force: per μ of the grid, the sum over vehicles of the
    largest deviance of that vehicle's statements; read with the profile's scalar crossing."""
    total = np.zeros(GRID.size)
    for v in {v for v, _ in statements}:
        mine = [np.frombuffer(c, np.uint8) * DEVIANCE_STEP for w, c in statements if w == v]
        total += np.max(mine, axis=0)
    dev = total - total.min()
    return max(_crossing(GRID, dev, CHI2_1_90, -1), bound), _crossing(GRID, dev, CHI2_1_90, +1)


def robust_upper(statements: list[tuple[str, bytes]]) -> float:
    """The combined upper end with, at each μ, the one statement that adds most left out, by
    brute force."""
    total = np.zeros(GRID.size)
    gap = np.zeros(GRID.size)
    for v in {v for v, _ in statements}:
        mine = np.sort([np.frombuffer(c, np.uint8) * DEVIANCE_STEP for w, c in statements
                        if w == v], axis=0)  # fmt: skip
        total += mine[-1]
        gap = np.maximum(gap, mine[-1] - (mine[-2] if len(mine) > 1 else 0.0))
    dev = total - gap
    dev = dev - dev.min()
    return _crossing(GRID, dev, CHI2_1_90, +1)


def test_one_window_alone_never_calls_a_road_slippery(tmp_path):
    """A dry bend: four cars say nothing above their measured grip, one window of a fifth (a
    turn-in) states μ ≤ 0.44. The range says what the statements say, but the call "slippery"
    needs a second statement: with any one window left out nothing bounds μ below 0.5."""
    parts = [_rows(v, f"{v}.nmea", [statement(1.0, 0.3, lower=False, upper=False)], [0.40])
             for v in "abcd"]  # fmt: skip
    parts.append(_rows("e", "e.nmea", [statement(0.42, 0.04, lower=False)], [0.41]))
    c = _cell(tmp_path, parts)
    assert c["status"] == STATUS_RANGE and c["mu_high"] < 0.5
    assert c["slippery"] == "unknown"
    # a second window — of the same pass, another pass of the car, or another car — confirms it
    one = statement(0.42, 0.04, lower=False)
    seconds = {
        "same pass": [*parts[:-1], _rows("e", "e.nmea", [one, one], [0.41, 0.41])],
        "same car": [*parts, _rows("e", "e2.nmea", [one], [0.41])],
        "another car": [*parts, _rows("f", "f.nmea", [one], [0.41])],
    }
    for k, (name, more) in enumerate(seconds.items()):
        c = _cell(tmp_path / str(k), more)
        assert c["slippery"] == "slippery", name


def test_two_vehicles_one_sided_statements_bound_a_cell(tmp_path):
    """One car proves μ ≥ 0.70 on the bend (no model statement); another's slip bounds it
    ≤ 0.85 (an upper end only): the cell is μ in [0.70, 0.85], not slippery, with no value."""
    a = _rows("a", "a.nmea", [None], [0.70])
    b = _rows("b", "b.nmea", [statement(0.6, 0.3, lower=False)], [0.40])
    c = _cell(tmp_path, [a, b])
    expect = brute_force([("b", statement(0.6, 0.3, lower=False))], 0.70)
    assert c["status"] == STATUS_RANGE and np.isnan(c["mu"])
    assert c["mu_low"] == pytest.approx(0.70) and c["mu_high"] == pytest.approx(expect[1])
    assert 0.70 < c["mu_high"] < 0.85
    assert c["slippery"] == "not slippery" and c["surface"] == "DRY"
    assert (c["n_vehicles"], c["n_passes"], c["n_statements"]) == (2, 2, 1)
    listed = json.loads(c["passes"])["listed"]
    assert [p["vehicle"] for p in listed] == ["a", "b"]
    assert listed[0]["mu_high"] is None  # a's statement: its measured grip only


def test_a_contradiction_is_flagged_never_averaged(tmp_path):
    """Two vehicles whose 90 % ranges do not meet ([0.27, 0.33] and [0.55, 0.67]): no μ
    satisfies both — the cell is flagged without a range; the measured grip stays."""
    a = _rows("a", "a.nmea", [statement(0.3, 0.1)], [0.2])
    b = _rows("b", "b.nmea", [statement(0.6, 0.1)], [0.25])
    c = _cell(tmp_path, [a, b])
    assert c["status"] == STATUS_CONTRADICTION
    assert np.isnan(c["mu"]) and np.isnan(c["mu_low"]) and np.isnan(c["mu_high"])
    assert c["grip_used_lower"] == pytest.approx(0.25)
    assert c["slippery"] == "unknown" and c["surface"] == "undetermined"


def test_an_estimate_below_the_measured_grip_is_flagged(tmp_path):
    """A pass's range [0.46, 0.50] while another pass proves 0.739: inconsistent, never a plain
    value; what the data prove still answers "is it slippery?"."""
    a = _rows("a", "one.nmea", [statement(0.48, 0.04), statement(0.48, 0.04)], [0.40, 0.41])
    b = _rows("b", "two.nmea", [None], [0.739])
    c = _cell(tmp_path, [a, b])
    assert c["status"] == STATUS_INCONSISTENT
    assert c["surface"] == "undetermined" and np.isnan(c["mu"])
    assert c["slippery"] == "not slippery"  # what the data prove: μ ≥ 0.739
    props = cells_geojson(aggregate_cells(tmp_path))["features"][0]["properties"]
    assert props["status"] == STATUS_INCONSISTENT


def test_passes_of_one_vehicle_are_not_multiplied(tmp_path_factory):
    """Ten passes of one car with the same statement say what one says (its nuisances are
    shared: never narrower than one long drive with the same windows); the same statement
    from two cars (independent) says more."""
    s = statement(0.5, 0.12)
    one = _cell(tmp_path_factory.mktemp("one"), [_rows("a", "p0.nmea", [s], [0.3])])
    ten = _cell(
        tmp_path_factory.mktemp("ten"), [_rows("a", f"p{i}.nmea", [s], [0.3]) for i in range(10)]
    )
    two = _cell(
        tmp_path_factory.mktemp("two"), [_rows(v, f"{v}.nmea", [s], [0.3]) for v in ("a", "b")]
    )
    assert (ten["mu_low"], ten["mu_high"], ten["mu"]) == (one["mu_low"], one["mu_high"], one["mu"])
    assert ten["n_passes"] == 10 and one["status"] == STATUS_ESTIMATE
    assert two["mu_high"] - two["mu_low"] < 0.8 * (one["mu_high"] - one["mu_low"])
    assert two["mu_low"] <= 0.5 <= two["mu_high"]


def test_cars_on_one_declared_tyre_are_not_multiplied(tmp_path_factory):
    """Two cars described by one vehicle file without a calibration of their own share its
    declared tyre (stiffness and shape priors): their statements combine as one car's."""
    s = statement(0.5, 0.12)
    one = _cell(tmp_path_factory.mktemp("one"), [_rows("a", "a.nmea", [s], [0.3])])
    shared = _cell(
        tmp_path_factory.mktemp("shared"),
        [_rows(v, f"{v}.nmea", [s], [0.3], tyres="car.toml digest") for v in ("a", "b")],
    )
    assert (shared["mu_low"], shared["mu_high"]) == (one["mu_low"], one["mu_high"])
    assert shared["n_vehicles"] == 2


def test_buckets_combine_their_own_passes(tmp_path):
    """A dry hour and an icy hour in the same cell: two cells, each with its own statement."""
    dry = _rows("a", "dry.nmea", [None], [0.8], hour=7)
    ice = [_rows(v, f"ice-{v}.nmea", [statement(0.15, 0.05)], [0.1], hour=15) for v in "bc"]
    _write(tmp_path, [dry, *ice])
    c = aggregate_cells(tmp_path).sort_values("bucket")
    assert list(c["slippery"]) == ["not slippery", "slippery"]
    assert list(c["status"]) == [STATUS_MEASURED, STATUS_ESTIMATE]


def test_per_sample_passes_state_their_mean_with_the_pass_sigma(tmp_path):
    """Rows without curves (a per-sample method): the pass states its inverse-variance mean
    with its median σ (its samples share their errors); vehicles then combine as any."""
    a = _rows("a", "a.nmea", [None] * 3, [0.3] * 3, mu=[0.48, 0.5, 0.52], sigma=[0.02] * 3)
    c = _cell(tmp_path, [a])
    assert c["status"] == STATUS_ESTIMATE and c["n_statements"] == 1
    half = 0.02 * np.sqrt(CHI2_1_90)
    assert c["mu_low"] == pytest.approx(0.5 - half, abs=0.01)
    assert c["mu_high"] == pytest.approx(0.5 + half, abs=0.01)


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    passes=st.lists(
        st.tuples(
            st.integers(0, 2),  # vehicle
            st.floats(0.1, 1.2),  # the statement's centre
            st.floats(0.03, 0.5),  # its log half-width
            st.sampled_from(["both", "upper", "lower", "none"]),  # the sides it states
            st.floats(0.0, 1.1),  # its measured grip's bound
        ),
        min_size=1,
        max_size=6,
    )
)
def test_cells_equal_the_brute_force_product_and_never_contradict_themselves(
    tmp_path_factory, passes
):
    """Property over random passes: the cell's range is the brute-force product's; the bound is
    the largest any pass proves; mu_low ≥ bound, mu_low ≤ mu ≤ mu_high, mu_high ≥ mu_low; a
    flagged cell has no range; the slippery call follows the stated range."""
    folder = tmp_path_factory.mktemp("cells")
    parts, stated = [], []
    for i, (v, centre, width, sides, b) in enumerate(passes):
        curve = None
        if sides != "none":
            curve = statement(centre, width, lower=sides in ("both", "lower"),
                              upper=sides in ("both", "upper"))  # fmt: skip
            stated.append((f"v{v}", curve))
        parts.append(_rows(f"v{v}", f"log{i}.nmea", [curve], [b]))
    r = _cell(folder, parts)
    bound = max(p[4] for p in passes)
    assert r["grip_used_lower"] == pytest.approx(bound)
    assert r["grip_used_lower"] <= r["grip_used"] + 1e-12
    if r["status"] in (STATUS_CONTRADICTION, STATUS_INCONSISTENT):
        assert np.isnan(r["mu_low"]) and np.isnan(r["mu_high"]) and np.isnan(r["mu"])
        assert r["slippery"] == ("not slippery" if bound > 0.5 + 1e-9 else "unknown")
        return
    assert r["mu_low"] >= bound - 1e-12 and r["mu_high"] >= r["mu_low"]
    if r["status"] == STATUS_ESTIMATE:
        assert r["mu_low"] <= r["mu"] <= r["mu_high"]
    else:
        assert np.isnan(r["mu"]) and r["mu_low"] == pytest.approx(bound)
    if stated and np.isfinite(r["mu_high"]):
        lo, hi = brute_force(stated, bound)
        assert r["mu_high"] == pytest.approx(hi, rel=1e-9)
        if r["status"] == STATUS_ESTIMATE:
            assert r["mu_low"] == pytest.approx(lo, rel=1e-9)
    if r["status"] == STATUS_MEASURED:
        assert r["mu_high"] == np.inf
    # the call: what stands with any one pass left out, or what the data prove
    if r["slippery"] == "slippery":
        assert robust_upper(stated) < 0.5 and r["mu_high"] < 0.5
    elif stated and robust_upper(stated) < 0.5 - 1e-9:
        assert r["slippery"] == "slippery"
    if bound > 0.5 + 1e-9:
        assert r["slippery"] == "not slippery"
