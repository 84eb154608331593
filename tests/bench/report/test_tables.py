"""The estimator table's bound parts (bench.report.tables)."""

import math

import pandas as pd

from bench.report.tables import bound_parts_text, worst_part_text


def _levels() -> pd.DataFrame:
    base = dict(scene="hertz", formulation="vi", strategy="uniform", order=1, eta_skew=0.0,
                eta_oscillation=0.0, eta_load=0.0, eta_excess_shear=0.0,
                eta_friction_complementarity=0.0)
    return pd.DataFrame([
        {**base, "ndofs": 500, "effectivity_index": 9.0, "eta_symmetric": 0.0,
         "eta_negative_traction": 1.0},   # coarse: not judged by either text
        {**base, "ndofs": 2000, "effectivity_index": 1.2, "eta_symmetric": 3.0,
         "eta_negative_traction": 1.0},
        {**base, "ndofs": 4160, "effectivity_index": 5.0, "eta_symmetric": 1.0,
         "eta_negative_traction": 3.0},
        {**base, "ndofs": 8000, "effectivity_index": 1.1, "eta_symmetric": 3.0,
         "eta_negative_traction": 1.0},
    ])


def test_the_worst_level_names_its_largest_part():
    # the 4160-DOF level has the largest effectivity from 1e3 DOFs; 3 of its 4 is N
    assert worst_part_text(_levels()) == ("negative traction 75 % (hertz, vi, uniform P1, "
                                          "4160 DOFs, effectivity 5)")


def test_the_median_shares_skip_the_coarse_levels():
    # symmetric's shares 0.75, 0.25, 0.75 (median 75 %); with the 500-DOF level it would
    # be 50 %
    assert bound_parts_text(_levels()) == "symmetric 75 %, negative traction 25 %"


def test_an_estimator_without_parts_gets_no_text():
    rows = _levels().assign(eta_symmetric=math.nan)
    assert worst_part_text(rows) == bound_parts_text(rows) == ""
