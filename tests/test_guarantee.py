"""The status-OK guarantee, tested toward the singular position of every dyad kind.

Where ``analyze`` reports status 0, the first analogs must agree with a 50-digit reference
(mpmath closed forms in ``_edge_mechanisms``, independent of the library's solvers) to
``ANALOG_TOL`` = 1e-8 of the largest first analog of the group and its inputs, and the second
analogs to 10 times that; closer to the singularity the position must be flagged -2, never
returned with wrong numbers. The conditioning is measured at each group's own scale, so
unrelated geometry far away, the units, or a dyad of another size never flag a regular group.
"""

from __future__ import annotations

import numpy as np
import pytest

import linkage
from assur import ANALOG_TOL
from linkage.model.scheme import from_dict, to_dict

from _edge_mechanisms import CASES, CHAIN, reference, relative_errors, rpp_reference, rpp_toml, _derivatives

DISTANCES = [10.0**-k for k in range(1, 17)]


@pytest.mark.parametrize("case", [*CASES.values(), CHAIN], ids=lambda c: c.kind)
def test_ok_positions_keep_the_guarantee_toward_the_singularity(case):
    mech = linkage.loads(case.toml)
    flagged = []
    for delta in DISTANCES:
        phi = case.singular_phi + case.side * delta
        motion = linkage.analyze(mech, [phi], on_failure="mask")
        if motion.status[0] != 0:
            flagged.append(delta)
            assert motion.status[0] in (-1, -2)
            assert np.isnan(motion.quantity(next(iter(reference(case, phi))))[1][0])
            continue
        e1, e2 = relative_errors(motion, reference(case, phi))
        assert e1 <= ANALOG_TOL, (case.kind, delta, e1)
        assert e2 <= 10 * ANALOG_TOL, (case.kind, delta, e2)
        # the reported bound really bounds the error
        assert e1 <= motion.error_bound[0], (case.kind, delta, e1, motion.error_bound[0])
    # the flag is set only near the singularity: regular down to 1e-4 rad (1e-3 for PRP, whose
    # pin is already 500 x its offset away there), flagged from 1e-8 rad on
    regular_until = 1e-3 if case.kind == "PRP" else 1e-4
    assert all(d < regular_until for d in flagged), flagged
    assert all(d in flagged for d in DISTANCES if d <= 1e-8)


def test_issue_example_near_the_four_bar_toggle_is_flagged_not_wrong():
    """crank 1, coupler 1.2, rocker 1, ground 2: at phi* - 1e-12 the analogs were 1.5e-4 off."""
    case = CASES["RRR"]
    mech = linkage.loads(case.toml)
    phi = np.arccos(0.04) - np.array([1e-12, 1e-15])
    motion = linkage.analyze(mech, phi, on_failure="mask")
    assert list(motion.status) == [-2, -2]
    assert np.all(motion.conditioning["II-RRR(2,3)"] < 1e-5)
    with pytest.raises(linkage.AssemblyError, match="singular"):
        linkage.analyze(mech, phi)


@pytest.mark.parametrize("gamma_deg", [30.0, 1.0, 0.1, 0.01, 1e-3, 1e-4, 1e-6])
def test_scotch_yoke_with_the_slot_turned_toward_the_rail(gamma_deg):
    """RPP is singular when the slot runs parallel to the rail (gamma -> 0)."""
    mech = linkage.loads(rpp_toml(gamma_deg))
    motion = linkage.analyze(mech, [0.7], on_failure="mask")
    gamma = np.radians(gamma_deg)
    if motion.status[0] == 0:
        e1, e2 = relative_errors(motion, _derivatives(rpp_reference(gamma_deg), 0.7))
        assert e1 <= ANALOG_TOL and e2 <= 10 * ANALOG_TOL
    else:
        assert motion.status[0] == -2
    # for small gamma the measure is proportional to sin(gamma): regular down to 0.1 deg,
    # flagged from 0.01 deg on (SINGULAR_TOL = 2.6e-4)
    assert (motion.status[0] == 0) == (gamma_deg >= 0.1)
    if gamma_deg > 1.0:
        return
    one_degree = linkage.analyze(linkage.loads(rpp_toml(1.0)), [0.7]).conditioning["II-RPP(2,3)"][0]
    ratio = motion.conditioning["II-RPP(2,3)"][0] / one_degree
    assert ratio == pytest.approx(np.sin(gamma) / np.sin(np.radians(1.0)), rel=0.01)


