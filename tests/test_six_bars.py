"""The shipped six-bars ``watt_six_bar`` and ``stephenson_six_bar`` against an independent solution.

The oracle here reads the scheme files with :mod:`tomllib` (not with the library's loader) and
places every point by circle intersections: the crank pin from the input angle, then each RRR
dyad's inner joint at the intersection of the circles about its two outer joints, on the side
that the file's assembly condition names. Nothing of the library's solvers is used for it.
"""

from __future__ import annotations

import math
import tomllib
from functools import cache

import numpy as np
import pytest

import linkage
from linkage.cli import main
from linkage.kinetostatics.reactions import solve_reactions, virtual_power_residual

#: the dyads of each scheme, in the order they are placed after the crank: (inner joint, link
#: from the first outer joint, first outer joint, link from the second outer joint, second outer
#: joint) -- the chain the scheme's topology comment describes
DYADS = {
    "watt_six_bar": [("B", "2", "A", "3", "C"), ("E", "4", "D", "5", "G")],
    "stephenson_six_bar": [("B", "2", "A", "3", "C"), ("F", "4", "E", "5", "G")],
}
SCHEMES = sorted(DYADS)
FORMULA = "I(0,1) → II-RRR(2,3) → II-RRR(4,5)"

#: 72 positions per revolution, started off the axes so no position is special by accident
PHI = np.radians(np.arange(72) * 5.0 + 1.0)
POSITION_TOL = 1e-12  # m: two exact solutions of the same equations, in round-off
FD_STEP = 1e-5        # rad: central-difference step for the first analogs
#: central differences err by h^2 |f'''| / 6 (~1e-10 here) plus round-off ~1e-16 / h (~1e-11)
FD_TOL = 1e-9         # m/rad for points, rad/rad for link angles (observed ~1e-11)
MIN_TRANSMISSION_DEG = 50.0  # every inner joint of both schemes keeps at least this


# ----------------------------------------------------------------------------------------------
# the scheme files, read with tomllib
# ----------------------------------------------------------------------------------------------


@cache
def raw(name: str) -> dict:
    """The scheme file as plain TOML data."""
    with open(linkage.shipped_schemes()[name], "rb") as f:
        return tomllib.load(f)


def local_points(link: dict) -> dict[str, np.ndarray]:
    """Every named point of a link in its local frame (m), from ``line``/``length``/``points``."""
    pts: dict[str, np.ndarray] = {}
    if "line" in link:
        p, q = link["line"]
        pts[p], pts[q] = np.zeros(2), np.array([link["length"], 0.0])
    for pname, spec in link.get("points", {}).items():
        if isinstance(spec, dict):
            angle = math.radians(spec.get("angle_deg", 0.0))
            pts[pname] = pts[spec["from"]] + spec["distance"] * np.array([math.cos(angle), math.sin(angle)])
        else:
            pts[pname] = np.asarray(spec, dtype=float)
    return pts


def local(name: str, link: str) -> dict[str, np.ndarray]:
    return local_points(raw(name)["links"][link])


def distance_in_link(name: str, link: str, p: str, q: str) -> float:
    pts = local(name, link)
    return float(np.linalg.norm(pts[q] - pts[p]))


# ----------------------------------------------------------------------------------------------
# the independent solution
# ----------------------------------------------------------------------------------------------


def cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def circle_intersections(P: np.ndarray, r1: float, Q: np.ndarray, r2: float) -> tuple[np.ndarray, np.ndarray]:
    """The two points at r1 from P and r2 from Q, (N, 2) each: left of P -> Q, then right."""
    d = Q - P
    L = np.linalg.norm(d, axis=1)
    along = (L**2 + r1**2 - r2**2) / (2 * L)
    h2 = r1**2 - along**2
    assert np.all(h2 > 0), "the circles do not intersect: the dyad does not assemble"
    u = d / L[:, None]
    n = np.column_stack([-u[:, 1], u[:, 0]])
    foot = P + along[:, None] * u
    h = np.sqrt(h2)[:, None]
    return foot + h * n, foot - h * n


def satisfies(condition: dict, X: np.ndarray, points: dict[str, np.ndarray]) -> np.ndarray:
    """Whether X (N, 2) meets a ``left_of`` / ``right_of`` assembly condition of the file."""
    if "left_of" in condition:
        a, b = condition["left_of"]
        return cross(points[b] - points[a], X - points[a]) > 0
    a, b = condition["right_of"]
    return cross(points[b] - points[a], X - points[a]) < 0


