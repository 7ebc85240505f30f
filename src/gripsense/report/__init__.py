"""Results people can look at: figures (matplotlib) and a self-contained HTML report."""

from gripsense.report.html import write_report

__all__ = ["write_report"]
