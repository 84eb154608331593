"""Scenes from a user's files (``--scene-file``): a Python file registers them with the public
API (``scenes.register_scene``) when imported; a TOML file describes one scene declaratively
(``scenes.declarative``, docs/scenes.md). Every process that builds
scenes imports the same files (the driver, and each Dask task before its sequence), and a file
is imported once per process."""

from __future__ import annotations

import hashlib
import importlib.util
import sys
import tomllib
from pathlib import Path

from scenes.base import SceneError
from scenes.declarative import register_toml_scene
from scenes.registry import SCENES, Broken, registering_as, unregister_origin

_LOADED: dict[str, str] = {}  # resolved path -> module name, per process
FILE_FAILURES: dict[str, Broken] = {}  # resolved path -> why it was left out, per process


def check_scene_file(path) -> Path:
    """The file ``path`` names; ValueError (one line) if it does not exist or is neither
    Python nor TOML: a wrong path is bad input, refused before anything runs."""
    flag = f"--scene-file={str(path)!r}"
    file = Path(path).expanduser()
    if not file.exists():
        raise ValueError(f"{flag} does not exist; give a Python file (.py) that registers "
                         "scenes or a TOML scene (.toml)")
    if not file.is_file() or file.suffix not in (".py", ".toml"):
        raise ValueError(f"{flag} is not a Python file (.py) that registers scenes or a "
                         "TOML scene (.toml)")
    return file


def load_scene_files(paths, report=None) -> list[str]:
    """Load each file once in this process: the module names of those that loaded. A file
    that fails to load (a bad scene, an exception, even ``sys.exit``) is named once on
    ``report`` (default stderr) and left out, with whatever it registered undone: every other
    scene keeps working, and ``list`` shows it. ValueError for a path that is not a scene
    file at all (``check_scene_file``)."""
    names = []
    for path in paths:
        file = check_scene_file(path)
        key = str(file.resolve())
        if key in FILE_FAILURES:
            continue
        if key not in _LOADED:
            try:
                _LOADED[key] = _load(file, f"file {file}")
            except (Exception, SystemExit) as error:  # the user's code: name it, leave it out
                _leave_out(key, file, error, report)
                continue
        names.append(_LOADED[key])
    return names


def _load(file: Path, origin: str) -> str:
    """Register the scenes of one file (undone if it fails half-way); its module name."""
    try:
        with registering_as(origin):
            if file.suffix == ".toml":
                return register_toml_scene(file)
            name = f"signorini_bench_scene_file_{len(_LOADED) + len(FILE_FAILURES)}"
            spec = importlib.util.spec_from_file_location(name, file)
            module = importlib.util.module_from_spec(spec)
            sys.modules[name] = module
            try:
                spec.loader.exec_module(module)
            except BaseException:
                del sys.modules[name]
                raise
            return name
    except BaseException:
        unregister_origin(origin)
        raise


def _leave_out(key: str, file: Path, error: BaseException, report) -> None:
    kind = "exited" if isinstance(error, SystemExit) else "failed to load"
    reason = f"{type(error).__name__}: {error}" if not isinstance(error, SceneError) \
        else str(error)
    FILE_FAILURES[key] = Broken(str(file), f"file {file}", reason)
    name = _toml_name(file)
    if name is not None and name not in SCENES.names():  # asking for it says why it is out
        SCENES.mark_broken(name, reason, f"file {file}")
    print(f"warning: --scene-file={str(file)!r} {kind} and is left out: {reason}",
          file=report or sys.stderr)


def _toml_name(file: Path) -> str | None:
    """The scene name a TOML file declares, None if it has none or cannot be read."""
    if file.suffix != ".toml":
        return None
    try:
        name = tomllib.loads(file.read_text()).get("name")
    except (OSError, ValueError):
        return None
    return name if isinstance(name, str) and name else None


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