def angle_of(P: np.ndarray, Q: np.ndarray) -> np.ndarray:
    d = Q - P
    return np.arctan2(d[:, 1], d[:, 0])


def place_link(pts_local: dict[str, np.ndarray], origin: np.ndarray, theta: np.ndarray) -> dict[str, np.ndarray]:
    """Global positions (N, 2) of a link's local points, its local origin at ``origin``."""
    c, s = np.cos(theta), np.sin(theta)
    return {p: origin + np.column_stack([c * v[0] - s * v[1], s * v[0] + c * v[1]]) for p, v in pts_local.items()}


def solve(name: str, phi: np.ndarray) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Every named point (N, 2) and every moving link's angle (N,) at the input angles phi."""
    data = raw(name)
    n = len(phi)
    points = {p: np.broadcast_to(np.asarray(v, dtype=float), (n, 2)) for p, v in data["links"]["0"]["points"].items()}
    angles: dict[str, np.ndarray] = {}

    def settle(link: str) -> None:
        """Angle and points of a link with its two line points placed."""
        p, q = data["links"][link]["line"]
        angles[link] = angle_of(points[p], points[q])
        points.update(place_link(local(name, link), points[p], angles[link]))

    crank = data["input"]
    pivot = data["links"][crank]["line"][0]
    angles[crank] = np.asarray(phi, dtype=float)
    points.update(place_link(local(name, crank), points[pivot], angles[crank]))
    for inner, link_a, outer_a, link_b, outer_b in DYADS[name]:
        left, right = circle_intersections(
            points[outer_a], distance_in_link(name, link_a, outer_a, inner),
            points[outer_b], distance_in_link(name, link_b, outer_b, inner))
        condition = data["assembly"][inner]
        on_left, on_right = satisfies(condition, left, points), satisfies(condition, right, points)
        assert np.all(on_left) != np.all(on_right), f"{inner}: the condition must pick one branch everywhere"
        points[inner] = left if np.all(on_left) else right
        settle(link_a)
        settle(link_b)
    return points, angles


def transmission_angles(name: str, phi: np.ndarray) -> dict[str, np.ndarray]:
    """At each dyad's inner joint, the angle between its two links folded into [0, 90] deg."""
    pts, _ = solve(name, phi)
    out = {}
    for inner, _, outer_a, _, outer_b in DYADS[name]:
        u, v = pts[outer_a] - pts[inner], pts[outer_b] - pts[inner]
        mu = np.degrees(np.arccos(np.sum(u * v, axis=1) / np.linalg.norm(u, axis=1) / np.linalg.norm(v, axis=1)))
        out[inner] = np.minimum(mu, 180.0 - mu)
    return out


def wrap(a: np.ndarray) -> np.ndarray:
    """Angles into (-pi, pi]."""
    return np.angle(np.exp(1j * np.asarray(a)))


@cache
def mech(name: str):
    return linkage.load(name)


@cache
def motion(name: str):
    return linkage.analyze(mech(name), PHI, order=1)


# ----------------------------------------------------------------------------------------------
# the oracle itself: it must close the loops it claims to close
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", SCHEMES)
def test_oracle_closes_every_pair(name):
    """Each revolute pair's point, placed from either of its links, is the same point."""
    data = raw(name)
    pts, angles = solve(name, PHI)
    for pair, spec in data["pairs"].items():
        for link in spec["links"]:
            if link == "0":
                continue
            p, _ = data["links"][link]["line"]
            where = place_link(local(name, link), pts[p], angles[link])[pair]
            np.testing.assert_allclose(where, pts[pair], rtol=0, atol=1e-15, err_msg=f"{name}: {pair} on {link}")


# ----------------------------------------------------------------------------------------------
# positions and first analogs
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", SCHEMES)
def test_positions_match_circle_intersections(name):
    mo, m = motion(name), mech(name)
    pts, angles = solve(name, PHI)
    assert set(m.point_names) == set(pts)
    for p in m.point_names:
        np.testing.assert_allclose(mo.point(p), pts[p], rtol=0, atol=POSITION_TOL, err_msg=f"{name}: {p}")
    for link, theta in angles.items():
        np.testing.assert_allclose(wrap(mo.quantity(f"{link}.theta")[0] - theta), 0, atol=POSITION_TOL,
                                   err_msg=f"{name}: link {link}")