def _with_far_frame_point(name: str, distance: float):
    data = to_dict(linkage.load(name))
    data["links"]["0"]["points"]["M"] = [distance, 0.0]
    return from_dict(data)


def test_an_unused_far_frame_point_does_not_flag_the_four_bar():
    phi = np.linspace(0.0, 2 * np.pi, 72, endpoint=False)
    plain = linkage.analyze(linkage.load("four_bar"), phi)
    far = linkage.analyze(_with_far_frame_point("four_bar", 1e4), phi, on_failure="mask")
    assert np.all(far.status == 0)
    np.testing.assert_allclose(far.conditioning["II-RRR(2,3)"], plain.conditioning["II-RRR(2,3)"],
                               rtol=1e-12)


@pytest.mark.parametrize("k", [1e-8, 1e-3, 1e3, 1e8])
def test_conditioning_does_not_depend_on_units_or_position(k):
    """Scaling and moving the whole mechanism leaves every group's conditioning unchanged."""
    mech = linkage.load("slotted_link_two_dyad")
    data = to_dict(mech)
    for link in data["links"].values():
        shift = [3.0, -2.0] if link is data["links"]["0"] else [0.0, 0.0]
        link["points"] = {p: [k * (v[0] + shift[0]), k * (v[1] + shift[1])]
                          for p, v in link["points"].items()}
        link["com"] = [k * c for c in link["com"]]
        for g in link.get("guides", {}).values():
            g["through"] = [k * (g["through"][0] + shift[0]), k * (g["through"][1] + shift[1])]
    scaled = from_dict(data)
    phi = np.linspace(0.0, 2 * np.pi, 36, endpoint=False)
    a = linkage.analyze(mech, phi)
    b = linkage.analyze(scaled, phi)
    assert a.conditioning.keys() == b.conditioning.keys()
    for key in a.conditioning:
        np.testing.assert_allclose(b.conditioning[key], a.conditioning[key], rtol=1e-9)
    np.testing.assert_allclose(b.quantity("B.x")[1], k * a.quantity("B.x")[1], rtol=1e-9,
                               atol=1e-12 * k)


def test_dyads_of_very_different_sizes_share_a_mechanism():
    """A 1e-6-scale rod and slider hung on a 1-m four-bar are regular wherever both are."""
    mech = linkage.loads(CASES["RRR"].toml)
    small = linkage.loads(_small_chain())
    phi = np.linspace(-1.2, 1.2, 49)
    big = linkage.analyze(mech, phi)
    both = linkage.analyze(small, phi, on_failure="mask")
    assert np.all(big.status == 0)
    assert np.all(both.status == 0), both.status
    assert np.nanmin(both.conditioning["II-RRP(4,5)"]) > 0.1


def _small_chain() -> str:
    """The chain of ``_edge_mechanisms`` with its rod and slider shrunk to micrometres: the slider
    runs on a guide of the rocker itself, so the small dyad assembles at every angle."""
    return CHAIN.toml.replace('''[links.4]
line = ["D", "E"]
length = 1.5''', '''[links.4]
line = ["D", "E"]
length = 2.0e-6''').replace('''points.D = { from = "C", distance = 0.5 }''',
                              '''points.D = { from = "C", distance = 0.5 }
guides.small = { through = "D", angle_deg = 0, offset = -1.0e-6 }''').replace('''[pairs.low]
kind = "P"
links = ["0", "5"]
guide = "low"''', '''[pairs.low]
kind = "P"
links = ["3", "5"]
guide = "small"''')


def test_cli_json_names_the_group_and_its_conditioning_at_a_singular_position(capsys, tmp_path):
    import json

    from linkage.cli import main

    scheme = tmp_path / "toggle.toml"
    scheme.write_text(CASES["RRR"].toml, encoding="utf-8")
    start = float(np.degrees(CASES["RRR"].singular_phi - 1e-9))
    code = main(["analyze", str(scheme), "--positions", "4", "--start", repr(start), "--format", "json"])
    out, err = capsys.readouterr()
    assert code == 0 and "singular" in err and "Traceback" not in err
    failed = json.loads(out)["failed"]
    singular = [f for f in failed if f["problem"] == "is singular"]
    assert [f["position"] for f in singular] == [1, 5]
    for f in singular:
        assert f["group"] == "II-RRR(2,3)" and 0 < f["conditioning"] < 1e-4
