"""Deprecated: the tyre-file registry moved to :mod:`gripsense.config.tyre_files` (where the
simulator and the fitters can use it); this name stays for one release.
"""

import warnings

from gripsense.config.tyre_files import (
    TYRE_FILE_TYPES,
    TyreModel,
    load_mf_tyre,
    load_tyre_model,
)

__all__ = ["TYRE_FILE_TYPES", "TyreModel", "load_mf_tyre", "load_tyre_model"]

warnings.warn(
    "gripsense.tyre_models is deprecated; import gripsense.config.tyre_files",
    DeprecationWarning,
    stacklevel=2,
)
