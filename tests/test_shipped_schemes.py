"""Every shipped scheme: it loads, decomposes as specified, closes its loops, has analogs that
agree with finite differences, and survives a write/read round trip; plus oracles from closed-form
formulas written here independently of the library (docs/methods.md#checks).

Reference numbers are computed in this file from the dimensions stated in each scheme's
description (they are the spec), never copied from the library's output.
"""

from __future__ import annotations

import math
import subprocess
import sys
import warnings
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest

import linkage
import linkage.kinetostatics.loads  # noqa: F401  registers the [loads] section (see test_fresh_import_loads_every_scheme)
from linkage.kinematics.motion import BranchWarning
from linkage.model.mechanism import Prismatic, Revolute

#: the structural formula of every shipped scheme (a spec, not an observed value)
EXPECTED_FORMULAS = {
    "flying_shears": "I(0,1) → II-RRR(2,3)",
    "four_bar": "I(0,1) → II-RRR(2,3)",
    "scotch_yoke": "I(0,1) → II-RPP(2,3)",
    "six_bar": "I(0,1) → II-RRR(2,3) → II-RRP(4,5)",
    "slider_crank": "I(0,1) → II-RRP(2,3)",
    "course_slider_crank": "I(0,1) → II-RRP(2,3)",
    "slider_crank_vertical": "I(0,1) → II-RRP(2,3)",
    "slotted_link": "I(0,1) → II-RPR(2,3)",
    "slotted_link_two_dyad": "I(0,1) → II-RPR(2,3) → II-PRP(4,5)",
    "six_bar_class3": "I(0,1) → III(2,3,4,5)",         # legs 2, 4, 5 on the ternary link 3
    "watt_six_bar": "I(0,1) → II-RRR(2,3) → II-RRR(4,5)",
    "stephenson_six_bar": "I(0,1) → II-RRR(2,3) → II-RRR(4,5)",
    "five_bar_two_input": "I(0,1) → I(0,4) → II-RRR(2,3)",   # two cranks place one dyad
    "piston_driven_crank": "I(0,3) → II-RRR(1,2)",      # the piston (link 3) driven along the frame guide
    "cylinder_boom": "I(K) → II(1,2,3)",                # the cylinder K: boom, barrel and rod in one group
}

SCHEMES = sorted(linkage.shipped_schemes())

#: 72 positions per revolution, started off the axes so no position is special by accident
PHI = np.radians(np.arange(72) * 5.0 + 1.0)

CLOSURE_TOL = 1e-12
H1, H2 = 1e-3, 5e-3  # finite-difference steps (rad) for first / second analogs
SLIDE_STEP = 0.25    # a slide input's steps: H1, H2 times this fraction of the mechanism's size (m)
FD_TOL1, FD_TOL2 = 1e-7, 1e-5


@lru_cache(maxsize=None)
def mech(name):
    return linkage.load(name)


def positions(name):
    """The sampled input coordinates: PHI for a crank; for a slide input (m), 72 slides across its
    declared stroke, kept 2 H2 inside both ends so that the finite differences stay in it."""
    m = mech(name)
    if m.coordinate.is_angle:
        return PHI
    a, b = m.input_range
    h2 = steps(name)[1]
    lo, hi = min(a, b) + 2 * h2, max(a, b) - 2 * h2
    return lo + (hi - lo) * (np.arange(72) + 0.5) / 72


def steps(name):
    """Finite-difference steps (h1, h2) of the input coordinate: rad for a crank, m for a slide."""
    m = mech(name)
    return (H1, H2) if m.coordinate.is_angle else (H1 * SLIDE_STEP * m.size, H2 * SLIDE_STEP * m.size)


@lru_cache(maxsize=None)
def motion(name):
    return linkage.analyze(mech(name), positions(name), order=2)


def rot(theta, p):
    """Rotate the local vector p (2,) by the angles theta (N,) -> (N, 2)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.column_stack([c * p[0] - s * p[1], s * p[0] + c * p[1]])


def wrap(a):
    """Angles into (-pi, pi]."""
    return np.angle(np.exp(1j * np.asarray(a)))


def on_link(m, pose, link, point):
    """Global position (N, 2) of a named point of a link from the link's pose."""
    return pose[:, :2] + rot(pose[:, 2], m.links[link].points[point])


