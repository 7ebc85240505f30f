"""The package version, in one place (read by the package and by result manifests)."""

__version__ = "0.1.0"
