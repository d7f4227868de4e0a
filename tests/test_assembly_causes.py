"""Assembly refusals that name their real cause, and declared modes of traced groups (issue 21).

- a dyad that assembles only inside a window narrower than the sweep's step is refused with that
  window (checked against the closed form of the slider-crank), and analyses over it once the
  window is declared as the input's range;
- a group that cannot be assembled with the branch an upstream condition chooses names that
  condition, not the dimensions of its own links;
- ``branch = +1 / -1`` on the class-III triad chooses the mode whose Jacobian determinant has that
  sign (checked by the test's own finite-difference Jacobian of the triad's closure).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import linkage
from _texts import four_bar_toml
from assur.base import OK, SINGULAR
from linkage.errors import SchemeError

SCHEMES = Path(__file__).resolve().parents[1] / "schemes"


# ----------------------------------------------------------------------------------------------
# a window narrower than the sweep
# ----------------------------------------------------------------------------------------------

E, R, TILT = 0.6, 0.1, 0.5          # guide through (0, E) turned TILT deg; crank OA = R


def _narrow_slider_crank(margin: float, extra: str = "") -> tuple[str, float, float]:
    """A slider-crank whose rod reaches the guide only near phi = 90.5 deg; the window (deg)
    from the closed form: A's distance from the guide, dist - R cos(phi - 90.5 deg), <= the rod."""
    dist = E * math.cos(math.radians(TILT))            # distance of O from the guide line
    rod = dist - R + margin
    half = math.degrees(math.acos(min(1.0, (dist - rod) / R)))
    text = (SCHEMES / "slider_crank.toml").read_text()
    text = text.replace("through = [0.0, 0.01335], angle_deg = 0", f"through = [0.0, {E}], angle_deg = {TILT}")
    text = text.replace("length = 0.0742", f"length = {R}").replace("length = 0.2225", f"length = {rod!r}")
    text = text.replace('from = "O"\ntowards_deg = 0', "branch = 1")
    text = text.replace('input = "1"', 'input = "1"\n' + extra)
    return text, 90 + TILT - half, 90 + TILT + half


def test_a_window_narrower_than_the_sweep_is_named_with_its_angles():
    text, low, high = _narrow_slider_crank(2e-6)
    assert high - low < 1.0 and math.floor(high) < low + 1     # no whole degree inside: the sweep misses it
    with pytest.raises(SchemeError) as info:
        linkage.loads(text)
    message = str(info.value)
    assert "can be assembled only for input angles from" in message and "narrower than" in message
    shown = [float(x) for x in message.split("from ")[1].split(" deg")[0].split(" to ")]
    np.testing.assert_allclose(shown, [low, high], atol=1e-4)
    assert "stays at least" not in message and "check the dimensions" not in message


def test_the_window_declared_as_the_range_is_analysed():
    _, low, high = _narrow_slider_crank(2e-6)
    inside = [math.ceil(low * 1e4) / 1e4, math.floor(high * 1e4) / 1e4]
    text, _, _ = _narrow_slider_crank(2e-6, f"range_deg = [{inside[0]}, {inside[1]}]")
    mech = linkage.loads(text)
    phi = np.radians(np.linspace(inside[0], inside[1], 9))
    motion = linkage.analyze(mech, phi, order=1, on_failure="mask")
    assert np.all((motion.status == OK) | (motion.status == SINGULAR))
    assert np.all(motion.status[2:-2] == OK)
    # B lies on the guide, at the rod's length from A (the test's own closure)
    A, B = motion.point("A"), motion.point("B")
    rod = E * math.cos(math.radians(TILT)) - R + 2e-6
    np.testing.assert_allclose(np.hypot(*(B - A).T), rod, rtol=1e-12)
    u = np.array([math.cos(math.radians(TILT)), math.sin(math.radians(TILT))])
    offset = (B - np.array([0.0, E])) @ np.array([-u[1], u[0]])
    np.testing.assert_allclose(offset, 0.0, atol=1e-12)


def test_a_wide_enough_gap_still_gives_the_dimensional_reason():
    text, _, _ = _narrow_slider_crank(-1e-3)           # the rod never reaches the guide
    with pytest.raises(SchemeError, match="stays at least"):
        linkage.loads(text)


# ----------------------------------------------------------------------------------------------
# an upstream condition that leaves the next group no assembly
# ----------------------------------------------------------------------------------------------

