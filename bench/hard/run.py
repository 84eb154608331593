"""Running the hard cases: a hard scene through ``cases.scenes.scene_case``, any other case
through its registration."""

from __future__ import annotations

import pandas as pd

from bench.hard.cases import scene_case
from bench.hard.registry import HARD_CASES, hard_case_names, hard_scene_names


def run_case(name: str) -> list[dict]:
    if name in hard_scene_names():
        return scene_case(name)
    return HARD_CASES.get(name)()


def run_hard(cases: list[str] | None = None, on_case=None) -> pd.DataFrame:
    """Run the named cases (default: all) and return their records as one table."""
    frames = []
    for name in cases or hard_case_names():
        frames.append(pd.DataFrame(run_case(name)))
        if on_case is not None:
            on_case(name, frames[-1])
    return pd.concat(frames, ignore_index=True)
