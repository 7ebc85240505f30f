"""The fleet map page: H3 cells coloured by their combined range on Leaflet, self-contained and
offline-first.

A bounded range is filled in the surface colour of its centre, a one-sided one (μ ≥ the
measured grip) hatched in the colour of its bound, a contradiction or an inconsistent cell red
and dashed; slippery cells get a thick dark border, and a cell whose newest data are older than
the fleet's newest is faded and dotted. A click lists the cell's statement and the passes
behind it, each with its own.

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
          box-shadow: 0 1px 4px rgba(0,0,0,.3); line-height: 1.5; max-width: 330px; }}
.swatch {{ display: inline-block; width: 14px; height: 14px; margin-right: 6px;
           vertical-align: middle; border: 1px solid #555; }}
.passes {{ border-collapse: collapse; font-size: 12px; margin-top: 4px; }}
.passes td, .passes th {{ padding: 1px 6px 1px 0; text-align: left; }}
</style></head>
<body><svg width="0" height="0" style="position:absolute" aria-hidden="true">
<defs>{patterns}</defs></svg>
<div id="map"></div>
<script>{leaflet_js}</script>
<script>
const cells = {geojson};
const bands = {bands};
const colours = {colours};
function classOf(mu) {{ for (const b of bands) {{ if (mu >= b[1]) return b[0]; }} return "ICE"; }}
function flagged(p) {{
  return p.status.startsWith("inconsistent") || p.status.startsWith("contradiction");
}}
function bounded(p) {{ return !flagged(p) && p.mu_high !== null && p.mu_low !== null; }}
function fill(p) {{
  if (flagged(p)) return "#c0392b";
  if (bounded(p)) return colours[classOf(Math.sqrt(p.mu_low * p.mu_high))];
  if (p.grip_used_lower === null || p.grip_used_lower <= 0) return "#888888";
  return "url(#hatch-" + classOf(p.grip_used_lower) + ")";   // one-sided: μ ≥ the bound
}}
function esc(t) {{
  const e = document.createElement("span"); e.textContent = t; return e.innerHTML;
}}
function fmt(x, d) {{ return x === null || x === undefined ? "–" : Number(x).toFixed(d); }}
function range(lo, hi) {{ return hi === null ? `μ ≥ ${{fmt(lo, 2)}}` :
                                 `μ in [${{fmt(lo, 2)}}, ${{fmt(hi, 2)}}]`; }}
function statement(p) {{
  if (flagged(p)) return `<b>${{p.status}}</b>: no combined range (the passes below); the ` +
                         `measured grip stands`;
  if (p.status === "estimate") return `estimate μ ≈ ${{fmt(p.mu, 2)}} [${{fmt(p.mu_low, 2)}}, ` +
                                       `${{fmt(p.mu_high, 2)}}] (90 %, tyre model; ${{p.surface}})`;
  if (bounded(p)) return `${{range(p.mu_low, p.mu_high)}} (90 %: the measured grip and the ` +
                         `tyre model's upper end; no value)`;
  return `${{range(p.grip_used_lower, null)}} (measured grip only: no upper end)`;
}}
function passList(p) {{
  const ps = JSON.parse(p.passes || '{{"listed": [], "more": 0}}');
  let h = '<table class="passes"><tr><th>vehicle</th><th>pass</th><th>its statement</th></tr>';
  for (const q of ps.listed) {{
    h += `<tr><td>${{esc(q.vehicle)}}</td><td>${{esc(q.log)}}</td>` +
         `<td>${{range(q.mu_low, q.mu_high)}}</td></tr>`;
  }}
  h += "</table>";
  if (ps.more > 0) h += `and ${{ps.more}} more passes`;
  return h;
}}
const map = L.map("map", {{preferCanvas: false}});
let tiles = null;
const layer = L.geoJSON(cells, {{
  style: f => {{
    const p = f.properties, slip = p.slippery === "slippery";
    return {{color: slip ? "#08306b" : "#333", weight: slip ? 4 : 1,
             fillColor: fill(p), fillOpacity: (bounded(p) ? 0.75 : 0.6) * (p.stale ? 0.45 : 1),
             dashArray: flagged(p) ? "3" : (p.stale ? "2 4" : null)}};
  }},
  onEachFeature: (f, l) => {{
    const p = f.properties;
    l.bindPopup(
      `<b>cell ${{esc(p.cell)}}</b>` +
      (p.stale ? `<br><b>older</b>: as of ${{p.bucket}} (the fleet's newest data: ` +
                 `${{p.newest_bucket}})` : ``) +
      `<br>${{statement(p)}}` +
      `<br><b>${{p.slippery || "unknown"}}</b> (slippery: μ < 0.5 at 95 %)` +
      `<br>measured: the data prove μ ≥ ${{fmt(p.grip_used_lower, 2)}} ` +
      `(model-free, level road)` +
      `<br>from ${{p.n_vehicles}} vehicles, ${{p.n_passes}} passes ` +
      `(${{p.n_statements}} statements, ${{p.n_estimates}} with a value)` +
      passList(p) +
      `<br>last update ${{p.last_update}}`, {{maxWidth: 360}});
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
  h += 'filled: a bounded range (colour of its centre); ' +
       '<span class="swatch" style="background:repeating-linear-gradient(45deg,#2e9e44 0 3px,' +
       '#fff 3px 6px)"></span>hatched: μ ≥ the measured grip only<br>';
  h += '<span class="swatch" style="background:#c0392b;opacity:.6"></span>' +
       'contradiction or inconsistent (click a cell)<br>';
  h += '<span class="swatch" style="border:3px solid #08306b"></span>slippery: μ < 0.5 at 95 %<br>';
  h += 'faded, dotted: older than the newest data of the fleet<br>';
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

COLOURS = {"ICE": "#3b6fd6", "SNOW": "#9ecae1", "WET": "#f2c14e", "DRY": "#2e9e44"}
"""Fill colour of each surface class on the map."""


def _patterns() -> str:
    """SVG hatch patterns, one per surface class (a one-sided range: μ ≥ the measured grip)."""
    return "".join(
        f'<pattern id="hatch-{name}" patternUnits="userSpaceOnUse" width="8" height="8" '
        f'patternTransform="rotate(45)"><rect width="8" height="8" fill="#ffffff"/>'
        f'<rect width="4" height="8" fill="{c}"/></pattern>'
        for name, c in COLOURS.items()
    )


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
        colours=json.dumps(COLOURS),
        patterns=_patterns(),
    )
    path = Path(path)
    path.write_text(page, encoding="utf-8")
    return path
