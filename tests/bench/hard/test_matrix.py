"""The hard cases' verdict matrix: one row per case (and variant), one column per
formulation/solver, identical skips in one line, every row that is not accurate listed with
its finding."""

import pandas as pd

from bench.hard.matrix import matrix_html, matrix_markdown, verdict_matrix


def table():
    rows = [dict(case="corner", variant="", formulation=f, solver=s, status="ok",
                 verdict="accurate", finding="contact zone [-1, -0.5]", reason="")
            for f in ("mixed", "vi") for s in ("active-set", "reference")]
    rows[1].update(verdict="failed", status="failed", finding="the reference solve failed",
                   reason="max iterations")
    rows += [dict(case="grazing-3d", variant="quad", formulation="", solver="",
                  status="skipped", verdict="refused", finding="", reason="no hexahedra")] * 3
    return pd.DataFrame(rows)


def test_one_row_per_case_one_column_per_pair_and_skips_collapsed():
    matrix = verdict_matrix(table())
    assert list(matrix.verdicts.index) == ["corner"]
    assert list(matrix.verdicts.columns) == ["mixed/active-set", "mixed/reference",
                                             "vi/active-set", "vi/reference"]
    assert matrix.verdicts.at["corner", "mixed/reference"] == "failed"
    assert matrix.skips == ("3 skipped (grazing-3d (quad)): no hexahedra",)
    assert matrix.notes == ("corner, mixed/reference: failed: the reference solve failed "
                            "(max iterations)",)


def test_the_html_cells_carry_their_verdict_class_and_finding():
    html = matrix_html(verdict_matrix(table()))
    assert '<td class="verdict failed" title="the reference solve failed (max iterations)">' \
        in html
    assert "3 skipped" in html and "Not accurate:" in matrix_markdown(verdict_matrix(table()))
