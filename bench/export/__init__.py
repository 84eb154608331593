"""Field output for ParaView and other viewers (``python -m bench export``)."""

from bench.export.fields import FORMATS, LEVELS, export_results

__all__ = ["FORMATS", "LEVELS", "export_results"]
