"""The on-disk cache of overkill references: one ``.npz`` per reference with a SHA-256
checksum beside it (``.sha256``). A file that fails its checksum or cannot be read is named,
deleted and rebuilt. The folder is ``$SIGNORINI_BENCH_CACHE`` or ``.cache/references`` under the
working directory."""

from __future__ import annotations

import hashlib
import json
import os
import sys
from pathlib import Path

import numpy as np
from skfem import MeshTet, MeshTri

from bench.truth.references import Reference, build_reference, recipes_for, reference_key


class CorruptCache(Exception):
    """A cached reference that must not be used (the message says why)."""


def cache_folder(given: str | Path | None = None) -> Path:
    """The folder of the cached references: ``given`` (a run's ``cache``), else
    ``$SIGNORINI_BENCH_CACHE``, else ``.cache/references``."""
    if given is not None:
        return Path(given).expanduser()
    return Path(os.environ.get("SIGNORINI_BENCH_CACHE", ".cache/references"))


def check_cache_folder(folder: str | Path) -> Path:
    """The cache folder ``folder``, created if needed and proved writable; ValueError (one
    line naming the value) for a file or a folder that cannot be written, before any
    reference is built."""
    flag = f"cache={str(folder)!r}"
    path = Path(folder).expanduser()
    if path.exists() and not path.is_dir():
        raise ValueError(f"{flag} is a file, not a folder; give a folder for the cached "
                         "references")
    try:
        path.mkdir(parents=True, exist_ok=True)
        probe = path / f".write-test-{os.getpid()}"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as error:
        raise ValueError(f"{flag} cannot be written: {error.strerror or type(error).__name__}"
                         "; give a writable folder") from None
    return path


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _checksum_path(path: Path) -> Path:
    return path.with_suffix(".sha256")


def save_reference(ref: Reference, path: Path) -> None:
    """Write the reference and then its checksum, each atomically."""
    path.parent.mkdir(parents=True, exist_ok=True)
    meta = {"recipe": ref.recipe, "order": ref.order, "lame": list(ref.lame),
            "ndofs": ref.ndofs, "energy": ref.energy, "norm": ref.norm,
            "contact_force": ref.contact_force,
            "zone": list(ref.zone), "estimated_error": ref.estimated_error, "rate": ref.rate,
            "build_seconds": ref.build_seconds}
    tmp = path.with_suffix(".tmp.npz")
    np.savez_compressed(tmp, p=ref.mesh.p, t=ref.mesh.t, u=ref.u,
                        pressure_s=ref.pressure_s, pressure_values=ref.pressure_values,
                        meta=json.dumps(meta))
    checksum = _checksum_path(path).with_suffix(".sha256.tmp")
    checksum.write_text(_digest(tmp) + "\n")
    os.replace(tmp, path)
    os.replace(checksum, _checksum_path(path))


def load_reference(path: Path, key: str) -> Reference:
    """The reference stored at ``path``; CorruptCache if its checksum is missing or wrong or
    it cannot be read."""
    checksum = _checksum_path(path)
    if not checksum.exists():
        raise CorruptCache("no checksum beside it")
    if checksum.read_text().strip() != _digest(path):
        raise CorruptCache("checksum mismatch")
    try:
        with np.load(path) as data:
            meta = json.loads(str(data["meta"]))
            return Reference(key=key, recipe=meta["recipe"], order=meta["order"],
                             mesh=_mesh(data["p"], data["t"]), u=data["u"],
                             lame=tuple(meta["lame"]), pressure_s=data["pressure_s"],
                             pressure_values=data["pressure_values"], ndofs=meta["ndofs"],
                             energy=meta["energy"], norm=meta["norm"],
                             contact_force=meta["contact_force"],
                             zone=tuple(meta["zone"]), estimated_error=meta["estimated_error"],
                             rate=meta["rate"], build_seconds=meta["build_seconds"])
    except Exception as error:  # zip, pickle, JSON and key errors alike: do not trust it
        raise CorruptCache(f"{type(error).__name__}: {error}") from None


def _mesh(p: np.ndarray, t: np.ndarray):
    return (MeshTet if p.shape[0] == 3 else MeshTri)(p, t)


def load_or_build(scene, max_dofs: int, recipe: str | None = None,
                  cache: str | Path | None = None) -> Reference:
    """The cached reference for (scene, max_dofs, recipe) in ``cache_folder(cache)``, built and
    stored if missing or corrupt; ``recipe`` None: the primary recipe of the scene's
    dimension."""
    recipe = recipes_for(scene)[0] if recipe is None else recipe
    key = reference_key(scene, max_dofs, recipe)
    path = cache_folder(cache) / f"{key}.npz"
    if path.exists():
        try:
            return load_reference(path, key)
        except CorruptCache as error:
            print(f"note: cached reference {path} is corrupt ({error}); deleting and "
                  "rebuilding it", file=sys.stderr)
            path.unlink(missing_ok=True)
            _checksum_path(path).unlink(missing_ok=True)
    print(f"building the {recipe} reference of scene {scene.name!r} with up to {max_dofs} "
          f"DOFs into {path} (once; later runs load it)", file=sys.stderr, flush=True)
    ref = build_reference(scene, max_dofs, recipe)
    save_reference(ref, path)
    print(f"built the {scene.name!r} reference: {ref.ndofs} DOFs in {ref.build_seconds:.1f} s",
          file=sys.stderr, flush=True)
    return ref
