"""Accelerometer CSVs as ``gripsense simulate`` writes them, read back with any subset of their
columns mapped; rows without the mapped channels are counted, malformed rows are errors."""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd
import pytest

from gripsense.constants import G0
from gripsense.errors import InputError
from gripsense.io.sensors.accel import read_accel_csv

OPTIONAL = ("ay", "az")


@pytest.mark.parametrize(
    "keys",
    [("ax", *c) for n in range(3) for c in itertools.combinations(OPTIONAL, n)] + [("ay", "az")],
    ids="+".join,
)
def test_the_simulated_accelerometer_csv_with_any_subset_mapped(simulated, keys):
    sim = simulated("nmea")
    raw = pd.read_csv(sim.accel)
    assert list(raw.columns) == ["t_s", "ax_g", "ay_g", "az_g"]
    spec = ",".join(["t=t_s:s", *(f"{k}={k}_g:g" for k in keys)])
    if "ax" not in keys:
        with pytest.raises(InputError, match=r"no column for ax .*add ax=HEADER:unit"):
            read_accel_csv(sim.accel, columns=spec)
        return
    d = read_accel_csv(sim.accel, columns=spec)
    assert len(d) == len(raw) and d.attrs["rows"]["rows_without_channel"] == 0
    for k in ("ax", "ay", "az"):
        if k in keys:
            np.testing.assert_allclose(d[k], raw[f"{k}_g"] * G0, rtol=1e-12)
        else:
            assert d[k].isna().all()


def test_channels_at_their_own_rates(tmp_path):
    """ax at 50 Hz, az at 25 Hz on rows of their own: the rows without ax are counted."""
    p = tmp_path / "a.csv"
    p.write_text("t_s,ax_g,az_g\n0,0.1,1.0\n0.02,0.2,\n0.03,,1.01\n0.04,0.3,\n")
    d = read_accel_csv(p, columns="auto")
    assert d["t_s"].tolist() == [0.0, 0.02, 0.04]
    assert (
        d.attrs["rows"]["note"] == "a.csv: 1 of 4 rows without ax_g: not used (the first at line 4)"
    )
    p.write_text("t_s,ax_g,az_g\n0,0.1,1.0\n,0.2,\n")
    with pytest.raises(InputError, match=r"a.csv: line 3, column 't_s' \(t\): no time"):
        read_accel_csv(p, columns="auto")
    p.write_text("t_s,ax_g,az_g\n0,0.1,\n0.02,0.2,\n")
    with pytest.raises(InputError, match=r"column 'az_g' \(az\) has no value on any row"):
        read_accel_csv(p, columns="auto")
