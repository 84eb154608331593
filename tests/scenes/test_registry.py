"""What a registration declares lives in its registry entry, so undoing an origin (a plugin that
failed half-way) forgets all of it: the unit, its metadata, its cell variants and figures."""

from bench.hard.registry import CASE_FIGURES, case_figure
from estimators.base import (
    ESTIMATOR_VARIANTS,
    ESTIMATORS,
    estimator_on,
    guaranteed_estimators,
    register_cell_variant,
    register_estimator,
    why_not_on,
)
from formulations.cells import family_for
from scenes.registry import registering_as, unregister_origin

ORIGIN = "plugin half-loaded"


def _estimate(scene, solution):
    raise AssertionError("never called")


def _on_quads(scene, solution):
    raise AssertionError("never called")


def test_undoing_an_origin_forgets_its_metadata_variants_and_figures():
    quad = family_for("quad", 2)
    with registering_as(ORIGIN):
        register_estimator("sure-bound", "a test estimator", guaranteed=True)(_estimate)
        register_cell_variant("sure-bound", "quad")(_on_quads)
        case_figure("a-case", "a caption")(lambda rows: None)
    assert "sure-bound" in guaranteed_estimators()
    assert ESTIMATORS.meta("sure-bound", "families") == ("tri", "tet")
    assert estimator_on("sure-bound", "quad") is _on_quads and why_not_on("sure-bound", quad) \
        is None
    assert "a-case" in CASE_FIGURES.names()
    unregister_origin(ORIGIN)
    assert "sure-bound" not in guaranteed_estimators() + ESTIMATORS.names()
    assert "sure-bound@quad" not in ESTIMATOR_VARIANTS.names()
    assert "a-case" not in CASE_FIGURES.names()
    assert "equilibrated" in guaranteed_estimators()  # the built-in ones stay