@pytest.mark.parametrize("name", SCHEMES)
def test_first_analogs_match_central_differences(name):
    """d/dphi of every point and link angle: (f(phi + h) - f(phi - h)) / 2h of the oracle, h = 1e-5."""
    mo = motion(name)
    ahead, theta_ahead = solve(name, PHI + FD_STEP)
    behind, theta_behind = solve(name, PHI - FD_STEP)
    for p in mech(name).point_names:
        fd = (ahead[p] - behind[p]) / (2 * FD_STEP)
        np.testing.assert_allclose(mo.point_analogs(p)[0], fd, rtol=0, atol=FD_TOL, err_msg=f"{name}: {p}'")
    for link in theta_ahead:
        fd = wrap(theta_ahead[link] - theta_behind[link]) / (2 * FD_STEP)
        np.testing.assert_allclose(mo.quantity(f"{link}.theta")[1], fd, rtol=0, atol=FD_TOL,
                                   err_msg=f"{name}: {link}.theta'")


# ----------------------------------------------------------------------------------------------
# structure
# ----------------------------------------------------------------------------------------------


def pairs_per_link(name: str) -> dict[str, set[str]]:
    joints: dict[str, set[str]] = {}
    for pair, spec in raw(name)["pairs"].items():
        for link in spec["links"]:
            joints.setdefault(link, set()).add(pair)
    return joints


@pytest.mark.parametrize("name", SCHEMES)
def test_structural_formula_and_chain(name):
    m = mech(name)
    assert linkage.structure_of(m).formula == FORMULA
    joints = pairs_per_link(name)
    n_links, n_pairs = len(joints), len(raw(name)["pairs"])
    assert (n_links, n_pairs) == (6, 7)
    assert 3 * (n_links - 1) - 2 * n_pairs == 1 == linkage.mobility(m)   # Chebyshev-Gruebler
    assert all(spec.get("kind", "R") == "R" for spec in raw(name)["pairs"].values())
    ternary = sorted(link for link, pairs in joints.items() if len(pairs) == 3)
    assert len(ternary) == 2 and all(len(joints[k]) == 2 for k in joints if k not in ternary)
    adjacent = bool(joints[ternary[0]] & joints[ternary[1]])
    # the Watt chain has its two ternary links joined directly, the Stephenson chain does not
    assert adjacent == (name == "watt_six_bar")


# ----------------------------------------------------------------------------------------------
# assembly over the full turn, transmission angles
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", SCHEMES)
def test_assembles_over_the_full_turn(name):
    phi = np.radians(np.arange(360.0))
    mo = linkage.analyze(mech(name), phi, order=0, on_failure="mask")
    assert np.all(mo.status == 0)


@pytest.mark.parametrize("name", SCHEMES)
def test_transmission_angles_are_comfortable(name):
    phi = np.linspace(0.0, 2 * np.pi, 3601)
    mu = transmission_angles(name, phi)
    for inner, values in mu.items():
        assert values.min() >= MIN_TRANSMISSION_DEG, (name, inner, values.min())
    # the first dyad is a four-bar: its extremes are at the crank's two in-line positions
    a = distance_in_link(name, "1", "O", "A")
    b = distance_in_link(name, "2", "A", "B")
    c = distance_in_link(name, "3", "C", "B")
    frame = raw(name)["links"]["0"]["points"]
    d = math.dist(frame["O"], frame["C"])
    extremes = [math.degrees(math.acos((b**2 + c**2 - e**2) / (2 * b * c))) for e in (d - a, d + a)]
    folded_min = min(min(x, 180 - x) for x in extremes)
    assert abs(mu["B"].min() - folded_min) < 1e-3


# ----------------------------------------------------------------------------------------------
# kinetostatics and the command line
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", SCHEMES)
def test_virtual_power_balance(name):
    reactions = solve_reactions(linkage.analyze(mech(name), PHI, omega=10.0))
    residual = virtual_power_residual(reactions)
    assert np.all(np.isfinite(residual)) and residual.max() <= 1e-9


@pytest.mark.parametrize("name", SCHEMES)
def test_cli_analyze(name, capsys):
    assert main(["analyze", name]) == 0
    out = capsys.readouterr().out
    assert out.strip()

