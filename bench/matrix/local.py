"""A run's sequences in this process (``run_specs``), one after another; ``bench.matrix.
distributed`` runs the same specs on Dask. ``bench.matrix.run`` is the one entry point to
both."""

from __future__ import annotations

import json
import secrets
import time
from collections.abc import Callable, Sequence
from pathlib import Path

from bench.matrix.files import atomic_text
from bench.matrix.provenance import provenance
from bench.matrix.spec import SequenceSpec
from bench.matrix.store import ResultStore
from bench.matrix.task import run_spec
from bench.sequence.loop import LevelResult
from bench.sequence.rows import INTERRUPTED, ResultRow
from bench.truth import truth_for


def new_run_identity() -> dict:
    """The run's columns: a unique run id (time, then random hex) and the provenance."""
    return {"run_id": time.strftime("%Y%m%dT%H%M%S-") + secrets.token_hex(3), **provenance()}


def truth_name(spec: SequenceSpec) -> str:
    return spec.scene + (f":{spec.labels['scene_parameters']}"
                         if spec.scene_parameters else "")


def write_truth_summary(out, name: str, truth) -> None:
    """``truth.json``: per scene, what errors were measured against (reference summary)."""
    path = Path(out) / "truth.json"
    summary = json.loads(path.read_text()) if path.exists() else {}
    if truth is None:
        summary[name] = {"kind": "none"}
    elif truth.kind == "reference":
        summary[name] = {"kind": "reference", **truth.reference.summary()}
        if truth.crosscheck is not None:
            summary[name]["crosscheck"] = truth.crosscheck.summary()
    else:
        summary[name] = {"kind": "exact", "source": truth.scene.exact.source}
    atomic_text(json.dumps(summary, indent=1, default=float), path)


def run_specs(specs: Sequence[SequenceSpec], store: ResultStore, run: dict,
              on_level: Callable[[LevelResult], None] | None = None,
              truths: dict | None = None, max_memory_gib: float | None = None,
              on_sequence: Callable[[SequenceSpec, str], None] | None = None) -> list[ResultRow]:
    """Run the specs one after another in this process; each finished level is stored at
    once, each sequence's end reason when it ends (``interrupted`` on Ctrl-C, which is then
    raised again). ``truths`` (by ``truth_name``) are built as needed when missing."""
    rows, truths = [], dict(truths or {})

    def record(result: LevelResult) -> None:
        store.append(result.row)
        rows.append(result.row)
        if on_level is not None:
            on_level(result)

    for spec in specs:
        name = truth_name(spec)

        def truth_of(scene, name=name, spec=spec):
            if name not in truths:  # run() prepares them; built here when missing
                truths[name] = truth_for(scene, spec.reference_dofs, spec.max_dofs,
                                         spec.order)
                write_truth_summary(store.out, name, truths[name])
            return truths[name]
        try:
            end = run_spec(spec, run, store.out, truth_of, record, max_memory_gib)
        except KeyboardInterrupt:
            store.finish(spec.key, INTERRUPTED)
            raise
        store.finish(spec.key, end)
        if on_sequence is not None:
            on_sequence(spec, end)
    return rows
