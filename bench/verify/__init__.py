"""Verification: the gates of ``expected.toml`` (rates, effectivity, closed-form contact, hard
verdicts) checked by ``python -m bench verify``."""

from bench.verify.expected import EXPECTED, claims, load_expected
from bench.verify.gates import Verdict, verdict_table, verify

__all__ = ["EXPECTED", "Verdict", "claims", "load_expected", "verdict_table", "verify"]
