"""The README's compare figures come from the results folder of the run."""

import pandas as pd
import pytest

from bench.cli import main
from bench.cli.compare_block import README_END, README_START, check_readme, write_compare_block


def test_the_block_counts_the_rows_and_verdicts_of_the_folder(tmp_path):
    out = tmp_path / "r"
    assert main(["run", "--scene", "free-boundary", "--solver", "active-set", "--strategy",
                 "uniform,adaptive", "--max-dofs", "300", "--out", str(out)]) == 0
    assert main(["hard", "--case", "no-contact", "--out", str(out)]) == 0
    readme = tmp_path / "README.md"
    readme.write_text(f"before\n{README_START}\nold\n{README_END}\nafter\n")
    write_compare_block(readme, out, 12.3)
    text = readme.read_text()
    rows, hard = pd.read_csv(out / "results.csv"), pd.read_csv(out / "hard.csv")
    statuses = rows["status"].value_counts()  # the coarsest levels may miss the contact
    by_status = ", ".join(f"{statuses[s]} {s}" for s in sorted(statuses.index))
    assert set(statuses.index) <= {"ok", "contact unresolved"}
    assert f"**{len(rows)} result rows** ({by_status}) in 2 sequences" in text
    assert text.startswith("before\n") and text.endswith("after\n") and "old" not in text
    assert "hard verdicts as expected" in text and "12 s wall time" in text
    assert len(hard) > 0


def test_compare_refuses_a_readme_without_markers_before_running(tmp_path, capsys):
    readme = tmp_path / "README.md"
    readme.write_text("no markers\n")
    assert main(["compare", "--readme", str(readme), "--out", str(tmp_path / "r"),
                 "--reports", str(tmp_path / "rep")]) == 2
    assert "is not a file with the markers" in capsys.readouterr().err
    assert not (tmp_path / "r" / "results.parquet").exists()
    with pytest.raises(ValueError):
        check_readme(tmp_path / "missing.md")


def test_the_repository_readme_has_the_markers():
    from pathlib import Path

    check_readme(Path(__file__).parents[3] / "README.md")
