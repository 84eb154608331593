"""Provenance: the columns of every row (commit, package versions, machine) and the numerical
stack of a run (``numerics``: versions and thread settings, recorded in run.json and the
report's appendix)."""

from __future__ import annotations

import functools
import json
import os
import platform
import subprocess
from importlib import metadata
from pathlib import Path

from bench.matrix.files import atomic_text

PACKAGES = ("numpy", "scipy", "scikit-fem", "cvxpy", "clarabel", "pandas")
NUMERICAL_STACK = ("numpy", "scipy", "scikit-fem", "mkl", "pypardiso", "scikit-sparse",
                   "clarabel", "cvxpy", "meshio")
THREAD_VARIABLES = ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS")


def _version(name: str) -> str:
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return "missing"


def numerics() -> dict[str, str]:
    """The versions of the numerical stack (MKL and PARDISO's wrapper included) and the thread
    settings a run used: results must not depend on them, but times do."""
    import numpy as np

    blas = np.show_config(mode="dicts").get("Build Dependencies", {}).get("blas", {})
    return {"numerical stack": " ".join(f"{n}={_version(n)}" for n in NUMERICAL_STACK),
            "threads": " ".join(f"{v}={os.environ.get(v, 'unset')}" for v in THREAD_VARIABLES)
            + f" cores={os.cpu_count() or '?'}",
            "numpy BLAS": f"{blas.get('name', '?')} {blas.get('version', '')}".strip()}


@functools.cache
def provenance() -> dict[str, str]:
    root = Path(__file__).resolve().parent.parent
    try:
        commit = subprocess.run(["git", "rev-parse", "--short=12", "HEAD"], cwd=root,
                                capture_output=True, text=True, timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                               cwd=root, capture_output=True, text=True, timeout=10).stdout
        commit = (commit + ("+dirty" if dirty.strip() else "")) if commit else "unknown"
    except (OSError, subprocess.SubprocessError):
        commit = "unknown"
    versions = [f"{name}={_version(name)}" for name in PACKAGES]
    cores = os.cpu_count() or "?"
    return {
        "commit": commit,
        "python": platform.python_version(),
        "versions": " ".join(versions),
        "machine": f"{platform.machine()} {platform.system()} {cores} cores "
                   f"{platform.processor() or ''}".strip(),
    }


def write_run_record(out: Path, config, run_id: str, reused) -> None:
    """run.json: this run's command, configuration and numerics, and under ``earlier`` those
    of every earlier run into the same folder (so a folder of several runs says so)."""
    path = Path(out) / "run.json"
    earlier = []
    try:
        previous = json.loads(path.read_text())
        earlier = previous.pop("earlier", []) + [previous]
    except (OSError, ValueError, AttributeError):
        pass  # none, or damaged: this run's record replaces it
    record = {"command": config.command, "configuration": config.record(), "run_id": run_id,
              "reused": list(reused), "numerics": numerics(), "earlier": earlier}
    atomic_text(json.dumps(record, indent=1, default=str), path)
