"""The hand-fused four-bar kernel of ``benchmarks/handfused.py`` against the library and independent oracles.

The kernel is what ``benchmarks/run.py`` times the library against, so it must do the same work and
get the same numbers. The checks run both ways: the kernel equals ``linkage.analyze`` (to 1e-12
relative), its positions satisfy the four-bar's constraints (distances, the assembly side, the
coupler point's place on the coupler), its analogs equal 5-point finite differences of its
positions, and it gives NaN exactly where the dyad cannot close (|C - A| > AB + CB, in closed
form) where the library reports status -1. Together they are an independent check of the library.
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

import linkage
from linkage import MechanismBuilder

_PATH = Path(__file__).resolve().parent.parent / "benchmarks" / "handfused.py"
_spec = importlib.util.spec_from_file_location("handfused", _PATH)
handfused = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(handfused)

SHIPPED = {"OA": 0.1, "AB": 0.3, "CB": 0.25, "C": (0.3, 0.0), "E_distance": 0.15, "E_deg": 30.0}
POINTS = ("A", "B", "E")


def e_local(distance: float, degrees: float) -> tuple[float, float]:
    """Coupler point in link 2's frame (x along A -> B), m."""
    return distance * math.cos(math.radians(degrees)), distance * math.sin(math.radians(degrees))


def kernel_args(g: dict) -> dict:
    return {"OA": g["OA"], "AB": g["AB"], "CB": g["CB"], "C": g["C"], "E_local": e_local(g["E_distance"], g["E_deg"])}


def build_fourbar(g: dict) -> linkage.Mechanism:
    """The four-bar of geometry ``g`` through the library's builder (as README shows it)."""
    b = MechanismBuilder("four_bar_test")
    b.link("0", points={"O": (0.0, 0.0), "C": g["C"]})
    b.link("1", line=("O", "A"), length=g["OA"])
    b.link("2", line=("A", "B"), length=g["AB"],
           points={"E": {"from": "A", "distance": g["E_distance"], "angle_deg": g["E_deg"]}})
    b.link("3", line=("C", "B"), length=g["CB"])
    for name, one, other in [("O", "0", "1"), ("A", "1", "2"), ("B", "2", "3"), ("C", "3", "0")]:
        b.revolute(name, one, other)
    b.inputs("1").assembly("B", left_of=("A", "C"))
    return b.build()


def library_quantities(motion: linkage.Motion) -> dict[str, np.ndarray]:
    """The library's results under the kernel's names."""
    out = {}
    for p in POINTS:
        out[p] = motion.point(p)
        out["d" + p], out["dd" + p] = motion.point_analogs(p)
    for k in ("2", "3"):
        out["theta" + k] = motion.poses[k][:, 2]
        out["dtheta" + k] = motion.first[k][:, 2]
        out["ddtheta" + k] = motion.second[k][:, 2]
    return out


def assert_close_relative(name: str, got: np.ndarray, want: np.ndarray, rel: float) -> None:
    """|got - want| <= rel * max|want| (angles compared modulo 2 pi)."""
    diff = got - want
    if name.startswith("theta"):
        diff = np.angle(np.exp(1j * diff))
    scale = max(float(np.max(np.abs(want))), 1e-300)
    worst = float(np.max(np.abs(diff)))
    assert worst <= rel * scale, f"{name}: largest difference {worst:.3g} > {rel:g} x {scale:.3g}"


@pytest.fixture(scope="module")
def phi() -> np.ndarray:
    return np.linspace(0.0, 2.0 * np.pi, 720, endpoint=False)


def test_kernel_equals_library_on_the_shipped_four_bar(phi):
    motion = linkage.analyze(linkage.load("four_bar"), phi, order=2, on_failure="mask")
    assert np.all(motion.status == 0)
    got = handfused.fourbar_kinematics(phi, **kernel_args(SHIPPED))
    want = library_quantities(motion)
    assert set(got) == set(want)
    for name in want:
        assert got[name].shape == want[name].shape, name
        assert_close_relative(name, got[name], want[name], 1e-12)


def test_positions_kernel_equals_the_full_kernel(phi):
    full = handfused.fourbar_kinematics(phi, **kernel_args(SHIPPED))
    pos = handfused.fourbar_positions(phi, **kernel_args(SHIPPED))
    assert set(pos) == {"A", "B", "E", "theta2", "theta3"}
    for name, value in pos.items():
        np.testing.assert_array_equal(value, full[name])


