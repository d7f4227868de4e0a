"""Batches of design variants (``linkage.analyze_variants``): each variant equals the same
mechanism loaded from its own scheme text and analysed alone; variants whose branch contradicts
the declared condition, or whose motion changes assembly mode, are flagged; bad input is refused
with a message naming the entry."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import linkage
from linkage.kinematics.batch import OTHER_BRANCH, analyze_variants, geometry_of
from linkage.errors import InputError

SCHEMES = Path(__file__).resolve().parent.parent / "schemes"
PHI = np.radians(np.arange(0.0, 360.0, 30.0))


def four_bar_text(oa: float, ab: float, cb: float, cx: float, condition: str = 'left_of = ["A", "C"]') -> str:
    """The shipped four-bar's scheme with other dimensions (written out, not derived from the batch)."""
    text = (SCHEMES / "four_bar.toml").read_text()
    for old, new in (("C = [0.3, 0.0]", f"C = [{cx!r}, 0.0]"), ("length = 0.1\n", f"length = {oa!r}\n"),
                     ("length = 0.3\n", f"length = {ab!r}\n"), ("length = 0.25\n", f"length = {cb!r}\n"),
                     ('left_of = ["A", "C"]', condition)):
        assert old in text
        text = text.replace(old, new)
    return text


def four_bar_geometry(dims: np.ndarray) -> dict:
    """The batch geometry of four-bars with rows (OA, AB, CB, Cx): a line link's second point lies
    at (length, 0) in its frame (the scheme format's rule for ``line``)."""
    zero = np.zeros(len(dims))
    return {"0": {"C": np.column_stack([dims[:, 3], zero])}, "1": {"A": np.column_stack([dims[:, 0], zero])},
            "2": {"B": np.column_stack([dims[:, 1], zero])}, "3": {"B": np.column_stack([dims[:, 2], zero])}}


def test_each_variant_equals_its_own_scheme_analysed_alone():
    rng = np.random.default_rng(11)
    dims = np.array([0.1, 0.3, 0.25, 0.3]) * (1 + 0.15 * (rng.random((6, 4)) - 0.5))
    dims[5] = [0.4, 0.3, 0.25, 0.3]          # a variant that cannot be assembled at some angles
    batch = analyze_variants(linkage.load("four_bar"), PHI, four_bar_geometry(dims))
    assert batch.poses["3"].shape == (6, 12, 3) and batch.count == 6
    for v, row in enumerate(dims):
        alone = linkage.analyze(linkage.loads(four_bar_text(*map(float, row))), PHI, on_failure="mask")
        np.testing.assert_array_equal(batch.status[v], alone.status)
        for link in ("1", "2", "3"):
            for got, want in ((batch.poses, alone.poses), (batch.first, alone.first), (batch.second, alone.second)):
                np.testing.assert_allclose(got[link][v], want[link], rtol=1e-13, atol=1e-15)
        for point in ("B", "E"):
            np.testing.assert_allclose(batch.point(point)[v], alone.point(point), rtol=1e-13, atol=1e-15)
            np.testing.assert_allclose(batch.point_analogs(point)[1][v], alone.point_analogs(point)[1],
                                       rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(batch.error_bound[v], alone.error_bound, rtol=1e-12)
    assert np.any(batch.status[5] == -1) and np.all(batch.status[:5] == 0)


def test_a_slider_crank_batch_with_a_prismatic_pair_and_geometry_of():
    text = (SCHEMES / "slider_crank.toml").read_text()
    mechs = [linkage.loads(text.replace("length = 0.0742", f"length = {crank!r}")
                           .replace("length = 0.2225", f"length = {rod!r}"))
             for crank, rod in ((0.0742, 0.2225), (0.06, 0.25), (0.09, 0.2))]
    batch = analyze_variants(mechs[0], PHI, geometry_of(mechs))
    for v, mech in enumerate(mechs):
        alone = linkage.analyze(mech, PHI)
        np.testing.assert_allclose(batch.point("B")[v], alone.point("B"), rtol=1e-13, atol=1e-15)
        np.testing.assert_allclose(batch.second["3"][v], alone.second["3"], rtol=1e-12, atol=1e-14)
        # the stroke in closed form: sqrt((rod + r)^2 - e^2) - sqrt((rod - r)^2 - e^2)
        r, rod, e = mech.links["1"].points["A"][0], mech.links["2"].points["B"][0], 0.01335
        fine = analyze_variants(mechs[0], np.linspace(0, 2 * np.pi, 3601), geometry_of(mechs), order=0)
        x = fine.point("B")[v][:, 0]
        assert np.ptp(x) == pytest.approx(np.sqrt((rod + r) ** 2 - e**2) - np.sqrt((rod - r) ** 2 - e**2), rel=1e-6)


def test_a_variant_whose_branch_contradicts_the_declared_condition_is_flagged():
    """Condition "B from O towards +y": for the base the closed-form branch (B left of A -> C)
    puts B above; a variant with the frame pivot C on the other side (-x) puts that branch's B
    below the frame line, so it is flagged OTHER_BRANCH instead of returned as OK."""
    base = linkage.loads(four_bar_text(0.1, 0.3, 0.25, 0.3, 'towards_deg = 90\n"from" = "O"'))
    dims = np.array([[0.1, 0.3, 0.25, 0.3], [0.1, 0.3, 0.25, -0.3]])
    batch = analyze_variants(base, PHI, four_bar_geometry(dims))
    assert np.all(batch.status[0] == 0)
    assert np.all(batch.status[1] == OTHER_BRANCH)
    assert np.all(batch.point("B")[1][:, 1] < 0)       # indeed below: the other assembly mode


@pytest.mark.parametrize("geometry, message", [
    ({"9": {"A": np.zeros((2, 2))}}, "no link '9'"),
    ({"1": {"Z": np.zeros((2, 2))}}, "link '1' has no point 'Z'"),
    ({"1": {"A": np.zeros((2, 3))}}, r"shape \(V, 2\), got \(2, 3\)"),
    ({"1": {"A": [[0.1, 0.0], [np.nan, 0.0]]}}, "variant 1 is not finite"),
    ({"1": {"A": np.zeros((2, 2))}, "2": {"B": np.zeros((3, 2))}}, "same number of variants"),
    ({}, "at least one point"),
])
def test_bad_geometry_is_refused_with_the_entry_named(geometry, message):
    with pytest.raises(InputError, match=message):
        analyze_variants(linkage.load("four_bar"), PHI, geometry)


def test_raise_mode_names_the_first_bad_variant():
    dims = np.array([[0.1, 0.3, 0.25, 0.3], [0.4, 0.3, 0.25, 0.3]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")      # no warning comes before the refusal
        with pytest.raises(linkage.AssemblyError, match="variant 1"):
            analyze_variants(linkage.load("four_bar"), PHI, four_bar_geometry(dims), on_failure="raise")
