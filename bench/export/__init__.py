"""Field output for ParaView and other viewers (``python -m bench export``)."""

from bench.export.fields import FORMATS, export_results

__all__ = ["FORMATS", "export_results"]
