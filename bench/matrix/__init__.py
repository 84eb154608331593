"""The matrix: every (scene, formulation, solver, estimator, strategy) sequence of a run, its
result store, artifacts, provenance and rates; ``RunConfig`` and ``run`` are the entry point."""

from bench.matrix.run import RunConfig, RunResult, run

__all__ = ["RunConfig", "RunResult", "run"]
