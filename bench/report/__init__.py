"""The report of a results folder: Markdown, self-contained HTML and figures."""

from bench.report.render import write_report

__all__ = ["write_report"]
