"""The documentation site builds with --strict (no broken link, no missing page, every page in
the navigation), and the README stays short: what it answers, the two commands, reading the
report, the commands, links."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).parents[1]


def test_the_site_builds_strictly(tmp_path):
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-q", "-d",
                           str(tmp_path / "site")], cwd=ROOT, capture_output=True, text=True,
                          env={"NO_MKDOCS_2_WARNING": "1", "PATH": ""})
    assert done.returncode == 0, done.stdout + done.stderr
    api = (tmp_path / "site" / "api" / "index.html").read_text()
    assert "CellFamily" in api and "RunConfig" in api  # the reference is generated


def test_every_docs_page_is_in_the_navigation():
    nav = (ROOT / "mkdocs.yml").read_text()
    pages = sorted(p.name for p in (ROOT / "docs").glob("*.md"))
    assert [p for p in pages if p not in nav] == []


def test_the_readme_is_short_and_links_the_docs():
    text = (ROOT / "README.md").read_text()
    assert len(text.encode()) <= 20_000  # about one page to scroll, not 96 KB
    for section in ("## Quick start", "## Reading the report", "## Commands",
                    "## Documentation"):
        assert section in text
    # no 1 000-character lines (but the one line compare writes between its markers)
    start, end = text.index("<!-- compare:start -->"), text.index("<!-- compare:end -->")
    prose = text[:start] + text[end:]
    assert max(len(line) for line in prose.splitlines()) <= 110
