"""Running the hard cases: a hard scene through ``cases.scenes.scene_case``, any other case
through its registration."""

from __future__ import annotations

import pandas as pd

from bench.hard.cases import scene_case
from bench.hard.registry import HARD_CASES, hard_case_names, hard_scene_names
from formulations.cells import DEFAULT_CELL


def run_case(name: str, cells=(DEFAULT_CELL,)) -> list[dict]:
    """A hard scene on each of ``cells``; any other case (built on triangles) once."""
    if name in hard_scene_names():
        return [record for cell in cells for record in scene_case(name, cell)]
    return HARD_CASES.get(name)()


def run_hard(cases: list[str] | None = None, on_case=None,
             cells=(DEFAULT_CELL,)) -> pd.DataFrame:
    """Run the named cases (default: all) and return their records as one table."""
    frames = []
    for name in cases or hard_case_names():
        frames.append(pd.DataFrame(run_case(name, cells)))
        if on_case is not None:
            on_case(name, frames[-1])
    return pd.concat(frames, ignore_index=True)
