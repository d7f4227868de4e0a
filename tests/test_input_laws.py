"""Several input links (mobility W > 1): each further input's angle follows a law of the first's.

Oracles, all written here: the shipped five-bar's points by circle intersection for given crank
angles; analogs by central differences of those; each crank's balancing moment as the generalized
force of its own coordinate in the two-degree-of-freedom five-bar (partial derivatives of the
load points' positions, by central differences with the other crank held); a symmetric five-bar
whose tool point stays on the symmetry line; tables sampled from a smooth law, against the law.
"""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

import linkage
from linkage import MechanismBuilder, SchemeError
from linkage.errors import InputError
from linkage.model.input_laws import InputLaw
from linkage.kinetostatics.reactions import solve_reactions, virtual_power_residual
from linkage.model.scheme import dumps, loads, scheme_path

# the shipped scheme's dimensions (schemes/five_bar_two_input.toml), m, kg, kg m^2
O, Q = np.array([0.0, 0.0]), np.array([0.15, 0.0])
CRANK, COUPLER = 0.05, 0.15
MASS = {"1": 0.4, "2": 0.6, "3": 0.6, "4": 0.4}
INERTIA = {"1": 0.0002, "2": 0.001125, "3": 0.001125, "4": 0.0002}
G = np.array([0.0, -9.81])
TOOL = np.array([0.0, -20.0])          # on B
PHASE = math.radians(150.0)

PHI = np.radians(np.arange(0.0, 360.0, 7.5) + 0.5)


def law(phi):
    return PHASE - phi


def five_bar(phi1, theta4):
    """Points A, B, D, S2, S3 and the couplers' angles for crank angles ``phi1`` and ``theta4``
    (B left of A -> D: elbow up), by circle intersection."""
    phi1, theta4 = np.broadcast_arrays(np.asarray(phi1, float), np.asarray(theta4, float))
    a = O + CRANK * np.stack([np.cos(phi1), np.sin(phi1)], axis=-1)
    d = Q + CRANK * np.stack([np.cos(theta4), np.sin(theta4)], axis=-1)
    ad = d - a
    dist = np.linalg.norm(ad, axis=-1)
    half = np.sqrt(COUPLER**2 - (dist / 2) ** 2)
    unit = ad / dist[..., None]
    normal = np.stack([-unit[..., 1], unit[..., 0]], axis=-1)     # to the left of A -> D
    b = (a + d) / 2 + half[..., None] * normal
    return {"A": a, "B": b, "D": d, "S2": (a + b) / 2, "S3": (d + b) / 2,
            "2": np.arctan2(*(b - a)[..., ::-1].T), "3": np.arctan2(*(b - d)[..., ::-1].T), "1": phi1, "4": theta4}


def test_shipped_five_bar_positions_and_analogs():
    mech = linkage.load("five_bar_two_input")
    motion = linkage.analyze(mech, PHI)
    exact = five_bar(PHI, law(PHI))
    size = mech.size
    for p in ("A", "B", "D", "S2", "S3"):
        assert np.max(np.abs(motion.point(p) - exact[p])) < 1e-12 * size, p
    assert np.max(np.abs(motion.poses["4"][:, 2] - exact["4"])) < 1e-12
    h = 1e-4
    ahead, behind = five_bar(PHI + h, law(PHI + h)), five_bar(PHI - h, law(PHI - h))
    for p in ("B", "S2", "D"):
        first = (ahead[p] - behind[p]) / (2 * h)
        second = (ahead[p] - 2 * exact[p] + behind[p]) / h**2
        analog1, analog2 = motion.point_analogs(p)
        assert np.max(np.abs(analog1 - first)) < 1e-7 * size, p
        assert np.max(np.abs(analog2 - second)) < 1e-5 * size, p
    assert np.allclose(motion.first["4"][:, 2], -1.0) and np.allclose(motion.second["4"][:, 2], 0.0)


