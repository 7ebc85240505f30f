# %% [markdown]
# # One drive, the field's formats: NMEA, VBOX, u-blox UBX, MDF4 and a CAN log
#
# A test day produces logs in many formats: a dual-antenna VBOX writes `.vbo`, a u-blox
# moving-base rover UBX frames between its NMEA sentences, a CANape or INCA measurement MDF4,
# a vehicle logger BLF with a DBC. gripsense reads them all into the same epoch table
# (`gripsense.io.logs.read_log`, docs/ingest.md). Here one bundled demo drive — a Magic
# Formula tyre near its limit on a wet road (μ 0.5) — is written in each format as
# `gripsense simulate --format` writes it, and friction is estimated from each file.

# %%
import gzip
import os
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from gripsense.demo import demo_dir
from gripsense.io import read_nmea
from gripsense.io.logs import LogOptions, write_log
from gripsense.io.logs.canlog import CAN_SIGNALS, write_can
from gripsense.pipeline import FrictionRun

OUT = Path(os.environ.get("GRIPSENSE_EXAMPLES_OUT", "docs/examples"))
OUT.mkdir(parents=True, exist_ok=True)
ROOT = Path.cwd() if (Path.cwd() / "tests").exists() else Path(__file__).resolve().parents[1]
DBC = ROOT / "tests" / "data" / "formats" / "vehicle.dbc"

# %%
d = demo_dir()
case = pd.read_csv(d / "cases.csv").set_index("case").loc["case021"]
nmea = d / case["nmea"]
steer = pd.read_csv(d / case["steer"])
epochs = read_nmea(nmea).epochs
lines = gzip.decompress(nmea.read_bytes()).decode().splitlines()
scratch = tempfile.TemporaryDirectory()  # the five logs; removed at the end
work = Path(scratch.name)
logs = {"NMEA": (nmea, LogOptions(), True)}
for fmt, name, suffix in (("vbo", "VBOX", ".vbo"), ("ubx", "UBX + NMEA", ".ubx"),
                          ("mf4", "MDF4", ".mf4")):  # fmt: skip
    columns = write_log(epochs, work / f"drive{suffix}", fmt, nmea_lines=lines, steer=steer)
    logs[name] = (work / f"drive{suffix}", LogOptions(columns=columns), fmt == "ubx")
write_can(epochs, work / "drive.blf", DBC)
can_columns = ",".join(f"{k}={v}" for k, v in CAN_SIGNALS.items())
logs["CAN BLF + DBC"] = (work / "drive.blf", LogOptions(columns=can_columns, dbc=DBC), True)

# %%
run = FrictionRun(d / case["vehicle_file"], receiver="v100")
rows = []
for name, (path, opts, needs_steer_csv) in logs.items():
    res = run.run_log(path, steer_csv=d / case["steer"] if needs_steer_csv else None,
                      log_options=opts)  # fmt: skip
    rep = res.ingest
    for s in res.summary.to_dict("records"):
        rows.append({"format": name, **s})
    front = res.summary.set_index("axle").loc["front"]
    est = (f"μ ≈ {front['mu']:.2f} [{front['mu_low']:.2f}, {front['mu_high']:.2f}]"
           if front["observable"] else "no value")  # fmt: skip
    print(f"{name:14s} {rep['total_lines']:5d} {rep['unit']:17s} front: proven μ ≥ "
          f"{front['grip_used_lower']:.3f}; {est}")  # fmt: skip
table = pd.DataFrame(rows)

# %%
front = table[table["axle"] == "front"].reset_index(drop=True)
fig, ax = plt.subplots(figsize=(7, 3.6))
x = np.arange(len(front))
ax.errorbar(x, front["mu"], yerr=[front["mu"] - front["mu_low"], front["mu_high"] - front["mu"]],
            fmt="o", capsize=5, label="estimate, 90 % interval")  # fmt: skip
ax.plot(x, front["grip_used_lower"], "^", color="C2", label="proven lower bound")
ax.axhline(case["mu_road"], color="0.4", ls="--", label="true road μ")
ax.set_xticks(x, front["format"])
ax.set_ylabel("front axle μ")
ax.set_title("The same drive read from five formats")
lo, hi = front["grip_used_lower"].min(), front["mu_high"].max()
ax.set_ylim(lo - 0.1 * (hi - lo) - 0.01, hi + 0.35 * (hi - lo) + 0.01)
ax.legend(loc="upper center", ncols=3, fontsize=8)
fig.tight_layout()
fig.savefig(OUT / "field_formats.png", dpi=120)

# %%
spread = (
    front[["mu", "mu_low", "mu_high", "grip_used_lower"]].max()
    - front[["mu", "mu_low", "mu_high", "grip_used_lower"]].min()
)
print("largest difference between formats:", spread.round(4).to_dict())
scratch.cleanup()
REPRODUCED: dict = {}
CHECKS = {
    "every format gives the same front-axle result (within 0.01)": bool((spread <= 0.01).all()),
    "every range holds the true μ": bool(
        ((front["mu_low"] <= case["mu_road"]) & (case["mu_road"] <= front["mu_high"])).all()
    ),
}