def quantities(m):
    """Every point coordinate, moving-link angle and slide of a mechanism."""
    q = [f"{p}.{a}" for p in m.point_names for a in "xy"]
    q += [f"{k}.theta" for k in m.moving_links]
    q += [f"{k}.s" for k, p in sorted(m.pairs.items()) if isinstance(p, Prismatic)]
    return q


# ----------------------------------------------------------------------------------------------
# generic checks, every shipped scheme
# ----------------------------------------------------------------------------------------------


def test_fresh_import_loads_every_scheme():
    """``import linkage`` alone must be enough to load every shipped scheme."""
    code = "import linkage\nfor n in linkage.shipped_schemes(): linkage.load(n)\n"
    root = Path(__file__).resolve().parent.parent
    done = subprocess.run([sys.executable, "-c", code], cwd=root, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]


def test_every_shipped_scheme_has_an_expected_formula():
    assert set(SCHEMES) == set(EXPECTED_FORMULAS)


def test_readme_lists_every_shipped_scheme():
    readme = Path(linkage.shipped_schemes()[SCHEMES[0]]).parent / "README.md"
    listed = readme.read_text(encoding="utf-8").split("## Shipped schemes")[1]
    for name in SCHEMES:
        assert f"| `{name}` | `{EXPECTED_FORMULAS[name]}` |" in listed, name


@pytest.mark.parametrize("name", SCHEMES)
def test_loads_with_formula_and_output(name):
    m = mech(name)
    assert linkage.structure_of(m).formula == EXPECTED_FORMULAS[name]
    assert linkage.mobility(m) == len(m.inputs) == (2 if name == "five_bar_two_input" else 1)
    assert m.description, "every shipped scheme describes itself"
    assert m.output is not None and m.output.start in ("max", "min")
    ext = linkage.extreme_positions(m)  # the declared output has extreme positions
    assert ext.value_max >= ext.value_min
    if m.input_range is None:           # over a turn: roots of the output's analog
        assert len(ext.roots) >= 1
    else:                               # within a range (a stroke): a root or an end of it
        candidates = np.concatenate([m.input_range, ext.roots])
        for where, value in ((ext.phi_max, ext.value_max), (ext.phi_min, ext.value_min)):
            assert np.min(np.abs(candidates - where)) <= 1e-12
            assert value == pytest.approx(linkage.analyze(m, [where]).quantity(m.output.quantity)[0][0], abs=1e-12)
        probe = linkage.analyze(m, np.linspace(*m.input_range, 101)).quantity(m.output.quantity)[0]
        assert ext.value_min - 1e-12 <= probe.min() and probe.max() <= ext.value_max + 1e-12


@pytest.mark.parametrize("name", SCHEMES)
def test_analyzes_over_a_revolution(name):
    with warnings.catch_warnings():
        warnings.simplefilter("error", BranchWarning)
        mo = linkage.analyze(mech(name), positions(name), order=2)
    assert np.all(mo.success)
    for q in quantities(mech(name)):
        for arr in mo.quantity(q):
            assert arr.shape == PHI.shape and np.all(np.isfinite(arr)), q


@pytest.mark.parametrize("name", SCHEMES)
def test_loop_closure(name):
    """Every pair's constraint, evaluated here from the link poses and local points."""
    m, mo = mech(name), motion(name)
    tol = CLOSURE_TOL * m.size
    for pname, pair in m.pairs.items():
        a, b = pair.links
        pa, pb = mo.poses[a], mo.poses[b]
        if isinstance(pair, Revolute):
            gap = on_link(m, pa, a, pair.point) - on_link(m, pb, b, pair.point)
            assert np.max(np.abs(gap)) <= tol, pname
        else:
            guide = m.links[a].guides[pair.guide]
            G = pa[:, :2] + rot(pa[:, 2], guide.point)
            u = np.column_stack([np.cos(pa[:, 2] + guide.angle), np.sin(pa[:, 2] + guide.angle)])
            P = on_link(m, pb, b, pair.point)
            off_line = u[:, 0] * (P - G)[:, 1] - u[:, 1] * (P - G)[:, 0]
            assert np.max(np.abs(off_line)) <= tol, pname
            # the slider keeps its angle relative to the guide link
            rel = wrap(pb[:, 2] - pa[:, 2] - (pb[0, 2] - pa[0, 2]))
            assert np.max(np.abs(rel)) <= CLOSURE_TOL, pname
            # the reported slide is the distance along the guide from the guide's point
            s = mo.quantity(f"{pname}.s")[0]
            assert np.allclose(s, np.sum(u * (P - G), axis=1), rtol=0, atol=tol), pname
    if m.coordinate.is_angle:   # the input link's angle is phi
        assert np.allclose(wrap(mo.poses[m.inputs[0]][:, 2] - PHI), 0, atol=CLOSURE_TOL)
    else:                       # the input pair's slide (measured above from the poses) is s
        s = mo.quantity(f"{m.input_pair(m.inputs[0])}.s")[0]
        assert np.allclose(s, positions(name), rtol=0, atol=tol)


