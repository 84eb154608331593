"""What errors are measured against: a scene's exact solution or a cached overkill reference
(docs/theory.md, section 6)."""

from bench.truth.kinds import ExactTruth, ReferenceTruth, truth_for

__all__ = ["ExactTruth", "ReferenceTruth", "truth_for"]
