# %% [markdown]
# # The thesis's circle experiments on a simulated Corolla (seed 000 ch. 9–11)
#
# The 2018 experiments drove circles of 20–40 m radius at 20–50 km/h with a GNSS compass on
# the roof and read μ per rear wheel with the brush model (Figs 72–81, 82, 138, 139) and the
# tread stiffness G from the cornering stiffness (Table 23, Fig. 93). Here the same grid is
# driven by the simulator on a road of known μ with the thesis's own tyre model (a brush tyre,
# G = 5e7 N/m³ as the thesis's eq. 9.5) and recorded by an emulated RTK-class compass; the
# thesis's method (`thesis-2`) reads it back.

# %%
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import pandas as pd

from gripsense.estimate.conditions import condition_table, conditions
from gripsense.estimate.stiffness import g_sweep, tread_stiffness
from gripsense.io import read_nmea
from gripsense.pipeline import FrictionRun
from gripsense.report import figures as F
from gripsense.sim.drives import simulate_drive, truth_vehicle

OUT = Path(os.environ.get("GRIPSENSE_EXAMPLES_OUT", "docs/examples"))
OUT.mkdir(parents=True, exist_ok=True)
QUICK = os.environ.get("GRIPSENSE_EXAMPLES_QUICK") == "1"

# %%
MU = 0.9  # dry asphalt, as the thesis's braking tests found
speeds_kmh = (25, 40) if QUICK else (20, 30, 40, 50)
radii_m = (20, 40) if QUICK else (20, 25, 30, 35, 40)
vehicle = truth_vehicle("sedan")
run = FrictionRun(vehicle, method="thesis-2", receiver="rtk")
tables, stiff, shown = [], [], None
for i, (v, r) in enumerate((v, r) for v in speeds_kmh for r in radii_m):
    drive = simulate_drive(vehicle, "brush", None, MU, receiver="rtk", seed=i, circle=(v / 3.6, r))
    result = run.run(read_nmea(drive.lines).epochs)
    # the steady part of the circle, after the lead-in settled
    conds = [(max(a, drive.settle_s), b) for a, b in conditions(result.wheels)]
    conds = [(a, b) for a, b in conds if b - a >= 3.0]
    ct = condition_table(result.wheels, conds).assign(drive=f"{v} km/h, R {r} m")
    tables.append(ct)
    stiff.append(
        tread_stiffness(result.wheels, vehicle, conds=conds).assign(drive=f"{v} km/h, R {r} m")
    )
    if conds and (shown is None or ct["ay_g"].mean() > shown[2]["ay_g"].mean()):
        shown = (result.wheels, conds[0], ct)  # the figures show the hardest condition
ct = pd.concat(tables, ignore_index=True)
G = pd.concat(stiff, ignore_index=True)
print(ct[["drive", "wheel", "speed_kmh", "radius_m", "ay_g", "mu"]].round(3).to_string())

# %% [markdown]
# Table 23-like: G per condition and wheel. In the linear range G comes back near the
# simulator's 5e7 (the thesis's eq. 9.5 value) but 10–20 % low: partial sliding already lowers
# F/tan α at a third of the limit, and 0.1° of slip-angle error moves G by tens of per cent at
# the small slip angles of the wide circles (the `G_rel_sigma` column). Near the limit the bias
# is larger (docs/physics.md §6). The thesis's own Table 23 also averages below its 5e7 (4.68e7).

# %%
print(G[["drive", "wheel", "slip_deg", "utilisation", "G", "near_limit"]].round(3).to_string())
g_lin = G.loc[~G["near_limit"], "G"].mean()
print(f"mean G in the linear range: {g_lin:.3g} N/m³ (the thesis's eq. 9.5: 5e7)")
mu_rear = ct["mu"].median()
print(f"median μ over the conditions: {mu_rear:.3f} (road μ {MU})")

# brush tyre in, brush-model G out: this shows the thesis's procedure and its bias, not its
# accuracy on real tyres (the truth is the estimator's own model); no source number reproduced
REPRODUCED = {}
CHECKS = {"G in the linear range within 20 % of the simulated 5e7": abs(g_lin - 5e7) < 0.2 * 5e7}

# %%
wheels, (t0, t1), ct0 = shown
F.condition_figure(wheels, t0, t1, title=f"one condition: {ct0['drive'].iloc[0]}").savefig(
    OUT / "condition.png", dpi=90
)
F.mu_vs_radius(ct).savefig(OUT / "mu_vs_radius.png", dpi=90)
F.mu_vs_yaw_rate(ct).savefig(OUT / "mu_vs_yaw_rate.png", dpi=90)
sweep = g_sweep(wheels, vehicle, t0, t1)
print(f"G sweep (Fig. 93): chosen {sweep.chosen:.3g} N/m³ — {sweep.reason}")
F.g_sweep_figure(sweep).savefig(OUT / "g_sweep.png", dpi=90)
