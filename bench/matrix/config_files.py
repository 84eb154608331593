"""Run files: a run described in TOML whose keys are the command line's options
(``max-dofs = 9000``, ``scene = ["paper"]``), or a results folder's run.json, read into
``RunConfig`` fields, and a ``RunConfig`` written back as such a file (docs/command-line.md,
"Run files"). The settings of ``compare`` are such a file in the package, ``compare.toml``."""

from __future__ import annotations

import json
import sys
import tomllib
from pathlib import Path

from bench.matrix.config import RunConfig
from bench.matrix.files import FULL, atomic_text
from bench.sequence.options import SECTIONS, option_fields

COMPARE_SETTINGS = Path(__file__).with_name("compare.toml")
# the default comparison of each dimension (``compare --dim``)
COMPARE_SETTINGS_BY_DIM = {2: COMPARE_SETTINGS, 3: COMPARE_SETTINGS.with_name("compare-3d.toml")}
COMPARE_KEYS = ("dim", "reports", "readme", "hard-cases")  # compare's own keys beside run's
PART_KEYS = ("part", "parts")  # a run file's [[part]] tables; run.json's "parts"
SECTION_TITLES = {"what": "what runs", "how": "how each sequence runs",
                  "where": "where it runs"}


class RunFileError(ValueError):
    """A run file that cannot be read or names a key that is not an option."""


def read_run_file(path: str | Path, extra: tuple[str, ...] = ()) -> dict:
    """The ``RunConfig`` fields a run file sets (a TOML run file, or the run.json of a results
    folder), and the keys of ``extra`` as they are (a command's own options)."""
    path = Path(path)
    try:
        text = path.read_text()
        data = json.loads(text) if path.suffix == ".json" else tomllib.loads(text)
    except (OSError, ValueError) as error:  # TOMLDecodeError and JSONDecodeError included
        raise RunFileError(f"config={str(path)!r} cannot be read as a run file "
                           f"(TOML, or a results folder's run.json): {error}") from None
    if path.suffix == ".json":
        data = data.get("configuration", data)  # run.json records it under this key
    return run_fields(data, f"config={str(path)!r}", extra)


def run_fields(data: dict, where: str, extra: tuple[str, ...] = ()) -> dict:
    """``data``'s keys (options, ``max-dofs``, or field names, ``max_dofs``) as ``RunConfig``
    fields; a key of ``extra`` is kept as written. A list field given one value gets a list
    of one."""
    options = {f.name: (f, o) for f, o in option_fields(RunConfig)}
    by_flag = {o.flag: name for name, (_, o) in options.items()}
    out: dict = {}
    for key, value in data.items():
        if key in PART_KEYS:  # [[part]] tables, or run.json's "parts"
            out["parts"] = part_fields(value, where)
            continue
        name = by_flag.get(key, key if key in options else None)
        if name is None and key in extra:
            out[key] = value
            continue
        if name is None:
            valid = ", ".join(sorted([*by_flag, *extra]))
            raise RunFileError(f"{where}: unknown key {key!r}; valid keys: {valid}")
        if name in out:
            raise RunFileError(f"{where}: {key!r} sets {name} a second time")
        field, opt = options[name]
        if not opt.saved:
            if value:
                print(f"note: {where} sets {key} = {_toml_value(value)}, which a run file does "
                      f"not do: a run file describes a run and never deletes results (it would "
                      f"delete rows other runs added); left out: give --{opt.flag} on the "
                      "command line to act", file=sys.stderr)
            continue
        if opt.kind in ("switch", "switch-off") and not isinstance(value, bool):
            raise RunFileError(f"{where}: {key} = {value!r} is not true or false")
        if opt.kind == "switch-off" and key == opt.flag:
            value = not value  # cold-start = true is nested = false
        if str(field.type).startswith("tuple") and isinstance(value, (str, int)):
            value = (value,)
        out[name] = tuple(value) if isinstance(value, list) else value
    return out