def generalized_forces(phi, omega, eps):
    """Each crank's balancing moment from the virtual power of its own coordinate, the other held:
    ``M_k = -sum(F . dr/dq_k + M dtheta/dq_k)`` over gravity, the tool's force and the inertia loads."""
    theta4 = law(phi)
    h = 1e-4
    here = five_bar(phi, theta4)
    # real accelerations along the motion (q4 = law(q1)): central differences in phi
    ahead, behind = five_bar(phi + h, law(phi + h)), five_bar(phi - h, law(phi - h))

    def wrapped(x):
        return (x + np.pi) % (2 * np.pi) - np.pi

    def accel(key):
        """Real acceleration of a point (N, 2) or angular acceleration of a link (N,)."""
        if key in ("2", "3"):
            first = wrapped(ahead[key] - behind[key]) / (2 * h)
            second = (wrapped(ahead[key] - here[key]) - wrapped(here[key] - behind[key])) / h**2
            return second * omega**2 + first * eps
        first = (ahead[key] - behind[key]) / (2 * h)
        second = (ahead[key] - 2 * here[key] + behind[key]) / h**2
        return second * omega**2 + first * eps

    loads = []     # (point key, force (N, 2)) and (link key, moment (N,))
    for link, com in (("2", "S2"), ("3", "S3")):
        loads.append(("force", com, MASS[link] * G - MASS[link] * accel(com)))
        loads.append(("moment", link, -INERTIA[link] * accel(link)))
    for link in ("1", "4"):      # cranks: centres of mass on their pivots; inertia moments
        loads.append(("moment", link, -INERTIA[link] * law_rate(link) * eps))   # theta'' = 0 for both
    loads.append(("force", "B", np.broadcast_to(TOOL, here["B"].shape)))
    moments = {}
    for k in ("1", "4"):
        plus = five_bar(phi + h, theta4) if k == "1" else five_bar(phi, theta4 + h)
        minus = five_bar(phi - h, theta4) if k == "1" else five_bar(phi, theta4 - h)
        power = np.zeros(len(phi))
        for kind, key, value in loads:
            if kind == "force":
                power += np.einsum("ni,ni->n", value, (plus[key] - minus[key]) / (2 * h))
            else:
                power += value * wrapped(plus[key] - minus[key]) / (2 * h)
        moments[k] = -power
    return moments


def law_rate(link):
    return 1.0 if link == "1" else -1.0


@pytest.mark.parametrize("omega, eps", [(0.0, 0.0), (12.0, 0.0), (-8.0, 30.0)])
def test_balancing_moment_per_input_against_generalized_forces(omega, eps):
    mech = linkage.load("five_bar_two_input")
    motion = linkage.analyze(mech, PHI, omega=omega, eps=eps)
    reactions = solve_reactions(motion)
    expected = generalized_forces(PHI, omega, eps)
    scale = max(np.max(np.abs(v)) for v in expected.values())
    assert np.max(np.abs(reactions.balancing_moment - expected["1"])) < 1e-6 * scale
    assert np.max(np.abs(reactions.balancing_moments["4"] - expected["4"])) < 1e-6 * scale
    assert reactions.balancing_moments["1"] is reactions.balancing_moment
    assert np.max(virtual_power_residual(reactions)) < 1e-12
    columns = reactions.columns()
    assert np.array_equal(columns["balancing_moment.4"], reactions.balancing_moments["4"])


def symmetric_five_bar(phase_deg=180.0) -> MechanismBuilder:
    b = MechanismBuilder("symmetric_five_bar")
    b.link("0", points={"O": (0.0, 0.0), "Q": (0.15, 0.0)})
    b.link("1", line=("O", "A"), length=0.05)
    b.link("2", line=("A", "B"), length=0.15)
    b.link("3", line=("D", "B"), length=0.15)
    b.link("4", line=("Q", "D"), length=0.05)
    for pair, x, y in [("O", "0", "1"), ("A", "1", "2"), ("B", "2", "3"), ("D", "3", "4"), ("Q", "4", "0")]:
        b.revolute(pair, x, y)
    return b.inputs("1", "4").assembly("B", left_of=("A", "D"))


def test_mirrored_cranks_keep_the_tool_on_the_symmetry_line():
    # theta_4 = 180 deg - phi mirrors D of A about x = 0.075: B stays on that line
    mech = symmetric_five_bar().input_law("4", ratio=-1.0, phase=math.pi).build()
    motion = linkage.analyze(mech, PHI)
    b, (b1, b2) = motion.point("B"), motion.point_analogs("B")
    assert np.max(np.abs(b[:, 0] - 0.075)) < 1e-14
    assert np.max(np.abs(b1[:, 0])) < 1e-13 and np.max(np.abs(b2[:, 0])) < 1e-12