def test_positions_satisfy_the_four_bar_constraints(phi):
    g = SHIPPED
    k = handfused.fourbar_positions(phi, **kernel_args(g))
    a, b, e = k["A"], k["B"], k["E"]
    c = np.array(g["C"])
    np.testing.assert_allclose(a, g["OA"] * np.column_stack([np.cos(phi), np.sin(phi)]), rtol=0, atol=1e-15)
    np.testing.assert_allclose(np.hypot(*(b - a).T), g["AB"], rtol=1e-14)
    np.testing.assert_allclose(np.hypot(*(b - c).T), g["CB"], rtol=1e-14)
    ac, ab = c - a, b - a
    assert np.all(ac[:, 0] * ab[:, 1] - ac[:, 1] * ab[:, 0] > 0), "B must be on the left of A -> C"
    np.testing.assert_allclose(np.hypot(*(e - a).T), g["E_distance"], rtol=1e-14)
    turn = np.arctan2(*(e - a).T[::-1]) - np.arctan2(*ab.T[::-1])
    np.testing.assert_allclose(np.angle(np.exp(1j * turn)), math.radians(g["E_deg"]), rtol=0, atol=1e-13)
    np.testing.assert_allclose(k["theta2"], np.arctan2(ab[:, 1], ab[:, 0]), rtol=0, atol=1e-15)


def five_point(f, phi: np.ndarray, h: float) -> tuple[dict, dict]:
    """5-point central first and second differences of every output of ``f(phi)``."""
    fm2, fm1, f0, fp1, fp2 = (f(phi + k * h) for k in (-2, -1, 0, 1, 2))
    first = {n: (fm2[n] - 8 * fm1[n] + 8 * fp1[n] - fp2[n]) / (12 * h) for n in f0}
    second = {n: (-fm2[n] + 16 * fm1[n] - 30 * f0[n] + 16 * fp1[n] - fp2[n]) / (12 * h * h) for n in f0}
    return first, second


@pytest.mark.parametrize("geometry", [SHIPPED, {"OA": 0.05, "AB": 0.2, "CB": 0.18, "C": (0.15, 0.04),
                                                "E_distance": 0.3, "E_deg": -60.0}])
def test_analogs_equal_finite_differences(phi, geometry):
    args = kernel_args(geometry)

    def positions(angles):
        out = handfused.fourbar_positions(angles, **args)
        out["theta2"], out["theta3"] = np.unwrap(out["theta2"]), np.unwrap(out["theta3"])
        return out

    first, second = five_point(positions, phi, 1e-3)
    k = handfused.fourbar_kinematics(phi, **args)
    for name in ("A", "B", "E", "theta2", "theta3"):
        assert_close_relative("d" + name, k["d" + name], first[name], 1e-8)
        assert_close_relative("dd" + name, k["dd" + name], second[name], 1e-6)


def test_nan_exactly_where_the_dyad_cannot_close():
    # AB + CB = 0.3: the dyad closes while |C - A| <= 0.3, i.e. cos(phi) >= 1/6 for OA = 0.1, C = (0.3, 0)
    g = {"OA": 0.1, "AB": 0.15, "CB": 0.15, "C": (0.3, 0.0), "E_distance": 0.1, "E_deg": 45.0}
    phi = np.linspace(0.0, 2.0 * np.pi, 361, endpoint=False)
    phi = phi[np.abs(np.cos(phi) - 1.0 / 6.0) > 0.05]            # away from the boundary
    closes = np.cos(phi) >= 1.0 / 6.0
    assert closes.any() and (~closes).any()
    k = handfused.fourbar_kinematics(phi, **kernel_args(g))
    for name, value in k.items():
        if name in ("A", "dA", "ddA"):
            assert np.all(np.isfinite(value)), name                  # the crank always moves
            continue
        rows = value if value.ndim == 1 else value.T
        assert np.all(np.isnan(rows[..., ~closes])), f"{name} is not NaN where the dyad cannot close"
        assert np.all(np.isfinite(rows[..., closes])), f"{name} is not finite where the dyad closes"
    motion = linkage.analyze(build_fourbar(g), phi, order=2, on_failure="mask")
    np.testing.assert_array_equal(motion.status == -1, ~closes)


@pytest.mark.parametrize("seed", range(4))
def test_kernel_equals_library_on_random_four_bars(seed):
    rng = np.random.default_rng(seed)
    g = {"OA": rng.uniform(0.05, 0.15), "AB": rng.uniform(0.25, 0.4), "CB": rng.uniform(0.15, 0.35),
         "C": (rng.uniform(0.2, 0.4), rng.uniform(-0.1, 0.1)), "E_distance": rng.uniform(0.05, 0.3),
         "E_deg": rng.uniform(-180.0, 180.0)}
    phi = np.linspace(0.0, 2.0 * np.pi, 360, endpoint=False)
    motion = linkage.analyze(build_fourbar(g), phi, order=2, on_failure="mask")
    good = (motion.status == 0) & (motion.conditioning["II-RRR(2,3)"] > 0.1)
    assert good.sum() > 30
    got = handfused.fourbar_kinematics(phi, **kernel_args(g))
    want = library_quantities(motion)
    for name in want:
        assert_close_relative(name, got[name][good], want[name][good], 1e-11)
    assert np.all(np.isnan(got["B"][motion.status == -1]))
