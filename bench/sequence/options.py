"""Fields that are also options: a dataclass field declared with ``option(...)`` carries its
command-line name, how the command line parses it, its help and the part of a run it belongs
to, so the parser (``bench.cli.generated``), the run files (``bench.matrix.config_files``) and
the dataclass share one default (docs/command-line.md, "Run files")."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import MISSING, Field, dataclass, field, fields

SECTIONS = ("what", "how", "where")  # what runs, how each sequence runs, where it runs


@dataclass(frozen=True)
class Option:
    """The command-line side of a field. ``flag``: the option's name without dashes (also its
    key in a run file); ``kind``: how the command line parses a value (``bench.cli.generated``
    maps each kind to a validating type); ``default_text``: the help's default when the
    field's default needs words (None); ``choices``: the allowed values of a ``choice``."""

    help: str
    flag: str
    kind: str
    section: str
    metavar: str | None = None
    default_text: str | None = None
    choices: Callable[[], list[str]] | None = None
    saved: bool = True  # part of a run's description (run files, run.json); False: an action


def option(default, help: str, *, flag: str, kind: str, section: str, **more) -> Field:
    """A dataclass field with ``default`` and its ``Option`` (a tuple default stays a tuple:
    frozen dataclasses keep it immutable)."""
    if section not in SECTIONS:
        raise ValueError(f"section={section!r} is not one of {', '.join(SECTIONS)}")
    return field(default=default,
                  metadata={"option": Option(help, flag, kind, section, **more)})


def option_fields(cls) -> list[tuple[Field, Option]]:
    """The fields of ``cls`` (a dataclass or an instance) that are options, in order."""
    return [(f, f.metadata["option"]) for f in fields(cls) if "option" in f.metadata]


def field_default(f: Field):
    """A field's default value (from its factory if it has one)."""
    if f.default is not MISSING:
        return f.default
    if f.default_factory is not MISSING:
        return f.default_factory()
    raise ValueError(f"field {f.name!r} has no default")
