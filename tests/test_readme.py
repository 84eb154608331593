"""The README's Python API section runs exactly as it stands: its ``python`` blocks, in order,
in one namespace, in a fresh folder."""

import re
from pathlib import Path

import pandas as pd

from bench.measure.contact import SOLVED_STATUSES as SOLVED
from estimators.base import ESTIMATORS  # noqa: F401  (the registries the snippets fill)
from formulations.registry import FORMULATIONS
from scenes.registry import SCENES

README = Path(__file__).parents[1] / "README.md"


def api_blocks() -> list[str]:
    text = README.read_text()
    section = text.split("**The Python API.**", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```python\n(.*?)```", section, flags=re.S)


def test_the_python_api_snippets_run_as_written(tmp_path, monkeypatch, capsys):
    blocks = api_blocks()
    assert len(blocks) == 3  # build a scene; run and get a DataFrame; register and read back
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    try:
        for block in blocks:
            exec(compile(block, str(README), "exec"), namespace)  # noqa: S102  (our own README)
        table, again = namespace["table"], namespace["again"]
        assert isinstance(table, pd.DataFrame) and table["status"].isin(SOLVED).all()
        assert set(table["formulation"]) == {"mixed", "nitsche"}
        # the parabola presses (from the level where the mesh resolves its contact zone)
        assert (table.groupby(["formulation", "estimator"])["contact_force"].last() > 0).all()
        assert len(again) == len(table)  # the folder holds this run's rows
        assert "mixed-quarter" in FORMULATIONS.names()
        assert "eta" in capsys.readouterr().out  # the printed table
    finally:
        SCENES.unregister("my-block")
        FORMULATIONS.unregister("mixed-quarter")
