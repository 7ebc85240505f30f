"""One column-mapping convention for every command that reads a table (docs/conventions.md).

For each command: a table whose headers carry a known name and a unit suffix works with no flag
and the mapping used is printed; the same data under other headers and units, mapped with
``--columns``, gives the same numbers (the conversion is checked against the first reading,
which uses SI or the source's own units); old flags mixed with ``--columns`` are an error; a unit
of the wrong kind is an error naming the key.
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from gripsense.cli import app
from gripsense.data import sample_path
from gripsense.io.sensors.steer import read_steer_csv

RUNNER = CliRunner()


def invoke(*args, code: int = 0):
    r = RUNNER.invoke(app, [str(a) for a in args])
    assert r.exit_code == code, (r.output, r.exception)
    return r.output


def numbers(text: str) -> list[float]:
    return [float(x) for x in re.findall(r"-?\d+\.\d+(?:e-?\d+)?", text)]


def test_tyre_fit_auto_and_mapped(tmp_path):
    from gripsense.physics.magic_formula.pac94 import pac94_lateral
    from gripsense.sim.tyre_data import PAC94_EXAMPLE

    rng = np.random.default_rng(3)
    n = 600
    fz = rng.uniform(2000, 6000, n)
    alpha = np.deg2rad(rng.uniform(-10, 10, n))
    gamma = np.deg2rad(rng.uniform(-3, 3, n))
    fy = pac94_lateral(PAC94_EXAMPLE, fz, alpha, gamma) + 20 * rng.standard_normal(n)
    auto = tmp_path / "auto.csv"
    pd.DataFrame(
        {"sa_deg": np.rad2deg(alpha), "ia_rad": gamma, "fz_kN": fz / 1e3, "fy_N": fy}
    ).to_csv(auto, index=False)
    out = invoke("tyre", "fit", auto, "--constraints", "none")
    assert "columns alpha ← sa_deg [deg], gamma ← ia_rad [rad], fz ← fz_kN [kN], fy ← fy_N [N]" in (
        " ".join(out.split())
    )
    # a TTC-like layout: SAE load sign, lbf, no unit suffix
    ttc = tmp_path / "ttc.csv"
    pd.DataFrame(
        {"SA": np.rad2deg(alpha), "IA": np.rad2deg(gamma), "FZ": -fz / 4.4482216152605, "FY": fy}
    ).to_csv(ttc, index=False)
    mapped = invoke(
        "tyre", "fit", ttc, "--constraints", "none",
        "--columns", "alpha=SA:deg,gamma=IA:deg,fz=-FZ:lbf,fy=FY:N",
    )  # fmt: skip
    assert "fz ← −FZ [lbf]" in mapped
    table = out[out.index("coefficient") :]
    assert numbers(table) == pytest.approx(numbers(mapped[mapped.index("coefficient") :]), rel=1e-5)


def test_fit_contact_auto_and_mapped(tmp_path):
    src = sample_path("thesis_table18.csv")
    auto = invoke("fit-contact", src)
    assert "columns mass ← mass_kg [kg], length ← length_m [m]" in auto
    df = pd.read_csv(src, comment="#")
    other = tmp_path / "t18.csv"
    pd.DataFrame({"Mass": df["mass_kg"], "Length": df["length_m"] * 100}).to_csv(other, index=False)
    mapped = invoke("fit-contact", other, "--columns", "mass=Mass:kg,length=Length:cm")
    # Table 18 fit (docs/physics.md §5): a = 0.010398, b = −1.0172e-4, from either layout
    for out in (auto, mapped):
        assert "a = 0.0103981 " in out and "b = -0.000101717 " in out
    assert invoke("fit-contact", other, code=2).count("\n") <= 2


def test_camber_auto_mapped_and_old_flags(tmp_path):
    t = np.arange(0, 2, 0.01)
    outer = 100.0 + np.where(t > 1, 200 * np.tan(np.deg2rad(2.0)), 0.0)
    auto = tmp_path / "laser.csv"
    pd.DataFrame({"t_s": t, "d_outer_mm": outer, "d_inner_mm": 100.0}).to_csv(auto, index=False)
    other = tmp_path / "laser_m.csv"
    pd.DataFrame({"clock": t * 1e3, "A": outer / 1e3, "B": 0.1}).to_csv(other, index=False)
    res = {}
    for name, src, extra in (
        ("auto", auto, []),
        ("mapped", other, ["--columns", "t=clock:ms,outer=A:m,inner=B:m"]),
        ("old", other, ["--outer-col", "A", "--inner-col", "B", "--scale-m", "1"]),
    ):
        if name == "old":  # the old flags read t_s only
            pd.DataFrame({"t_s": t, "A": outer / 1e3, "B": 0.1}).to_csv(other, index=False)
        out = tmp_path / f"{name}.csv"
        text = invoke("camber", src, "--spacing-m", 0.2, "--calibrate-s", 0.5, "-o", out, *extra)
        res[name] = pd.read_csv(out)["camber_deg"].to_numpy()
        if name == "auto":
            assert "columns t ← t_s [s], outer ← d_outer_mm [mm], inner ← d_inner_mm [mm]" in text
        if name == "old":
            assert "deprecated" in text and "--columns" in text
    assert res["auto"][t > 1] == pytest.approx(2.0, abs=1e-9)
    assert res["mapped"] == pytest.approx(res["auto"], abs=1e-9)
    assert res["old"] == pytest.approx(res["auto"], abs=1e-9)
    both = invoke(
        "camber", other, "--spacing-m", 0.2, "--outer-col", "A", "--columns", "outer=A:m", code=2
    )
    assert "either --columns or the old flags (--outer-col)" in both


def test_steering_identify_auto_and_mapped(tmp_path):
    from gripsense.config import SteeringCar
    from gripsense.physics.steering_system import simulate_release

    toml = sample_path("of18_steering.toml")
    car = SteeringCar.from_toml(toml).with_cs(70.0)
    r = simulate_release(car, alpha0_rad=np.deg2rad(30) / 5, duration_s=4.0)
    t = np.concatenate([np.arange(-0.5, 0, 1e-3), r["t_s"]])
    a = np.rad2deg(np.concatenate([np.full(500, r["alpha_rad"][0]), r["alpha_rad"]])) * 5
    auto = tmp_path / "release.csv"
    pd.DataFrame({"time_ms": t * 1e3, "handwheel_deg": a}).to_csv(auto, index=False)
    other = tmp_path / "release_other.csv"
    pd.DataFrame({"T": t, "SWA": np.deg2rad(a)}).to_csv(other, index=False)
    out_auto = invoke("steering", "identify", toml, "--release", auto)
    assert "columns t ← time_ms [ms], steer ← handwheel_deg [deg]" in out_auto
    out_mapped = invoke(
        "steering", "identify", toml, "--release", other, "--columns", "t=T:s,steer=SWA:rad"
    )
    settle = re.compile(r"settling time (\d\.\d+) s")
    assert settle.search(out_auto)[1] == settle.search(out_mapped)[1]
    # one --columns serves every recording kind; keys of another kind are ignored per file
    out = invoke(
        "steering", "identify", toml, "--release", other,
        "--columns", "t=T:s,steer=SWA:rad,yaw_rate=R:dps",
    )  # fmt: skip
    assert settle.search(out)[1] == settle.search(out_auto)[1]


def test_steer_channel_any_angle_unit(tmp_path):
    t = np.linspace(0, 10, 101)
    deg = 3 * np.sin(t)
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    pd.DataFrame({"t_s": t, "road_wheel_deg": deg}).to_csv(a, index=False)
    pd.DataFrame({"time_ms": t * 1e3, "delta_rad": np.deg2rad(deg)}).to_csv(b, index=False)
    ra, rb = read_steer_csv(a), read_steer_csv(b)
    assert rb["t_s"].to_numpy() == pytest.approx(ra["t_s"].to_numpy())
    assert rb["steer_rad"].to_numpy() == pytest.approx(np.deg2rad(deg), abs=1e-12)
    assert rb.attrs["columns"] == {"t": "time_ms:ms", "road_wheel": "delta_rad:rad"}


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            [
                "friction",
                "--table",
                "{csv}",
                "--vehicle",
                "{veh}",
                "--columns",
                "t=t:s,speed=v:kmh,slip=beta:kmh,yaw_rate=r:dps",
            ],
            "kmh is a unit of speed, but slip needs a unit of angle",
        ),
        (
            ["fit-contact", "{csv}", "--columns", "mass=m:N,length=l:cm"],
            "N is a unit of force, but mass needs a unit of mass",
        ),
        (["brake-mu", "{csv}", "--columns", "t=t:s,ax=a:dps"], "use g, mps2"),
    ],
)
def test_unit_of_the_wrong_kind(tmp_path, args, message):
    csv = tmp_path / "x.csv"
    csv.write_text("t,v,beta,r,m,l,a\n0,1,2,3,4,5,6\n")
    veh = sample_path("corolla_sim.toml")
    out = invoke(*(a.format(csv=csv, veh=veh) for a in args), code=2)
    assert message in " ".join(out.split())
