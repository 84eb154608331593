"""The truth's gates in full (both reference scenes, the second recipe's cross-check, the
error-bar model to its whole budget): what ``python -m bench verify`` checks beyond the reduced
run of test_gates.py, whose sequences it does not rerun. A file of its own, so that CI's two
worker processes run it beside the gate runs."""

import pytest

from bench.verify import load_expected
from bench.verify.gates import gate_names, verify_truth

FULL = sorted(set(gate_names(load_expected())) - set(gate_names(load_expected(), quick=True)))


@pytest.mark.slow  # the hertz references (P3 and the P2 cross-check) and the error bar to 1.6e5
def test_full_truth_gates(tmp_path):
    verdicts = verify_truth(tmp_path)
    failed = [f"{v.gate} {v.combination}: {v.value:.4g} not in [{v.low:g}, {v.high:g}]"
              for v in verdicts if not v.passed]
    assert not failed, "; ".join(failed)
    assert {v.gate for v in verdicts} >= set(FULL)
