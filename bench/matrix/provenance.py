"""Provenance columns: commit, package versions, machine."""

from __future__ import annotations

import functools
import os
import platform
import subprocess
from importlib import metadata
from pathlib import Path

PACKAGES = ("numpy", "scipy", "scikit-fem", "cvxpy", "clarabel", "pandas")


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
    versions = []
    for name in PACKAGES:
        try:
            versions.append(f"{name}={metadata.version(name)}")
        except metadata.PackageNotFoundError:
            versions.append(f"{name}=missing")
    cores = os.cpu_count() or "?"
    return {
        "commit": commit,
        "python": platform.python_version(),
        "versions": " ".join(versions),
        "machine": f"{platform.machine()} {platform.system()} {cores} cores "
                   f"{platform.processor() or ''}".strip(),
    }