def _fd_samples(name, offsets):
    """Values of every quantity at PHI + k for k in offsets: dict q -> (len(offsets), N)."""
    m = mech(name)
    phi = np.concatenate([positions(name) + k for k in offsets])
    mo = linkage.analyze(m, phi, order=0)
    out = {}
    for q in quantities(m):
        v = mo.quantity(q)[0].reshape(len(offsets), len(PHI))
        if q.endswith(".theta"):
            centre = v[len(offsets) // 2]
            v = centre + wrap(v - centre)  # continuous across +-pi
        out[q] = v
    return out


@pytest.mark.parametrize("name", SCHEMES)
def test_analogs_match_finite_differences(name):
    """5-point central differences: O(h^4) for both the first and the second derivative."""
    m, mo = mech(name), motion(name)
    h1, h2 = steps(name)
    s1 = _fd_samples(name, [-2 * h1, -h1, 0.0, h1, 2 * h1])
    s2 = _fd_samples(name, [-2 * h2, -h2, 0.0, h2, 2 * h2])
    for q in quantities(m):
        value, d1, d2 = mo.quantity(q)
        f = s1[q]
        fd1 = (f[0] - 8 * f[1] + 8 * f[3] - f[4]) / (12 * h1)
        f = s2[q]
        fd2 = (-f[0] + 16 * f[1] - 30 * f[2] + 16 * f[3] - f[4]) / (12 * h2**2)
        # the analogs' natural scale: per rad, m for lengths and 1 for angles; per m of a slide
        # input, 1 for lengths and 1/m for angles
        length = (1.0 if q.endswith(".theta") else m.size) / (1.0 if m.coordinate.is_angle else m.size)
        scale1 = max(np.max(np.abs(d1)), length)
        scale2 = max(np.max(np.abs(d2)), length)
        assert np.max(np.abs(d1 - fd1)) <= FD_TOL1 * scale1, (q, np.max(np.abs(d1 - fd1)) / scale1)
        assert np.max(np.abs(d2 - fd2)) <= FD_TOL2 * scale2, (q, np.max(np.abs(d2 - fd2)) / scale2)


@pytest.mark.parametrize("name", SCHEMES)
def test_roundtrip(name):
    m = mech(name)
    again = linkage.loads(linkage.dumps(m))
    assert again == m
    assert linkage.structure_of(again).formula == EXPECTED_FORMULAS[name]
    a, b = linkage.analyze(m, positions(name)), linkage.analyze(again, positions(name))
    for p in m.point_names:
        assert np.array_equal(a.point(p), b.point(p)), p


# ----------------------------------------------------------------------------------------------
# slider-crank, horizontal and vertical: textbook closed forms (docs/methods.md#checks)
# ----------------------------------------------------------------------------------------------

L1, L2, LAS2, ECC = 0.0742, 0.2225, 0.0741, 0.01335


def slider_crank_horizontal(phi):
    """Guide y = ECC, slider right of O: x_B = l1 cos(phi) + sqrt(l2^2 - (l1 sin(phi) - e)^2)."""
    g = L1 * np.sin(phi) - ECC          # g and its derivatives
    g1, g2 = L1 * np.cos(phi), -L1 * np.sin(phi)
    W = np.sqrt(L2**2 - g**2)
    W1 = -g * g1 / W
    W2 = -(g1**2 + g * g2) / W - g**2 * g1**2 / W**3
    xB = L1 * np.cos(phi) + W
    xB1 = -L1 * np.sin(phi) + W1
    xB2 = -L1 * np.cos(phi) + W2
    th2 = np.arctan2(ECC - L1 * np.sin(phi), W)
    i21 = -L1 * np.cos(phi) / (L2 * np.cos(th2))
    # from l1 sin(phi) + l2 sin(th2) = e differentiated twice
    th2_2 = (L1 * np.sin(phi) + L2 * np.sin(th2) * i21**2) / (L2 * np.cos(th2))
    return xB, xB1, xB2, th2, i21, th2_2


def slider_crank_vertical(phi):
    """Guide x = ECC, slider above O: y_B = l1 sin(phi) + sqrt(l2^2 - (l1 cos(phi) - e)^2)."""
    g = L1 * np.cos(phi) - ECC
    g1, g2 = -L1 * np.sin(phi), -L1 * np.cos(phi)
    W = np.sqrt(L2**2 - g**2)
    W1 = -g * g1 / W
    W2 = -(g1**2 + g * g2) / W - g**2 * g1**2 / W**3
    yB = L1 * np.sin(phi) + W
    yB1 = L1 * np.cos(phi) + W1
    yB2 = -L1 * np.sin(phi) + W2
    th2 = np.arctan2(W, ECC - L1 * np.cos(phi))
    # from l1 cos(phi) + l2 cos(th2) = e differentiated twice
    i21 = -L1 * np.sin(phi) / (L2 * np.sin(th2))
    th2_2 = -(L1 * np.cos(phi) + L2 * np.cos(th2) * i21**2) / (L2 * np.sin(th2))
    return yB, yB1, yB2, th2, i21, th2_2


def test_slider_crank_closed_form():
    mo = motion("slider_crank")
    xB, xB1, xB2, th2, i21, th2_2 = slider_crank_horizontal(PHI)
    for got, want in zip(mo.quantity("B.x"), (xB, xB1, xB2)):
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-13)
    for got in mo.quantity("B.y")[1:]:
        np.testing.assert_allclose(got, 0, atol=1e-14)
    np.testing.assert_allclose(mo.quantity("B.y")[0], ECC, atol=1e-15)
    t, t1, t2 = mo.quantity("2.theta")
    np.testing.assert_allclose(wrap(t - th2), 0, atol=1e-13)
    np.testing.assert_allclose(t1, i21, rtol=0, atol=1e-13)
    np.testing.assert_allclose(t2, th2_2, rtol=0, atol=1e-12)
    A = L1 * np.column_stack([np.cos(PHI), np.sin(PHI)])
    S2 = A + LAS2 * np.column_stack([np.cos(th2), np.sin(th2)])
    np.testing.assert_allclose(mo.point("S2"), S2, rtol=0, atol=1e-14)
    np.testing.assert_allclose(mo.quantity("slide.s")[0], xB, rtol=0, atol=1e-14)
    # docs/methods.md#checks form of x_B'
    np.testing.assert_allclose(xB1, -L1 * np.sin(PHI) - L2 * np.sin(th2) * i21, atol=1e-14)


