"""The report: renders from a small results table, self-contained HTML, escaping, missing data,
and a real browser."""

import base64
import shutil
import subprocess
from html.parser import HTMLParser

import numpy as np
import pandas as pd
import pytest

from bench.hard import run_hard, write_hard
from bench.matrix import RunConfig, run
from bench.report import write_report
from formulations import formulation_names, solver_names

SECTIONS = ["summary", "questions", "contents", "what-was-run", "scenes", "results-per-scene",
            "summary-across-scenes", "failures-and-skips", "hard-cases", "known-limitations"]
PNG = b"\x89PNG\r\n\x1a\n"


class Collector(HTMLParser):
    def __init__(self):
        super().__init__()
        self.ids, self.images, self.external, self.scripts = [], [], [], 0
        self.anchors = []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if "id" in attrs:
            self.ids.append(attrs["id"])
        if tag == "img":
            self.images.append(attrs.get("src", ""))
        if tag == "a" and attrs.get("href", "").startswith("#"):
            self.anchors.append(attrs["href"][1:])
        if (tag == "script" and "src" in attrs) or tag == "link" or (
                tag == "img" and not attrs.get("src", "").startswith("data:")):
            self.external.append(tag)
        self.scripts += tag == "script"


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    out = tmp_path_factory.mktemp("results")
    run(RunConfig(scenes=("paper", "free-boundary"), formulations=("mixed", "vi"),
                  solvers=("active-set",), strategies=("uniform", "adaptive"), max_dofs=600,
                  crosscheck_dofs=600, out=str(out)))
    write_hard(run_hard(["no-contact", "penalty-eps", "invalid"]), out)
    return out


@pytest.fixture(scope="module")
def report(results, tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    write_report(pd.read_parquet(results / "results.parquet"), out, results, "test command")
    return out


def test_html_is_self_contained_with_every_section_and_figure(report):
    html = (report / "index.html").read_text()
    parser = Collector()
    parser.feed(html)
    assert [s for s in SECTIONS if s not in parser.ids] == []
    assert [a for a in parser.anchors if a not in parser.ids] == []  # every link lands
    assert parser.external == []  # no linked scripts, stylesheets or images
    assert parser.scripts == 0  # static: nothing to load or run
    # PNG: 2 scenes x (scene, convergence, work-precision, meshes, deformed, pressure), the
    # free-boundary's effectivity (the paper has no truth without --reference-dofs), the hard
    # cases' figure and the estimators' effectivity across scenes
    assert len(parser.images) == 15
    # a light page: at most 5 MB (it was 10.5 MB with plotly's JavaScript and every PNG)
    assert len(html.encode()) <= 5_000_000
    for src in parser.images:
        assert src.startswith("data:image/png;base64,")
        data = base64.b64decode(src.split(",", 1)[1])
        assert data.startswith(PNG) and len(data) > 5000


def test_markdown_links_every_figure_file(report):
    text = (report / "README.md").read_text()
    for title in ("## Summary", "## Contents", "## Appendix: what was run", "## Scenes",
                  "## Results per scene",
                  "## Summary across scenes", "## Failures and skips", "## Hard cases",
                  "## Known limitations"):
        assert title in text
    hard = text.split("## Hard cases")[1].split("## Known limitations")[0]
    # the verdict matrix: one row per case, a refused row's finding listed below it
    assert "poisson_ratio=0.5 is not < 0.5" in hard and "refused" in hard
    # every formulation with every solver that has a method for it (nitsche's theta = 1 has a
    # QP form for the reference, so every registered pair here): one column each
    row = next(line for line in hard.splitlines() if line.startswith("| no-contact "))
    assert row.count("accurate") == len(formulation_names()) * len(solver_names())
    figures = sorted(p.name for p in (report / "figures").glob("*.png"))
    assert len(figures) == 15 and "hard-penalty-eps.png" in figures  # the case brings it
    for name in figures:
        assert f"figures/{name}" in text
    assert "test command" in text and "agrees" in text  # rates verdicts against the claims
    verdict = text.split("## Verdict", 1)[1].split("## Questions you may bring", 1)[0]
    assert "| free-boundary | " in verdict and "| paper " in verdict
    assert "slopes agree" in verdict and "reach" in verdict  # "k of n reach it" or "none"
    questions = text.split("## Questions you may bring", 1)[1].split("## Contents", 1)[0]
    assert questions.count("### ") >= 5 and "](#estimators)" in questions
    assert '<a id="estimators"></a>' in text  # where the link lands
    assert text.index("## Verdict") < text.index("## Appendix: what was run")
    assert "numerical stack" in text and "threads" in text  # the appendix's versions


def test_strings_from_results_are_escaped_and_missing_columns_reported(results, tmp_path):
    table = pd.read_parquet(results / "results.parquet")
    table.loc[table.index[0], "status"] = "failed"
    table.loc[table.index[0], "reason"] = "<script>alert('x')</script> & co"
    table = table.drop(columns=["effectivity_index", "t_refine"])
    write_report(table, tmp_path, None)
    html = (tmp_path / "index.html").read_text()
    assert "<script>alert" not in html
    assert "&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt; &amp; co" in html
    assert "effectivity_index" in html and "t_refine" in html  # listed as missing
    assert "Missing columns" in (tmp_path / "README.md").read_text()


def test_report_of_only_failed_rows_still_renders(tmp_path):
    table = pd.DataFrame([{"scene": "paper", "formulation": "mixed", "solver": "reference",
                           "estimator": "residual", "strategy": "uniform", "level": -1,
                           "status": "failed", "reason": "RuntimeError: boom", "run_id": "1"}])
    write_report(table, tmp_path)
    text = (tmp_path / "README.md").read_text()
    assert "RuntimeError: boom" in text
    assert "Not run for these results (no `hard.csv`" in text


CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is not installed "
                                             "(.ci/run installs it)")
