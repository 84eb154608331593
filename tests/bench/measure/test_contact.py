"""Contact-zone measures: Jaccard's distance of two zones, against overlaps done by hand."""

import pytest


def test_zone_jaccard_is_one_minus_overlap_over_union():
    from bench.measure.contact import zone_jaccard

    assert zone_jaccard((-1.0, 1.0), (-1.0, 1.0)) == 0.0
    assert zone_jaccard((0.0, 2.0), (1.0, 3.0)) == pytest.approx(1 - 1 / 3)  # overlap 1, union 3
    assert zone_jaccard((0.0, 1.0), (2.0, 3.0)) == 1.0
    nan = float("nan")
    assert zone_jaccard((nan, nan), (0.0, 1.0)) == 1.0 and zone_jaccard((nan, nan), (nan, nan)) == 0
