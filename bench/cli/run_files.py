"""A run file's values checked as the command line checks its options (docs/command-line.md,
"Run files"): the same parser per option kind, so that ``max-dofs = 1e3`` means in a file what
``--max-dofs 1e3`` means on the command line, and a bad value is refused naming the file, the
key, the value and what is allowed, never an option the user did not type."""

from __future__ import annotations

import argparse

from bench.cli.generated import TYPES
from bench.matrix.config_files import RunFileError
from bench.sequence.options import option_fields


def _as_text(value) -> str:
    if isinstance(value, (list, tuple)):
        return ",".join(str(v) for v in value)
    return str(value)


def _checked(opt, name: str, value):
    """``value`` of the option ``opt`` (field ``name``) as the command line would parse it;
    ValueError with what is allowed."""
    if opt.kind in ("switch", "switch-off"):
        if not isinstance(value, bool):
            raise ValueError("is not true or false")
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
