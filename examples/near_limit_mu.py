# %% [markdown]
# # μ vs how hard the tyres work: what the data prove and what can be estimated
#
# Beyond the seeds. The bundled demo drives circle on roads of μ 0.9 and 0.5 at rising speed,
# on a Magic Formula tyre the estimator is not told about (the vehicle file describes brush
# tyres, as a user would write it), recorded by an RTK-class compass. Per window of the
# recommended method (`axle-window`): the measured grip |F_axle|/Fz_axle with its model-free
# lower bound ("the data prove μ ≥ …"), and — only where the tyres work near their limit — the
# estimate of μ with its 90 % interval (docs/friction.md, docs/physics.md §13–14).

# %%
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import pandas as pd

from gripsense.demo import demo_dir
from gripsense.pipeline import FrictionRun

OUT = Path(os.environ.get("GRIPSENSE_EXAMPLES_OUT", "docs/examples"))
OUT.mkdir(parents=True, exist_ok=True)
QUICK = os.environ.get("GRIPSENSE_EXAMPLES_QUICK") == "1"

# %%
d = demo_dir()
cases = pd.read_csv(d / "cases.csv")
cases = cases[cases["receiver"] == "rtk"]
if QUICK:
    cases = cases[cases["speed_kmh"] == cases.groupby("mu_road")["speed_kmh"].transform("max")]
rows, axles = [], []
for c in cases.itertuples():
    run = FrictionRun(d / c.vehicle_file, receiver="rtk")
    res = run.run_log(d / c.nmea, steer_csv=d / c.steer)  # the steering channel: front axle too
    w = res.windows.assign(case=c.case, mu_road=c.mu_road, tyre=c.tyre)
    rows.append(w)
    for s in res.summary.to_dict("records"):
        axles.append({**s, "mu_road": c.mu_road})
        est = (
            f"μ ≈ {s['mu']:.2f} [{s['mu_low']:.2f}, {s['mu_high']:.2f}]"
            if s["observable"]
            else "no value"
        )
        print(
            f"{c.case} road μ {c.mu_road}, {c.speed_kmh} km/h, {s['axle']}: "
            f"proven μ ≥ {s['grip_used_lower']:.3f}; {est}"
        )
win = pd.concat(rows, ignore_index=True)
obs = win[win["observable"].astype(bool)]
covered = ((obs["mu_low"] <= obs["mu_road"]) & (obs["mu_road"] <= obs["mu_high"])).sum()
print(f"{len(win)} windows, {len(obs)} with an estimate, {covered} of them hold the true μ")
est = [a for a in axles if a["observable"]]
held = sum(a["mu_low"] <= a["mu_road"] <= a["mu_high"] for a in est)
print(f"{len(axles)} axles, {len(est)} with an estimate, {held} of them hold the true μ (90 %)")
CHECKS = {
    "no proven bound above the true μ": bool((win["grip_used_lower"] <= win["mu_road"]).all()),
    "some axles near the limit give an estimate": any(a["observable"] for a in axles),
}
REPRODUCED = {}

# %%
fig, ax = plt.subplots(figsize=(7.5, 4.8), layout="constrained")
for k, (mu, g) in enumerate(win.groupby("mu_road")):
    color = f"C{k}"
    ax.axhline(mu, color=color, ls=":", lw=1)
    ax.plot(
        g["grip_used"],
        g["grip_used_lower"],
        "v",
        color=color,
        ms=4,
        alpha=0.6,
        label=f"road μ {mu}: proven μ ≥ (model-free)",
    )
    o = g[g["observable"].astype(bool)]
    ax.errorbar(
        o["grip_used"],
        o["mu"],
        yerr=[o["mu"] - o["mu_low"], o["mu_high"] - o["mu"]],
        fmt="o",
        color=color,
        ms=4,
        capsize=2,
        label=f"road μ {mu}: estimate, 90 %",
    )
ax.plot([0, 1.2], [0, 1.2], color="0.5", lw=0.8, ls="--")
ax.set(xlabel="measured grip |F_axle| / Fz_axle [-]", ylabel="μ [-]", xlim=(0, 1.1), ylim=(0, 1.3))
ax.set_title("Per axle and window: estimates only near the limit; bounds everywhere")
ax.legend(fontsize=7, loc="upper left")
fig.savefig(OUT / "mu_vs_grip.png", dpi=90)
