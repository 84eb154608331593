"""CI gates: every entry of bench/expected.toml must pass (rates, effectivity, Hertz).

The gate runs take about 35 minutes on 2 cores beside the rest of the slow group, which CI runs
in its second stage (the paper scene's overkill reference is built once and cached under
.cache/references, or $SIGNORINI_BENCH_CACHE)."""

import os
from pathlib import Path

import pytest

from bench.verify import load_expected, verify
from bench.verify.gates import gate_names

GATES = gate_names(load_expected(), quick=True)


@pytest.fixture(scope="module")
def verdicts(tmp_path_factory):
    # the hard cases' verdicts are asserted by tests/bench/test_hard.py; the truth's gates
    # run in their reduced version ([truth.quick]); the full ones in test_truth_gates.py
    # on two worker processes (the CI machine's cores); the rows do not depend on it
    # CI keeps the folder (SIGNORINI_VERIFY_OUT) to record its figures in the history
    # (docs/history.md); elsewhere a temporary one
    given = os.environ.get("SIGNORINI_VERIFY_OUT")
    out = Path(given) if given else tmp_path_factory.mktemp("verify")
    out.mkdir(parents=True, exist_ok=True)
    verdicts, _, _ = verify(out, hard=False, quick=True, workers=2)
    return verdicts


@pytest.mark.slow  # the gate runs: about 35 minutes on 2 cores
@pytest.mark.parametrize("gate", GATES)
def test_gate(verdicts, gate):
    mine = [v for v in verdicts if v.gate == gate]
    assert mine, f"gate {gate!r} selected no rows"
    failed = [f"{v.combination}: {v.value:.4g} not in [{v.low:g}, {v.high:g}]"
              for v in mine if not v.passed]
    assert not failed, f"{gate} ({mine[0].source}): " + "; ".join(failed)


def test_every_gate_says_where_its_numbers_come_from():
    for gate in load_expected()["gate"]:
        assert len(gate["source"]) > 20, gate["name"]
        assert "min" in gate or "max" in gate, gate["name"]


def test_a_gate_with_a_dimension_selects_only_that_dimension():
    import pandas as pd

    from bench.verify.gates import check_gates

    rates = pd.DataFrame({"scene": ["paper", "paper-3d"], "estimator": ["equilibrated"] * 2,
                          "dim": [2, 3], "effectivity_max": [1.5, 2.5]})
    gate = {"name": "g", "quantity": "effectivity_max", "estimator": "equilibrated",
            "max": 2.0, "source": "a test"}
    both = check_gates({"gate": [gate]}, [rates])
    assert [v.passed for v in both] == [True, False]
    planar = check_gates({"gate": [{**gate, "dim": 2}]}, [rates])
    assert [(v.combination, v.passed) for v in planar] == [("paper/equilibrated", True)]
