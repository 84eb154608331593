"""A run in parts (RunConfig.parts, docs/command-line.md "Runs in parts"): the union of
several matrices, read from and written to run files, refused where a part sets where a run
runs."""

import json
import tomllib

import pytest

from bench.matrix.config import RunConfig
from bench.matrix.config_files import compare_settings, run_fields, run_file_text

PARTS = ({"orders": (1,), "strategies": ("uniform", "adaptive")},
         {"orders": (2, 3), "estimators": ("residual", "equilibrated"), "max_dofs": 5000})


def test_the_run_is_the_union_of_its_parts_each_sequence_once():
    config = RunConfig(scenes=("paper",), estimators=("residual",), parts=PARTS)
    specs = config.specs()
    # part 1: 2 strategies x residual; part 2: 2 orders x 2 estimators, adaptive (the default)
    assert len(specs) == 2 + 4
    assert {(s.order, s.estimator, s.strategy, s.max_dofs) for s in specs if s.order > 1} == {
        (o, e, "adaptive", 5000) for o in (2, 3) for e in ("residual", "equilibrated")}
    twice = RunConfig(scenes=("paper",), parts=(PARTS[0], PARTS[0]))
    assert len(twice.specs()) == 2  # a sequence two parts share runs once


def test_parts_survive_a_run_file_and_run_json():
    config = RunConfig(scenes=("paper",), parts=PARTS)
    text = run_file_text(config)
    assert "[[part]]" in text and "order = [2, 3]" in text
    assert RunConfig(**run_fields(tomllib.loads(text), "file")).parts == config.parts
    record = json.loads(json.dumps(config.record(), default=list))
    assert RunConfig(**run_fields(record, "run.json")).parts == config.parts


@pytest.mark.parametrize("part, named", [({"out": "x"}, "out"), ({}, "nothing"),
                                         ({"workers": 2}, "workers")])
def test_a_part_that_sets_where_the_run_runs_is_refused(part, named):
    with pytest.raises(ValueError, match=rf"parts\[0\] sets {named}; a part sets one or more "
                                         "of: max-dofs"):
        RunConfig(parts=(part,))


def test_a_bad_value_in_a_part_is_named_as_a_run_would():
    with pytest.raises(ValueError, match="unknown nonsense"):
        RunConfig(parts=({"estimators": ("nonsense",)},))


def test_the_default_comparison_has_p2_and_p3_adaptive_parts():
    parts = [dict(p) for p in compare_settings()["parts"]]
    orders = {o for p in parts for o in p["orders"]}
    assert orders == {1, 2, 3}
    # above P1 never uniform (its rate is capped there: docs/results.md); the goal part adds
    # the goal-driven strategy beside the adaptive one
    assert all("uniform" not in p["strategies"] and "adaptive" in p["strategies"]
               for p in parts if p["orders"] != (1,))