def part_fields(parts, where: str) -> tuple:
    """The ``[[part]]`` tables of a run file as ``RunConfig.parts`` (docs/command-line.md,
    "Runs in parts")."""
    if not isinstance(parts, list) or not all(isinstance(p, dict) for p in parts):
        raise RunFileError(f"{where}: part must be a list of tables ([[part]]), got {parts!r}")
    return tuple(tuple(sorted(run_fields(part, f"{where} part {k + 1}").items()))
                 for k, part in enumerate(parts))


def dataclass_fields(data: dict, names: list[str], where: str) -> dict:
    """``data``'s keys as the field ``names`` of a dataclass (``uniform-max-dofs`` or
    ``uniform_max_dofs``); an unknown key is refused naming the valid ones. Lists become
    tuples."""
    out = {}
    for key, value in data.items():
        name = key.replace("-", "_")
        if name not in names:
            valid = ", ".join(n.replace("_", "-") for n in names)
            raise RunFileError(f"{where}: unknown key {key!r}; valid keys: {valid}")
        out[name] = tuple(value) if isinstance(value, list) else value
    return out


def read_toml(path: str | Path, what: str) -> dict:
    try:
        return tomllib.loads(Path(path).read_text())
    except (OSError, ValueError) as error:
        raise RunFileError(f"config={str(path)!r} cannot be read as {what}: {error}") from None


def compare_settings(path: str | Path | None = None, dim: int = 2) -> dict:
    """The settings of ``compare`` (fields, plus ``dim``, ``reports`` and ``readme``): the
    package's for ``dim`` unless ``path``."""
    return read_run_file(COMPARE_SETTINGS_BY_DIM[dim] if path is None else path,
                         extra=COMPARE_KEYS)


def run_file_text(config: RunConfig, command: str = "") -> str:
    """``config`` as a TOML run file, every option written (an unset one as a comment), by
    section; reading it back gives the same ``RunConfig``."""
    lines = ["# a run of signorini-bench; repeat it with: python -m bench run --config FILE"]
    if command:
        lines.append(f"# written by: {command}")
    for section in SECTIONS:
        lines.append(f"\n# {SECTION_TITLES[section]}")
        for field, opt in option_fields(config):
            if opt.section != section or not opt.saved:
                continue
            value = getattr(config, field.name)
            if opt.kind == "switch-off":
                value = not value
            lines.append(f"# {opt.flag}: not set" if value is None
                         else f"{opt.flag} = {_toml_value(value)}")
    return "\n".join(lines + part_tables(config)) + "\n"


def part_tables(config: RunConfig) -> list[str]:
    """The run's parts as ``[[part]]`` tables (keys as the command line's options)."""
    options = {f.name: o for f, o in option_fields(config)}
    lines = ["\n# the run is the union of these matrices, each the settings above with its own"
             ] if config.parts else []
    for part in config.parts:
        lines.append("[[part]]")
        lines += [f"{options[name].flag} = "
                  f"{_toml_value(not value if options[name].kind == 'switch-off' else value)}"
                  for name, value in part]
    return lines


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    return json.dumps(str(value))  # a TOML basic string: JSON's escapes are TOML's


def save_run_file(config: RunConfig, path: str | Path, command: str = "") -> Path:
    """Write ``config`` as a run file to ``path`` (RunFileError when ``path`` is a folder or
    cannot be written)."""
    path = Path(path)
    if path.is_dir():
        raise RunFileError(f"save_config={str(path)!r} is a folder; give a file name, e.g. "
                           f"{str(path / 'run.toml')!r}")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        atomic_text(run_file_text(config, command), path)
    except OSError as error:
        if error.errno in FULL:
            raise
        raise RunFileError(f"save_config={str(path)!r} cannot be written: "
                           f"{error.strerror or error}; give a writable file") from None
    return path
