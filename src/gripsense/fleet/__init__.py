"""Fleet friction map: many drives → Dask → H3 cells → map page (``gripsense fleet``)."""

from gripsense.fleet.aggregate import aggregate_cells, cells_geojson
from gripsense.fleet.mapping import write_map
from gripsense.fleet.run import FleetResult, run_fleet

__all__ = ["FleetResult", "aggregate_cells", "cells_geojson", "run_fleet", "write_map"]