def test_periodic_table_follows_its_smooth_law():
    # theta_4 = 150 deg - phi + 0.3 sin(phi), sampled every 5 deg over one turn (it loses one turn)
    grid = np.radians(np.arange(0.0, 361.0, 5.0))
    smooth = lambda p: PHASE - p + 0.3 * np.sin(p)                  # noqa: E731
    mech = symmetric_five_bar().input_law("4", table=(grid, smooth(grid))).build()
    phi = np.radians(np.arange(-400.0, 400.0, 3.7))                  # beyond the table, both ways
    motion = linkage.analyze(mech, phi)
    theta = motion.poses["4"][:, 2]
    assert np.max(np.abs(theta - smooth(phi))) < 2e-6
    assert np.max(np.abs(motion.first["4"][:, 2] - (-1 + 0.3 * np.cos(phi)))) < 2e-4
    assert np.max(np.abs(motion.second["4"][:, 2] + 0.3 * np.sin(phi))) < 2e-2
    assert np.max(np.abs(motion.point("D") - five_bar(phi, theta)["D"])) < 1e-14


def test_table_over_part_of_a_turn_needs_a_range_inside_it():
    grid = np.radians(np.arange(0.0, 181.0, 10.0))
    table = (grid, PHASE - grid)
    with pytest.raises(SchemeError, match=r"input law of link '4': its table holds for phi in \[0, 180\] deg"):
        symmetric_five_bar().input_law("4", table=table).build()
    mech = symmetric_five_bar().input_law("4", table=table).input_range(math.radians(10), math.radians(170)).build()
    motion = linkage.analyze(mech, np.radians([10.0, 90.0, 170.0]))
    assert np.allclose(motion.poses["4"][:, 2], PHASE - np.radians([10.0, 90.0, 170.0]), atol=1e-12)
    with pytest.raises(InputError, match=r"200 deg lie outside the table of input link '4' \(0 to 180 deg\)"):
        linkage.analyze(mech, np.radians([90.0, 200.0]))


@pytest.mark.parametrize("law_kwargs, message", [
    ({}, "input link '4' needs a law"),
    ({"ratio": 0.0}, "ratio must be"),
    ({"ratio": float("nan")}, "ratio must be"),
    ({"table": ([0.0, 1.0, 2.0], [0.0, 1.0, 2.0])}, "at least 4 pairs"),
    ({"table": ([0.0, 1.0, 1.0, 2.0], [0.0, 1.0, 2.0, 3.0])}, "must increase; entry 3"),
    ({"table": ([0.0, 2.0, 4.0, 7.0], [0.0, 1.0, 2.0, 3.0])}, "spans 401.07"),
    ({"table": ([0.0, 2.0, 4.0, 2 * math.pi], [0.0, 1.0, 2.0, 3.0])}, "whole number of turns"),
    ({"table": ([0.0, 1.0, 2.0, 3.0], [0.0, 1.0, 2.0, 3.0]), "ratio": 2.0}, "not both"),
])
def test_refused_laws_name_the_link_and_the_value(law_kwargs, message):
    b = symmetric_five_bar()
    if law_kwargs:
        b.input_law("4", **law_kwargs)
    with pytest.raises(SchemeError, match=message):
        b.build()


def test_law_of_a_link_that_is_not_a_further_input():
    with pytest.raises(SchemeError, match="first input link's angle is phi itself"):
        symmetric_five_bar().input_law("4", ratio=1.0).input_law("1", ratio=2.0).build()
    with pytest.raises(SchemeError, match="'3' is not an input link"):
        symmetric_five_bar().input_law("4", ratio=1.0).input_law("3", ratio=2.0).build()


@pytest.mark.parametrize("law", [InputLaw(-2.0, 0.4), InputLaw(table=((0.0, 1.0, 2.5, 4.0, 2 * math.pi),
                                                                       (0.1, 0.5, 0.2, 0.3, 0.1)))])
def test_scheme_text_round_trip(law):
    b = symmetric_five_bar()
    b.input_law("4", ratio=law.ratio, phase=law.phase) if law.table is None else b.input_law("4", table=law.table)
    mech = b.build()
    again = loads(dumps(mech))
    assert again.input_laws == mech.input_laws
    phi = np.radians([3.0, 100.0, 250.0])
    assert np.array_equal(linkage.analyze(again, phi).point("B"), linkage.analyze(mech, phi).point("B"))


