"""Checks made before any work starts: output folders that can be written, and a clear line
instead of a traceback for what a user can get wrong."""

from __future__ import annotations

import tempfile
from pathlib import Path

# the folder options of each command that will be written to
OUTPUT_OPTIONS = {"run": ("out",), "compare": ("out", "reports"), "report": ("out",),
                  "export": (),
                  "verify": ("out",), "hard": ("out",), "scaling": ("out",),
                  "study": ("out", "report")}


class InputError(ValueError):
    """A bad option value or environment fault, refused before any work."""


def check_output_folder(path: str | Path, option: str) -> Path:
    """Create ``path`` if needed and prove it writable; else InputError naming the option.
    An empty value is refused: it would silently write into the current folder."""
    flag = f"--{option.replace('_', '-')}={str(path)!r}"
    if not str(path).strip():
        raise InputError(f"{flag} is empty; give a folder to write into")
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise InputError(f"{flag} is a file, not a folder; give a folder to write into")
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path, prefix=".write-test-"):
            pass
    except OSError as error:
        reason = error.strerror or type(error).__name__
        raise InputError(f"{flag} cannot be written: {reason}; give a writable folder") \
            from None
    return path


def check_output_folders(command: str, args) -> None:
    for option in OUTPUT_OPTIONS.get(command, ()):
        check_output_folder(getattr(args, option), option)

