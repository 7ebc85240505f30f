# %% [markdown]
# # A friction map from a fleet (synthetic fleet)
#
# Beyond the seeds. Cars drive the curves of a small road network whose surfaces are known (dry
# μ 0.9, wet 0.5, snow 0.25), recorded by emulated RTK-class compasses. `run_fleet` processes
# every log on a local Dask cluster and combines every pass's statement per H3 cell: what the
# data prove (`grip_used_lower`, model-free), the range the passes' likelihoods leave together
# (`mu_low`, `mu_high`) and a value where that range is narrow (docs/fleet.md). The interactive
# page is `OUTDIR/map.html`; here the cells are drawn as a static figure.

# %%
import os
import shutil
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import h3
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Polygon

from gripsense.data import sample_path
from gripsense.fleet import run_fleet
from gripsense.sim.fleet_data import Site, write_fleet

OUT = Path(os.environ.get("GRIPSENSE_EXAMPLES_OUT", "docs/examples"))
OUT.mkdir(parents=True, exist_ok=True)
QUICK = os.environ.get("GRIPSENSE_EXAMPLES_QUICK") == "1"

# %%
SITES = [
    Site("dry", 33.620, 133.7195, 30.0, 0.9),
    Site("wet", 33.625, 133.7195, 30.0, 0.5),
    Site("snow", 33.630, 133.7195, 30.0, 0.25),
]


def site_of(cell):
    lat = h3.cell_to_latlng(cell)[0]
    return min(SITES, key=lambda s: abs(s.lat_deg - lat))


# %%
if __name__ == "__main__":  # Dask starts worker processes: scripts need the guard
    scratch = tempfile.TemporaryDirectory(prefix="gripsense-fleet-")  # removed at exit
    work = Path(scratch.name)
    truth = write_fleet(
        work / "logs", sample_path("corolla_sim.toml"), SITES, n_vehicles=1 if QUICK else 3
    )
    # the fleet's vehicle file: tyres calibrated on the car (G known to 5 %, no camber thrust)
    vehicle = work / "vehicle.toml"
    vehicle.write_text(
        sample_path("corolla_sim.toml")
        .read_text()
        .replace(
            'pressure = "parabolic"',
            'pressure = "parabolic"\nstiffness_uncertainty = 0.05\ncamber_thrust_ratio = 0.0',
        )
    )
    res = run_fleet(
        [str(work / "logs" / "**" / "*.nmea.gz")],
        work / "out",
        vehicle=vehicle,
        receiver="rtk",
        workers=1 if QUICK else 2,
    )
    cells = res.cells
    shutil.copy(work / "out" / "map.html", OUT / "fleet_map.html")
    print(f"{len(truth)} logs → {len(cells)} cells; map page: fleet_map.html beside the figures")

    cells = cells.assign(mu_road=[site_of(c).mu for c in cells["cell"]])
    est = cells.dropna(subset=["mu"])
    print(cells.groupby("mu_road")[["grip_used_lower", "mu", "mu_high"]].median().round(3))
    print(cells["status"].value_counts().to_string())
    bounded = np.isfinite(cells["mu_high"])
    CHECKS = {
        "no cell proves more than its road's μ": bool(
            (cells["grip_used_lower"] <= cells["mu_road"] + 1e-9).all()
        ),
        "some cells carry an estimate": len(est) > 0,
        "every bounded range holds its road's μ": bool(
            ((cells["mu_low"] <= cells["mu_road"]) & (cells["mu_road"] <= cells["mu_high"]))[
                bounded
            ].all()
        ),
    }
    REPRODUCED = {}

# %%
if __name__ == "__main__":  # Dask starts worker processes: scripts need the guard
    fig, axes = plt.subplots(1, len(SITES), figsize=(12, 4.2), layout="constrained")
    # viridis: every μ stands out from the white background (RdYlGn's pale yellow at 0.5 did not)
    cmap, norm = plt.get_cmap("viridis"), plt.Normalize(0.0, 1.0)
    for ax, site in zip(axes, SITES, strict=True):
        sub = cells[[site_of(c) is site for c in cells["cell"]]]
        for row in sub.itertuples():
            # a value; else a bounded range's centre (dotted); else the proven bound (hatched)
            ranged = np.isfinite(row.mu_high)
            value = (
                row.mu
                if np.isfinite(row.mu)
                else np.sqrt(row.mu_low * row.mu_high)
                if ranged
                else row.grip_used_lower
            )
            poly = np.array(h3.cell_to_boundary(row.cell))[:, ::-1]  # (lon, lat)
            ax.add_patch(
                Polygon(
                    poly,
                    facecolor=cmap(norm(value)),
                    edgecolor="0.3",
                    lw=0.3,
                    hatch=None if np.isfinite(row.mu) else ".." if ranged else "///",
                )
            )
        if len(sub):
            ax.autoscale_view()
        ax.set_aspect(1 / np.cos(np.deg2rad(site.lat_deg)))
        ax.set(title=f"{site.name} (road μ {site.mu})", xlabel="longitude [°]")
        ax.ticklabel_format(useOffset=False)
        ax.tick_params(labelsize=7)
        ax.xaxis.set_major_locator(plt.MaxNLocator(3))  # every panel: labels do not run together
    axes[0].set_ylabel("latitude [°]")
    fig.colorbar(
        plt.cm.ScalarMappable(norm=norm, cmap=cmap),
        ax=axes,
        label="μ (dotted: range centre; hatched: proven μ ≥)",
    )
    fig.savefig(OUT / "fleet_map.png", dpi=90)
