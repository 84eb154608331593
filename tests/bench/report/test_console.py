"""The console's last lines: at most ten, naming index.html, one headline per scene, the hard
verdicts as counts and only the rows that were not as expected."""

import pandas as pd
import pytest

import bench.cli.commands as commands
from bench.cli import main
from bench.report.console import MAX_LINES, console_summary, duration
from bench.sequence.rows import ResultRow


def test_report_ends_with_the_report_paths_and_a_headline(finished_run, tmp_path, capsys):
    assert main(["report", "--results", str(finished_run), "--out", str(tmp_path)]) == 0
    last = capsys.readouterr().out.strip().splitlines()[-3:]
    assert last[0] == (f"report: {tmp_path / 'index.html'} (open in a browser), "
                       f"{tmp_path / 'README.md'}")
    # the recommendation sentence (this small run reaches no 1e-2: it says so)
    assert last[2].startswith("free-boundary: ") and last[2].endswith(".")


@pytest.mark.slow  # a whole (small) compare run: ~32 s on a fresh clone
def test_compare_ends_with_at_most_ten_lines_naming_index_html(tmp_path, capsys, monkeypatch):
    # the whole comparison on one scene and one hard case (the wiring, not the catalogue)
    monkeypatch.setattr(commands, "compared_scenes", lambda dim: ["free-boundary"])
    settings = commands.compare_settings  # its parts' own scene lists: the one scene too

    def one_scene(**kw):
        out = settings(**kw)
        return {**out, "parts": tuple(tuple((k, v) for k, v in dict(part).items()
                                            if k != "scenes") for part in out["parts"])}

    monkeypatch.setattr(commands, "compare_settings", one_scene)
    real = commands.run_hard
    monkeypatch.setattr(commands, "run_hard",
                        lambda cases, **kw: real(["no-contact"], **kw))
    # every part at most 400 DOFs (P3 starts at 312), in-process, the candidates timed once more
    assert main(["compare", "--max-dofs", "400", "--crosscheck-dofs", "0", "--workers", "0",
                 "--timing-repeats", "1", "--out", str(tmp_path / "r"),
                 "--reports", str(tmp_path / "rep")]) == 0
    out = capsys.readouterr().out.rstrip().split("\n\n")[-1].splitlines()
    assert len(out) <= MAX_LINES
    assert out[0].startswith(f"report: {tmp_path / 'rep' / 'index.html'}")
    assert "wall time" in out[1] and out[2].startswith("free-boundary: ")
    assert out[-1].startswith("hard cases: ") and "as expected" in out[-1]


def test_unexpected_hard_rows_are_listed_within_the_ten_lines(tmp_path):
    table = pd.DataFrame([ResultRow(scene="s", formulation="vi", solver="active-set",
                                    estimator="residual", strategy="uniform", level=0,
                                    status="ok", energy_error=1.0, eta=2.0).as_dict()])
    hard = pd.DataFrame([{"case": "no-contact", "formulation": "vi", "solver": "active-set",
                          "variant": "", "verdict": "failed", "status": "failed"}] * 20)
    lines = console_summary(tmp_path / "README.md", table, hard, 75.0)
    assert len(lines) == MAX_LINES and "wall time 1 min 15 s" in lines[1]
    assert lines[-1].startswith("  UNEXPECTED no-contact/vi/active-set/: failed")
    assert "more in hard.md" in lines[-1]
    assert duration(42.0) == "42.0 s"


def test_numbers_in_prose_have_three_significant_figures_and_no_exponent():
    from bench.report.ranking import sig3

    assert [sig3(x) for x in (2123.4, 0.000341, 4.4, 16.0)] == ["2120", "0.000341", "4.4", "16"]
