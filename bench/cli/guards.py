"""Checks made before any work starts: output folders that can be written, and a clear line
instead of a traceback for what a user can get wrong."""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

from bench.matrix.files import DiskFull

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
    """Every output folder option of ``command`` (one left unset takes its default later)."""
    for option in OUTPUT_OPTIONS.get(command, ()):
        if getattr(args, option) is not None:
            check_output_folder(getattr(args, option), option)



def written_by(folder: Path, command: str) -> bool:
    """Whether every run recorded in ``folder/run.json`` was ``python -m bench COMMAND``."""
    try:
        record = json.loads((folder / "run.json").read_text())
        runs = [record, *record.get("earlier", [])]
        return all(str(r.get("command", "")).split()[3:4] == [command] for r in runs)
    except (OSError, ValueError, AttributeError, TypeError):
        return False


def check_compare_out(out: str | Path, overwrite: bool) -> None:
    """``compare`` replaces the results of its folder: refuse a non-empty folder that it did
    not write itself, unless ``--overwrite`` (InputError, before anything is touched)."""
    folder = Path(out)
    if overwrite or not folder.is_dir() or written_by(folder, "compare"):
        return
    if any(p.name not in (".lock", "report") for p in folder.iterdir()):  # report: its own
        raise InputError(f"--out={str(out)!r} holds files that compare did not write (it "
                         "replaces the results of its folder); give a new or empty folder, "
                         "or --overwrite to replace them")


def full_disk(error: OSError) -> str:
    """The line that a full disk ends a command with (``DiskFull`` names the folder and the
    space needed itself)."""
    if isinstance(error, DiskFull):
        return str(error)
    where = f" while writing {error.filename}" if error.filename else ""
    return (f"no space left on the device{where}; free some space and run again: every row "
            "finished before this is kept")
