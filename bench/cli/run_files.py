"""A run file's values checked as the command line checks its options (docs/command-line.md,
"Run files"): the same parser per option kind, so that ``max-dofs = 1e3`` means in a file what
``--max-dofs 1e3`` means on the command line, and a bad value is refused naming the file, the
key, the value and what is allowed, never an option the user did not type."""

from __future__ import annotations

import argparse

from bench.cli.generated import TYPES
from bench.cli.guards import InputError
from bench.matrix.config import RunConfig
from bench.matrix.config_files import COMPARE_KEYS, RunFileError, read_run_file
from bench.matrix.scene_files import load_scene_files
from bench.sequence.options import option_fields
from bench.study.run import read_study_file


def _as_text(value) -> str:
    if isinstance(value, (list, tuple)):
        return ",".join(str(v) for v in value)
    return str(value)


def _checked(opt, name: str, value):
    """``value`` of the option ``opt`` (field ``name``) as the command line would parse it;
    ValueError with what is allowed (a switch's true or false is checked as it is read,
    ``config_files.run_fields``)."""
    if opt.kind in ("switch", "switch-off"):
        return value
    if opt.kind == "files":
        items = [value] if isinstance(value, str) else value
        if not isinstance(items, (list, tuple)) or not all(isinstance(v, str) for v in items):
            raise ValueError("is not a file name or a list of file names")
        return tuple(items)
    if opt.kind == "choice":
        if value not in opt.choices():
            raise ValueError(f"is not one of {', '.join(map(str, opt.choices()))}")
        return value
    if isinstance(value, bool) or isinstance(value, dict):
        raise ValueError(f"is not a value of --{opt.flag}")
    try:
        parsed = TYPES[opt.kind](name)(_as_text(value))
    except argparse.ArgumentTypeError as error:
        raise ValueError(str(error)) from None
    return tuple(parsed) if isinstance(parsed, list) else parsed


def checked_run_file(fields: dict, path: str, cls) -> dict:
    """``fields`` (a run file's, by field name, ``read_run_file``) with every option's value
    parsed as on the command line; RunFileError naming the file, the key and the value."""
    out = dict(fields)
    for field, opt in option_fields(cls):
        if field.name not in fields or fields[field.name] is None:
            continue
        value = fields[field.name]
        try:
            out[field.name] = _checked(opt, field.name, value)
        except ValueError as error:
            shown = repr(_as_text(value))
            raise RunFileError(f"config={path!r}: {opt.flag} = {shown} {error}"
                               if str(error).startswith("is ") else
                               f"config={path!r}: {opt.flag} = {shown}: {error}") from None
    return out


def run_file_defaults(argv: list[str]) -> dict:
    """``--config FILE`` of run or compare, read before the parser is built: the file's values
    become the command's defaults (so options given override them) and its scene files
    are loaded (their scenes are valid names)."""
    command = next((a for a in argv if not a.startswith("-")), None)
    path = next((argv[k + 1] for k, a in enumerate(argv[:-1]) if a == "--config"),
                next((a.split("=", 1)[1] for a in argv if a.startswith("--config=")), None))
    if path is None or command not in ("run", "compare", "study"):
        return {}
    if command == "study":
        return {"study": read_study_file(path)}
    fields = read_run_file(path, COMPARE_KEYS if command == "compare" else ())
    load_scene_files(fields.get("scene_files", ()))  # before the names are checked
    fields = checked_run_file(fields, path, RunConfig)
    return {command: fields}


def overwrite_of(args, default: bool) -> bool:
    """``--overwrite`` or ``--no-overwrite`` (not both), else ``default``."""
    if args.overwrite and args.no_overwrite:
        raise InputError("--overwrite and --no-overwrite contradict each other; give one")
    return False if args.no_overwrite else (args.overwrite or default)
