"""The history of figures: recording replaces a commit's entry instead of duplicating it, a
deliberately injected 20 % slowdown and a 20 % looser bound are flagged against ten commits
of ordinary noise, the ordinary noise is not, and the page shows every commit."""

import numpy as np
import pandas as pd
import pytest

from bench.cli.commands import main
from bench.history import append_figures, figures_of, moves, read_history, write_page

RNG = np.random.default_rng(20261205)


def verify_folder(path, effectivity: float):
    path.mkdir(parents=True, exist_ok=True)
    pd.DataFrame([{"gate": "guaranteed bound effectivity at most 3", "combination": "paper/vi",
                   "value": effectivity, "low": 1.0, "high": 3.0, "passed": True},
                  {"gate": "adaptive error rate is O(h)", "combination": "paper/vi",
                   "value": -0.5, "low": -0.6, "high": -0.45, "passed": True}]
                 ).to_csv(path / "verdicts.csv", index=False)
    return path


def scaling_folder(path, seconds: float):
    path.mkdir(parents=True, exist_ok=True)
    pd.DataFrame([{"dim": 2, "order": 1, "backend": "pardiso", "ndofs": 1_000_000,
                   "fast_over_linear": seconds / 3.0, "t_fast_solve": seconds,
                   "t_assemble": 1.2, "peak_gib": 2.7}]).to_csv(path / "scaling.csv",
                                                                 index=False)
    return path


def record(tmp_path, commit: int, effectivity: float, seconds: float):
    stamp = f"2026-12-{commit + 1:02d}T00:00:00"
    figures = (figures_of("verify", verify_folder(tmp_path / f"v{commit}", effectivity),
                          f"c{commit:02d}", stamp)
               + figures_of("scaling", scaling_folder(tmp_path / f"s{commit}", seconds),
                            f"c{commit:02d}", stamp))
    return append_figures(figures, tmp_path / "figures.csv")


@pytest.fixture
def ten_commits(tmp_path):
    for commit in range(10):  # 1 % noise on the bound, 3 % on the time
        record(tmp_path, commit, 1.5 * (1 + 0.01 * RNG.standard_normal()),
               3.3 * (1 + 0.03 * RNG.standard_normal()))
    return tmp_path


def moved_names(path) -> set[str]:
    return {m.name for m in moves(read_history(path / "figures.csv")) if m.moved}


def test_ordinary_noise_is_not_flagged(ten_commits):
    record(ten_commits, 10, 1.5 * 1.01, 3.3 * 1.04)
    assert moved_names(ten_commits) == set()


def test_a_twenty_percent_slowdown_and_looser_bound_are_flagged(ten_commits):
    record(ten_commits, 10, 1.5 * 1.2, 3.3 * 1.2)
    moved = moved_names(ten_commits)
    assert "guaranteed bound effectivity at most 3 [paper/vi]" in moved
    assert "2D P1 pardiso 1000000 DOFs: t_fast_solve" in moved
    assert "2D P1 pardiso 1000000 DOFs: fast_over_linear" in moved
    assert "2D P1 pardiso 1000000 DOFs: t_assemble" not in moved  # it did not move


def test_recording_a_commit_again_replaces_its_entry(tmp_path):
    record(tmp_path, 0, 1.5, 3.3)
    frame = record(tmp_path, 0, 1.6, 3.3)
    assert len(frame) == 6  # two gates, four scaling figures, once
    assert frame.loc[frame["name"].str.startswith("guaranteed"), "value"].item() == 1.6


def test_the_page_shows_every_commit_and_the_moves(ten_commits):
    record(ten_commits, 10, 1.8, 3.3)
    page = write_page(read_history(ten_commits / "figures.csv"),
                      ten_commits / "page").read_text()
    assert page.count("<h2>") == 2 and "c10" in page and "c01" in page
    assert "moved beyond their noise at the last commit: 1" in page


def test_the_command_records_checks_and_refuses_bad_input(tmp_path, capsys):
    history = str(tmp_path / "figures.csv")
    folder = verify_folder(tmp_path / "v", 1.5)
    assert main(["history", "record", f"verify={folder}", "--file", history,
                 "--commit", "abc"]) == 0
    assert "recorded 2 figures of abc" in capsys.readouterr().out
    assert main(["history", "record", f"nothing={folder}", "--file", history]) == 2
    assert "SOURCE=FOLDER with SOURCE one of compare, scaling, verify" in (
        capsys.readouterr().err)
    assert main(["history", "check", "--file", history, "--strict"]) == 0


def test_the_readme_source_reads_a_compare_block():
    from bench.history.readme_source import headline

    text = ("Last run: **1827 result rows**; 296 of 296 hard verdicts as expected; 572 s wall "
            "time in all (references, run, timings, hard cases, report).\n\n"
            "- hertz: use vi adaptive P3 steered by residual: 0.01 in 0.558 s (4002 DOFs), "
            "0.001 in 1.92 s (12768 DOFs); stop on equilibrated-local (effectivity 1.04..1.12, "
            "never below the error).\n")
    figures = {name: value for name, value, _, _ in headline(text)}
    assert figures == {"hertz to 0.01: seconds": 0.558, "hertz to 0.01: DOFs": 4002.0,
                       "hertz to 0.001: seconds": 1.92, "hertz to 0.001: DOFs": 12768.0,
                       "wall time": 572.0}
