"""The hard cases as a verdict matrix: one row per case (and variant), one column per
formulation/solver, each cell the verdict, its finding kept for the HTML's tooltip; skipped
combinations sharing a reason collapse into one line (docs/verification.md)."""

from __future__ import annotations

from dataclasses import dataclass

import pandas as pd


@dataclass(frozen=True)
class VerdictMatrix:
    """``verdicts`` and ``findings``: DataFrames indexed by case (and variant), one column per
    formulation/solver; ``skips``: one line per distinct reason of the skipped rows;
    ``notes``: every row that is not accurate, with its finding (a failure's reason)."""

    verdicts: pd.DataFrame
    findings: pd.DataFrame
    skips: tuple[str, ...]
    notes: tuple[str, ...] = ()


def _label(row) -> str:
    variant = row.get("variant", "")
    variant = "" if pd.isna(variant) else str(variant)
    return str(row["case"]) + (f" ({variant})" if variant else "")


def verdict_matrix(table: pd.DataFrame) -> VerdictMatrix:
    """The matrix of ``table`` (hard.csv's rows)."""
    rows = table.copy()
    rows["row"] = [_label(r) for _, r in rows.iterrows()]
    for column in ("formulation", "solver"):
        rows[column] = rows[column].fillna("").astype(str)
    rows["column"] = (rows["formulation"] + "/" + rows["solver"]).str.strip("/")
    skipped = rows["status"].eq("skipped") if "status" in rows else rows["row"].eq(None)
    skips = rows[skipped].groupby("reason", sort=True)["row"].apply(list)
    lines = tuple(f"{len(names)} skipped ({', '.join(sorted(set(names)))}): {reason}"
                  for reason, names in skips.items())
    judged = rows[~skipped]
    def text(column: str) -> pd.Series:
        return judged.get(column, pd.Series("", index=judged.index)).astype(object).fillna("")\
            .astype(str)

    finding = text("finding") + text("reason").map(lambda r: f" ({r})" if r else "")
    judged = judged.assign(finding_text=finding)
    verdicts = judged.pivot_table(index="row", columns="column", values="verdict",
                                  aggfunc="first", sort=True).fillna("")
    findings = judged.pivot_table(index="row", columns="column", values="finding_text",
                                  aggfunc="first", sort=True).reindex_like(verdicts).fillna("")
    notes = tuple(f"{r['row']}, {r['column']}: {r['verdict']}: {r['finding_text'].strip()}"
                  for _, r in judged[judged["verdict"] != "accurate"].iterrows())
    return VerdictMatrix(verdicts, findings, lines, notes)


def matrix_markdown(matrix: VerdictMatrix) -> str:
    """The verdicts as a Markdown table, then the collapsed skips."""
    text = matrix.verdicts.reset_index().rename(columns={"row": "case"}).to_markdown(
        index=False) if len(matrix.verdicts) else "No judged rows."
    notes = "".join(f"\n- {line}" for line in matrix.notes)
    return (text + "".join(f"\n\n{line}" for line in matrix.skips)
            + (f"\n\nNot accurate:\n{notes}" if notes else ""))


def matrix_html(matrix: VerdictMatrix) -> str:
    """An HTML table, each cell classed by its verdict and titled with its finding."""
    from html import escape

    head = "".join(f"<th>{escape(c)}</th>" for c in matrix.verdicts.columns)
    body = []
    for case, verdicts in matrix.verdicts.iterrows():
        cells = "".join(
            f'<td class="verdict {escape(v)}" title="{escape(matrix.findings.at[case, c])}">'
            f"{escape(v)}</td>" for c, v in verdicts.items())
        body.append(f"<tr><th>{escape(str(case))}</th>{cells}</tr>")
    skips = "".join(f"<p>{escape(line)}</p>" for line in matrix.skips)
    if matrix.notes:
        skips += ("<p>Not accurate:</p><ul>"
                  + "".join(f"<li>{escape(line)}</li>" for line in matrix.notes) + "</ul>")
    return (f'<div class="table-scroll"><table class="verdicts"><thead><tr><th>case</th>{head}'
            f"</tr></thead><tbody>{''.join(body)}</tbody></table></div>{skips}")
