"""The registries are the only list of names: a formulation, a hard scene, an estimator and a
hard case registered at run time, with no other edit, appear in ``python -m bench list``, in
the matrix, in the hard-case table, in the figures' legend and in the report."""

import functools
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from bench.cli import main
from bench.hard import hard_case, hard_case_names, run_hard, write_hard
from bench.hard.registry import HARD_CASES
from bench.matrix import RunConfig, run
from bench.measure.contact import SOLVED_STATUSES as SOLVED
from bench.report import figures, panels, write_report
from conftest import square_scene
from estimators.base import ESTIMATORS, register_estimator
from estimators.residual import triangles as residual
from formulations.methods import mixed
from formulations.registry import FORMULATIONS, register_formulation
from scenes.registry import SCENES, register_scene

NEW_FORMULATION, NEW_SCENE = "mixed-quarter", "pressed-square"
NEW_ESTIMATOR, NEW_CASE = "residual-copy", "constant-case"


@pytest.fixture(scope="module")
def registered():
    register_formulation(NEW_FORMULATION, "the mixed method with h/H = 1/4")(
        functools.partial(mixed.discretise, h_over_H=0.25))
    register_scene(NEW_SCENE, "hard: a flat obstacle presses a square up by 0.01",
                   tags=("hard",), dim=2)(
        lambda: replace(square_scene(lambda x: np.full(x.shape[1:], -0.01), name=NEW_SCENE),
                        tags=("hard",)))
    register_estimator(NEW_ESTIMATOR, "the residual estimator again")(residual.estimate)
    hard_case(NEW_CASE, "one accurate record")(lambda: [dict(
        case=NEW_CASE, scene="-", formulation="-", solver="-", variant="", verdict="accurate")])
    yield
    FORMULATIONS.unregister(NEW_FORMULATION)
    SCENES.unregister(NEW_SCENE)
    ESTIMATORS.unregister(NEW_ESTIMATOR)
    HARD_CASES.unregister(NEW_CASE)


@pytest.fixture(scope="module")
def results(registered, tmp_path_factory):
    out = tmp_path_factory.mktemp("registered")
    result = run(RunConfig(scenes=("paper", NEW_SCENE), formulations=("mixed", NEW_FORMULATION),
                           solvers=("active-set",), estimators=("residual", NEW_ESTIMATOR),
                           strategies=("uniform", "adaptive"), max_dofs=600, out=str(out)))
    write_hard(run_hard([NEW_SCENE, NEW_CASE]), out)
    return out, result


def test_list_shows_both(registered, capsys):
    assert main(["list"]) == 0
    listed = capsys.readouterr().out
    for name in (NEW_FORMULATION, NEW_ESTIMATOR, NEW_CASE):
        assert f"  {name} " in listed
    assert listed.count(f"  {NEW_SCENE} ") == 2  # as a scene and as a hard case
    assert {NEW_SCENE, NEW_CASE} <= set(hard_case_names())


def test_the_matrix_runs_both(results):
    _, result = results
    table = result.table
    assert {NEW_FORMULATION, "mixed"} == set(table["formulation"])
    assert {NEW_ESTIMATOR, "residual"} == set(table["estimator"])
    assert NEW_SCENE in set(table["scene"])
    assert table["status"].isin(SOLVED).all()
    # h/H = 1/4 really reached the discretisation
    assert table.loc[table["formulation"] == NEW_FORMULATION, "max_h_over_H"].eq(0.25).all()


def test_the_hard_table_has_the_scene_with_every_formulation(results):
    out, _ = results
    hard = pd.read_csv(out / "hard.csv")
    assert set(hard["case"]) == {NEW_SCENE, NEW_CASE}
    assert NEW_FORMULATION in set(hard["formulation"])
    assert (hard["verdict"] == "accurate").all()


def test_figures_give_the_new_formulation_its_own_colour_and_legend(results):
    _, result = results
    paper = result.table[result.table["scene"] == "paper"]
    figure = panels.convergence(paper)
    assert NEW_FORMULATION in [ax.get_title() for ax in figure.axes]  # its own panel
    assert NEW_ESTIMATOR in [t.get_text() for t in figure.legends[0].get_texts()]
    assert panels.estimator_colour(NEW_ESTIMATOR) != panels.estimator_colour("residual")
    assert figures.colour(NEW_FORMULATION) != figures.colour("mixed")
    assert figures.line_style(NEW_ESTIMATOR) != figures.line_style("residual")


def test_the_report_shows_both(results, tmp_path):
    out, result = results
    readme = write_report(pd.read_parquet(out / "results.parquet"), tmp_path, out).read_text()
    assert all(name in readme for name in (NEW_FORMULATION, NEW_SCENE, NEW_ESTIMATOR))
    hard_section = readme.split("Hard cases", 1)[1]
    assert NEW_SCENE in hard_section and NEW_FORMULATION in hard_section


def test_a_registered_backend_is_offered_and_solves(tmp_path):
    """A back-end is one module and one ``register_backend``: a dense Cholesky one here."""
    from scipy import linalg

    from formulations.solvers.backends import (
        Backend,
        CondensedFactor,
        register_backend,
        unregister_backend,
    )

    def factorise(K):
        factor = linalg.cho_factor(K.toarray(), lower=True)
        return lambda b: linalg.cho_solve(factor, b)

    def condense(K, interior, contact):
        dense = K.toarray()
        schur = dense[np.ix_(contact, contact)] - dense[np.ix_(contact, interior)] @ \
            np.linalg.solve(dense[np.ix_(interior, interior)], dense[np.ix_(interior, contact)])
        return CondensedFactor("dense", contact, factorise(K), linalg.cholesky(schur, lower=True))

    register_backend(Backend("dense", rank=9, factorise=factorise, condense=condense))
    try:
        out = tmp_path / "r"
        assert main(["run", "--scene", "paper", "--formulation", "mixed", "--solver",
                     "active-set", "--estimator", "residual", "--strategy", "uniform",
                     "--max-dofs", "600", "--backend", "dense", "--out", str(out)]) == 0
        table = pd.read_parquet(out / "results.parquet")
        assert (table["backend"] == "dense").all() and table["status"].isin(SOLVED).all()
        assert (table["stationarity"] < 1e-10).all()
    finally:
        unregister_backend("dense")