def test_scheme_keys_in_degrees():
    text = (scheme_path("five_bar_two_input")).read_text()
    table = ", ".join(f"[{p:g}, {150 - p:g}]" for p in range(0, 361, 45))
    changed = text.replace("ratio = -1.0                      # a pair of equal gears: it turns the other way, as fast\n"
                           "phase_deg = 150.0", f"table_deg = [{table}]")
    assert changed != text
    mech, shipped = loads(changed), linkage.load("five_bar_two_input")
    assert np.max(np.abs(linkage.analyze(mech, PHI).point("B") - linkage.analyze(shipped, PHI).point("B"))) < 1e-13
    bad = text.replace("phase_deg = 150.0", "phase_deg = 150.0\nphase = 2.0")
    with pytest.raises(SchemeError, match="input_laws.4"):
        loads(bad)


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "linkage", *args], capture_output=True, text=True, timeout=120)


def test_cli_input_law_overrides_the_scheme(tmp_path):
    shipped = run_cli("analyze", "five_bar_two_input", "--format", "csv", "--columns", "B.*")
    same = run_cli("analyze", "five_bar_two_input", "--input-law", "4:-1:150", "--format", "csv", "--columns", "B.*")
    assert shipped.returncode == same.returncode == 0
    assert same.stdout == shipped.stdout
    csv = tmp_path / "law.csv"
    csv.write_text("phi_deg,theta_deg\n" + "".join(f"{p},{180 - p}\n" for p in range(0, 361, 30)))
    mirrored = run_cli("analyze", "five_bar_two_input", "--input-law", f"4:{csv}", "--format", "csv", "--columns",
                       "B.x", "--positions", "8")
    assert mirrored.returncode == 0, mirrored.stderr
    rows = [line.split(",") for line in mirrored.stdout.splitlines() if line and line[0].isdigit()]
    assert len(rows) == 9 and all(abs(float(r[-1]) - 0.075) < 1e-12 for r in rows)
    forces = run_cli("forces", "five_bar_two_input", "--omega", "10", "--format", "csv")
    assert forces.returncode == 0, forces.stderr
    header = next(line for line in forces.stdout.splitlines() if line.startswith("i,"))
    assert header.split(",")[2:4] == ["balancing_moment", "balancing_moment.4"]


@pytest.mark.parametrize("argument, message", [
    ("4:0", "the ratio must be nonzero"),
    ("4", "expected LINK:RATIO"),
    ("3:2", "'3' is not an input link"),
    ("4:missing.csv", "cannot read it"),
])
def test_cli_refuses_bad_laws_without_a_traceback(argument, message):
    done = run_cli("analyze", "five_bar_two_input", "--input-law", argument)
    assert done.returncode != 0
    assert message in done.stderr and "Traceback" not in done.stderr


def test_reduced_inertia_counts_the_second_crank_with_its_law():
    """I_red(phi) = sum(m v_S^2 + J w^2) / w_1^2 with the kinetic energy computed here (crank 4 at
    theta_4' = -1 + 0.3 cos(phi), the couplers by central differences of the circle intersection)."""
    from linkage.dynamics.reduced import reduced_characteristics

    grid = np.radians(np.arange(0.0, 361.0, 2.0))
    smooth = lambda p: PHASE - p + 0.3 * np.sin(p)                  # noqa: E731
    shipped = linkage.load("five_bar_two_input")
    mech = shipped.with_input_laws(**{"4": InputLaw(table=(tuple(grid), tuple(smooth(grid))))})
    reduced = reduced_characteristics(mech, PHI, 1)
    h = 1e-5
    ahead, behind = five_bar(PHI + h, smooth(PHI + h)), five_bar(PHI - h, smooth(PHI - h))
    energy = INERTIA["1"] * 1.0                                      # crank 1: com on its pivot
    for link, com in (("2", "S2"), ("3", "S3")):
        v = (ahead[com] - behind[com]) / (2 * h)
        w = ((ahead[link] - behind[link] + np.pi) % (2 * np.pi) - np.pi) / (2 * h)
        energy = energy + MASS[link] * np.sum(v**2, axis=1) + INERTIA[link] * w**2
    energy = energy + INERTIA["4"] * (-1 + 0.3 * np.cos(PHI)) ** 2  # crank 4: com on its pivot
    assert np.max(np.abs(reduced.inertia - energy)) < 1e-5 * np.max(energy)
    assert reduced.inertia_constant == pytest.approx(INERTIA["1"], rel=1e-12)
