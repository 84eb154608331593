"""Scenes from a user's files (``--scene-file``): a Python file registers them with the public
API (``scenes.register_scene``) when imported; a TOML file describes one scene declaratively
(``scenes.declarative``, docs/scenes.md). Every process that builds
scenes imports the same files (the driver, and each Dask task before its sequence), and a file
is imported once per process."""

from __future__ import annotations

import hashlib
import importlib.util
import sys
from pathlib import Path

from scenes.base import SceneError
from scenes.declarative import register_toml_scene
from scenes.registry import registering_as

_LOADED: dict[str, str] = {}  # resolved path -> module name, per process


def load_scene_files(paths) -> list[str]:
    """Load each file once in this process; ValueError (one line, naming the option and the
    value) for a missing file, one that is neither Python nor TOML, or one that fails."""
    names = []
    for path in paths:
        flag = f"--scene-file={str(path)!r}"
        file = Path(path).expanduser()
        if not file.is_file() or file.suffix not in (".py", ".toml"):
            raise ValueError(f"{flag} is not a Python file (.py) that registers scenes or a "
                             "TOML scene (.toml)")
        key = str(file.resolve())
        if key not in _LOADED and file.suffix == ".toml":
            try:
                with registering_as(f"file {file}"):
                    _LOADED[key] = register_toml_scene(file)
            except (SceneError, ValueError) as error:
                raise ValueError(f"{flag}: {error}") from None
        elif key not in _LOADED:
            name = f"signorini_bench_scene_file_{len(_LOADED)}"
            spec = importlib.util.spec_from_file_location(name, file)
            module = importlib.util.module_from_spec(spec)
            sys.modules[name] = module
            try:
                with registering_as(f"file {file}"):
                    spec.loader.exec_module(module)
            except Exception as error:  # the user's code: name the file and the error
                del sys.modules[name]
                raise ValueError(f"{flag} failed to import: {type(error).__name__}: "
                                 f"{error}") from None
            _LOADED[key] = name
        names.append(_LOADED[key])
    return names


def scene_files_in(argv: list[str]) -> list[str]:
    """The values of every ``--scene-file`` in a command line (read before the parser is
    built, since the parser's list of valid scenes must include the file's)."""
    files = []
    for k, arg in enumerate(argv):
        if arg == "--scene-file" and k + 1 < len(argv):
            files.append(argv[k + 1])
        elif arg.startswith("--scene-file="):
            files.append(arg.split("=", 1)[1])
    return files


def source_digest(paths) -> str:
    """A digest of the files' contents ('' for none): part of each sequence's key, so that a
    changed scene file is never taken for the one an earlier run used."""
    if not paths:
        return ""
    digest = hashlib.sha256()
    for path in paths:
        digest.update(Path(path).expanduser().read_bytes())
    return digest.hexdigest()[:16]