def test_slider_crank_vertical_closed_form():
    mo = motion("slider_crank_vertical")
    yB, yB1, yB2, th2, i21, th2_2 = slider_crank_vertical(PHI)
    for got, want in zip(mo.quantity("B.y"), (yB, yB1, yB2)):
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-13)
    np.testing.assert_allclose(mo.quantity("B.x")[0], ECC, atol=1e-15)
    for got in mo.quantity("B.x")[1:]:
        np.testing.assert_allclose(got, 0, atol=1e-14)
    t, t1, t2 = mo.quantity("2.theta")
    np.testing.assert_allclose(wrap(t - th2), 0, atol=1e-13)
    np.testing.assert_allclose(t1, i21, rtol=0, atol=1e-13)
    np.testing.assert_allclose(t2, th2_2, rtol=0, atol=1e-12)
    A = L1 * np.column_stack([np.cos(PHI), np.sin(PHI)])
    S2 = A + LAS2 * np.column_stack([np.cos(th2), np.sin(th2)])
    np.testing.assert_allclose(mo.point("S2"), S2, rtol=0, atol=1e-14)
    np.testing.assert_allclose(mo.quantity("slide.s")[0], yB, rtol=0, atol=1e-14)


def test_slider_crank_extreme_positions():
    """Far extreme: crank and rod in line; near extreme: rod folded back over the crank."""
    ext = linkage.extreme_positions(mech("slider_crank"), "B.x")
    assert abs(ext.phi_max - math.asin(ECC / (L1 + L2))) < 1e-10
    assert abs(ext.phi_min - (math.pi + math.asin(ECC / (L2 - L1)))) < 1e-10
    assert abs(ext.value_max - math.sqrt((L1 + L2) ** 2 - ECC**2)) < 1e-13
    assert abs(ext.value_min - math.sqrt((L2 - L1) ** 2 - ECC**2)) < 1e-13
    assert np.allclose(linkage.table_angles(mech("slider_crank"), 12)[0], ext.phi_max)