def test_html_renders_in_headless_chromium(report, tmp_path):
    shot = tmp_path / "shot.png"
    run = subprocess.run(
        [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
         "--no-first-run", "--disable-background-networking", "--disable-component-update",
         "--disable-sync", f"--user-data-dir={tmp_path / 'profile'}", "--enable-logging=stderr",
         "--v=0", "--window-size=1280,2400", f"--screenshot={shot}",
         (report / "index.html").as_uri()], capture_output=True, text=True, timeout=120)
    assert shot.exists(), run.stderr[-2000:]
    console = [line for line in run.stderr.splitlines() if "CONSOLE" in line
               or "Failed to load resource" in line or "Uncaught" in line]
    assert console == []
    from matplotlib.image import imread

    pixels = imread(shot)
    assert pixels.shape[0] > 1000 and float(np.std(pixels[..., :3])) > 0.05  # not blank


LAYOUT_PROBE = """<script>
window.addEventListener('load', () => {
  const advice = document.querySelector('#summary ul.recommendations').getBoundingClientRect();
  const cut = [...document.querySelectorAll('table')].filter(
    t => !t.parentElement.classList.contains('table-scroll')
         && t.scrollWidth > t.parentElement.clientWidth).length;
  document.body.setAttribute('data-layout', JSON.stringify({
    adviceTop: advice.top, adviceBottom: advice.bottom, viewport: window.innerHeight,
    cut: cut, height: document.documentElement.scrollHeight,
    sentences: [...document.querySelectorAll('#summary ul.recommendations li')].map(
      li => li.textContent),
    headers: [...document.querySelectorAll('#summary th')].map(t => t.textContent),
    pageOverflow: document.documentElement.scrollWidth - window.innerWidth}));
});
</script>"""
SCREEN = (1400, 900)  # the window the first screen is measured in
MAX_SCREENS = 15  # the page's height, folded details closed


@pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is not installed "
                                             "(.ci/run installs it)")
def test_first_screen_holds_every_recommendation_and_no_table_overflows(report, tmp_path):
    import json
    import re

    probe = tmp_path / "probe.html"  # the report plus a measuring script (test side only)
    probe.write_text((report / "index.html").read_text().replace("</body>",
                                                                 LAYOUT_PROBE + "</body>"))
    browser = [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
               "--disable-background-networking", "--disable-component-update",
               f"--user-data-dir={tmp_path / 'profile'}",
               f"--window-size={SCREEN[0]},{SCREEN[1]}", "--virtual-time-budget=10000"]
    dom = subprocess.run([*browser, "--dump-dom", probe.as_uri()], capture_output=True,
                         text=True, timeout=120).stdout
    layout = json.loads(re.search(r"data-layout=\"([^\"]*)\"", dom).group(1)
                        .replace("&quot;", '"'))
    # one recommendation per scene, whole, on the first screen
    assert 0 <= layout["adviceTop"] and layout["adviceBottom"] <= layout["viewport"]
    assert [s.split(":")[0] for s in layout["sentences"]] == ["free-boundary", "paper"]
    assert any(h.startswith("cheapest to 0.01") for h in layout["headers"])
    assert any(h.startswith("stop on") for h in layout["headers"])
    assert layout["cut"] == 0 and layout["pageOverflow"] <= 0  # wide tables scroll in a box
    assert layout["height"] <= MAX_SCREENS * SCREEN[1]
    shot = tmp_path / "first-screen.png"
    subprocess.run([*browser, f"--screenshot={shot}", (report / "index.html").as_uri()],
                   capture_output=True, timeout=120)
    from matplotlib.image import imread

    assert float(np.std(imread(shot)[..., :3])) > 0.05  # the first screen is not blank


@pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is not installed "
                                             "(.ci/run installs it)")
def test_the_page_renders_within_three_seconds(report, tmp_path):
    """The page's own render time: a screenshot of it, less one of an empty page (the
    browser's start)."""
    import time

    def seconds(url: str) -> float:
        start = time.perf_counter()
        subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu",
                        "--no-first-run", "--disable-background-networking",
                        f"--user-data-dir={tmp_path / 'profile'}", "--window-size=1280,2400",
                        f"--screenshot={tmp_path / 'shot.png'}", url], capture_output=True,
                       timeout=120)
        return time.perf_counter() - start

    blank = min(seconds("about:blank") for _ in range(2))
    page = min(seconds((report / "index.html").as_uri()) for _ in range(2))
    # the target: 3 s on the 2-core machine (measured 0.3 s for a 1.9 MB page; the 10.5 MB
    # page with plotly took about 7 s)
    assert page - blank <= 3.0