UPPER_DYAD = '''
[links.4]
line = ["G", "D"]
length = 0.3
[links.5]
line = ["F", "D"]
length = 0.3
[pairs.G]
links = ["3", "4"]
[pairs.D]
links = ["4", "5"]
[pairs.F]
links = ["5", "0"]
[assembly.D]
left_of = ["G", "F"]
'''


def _two_dyads(condition: str) -> str:
    """A four-bar (rocker CB = 0.25 about C = (0.3, 0)) with a dyad from the rocker's tip G = B to
    the frame point F = (0.3, 0.6), arms 0.3 + 0.3: it reaches the upper B (|GF| <= 0.45) and never
    the lower one (|GF| >= 0.75)."""
    text = four_bar_toml(0.1, 0.3, 0.25, 0.3, assembly=condition, tail=UPPER_DYAD)
    text = text.replace("points = { O = [0.0, 0.0], C = [0.3, 0.0] }",
                        "points = { O = [0.0, 0.0], C = [0.3, 0.0], F = [0.3, 0.6] }")
    return text.replace('line = ["C", "B"]\nlength = 0.25', 'line = ["C", "B"]\nlength = 0.25\n'
                                                           'points.G = { from = "C", distance = 0.25 }')


def test_the_upstream_condition_is_named_when_the_next_group_needs_its_other_branch():
    with pytest.raises(SchemeError) as info:
        linkage.loads(_two_dyads('right_of = ["A", "C"]'))
    message = str(info.value)
    assert "II-RRR(4,5)" in message and "condition on point 'B'" in message and "II-RRR(2,3)" in message
    assert "360 of 360" in message and "check the dimensions" not in message
    mech = linkage.loads(_two_dyads('left_of = ["A", "C"]'))
    motion = linkage.analyze(mech, np.radians(np.arange(0.0, 360.0, 30.0)), order=0)
    assert np.all(motion.point("B")[:, 1] > 0.1)


# ----------------------------------------------------------------------------------------------
# branch = +1 / -1 on the class-III triad
# ----------------------------------------------------------------------------------------------

TRIAD = ("2", "3", "4", "5")


def _closure_jacobian_sign(mech, motion, n: int) -> float:
    """Sign of det of the triad's closure Jacobian with respect to its 12 pose coordinates, by
    central finite differences of the test's own residual: each of the six pairs' two points
    coincide."""
    pairs = [(name, pair.links) for name, pair in mech.pairs.items()
             if set(pair.links) & set(TRIAD)]
    known = {k: motion.poses[k][n] for k in mech.links if k not in TRIAD}

    def point(pose, local):
        c, s = math.cos(pose[2]), math.sin(pose[2])
        return np.array([pose[0] + c * local[0] - s * local[1], pose[1] + s * local[0] + c * local[1]])

    def residual(q):
        poses = {**known, **{k: q[3 * i:3 * i + 3] for i, k in enumerate(TRIAD)}}
        out = []
        for name, (a, b) in pairs:
            out.extend(point(poses[a], mech.links[a].points[name]) - point(poses[b], mech.links[b].points[name]))
        return np.array(out)

    q = np.concatenate([motion.poses[k][n] for k in TRIAD])
    h = 1e-7
    jac = np.column_stack([(residual(q + h * e) - residual(q - h * e)) / (2 * h) for e in np.eye(12)])
    return float(np.sign(np.linalg.det(jac)))


def test_branch_on_the_triad_chooses_the_mode_by_the_sign_of_its_jacobian():
    text = (SCHEMES / "six_bar_class3.toml").read_text()
    phi = np.radians(np.arange(0.0, 360.0, 45.0))
    chosen = {}
    for value in (1, -1):
        mech = linkage.loads(text.replace('left_of = ["F", "C"]', f"branch = {value}"))
        motion = linkage.analyze(mech, phi, order=0)
        assert np.all(motion.status == OK)
        signs = {_closure_jacobian_sign(mech, motion, n) for n in range(len(phi))}
        chosen[value] = (motion.point("D"), signs)
    # the two signs pick two different modes, each with one sign of the determinant over the turn;
    # the test's residual orders the unknowns as the library does (links in order, x, y, theta), so
    # the signs are comparable up to one common factor
    assert len(chosen[1][1]) == 1 and len(chosen[-1][1]) == 1 and chosen[1][1] != chosen[-1][1]
    assert np.max(np.abs(chosen[1][0] - chosen[-1][0])) > 1e-3
    declared = linkage.analyze(linkage.loads(text), phi, order=0).point("D")
    assert any(np.allclose(declared, chosen[v][0], atol=1e-9) for v in (1, -1))
