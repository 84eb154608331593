"""A semismooth system whose Newton iteration fails is solved as its formulation's QP
(formulations.discretisation.solve): on hertz, penalty P2 adaptive, the plain iteration
revisits an active set and the damped one stalls at |R| = 25 on the level of 1198 DOFs; the
QP method answers it, and the reference solver agrees."""

import pandas as pd

from bench.cli import main


def test_the_qp_method_answers_where_semismooth_newton_fails(tmp_path):
    out = tmp_path / "r"
    assert main(["run", "--scene", "hertz", "--formulation", "penalty", "--order", "2",
                 "--strategy", "adaptive", "--max-dofs", "1300", "--crosscheck-dofs", "3000",
                 "--out", str(out)]) == 0
    rows = pd.read_parquet(out / "results.parquet").set_index("ndofs")
    assert (rows["status"] == "ok").all()
    assert rows.loc[1198, "safeguard"].startswith("the QP method")
    # the reference solver's answer: 2.3e-9 measured; 1e-7 is its tolerance's scale
    assert rows.loc[1198, "crosscheck_energy_difference"] <= 1e-7