def test_slider_crank_vertical_extreme_positions():
    ext = linkage.extreme_positions(mech("slider_crank_vertical"), "B.y")
    assert abs(ext.phi_max - math.acos(ECC / (L1 + L2))) < 1e-10
    assert abs(ext.phi_min - (math.pi + math.acos(ECC / (L2 - L1)))) < 1e-10
    assert abs(ext.value_max - math.sqrt((L1 + L2) ** 2 - ECC**2)) < 1e-13
    assert abs(ext.value_min - math.sqrt((L2 - L1) ** 2 - ECC**2)) < 1e-13


def test_slider_x_axis_runs_along_its_guide():
    mo = motion("slider_crank_vertical")
    np.testing.assert_allclose(wrap(mo.quantity("3.theta")[0] - math.pi / 2), 0, atol=1e-14)


# ----------------------------------------------------------------------------------------------
# four-bars (four_bar, flying_shears, the first dyad of six_bar): Freudenstein's equation
# ----------------------------------------------------------------------------------------------


def four_bar(phi, a, b, c, d):
    """Crank a about O = (0, 0), coupler b, rocker c about C = (d, 0), B left of A -> C.

    B = C + c (cos t3, sin t3) and |B - A| = b give P cos t3 + Q sin t3 = R, solved for t3 by
    t3 = atan2(Q, P) +- acos(R / hypot(P, Q)); the root with B left of A -> C is kept.
    Returns t2, t3 and their first and second analogs (from the loop equation).
    """
    ca, sa = np.cos(phi), np.sin(phi)
    P = 2 * c * (d - a * ca)
    Q = -2 * c * a * sa
    R = b**2 - d**2 - c**2 - a**2 + 2 * a * d * ca
    base, half = np.arctan2(Q, P), np.arccos(R / np.hypot(P, Q))
    A = a * np.column_stack([ca, sa])
    Cp = np.array([d, 0.0])
    t3 = None
    for cand in (base + half, base - half):
        B = Cp + c * np.column_stack([np.cos(cand), np.sin(cand)])
        left = (Cp - A)[:, 0] * (B - A)[:, 1] - (Cp - A)[:, 1] * (B - A)[:, 0] > 0
        t3 = cand if t3 is None else np.where(left, cand, t3)
    B = Cp + c * np.column_stack([np.cos(t3), np.sin(t3)])
    t2 = np.arctan2(*(B - A)[:, ::-1].T)
    # first analogs: the loop a e1 + b e2 = d ex + c e3 projected on e2 and e3
    t3_1 = a * np.sin(t2 - phi) / (c * np.sin(t2 - t3))
    t2_1 = -a * np.sin(t3 - phi) / (b * np.sin(t3 - t2))
    # second analogs: the loop differentiated twice, projected the same way
    t3_2 = (-a * np.cos(phi - t2) - b * t2_1**2 + c * t3_1**2 * np.cos(t2 - t3)) / (c * np.sin(t2 - t3))
    t2_2 = (a * np.cos(phi - t3) + b * t2_1**2 * np.cos(t2 - t3) - c * t3_1**2) / (b * np.sin(t3 - t2))
    return A, B, (t2, t2_1, t2_2), (t3, t3_1, t3_2)


def _check_four_bar(mo, a, b, c, d, atol=1e-12):
    A, B, t2, t3 = four_bar(PHI, a, b, c, d)
    np.testing.assert_allclose(mo.point("A"), A, rtol=0, atol=1e-15)
    np.testing.assert_allclose(mo.point("B"), B, rtol=0, atol=atol)
    for link, want in (("2", t2), ("3", t3)):
        got = mo.quantity(f"{link}.theta")
        np.testing.assert_allclose(wrap(got[0] - want[0]), 0, atol=atol)
        np.testing.assert_allclose(got[1], want[1], rtol=0, atol=atol)
        np.testing.assert_allclose(got[2], want[2], rtol=0, atol=10 * atol)
    return A, B, t2, t3


