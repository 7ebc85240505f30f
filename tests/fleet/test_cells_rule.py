"""A fleet cell obeys a drive's rule (issue "What a newcomer trips on"): the range's lower end is
at least the measured grip's bound, a value lies inside its range, and a cell whose estimate is
below the grip its data prove is flagged — never shown as a plain value. Rows are written as the
fleet's workers write them; the aggregation (DuckDB) is the code under test."""

from __future__ import annotations

import numpy as np
import pandas as pd
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gripsense.fleet.aggregate import STATUS_INCONSISTENT, aggregate_cells, cells_geojson
from gripsense.fleet.tasks import ROW_COLUMNS

CELL = "8b2e6d9434b0fff"


def _rows(vehicle: str, log: str, mu, sigma, bound, grip) -> pd.DataFrame:
    n = len(mu)
    t = pd.Timestamp("2026-01-05T10:00:00Z") + pd.to_timedelta(np.arange(n), unit="s")
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
            "mu_low": np.asarray(mu) - 1.645 * np.asarray(sigma),
            "mu_high": np.asarray(mu) + 1.645 * np.asarray(sigma),
            "grip_used": grip,
            "grip_used_lower": bound,
        }
    )[ROW_COLUMNS]


def _write(folder, parts):
    for i, df in enumerate(parts):
        d = folder / "epochs" / f"vehicle={df['vehicle'].iloc[0]}"
        d.mkdir(parents=True, exist_ok=True)
        df.drop(columns="vehicle").to_parquet(d / f"log{i}.parquet", index=False)


def test_an_estimate_below_the_measured_grip_is_flagged(tmp_path):
    """The issue's cell: μ 0.48 [0.46, 0.50] from one pass, while another pass proves 0.739."""
    _write(
        tmp_path,
        [
            _rows("a", "one.nmea", [0.48, 0.48], [0.013, 0.013], [0.40, 0.41], [0.45, 0.46]),
            _rows("b", "two.nmea", [np.nan], [np.nan], [0.739], [0.80]),
        ],
    )
    c = aggregate_cells(tmp_path).iloc[0]
    assert c["status"] == STATUS_INCONSISTENT
    assert c["surface"] == "undetermined"
    assert c["mu_low"] >= c["grip_used_lower"]
    assert c["slippery"] == "not slippery"  # what the data prove: μ ≥ 0.739
    props = cells_geojson(aggregate_cells(tmp_path))["features"][0]["properties"]
    assert props["status"] == STATUS_INCONSISTENT


@settings(
    max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    passes=st.lists(
        st.tuples(
            st.floats(0.1, 1.2),  # μ of the pass (NaN when absent)
            st.booleans(),  # the pass has an estimate
            st.floats(0.005, 0.2),  # its σ
            st.floats(0.0, 1.1),  # its measured grip's bound
            st.floats(0.0, 0.3),  # the measured grip above its bound
        ),
        min_size=1,
        max_size=5,
    )
)
def test_cells_never_contradict_themselves(tmp_path_factory, passes):
    """Property over random passes: grip_used_lower ≤ grip_used; mu_low ≥ grip_used_lower;
    a plain estimate has mu_low ≤ mu ≤ mu_high; a value below the bound is flagged."""
    folder = tmp_path_factory.mktemp("cells")
    parts = [
        _rows(f"v{i % 2}", f"log{i}.nmea", [mu if has else np.nan], [sd], [b], [b + dg])
        for i, (mu, has, sd, b, dg) in enumerate(passes)
    ]
    _write(folder, parts)
    c = aggregate_cells(folder)
    assert len(c) == 1
    r = c.iloc[0]
    assert r["grip_used_lower"] <= r["grip_used"] + 1e-12
    if np.isfinite(r["mu"]):
        assert r["mu_low"] >= r["grip_used_lower"] - 1e-12
        if r["status"] == "estimate":
            assert r["mu_low"] <= r["mu"] <= r["mu_high"]
        else:
            assert r["status"] == STATUS_INCONSISTENT
            assert r["mu"] < r["grip_used_lower"]
    else:
        assert r["status"] == "measured grip only" and np.isnan(r["mu_low"])
        # what the data prove still answers "is it slippery?"
        assert r["slippery"] == ("not slippery" if r["grip_used_lower"] > 0.5 + 1e-9 else "unknown")
