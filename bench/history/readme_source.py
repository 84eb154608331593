"""The comparison's headline as an earlier commit recorded it (docs/history.md, "Earlier
commits"): the README's compare block (``bench/cli/compare_block.py`` writes it from a run)
holds, per scene, the recommended combination's time and DOFs to each target and the run's
wall time. Read from ``git show COMMIT:README.md``, it gives the history figures of commits
whose results folders are gone, recorded as the ``compare`` source's (the same names), so
that a new comparison's figures are judged against them."""

from __future__ import annotations

import math
import re
import subprocess

ANSWER = re.compile(r"^- (?P<scene>[\w-]+): use .*?: (?P<reached>.*?); stop", re.M)
REACHED = re.compile(r"(?P<target>[0-9.e-]+) in (?P<seconds>[0-9.e+-]+) s \((?P<dofs>\d+) DOFs\)")
WALL = re.compile(r"; (?P<seconds>\d+) s wall time in all")


def headline(text: str) -> list[tuple]:
    """The figures of one README's compare block (none if it has no block)."""
    out = []
    for answer in ANSWER.finditer(text):
        for reached in REACHED.finditer(answer["reached"]):
            where = f"{answer['scene']} to {float(reached['target']):g}"
            out.append((f"{where}: seconds", float(reached["seconds"]), "time", math.nan))
            out.append((f"{where}: DOFs", float(reached["dofs"]), "count", math.nan))
    wall = WALL.search(text)
    if wall:
        out.append(("wall time", float(wall["seconds"]), "time", math.nan))
    return out


def readme_commits(count: int, path: str = "README.md") -> list[tuple[str, str, str]]:
    """(commit, its ISO date, its README's text) of the last ``count`` commits that changed
    ``path``, oldest first."""
    log = subprocess.run(["git", "log", f"-n{int(count)}", "--format=%h %cI", "--", path],
                         check=True, capture_output=True, text=True).stdout.split("\n")
    out = []
    for line in filter(None, log):
        commit, date = line.split()
        text = subprocess.run(["git", "show", f"{commit}:{path}"], check=True,
                              capture_output=True, text=True).stdout
        out.append((commit, date, text))
    return out[::-1]