def test_four_bar_freudenstein():
    mo = motion("four_bar")
    A, B, t2, t3 = _check_four_bar(mo, 0.1, 0.3, 0.25, 0.3)
    ang = t2[0] + math.radians(30)
    E = A + 0.15 * np.column_stack([np.cos(ang), np.sin(ang)])
    np.testing.assert_allclose(mo.point("E"), E, rtol=0, atol=1e-12)


# ----------------------------------------------------------------------------------------------
# flying shears
# ----------------------------------------------------------------------------------------------

FS = dict(a=0.1, b=0.4, c=0.35, d=0.4)


def test_flying_shears_closed_form_and_knife():
    mo = motion("flying_shears")
    A, B, t2, t3 = _check_four_bar(mo, **FS)
    ang = t2[0] - math.radians(40)
    E = A + 0.25 * np.column_stack([np.cos(ang), np.sin(ang)])
    np.testing.assert_allclose(mo.point("E"), E, rtol=0, atol=1e-12)
    # knife velocity analog: E' = A' + 0.25 t2' E(ang + 90 deg)
    A1 = FS["a"] * np.column_stack([-np.sin(PHI), np.cos(PHI)])
    E1 = A1 + 0.25 * t2[1][:, None] * np.column_stack([-np.sin(ang), np.cos(ang)])
    np.testing.assert_allclose(mo.point_analogs("E")[0], E1, rtol=0, atol=1e-12)


def test_flying_shears_grashof_crank_rocker():
    m = mech("flying_shears")
    ends = {"0": ("O", "C"), "1": ("O", "A"), "2": ("A", "B"), "3": ("C", "B")}
    lengths = {k: math.dist(*(m.links[k].points[p] for p in pts)) for k, pts in ends.items()}
    assert np.allclose([lengths[k] for k in "0123"], [FS["d"], FS["a"], FS["b"], FS["c"]])
    s, l = min(lengths.values()), max(lengths.values())
    assert lengths["1"] == s                      # the crank is the shortest link
    assert s + l < sum(lengths.values()) - s - l  # Grashof: the crank turns fully
    mo = linkage.analyze(m, np.linspace(0, 2 * np.pi, 721), order=0)
    assert np.all(mo.success)


def test_flying_shears_transmission_angle():
    """The angle between coupler and rocker at B, folded into [0, 90] deg, is >= 40 deg."""
    phi = np.linspace(0, 2 * np.pi, 3601)
    mo = linkage.analyze(mech("flying_shears"), phi, order=0)
    u, v = mo.point("A") - mo.point("B"), mo.point("C") - mo.point("B")
    mu = np.degrees(np.arccos(np.sum(u * v, axis=1) / np.linalg.norm(u, axis=1) / np.linalg.norm(v, axis=1)))
    folded = np.minimum(mu, 180 - mu)
    assert folded.min() >= 40.0
    # the extremes of mu are at the crank's two in-line positions (|AC| = d -+ a)
    a, b, c, d = FS.values()
    mu_lo = math.degrees(math.acos((b**2 + c**2 - (d - a) ** 2) / (2 * b * c)))
    mu_hi = math.degrees(math.acos((b**2 + c**2 - (d + a) ** 2) / (2 * b * c)))
    assert abs(mu.min() - mu_lo) < 1e-9 and abs(mu.max() - mu_hi) < 1e-9
    assert min(mu_lo, 180 - mu_hi) >= 40.0


# ----------------------------------------------------------------------------------------------
# six-bar: four-bar + rod and slider
# ----------------------------------------------------------------------------------------------


def test_six_bar_closed_form():
    mo = motion("six_bar")
    _, _, _, t3 = _check_four_bar(mo, 0.1, 0.3, 0.25, 0.3)
    D = np.array([0.3, 0.0]) + 0.35 * np.column_stack([np.cos(t3[0]), np.sin(t3[0])])
    np.testing.assert_allclose(mo.point("D"), D, rtol=0, atol=1e-12)
    xF = D[:, 0] + np.sqrt(0.4**2 - (0.3 - D[:, 1]) ** 2)
    np.testing.assert_allclose(mo.quantity("F.x")[0], xF, rtol=0, atol=1e-12)
    np.testing.assert_allclose(mo.quantity("F.y")[0], 0.3, rtol=0, atol=1e-15)
    # F' from x_F = x_D + sqrt(l4^2 - (0.3 - y_D)^2)
    D1 = 0.35 * t3[1][:, None] * np.column_stack([-np.sin(t3[0]), np.cos(t3[0])])
    xF1 = D1[:, 0] + (0.3 - D[:, 1]) * D1[:, 1] / (xF - D[:, 0])
    np.testing.assert_allclose(mo.quantity("F.x")[1], xF1, rtol=0, atol=1e-12)


