"""CI gates: every entry of bench/expected.toml must pass (rates, effectivity, Hertz).

The gate runs take about two minutes (the paper scene's overkill reference is built once and
cached under .cache/references, or $SIGNORINI_BENCH_CACHE)."""

import pytest

from bench.verify import load_expected, verify

GATES = sorted({gate["name"] for gate in load_expected()["gate"]})


@pytest.fixture(scope="module")
def verdicts(tmp_path_factory):
    # the hard cases' verdicts are asserted by tests/bench/test_hard.py
    verdicts, _, _ = verify(tmp_path_factory.mktemp("verify"), hard=False)
    return verdicts


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
