"""What errors are measured against: a scene's exact solution or a cached overkill reference
(docs/theory.md, section 6)."""

from bench.truth.kinds import ExactTruth, ReferenceTruth, truth_for
from bench.truth.references import TruthError

__all__ = ["ExactTruth", "ReferenceTruth", "TruthError", "truth_for"]
