"""Plugins: installed packages that register scenes, formulations, solvers, back-ends,
estimators or hard cases through entry points (docs/own-problem.md, "Plugins").

A package declares, in its ``pyproject.toml``, one entry point per module to import, in the
group of what it registers::

    [project.entry-points."signorini_bench.formulations"]
    my-formulation = "my_package.formulation"

Importing the module registers its units with the public API (``register_formulation``, ...);
they are then recorded with the origin ``plugin DIST`` (``python -m bench list`` shows it).
A plugin that fails to import (or calls ``sys.exit``) is named on stderr and skipped,
whatever it registered before failing is undone, and the run goes on. Every process that
builds scenes loads the plugins once (the driver, and each Dask task before its sequence).
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from importlib.metadata import entry_points

from scenes.registry import registering_as, unregister_origin

GROUPS = tuple(f"signorini_bench.{kind}" for kind in (
    "scenes", "formulations", "solvers", "backends", "estimators", "hard_cases"))


@dataclass(frozen=True)
class PluginFailure:
    """An entry point that did not load, and why (one line)."""

    group: str
    name: str
    distribution: str
    reason: str


_LOADED = False
FAILURES: list[PluginFailure] = []


def load_plugins(report=None) -> list[PluginFailure]:
    """Import every entry point of ``GROUPS`` once per process, in that order (scenes first);
    the failures (also written to ``report``, default stderr, when they happen)."""
    global _LOADED
    if _LOADED:
        return list(FAILURES)
    _LOADED = True
    broken: set[str] = set()
    for group in GROUPS:
        for point in entry_points(group=group):
            distribution = point.dist.name if point.dist is not None else "?"
            origin = f"plugin {distribution}"
            if distribution in broken:
                continue  # the whole plugin is skipped, not half of it
            try:
                with registering_as(origin):
                    point.load()
            except (Exception, SystemExit) as error:  # a third party's code, even sys.exit:
                # name it, skip it, go on
                unregister_origin(origin)
                broken.add(distribution)
                failure = PluginFailure(group, point.name, distribution,
                                        f"{type(error).__name__}: {error}")
                FAILURES.append(failure)
                print(f"warning: plugin {distribution!r} (entry point {point.name!r} in "
                      f"{group}) failed to import and is skipped: {failure.reason}",
                      file=report or sys.stderr)
    return list(FAILURES)
