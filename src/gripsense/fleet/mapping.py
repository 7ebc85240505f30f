"""The fleet map page: H3 cells coloured by μ on Leaflet, self-contained and offline-first.

Leaflet 1.9.4 (BSD-2) is bundled in ``gripsense/data/web/leaflet`` and inlined, so the page needs
no network. The background map tiles (OpenStreetMap) do need it: they are off by default and a
checkbox loads them; without tiles the cells show on a plain background.
"""

from __future__ import annotations

import html
import json
from importlib import resources
from pathlib import Path

import pandas as pd

from gripsense.fleet.aggregate import cells_geojson
from gripsense.physics.surface import SURFACE_BANDS

__all__ = ["write_map"]

_TEMPLATE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title>
<style>{leaflet_css}</style>
<style>
html, body {{ margin: 0; height: 100%; font-family: sans-serif; }}
#map {{ position: absolute; top: 0; bottom: 0; left: 0; right: 0; background: #eef0f2; }}
.panel {{ background: white; padding: 8px 10px; border-radius: 4px; font-size: 13px;
          box-shadow: 0 1px 4px rgba(0,0,0,.3); line-height: 1.5; }}
.swatch {{ display: inline-block; width: 14px; height: 14px; margin-right: 6px;
           vertical-align: middle; border: 1px solid #555; }}
</style></head>
<body><div id="map"></div>
<script>{leaflet_js}</script>
<script>
const cells = {geojson};
const bands = {bands};
const colours = {{ICE: "#3b6fd6", SNOW: "#9ecae1", WET: "#f2c14e", DRY: "#2e9e44"}};
function plain(p) {{ return p.mu !== null && p.status === "estimate"; }}
function colour(p) {{
  if (!plain(p)) return p.mu === null ? "#888888" : "#c0392b";
  for (const b of bands) {{ if (p.mu >= b[1]) return colours[b[0]]; }}
  return colours.ICE;
}}
function fmt(x, d) {{ return x === null || x === undefined ? "–" : Number(x).toFixed(d); }}
const map = L.map("map", {{preferCanvas: false}});
let tiles = null;
const layer = L.geoJSON(cells, {{
  style: f => ({{color: "#333", weight: 1, fillColor: colour(f.properties),
                fillOpacity: plain(f.properties) ? 0.75 : 0.35,
                dashArray: plain(f.properties) ? null : "3"}}),
  onEachFeature: (f, l) => {{
    const p = f.properties;
    l.bindPopup(
      `<b>cell ${{p.cell}}</b><br>` +
      (p.mu === null ? `no μ estimate`
       : !plain(p) ? `<b>${{p.status}}</b>: the tyre model's μ ≈ ${{fmt(p.mu, 2)}} ` +
                     `[…, ${{fmt(p.mu_high, 2)}}] is below what the data prove — check the ` +
                     `vehicle file (stiffness, receiver)`
       : `estimate μ ≈ ${{fmt(p.mu, 2)}} [${{fmt(p.mu_low, 2)}}, ` +
         `${{fmt(p.mu_high, 2)}}] (90 %, tyre model)<br>surface ${{p.surface}}`) +
      `<br><b>${{p.slippery || "unknown"}}</b> (slippery: μ < 0.5 at 95 %)` +
      `<br>measured: the data prove μ ≥ ${{fmt(p.grip_used_lower, 2)}} ` +
      `(model-free, level road)` +
      `<br>${{p.n_estimates}} estimates, ${{p.n_vehicles}} vehicles, ${{p.n_passes}} passes` +
      `<br>last update ${{p.last_update}}`);
  }}
}}).addTo(map);
if (cells.features.length) {{ map.fitBounds(layer.getBounds(), {{padding: [20, 20]}}); }}
else {{ map.setView([0, 0], 2); }}
const legend = L.control({{position: "bottomright"}});
legend.onAdd = () => {{
  const d = L.DomUtil.create("div", "panel");
  let h = "<b>{title}</b><br>";
  for (const b of bands) {{
    h += `<span class="swatch" style="background:${{colours[b[0]]}}"></span>` +
         `${{b[0]}} (μ ≥ ${{b[1]}})<br>`;
  }}
  h += '<span class="swatch" style="background:#888888;opacity:.5"></span>' +
       'measured grip only (no estimate)<br>';
  h += '<span class="swatch" style="background:#c0392b;opacity:.5"></span>' +
       'inconsistent: estimate below the measured grip<br>';
  h += 'slippery: μ < 0.5 at 95 %; not slippery: μ > 0.5 at 95 %; else unknown (click a ' +
       'cell)<br>';
  h += '<label><input type="checkbox" id="tiles"> background map (needs network)</label>';
  d.innerHTML = h;
  L.DomEvent.disableClickPropagation(d);
  return d;
}};
legend.addTo(map);
document.getElementById("tiles").addEventListener("change", e => {{
  if (e.target.checked) {{
    tiles = L.tileLayer("https://tile.openstreetmap.org/{{z}}/{{x}}/{{y}}.png",
      {{maxZoom: 19, attribution: "© OpenStreetMap contributors"}}).addTo(map);
    tiles.bringToBack();
  }} else if (tiles) {{ map.removeLayer(tiles); tiles = null; }}
}});
</script></body></html>
"""


def write_map(
    cells: pd.DataFrame, path: str | Path, *, title: str = "gripsense friction map"
) -> Path:
    """Write the map page for *cells* (:func:`gripsense.fleet.aggregate.aggregate_cells`).

    Parameters
    ----------
    cells : pandas.DataFrame
        Cell table of :func:`gripsense.fleet.aggregate_cells`.
    path : str or Path
        Output ``.html``.
    title : str
        Page title.
    """
    web = resources.files("gripsense") / "data" / "web" / "leaflet"
    js = (web / "leaflet.js").read_text(encoding="utf-8")
    css = (web / "leaflet.css").read_text(encoding="utf-8")
    bands = sorted(((str(b[0]), float(b[1])) for b in SURFACE_BANDS), key=lambda b: -b[1])
    page = _TEMPLATE.format(
        title=html.escape(title),
        leaflet_css=css,
        leaflet_js=js.replace("</script", "<\\/script"),
        geojson=json.dumps(cells_geojson(cells)).replace("</", "<\\/"),
        bands=json.dumps(bands),
    )
    path = Path(path)
    path.write_text(page, encoding="utf-8")
    return path