# ----------------------------------------------------------------------------------------------
# Scotch yoke
# ----------------------------------------------------------------------------------------------

R_YOKE, D_OFFSET = 0.05, 0.15


def test_scotch_yoke_is_harmonic():
    mo = motion("scotch_yoke")
    x, x1, x2 = mo.quantity("D.x")
    np.testing.assert_allclose(x, R_YOKE * np.cos(PHI) + D_OFFSET, rtol=0, atol=1e-15)
    np.testing.assert_allclose(x1, -R_YOKE * np.sin(PHI), rtol=0, atol=1e-15)
    np.testing.assert_allclose(x2, -R_YOKE * np.cos(PHI), rtol=0, atol=1e-15)
    for arr in mo.quantity("D.y"):
        np.testing.assert_allclose(arr, 0, atol=1e-15)
    for arr in mo.quantity("3.theta"):
        np.testing.assert_allclose(arr, 0, atol=1e-15)
    s, s1, s2 = mo.quantity("slot.s")  # the block's height in the slot
    np.testing.assert_allclose(s, R_YOKE * np.sin(PHI), rtol=0, atol=1e-15)
    np.testing.assert_allclose(s1, R_YOKE * np.cos(PHI), rtol=0, atol=1e-15)
    np.testing.assert_allclose(s2, -R_YOKE * np.sin(PHI), rtol=0, atol=1e-15)
    np.testing.assert_allclose(mo.quantity("rail.s")[0], R_YOKE * np.cos(PHI), rtol=0, atol=1e-15)


def test_scotch_yoke_extreme_positions():
    """Both dead centres, phi = 0 and pi (a root exactly at the start of the sweep included)."""
    ext = linkage.extreme_positions(mech("scotch_yoke"), "D.x")
    assert abs(wrap(ext.phi_max)) < 1e-10
    assert abs(ext.phi_min - math.pi) < 1e-10
    assert abs(ext.stroke - 2 * R_YOKE) < 1e-14


# ----------------------------------------------------------------------------------------------
# slotted link
# ----------------------------------------------------------------------------------------------

R_CRANK, O1_Y = 0.076, 0.12


def test_slotted_link_rocker_follows_the_block():
    mo = motion("slotted_link")
    A = np.column_stack([R_CRANK * np.cos(PHI), O1_Y + R_CRANK * np.sin(PHI)])
    A1 = R_CRANK * np.column_stack([-np.sin(PHI), np.cos(PHI)])
    np.testing.assert_allclose(mo.point("A"), A, rtol=0, atol=1e-15)
    t, t1, _ = mo.quantity("3.theta")
    np.testing.assert_allclose(wrap(t - np.arctan2(A[:, 1], A[:, 0])), 0, atol=1e-14)
    r2 = np.sum(A * A, axis=1)
    np.testing.assert_allclose(t1, (A[:, 0] * A1[:, 1] - A[:, 1] * A1[:, 0]) / r2, rtol=0, atol=1e-13)
    np.testing.assert_allclose(mo.quantity("slot.s")[0], np.sqrt(r2), rtol=0, atol=1e-15)
    C = 0.5 * np.column_stack([np.cos(t), np.sin(t)])
    np.testing.assert_allclose(mo.point("C"), A / np.sqrt(r2)[:, None] * 0.5, rtol=0, atol=1e-14)
    np.testing.assert_allclose(mo.point("C"), C, rtol=0, atol=1e-15)


def test_slotted_link_extreme_positions():
    """Extremes with the crank perpendicular to the rocker: half swing asin(r / O1O3)."""
    delta = math.asin(R_CRANK / O1_Y)
    ext = linkage.extreme_positions(mech("slotted_link"), "3.theta")
    assert abs(ext.value_max - (math.pi / 2 + delta)) < 1e-13
    assert abs(ext.value_min - (math.pi / 2 - delta)) < 1e-13
    assert abs(ext.phi_max - (math.pi + delta)) < 1e-10
    assert abs(ext.phi_min - (2 * math.pi - delta)) < 1e-10
