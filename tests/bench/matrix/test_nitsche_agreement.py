"""Nitsche's method against the P3 reference on the paper scene, beside the mixed method."""

import json

import pytest

from bench.matrix import RunConfig, run
from bench.measure.contact import SOLVED_STATUSES as SOLVED


@pytest.mark.slow  # solves against a paper reference built on a fresh clone: ~37 s
def test_nitsche_energy_is_as_close_to_the_reference_as_the_mixed_methods(tmp_path):
    result = run(RunConfig(scenes=("paper",), formulations=("mixed", "nitsche"),
                           solvers=("active-set",), strategies=("adaptive",), max_dofs=20000,
                           reference_dofs=200000, out=str(tmp_path)))
    reference = json.loads((tmp_path / "truth.json").read_text())["paper"]["energy"]
    table = result.table
    assert table["status"].isin(SOLVED).all()
    finest = table.sort_values("level").groupby("formulation").tail(1).set_index("formulation")
    gap = (finest["energy"] - reference).abs()
    # both converge to the reference energy 402.2811 (its own error 2.5e-4 in the energy
    # norm); measured at the finest adaptive P1 level (~15 000 .. 20 000 DOFs): nitsche within
    # a factor 2 of mixed's distance, as its O(h) energy-norm error predicts
    assert gap["nitsche"] <= 2 * gap["mixed"], gap.to_dict()
    assert gap.max() < 0.01 * reference  # and both within 1 % in energy
