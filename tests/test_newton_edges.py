"""The edges of the groups solved by Newton's method: a failure to converge is a typed error naming
the group, the angle and the residual; continuation refines its step where a mode moves fast; a
change point of a traced mode is found, warned about and singular.

Oracles written here: one Newton step on the pin equations with their Jacobian derived by hand,
the smallest singular value of that Jacobian at a position built to be singular, pin gaps, and a
multi-start least-squares solve of the triad.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import least_squares

import assur.generic
import linkage
import linkage.kinematics.tracing
from assur.base import NOT_CONVERGED, OK, SINGULAR
from linkage.kinematics.assembly import assembly_plans
from linkage.errors import AssemblyError, ConvergenceError, SchemeError
from linkage.kinematics.motion import BranchWarning

SCHEMES = Path(__file__).resolve().parent.parent / "schemes"

# ----------------------------------------------------------------------------------------------
# mechanisms: every moving link's frame is the global frame at the design angle, so the local
# points below are the global points there and each link's pose is (0, 0, 0)
# ----------------------------------------------------------------------------------------------

#: a class-IV group (links 2-5 form a closed contour of four; no closed form): crank OA turns
#: link 2 (A, P, S); link 4 (Q, R, T) turns about the frame point T; binary links PQ and RS
CLASS4_POINTS = {"A": (0.03, 0.0), "P": (0.137, 0.13), "S": (0.062, 0.233), "Q": (0.334, 0.084),
                 "R": (0.276, 0.279), "T": (0.396, 0.237)}
CLASS4_LINKS = {"2": "APS", "3": "PQ", "4": "QRT", "5": "RS"}
CLASS4_PAIRS = {"A": ("1", "2"), "P": ("2", "3"), "Q": ("3", "4"), "R": ("4", "5"), "S": ("5", "2"), "T": ("4", "0")}


def _table(points: dict, names: str) -> str:
    return "{ " + ", ".join(f"{n} = [{points[n][0]!r}, {points[n][1]!r}]" for n in names) + " }"


def _scheme(name: str, crank: float, points: dict, links: dict, pairs: dict, frame: str, condition: str,
            extra: str = "") -> str:
    text = [f'name = "{name}"', 'input = "1"', extra,
            "[links.0]", f"points = {_table({'O': (0.0, 0.0), **points}, 'O' + frame)}",
            "[links.1]", 'line = ["O", "A"]', f"length = {crank!r}"]
    for link, names in links.items():
        text += [f"[links.{link}]", f"points = {_table(points, names)}"]
    for pair, (a, b) in {"O": ("0", "1"), **pairs}.items():
        text += [f"[pairs.{pair}]", f'links = ["{a}", "{b}"]']
    return "\n".join(text + [condition, ""])


def class4_text(extra: str = "") -> str:
    return _scheme("class4", 0.03, CLASS4_POINTS, CLASS4_LINKS, CLASS4_PAIRS, "T",
                   '[assembly.P]\nleft_of = ["O", "A"]', extra)


def pose_gap(a: np.ndarray, b: np.ndarray, size: float) -> float:
    """Distance between two stacked poses ``(3 L,)`` of L links, m (angles wrapped, times ``size``)."""
    d = np.asarray(a, float) - np.asarray(b, float)
    d[2::3] = size * ((d[2::3] + np.pi) % (2 * np.pi) - np.pi)
    return float(np.linalg.norm(d))


def gaps(points: dict, pairs: dict, local: dict, poses: dict) -> np.ndarray:
    """``(N, pairs)``: distance between a pair's point as carried by each of its two links, m."""
    out = []
    for pair, (a, b) in pairs.items():
        ends = []
        for link in (a, b):
            x, y, t = poses[link].T
            px, py = local[link][pair]
            ends.append(np.column_stack([x + np.cos(t) * px - np.sin(t) * py, y + np.sin(t) * px + np.cos(t) * py]))
        out.append(np.hypot(*(ends[0] - ends[1]).T))
    return np.column_stack(out)


def local_points(crank: float, points: dict, links: dict, pairs: dict) -> dict:
    """Local coordinates of every pair's point on each link (moving links: the global point at
    the design angle; the crank: along its line; the frame: global)."""
    local = {"0": dict(points), "1": {"A": (crank, 0.0)}}
    for link, names in links.items():
        local[link] = {n: points[n] for n in names}
    return local


def equations(pairs, local, crank_angle, unknown: np.ndarray):
    """The pin equations ``F(q)`` (2 per pair, m) and their Jacobian ``dF/dq`` derived by hand, for
    the group's poses ``q`` (links in the order of ``local``, minus 0 and 1) at a crank angle."""
    movers = [k for k in local if k not in ("0", "1")]
    column = {k: 3 * i for i, k in enumerate(movers)}
    poses = {"0": np.zeros(3), "1": np.array([0.0, 0.0, crank_angle])}
    poses.update({k: unknown[3 * i:3 * i + 3] for i, k in enumerate(movers)})
    F = np.zeros(2 * len(pairs))
    J = np.zeros((2 * len(pairs), 3 * len(movers)))
    for r, (pair, (a, b)) in enumerate(pairs.items()):
        for link, sign in ((a, 1.0), (b, -1.0)):
            x, y, t = poses[link]
            px, py = local[link][pair]
            c, s = np.cos(t), np.sin(t)
            F[2 * r:2 * r + 2] += sign * np.array([x + c * px - s * py, y + s * px + c * py])
            if link in column:
                j = column[link]
                J[2 * r, j], J[2 * r + 1, j + 1] = sign, sign
                J[2 * r:2 * r + 2, j + 2] = sign * np.array([-s * px - c * py, c * px - s * py])
    return F, J


# ----------------------------------------------------------------------------------------------
# 1. Newton failures: a typed error with the group, the angle and the residual
# ----------------------------------------------------------------------------------------------


def test_a_newton_failure_names_the_group_the_angle_and_the_residual(monkeypatch):
    """With one Newton step allowed, no position between the sweep's angles converges: analyze
    raises ConvergenceError with the residual of the point one Newton step reaches from the
    plan's start, computed here on the pin equations; mask mode gives status -4."""
    mech = linkage.loads(class4_text())
    plan = assembly_plans(mech)[0]
    phi = np.radians([40.5, 200.5])
    start = plan.start(phi)
    local = local_points(0.03, CLASS4_POINTS, CLASS4_LINKS, CLASS4_PAIRS)
    expected = []
    for n, angle in enumerate(phi):
        q0 = np.concatenate([start[k][n] for k in CLASS4_LINKS])
        F, J = equations(CLASS4_PAIRS, local, angle, q0)
        q1 = q0 - np.linalg.solve(J, F)
        reached = {k: q1[None, 3 * i:3 * i + 3] for i, k in enumerate(CLASS4_LINKS)}
        reached.update({"0": np.zeros((1, 3)), "1": np.array([[0.0, 0.0, angle]])})
        expected.append(float(np.max(gaps(CLASS4_POINTS, CLASS4_PAIRS, local, reached))))
        assert expected[-1] < 1e-3 * np.max(gaps(CLASS4_POINTS, CLASS4_PAIRS, local, {**reached, **{
            k: start[k][n:n + 1] for k in CLASS4_LINKS}}))          # one step closes the start's gap a lot

    monkeypatch.setattr(assur.generic, "NEWTON_STEPS", 1)
    with pytest.raises(ConvergenceError) as caught:
        linkage.analyze(mech, phi)
    error = caught.value
    assert isinstance(error, AssemblyError)
    assert error.group == "IV(2,3,4,5)"
    np.testing.assert_allclose(error.not_converged_deg, [40.5, 200.5])
    np.testing.assert_allclose(error.angles_deg, [40.5, 200.5])
    np.testing.assert_allclose(error.residual, expected, rtol=1e-5)
    assert error.size == pytest.approx(mech.size)
    text = str(error)
    assert "IV(2,3,4,5)" in text and "40.5 (" in text and "200.5 (" in text
    assert f"{error.residual[0]:.3g} m, {error.residual[0] / mech.size:.3g}" in text

    motion = linkage.analyze(mech, phi, on_failure="mask")
    assert np.all(motion.status == NOT_CONVERGED)
    assert np.all(np.isnan(motion.poses["3"]))
    # the sweep's own angles start on a trace sample closed to TRACE_CLOSURE of the size: the
    # polish to STEP_TOL takes two steps there
    monkeypatch.setattr(assur.generic, "NEWTON_STEPS", 2)
    assert np.all(linkage.analyze(mech, np.radians([40.0, 200.0]), on_failure="mask").status == OK)
    assert np.all(linkage.analyze(mech, phi, on_failure="mask").status == NOT_CONVERGED)


def test_a_start_on_another_mode_is_not_a_silent_success():
    """Newton's method from a start far from every solution (every link moved by half the size)
    reports -4, never OK with whatever mode it wanders to; the residual is that of its point."""
    mech = linkage.loads(class4_text())
    group = linkage.structure_of(mech).groups[0]
    plan = assembly_plans(mech)[0]
    phi = np.radians([40.5])
    known = {"0": np.zeros((1, 3)), "1": np.array([[0.0, 0.0, phi[0]]])}
    start = {k: v + [0.5 * mech.size, -0.5 * mech.size, 2.0] for k, v in plan.start(phi).items()}
    placed = group.position(known, start=start)
    assert placed.status[0] == NOT_CONVERGED
    assert np.isfinite(group.closure(known, start)[0])


# ----------------------------------------------------------------------------------------------
# 2. continuation with step control
# ----------------------------------------------------------------------------------------------

COARSE = 16      # sweep angles: 22.5 deg steps


@pytest.mark.parametrize("scheme", ["six_bar_class3", "class4"])
def test_a_fast_mode_is_traced_at_a_coarse_sweep(monkeypatch, scheme):
    """At 22.5 deg steps the group moves more than TRACE_JUMP of the size between sweep angles (the
    triad's listed modes and the class-IV group's Newton continuation alike): the step is refined
    and the mode kept, equal to the analysis with the default 1 deg sweep; without refinement the
    mode is lost."""
    text = (SCHEMES / "six_bar_class3.toml").read_text() if scheme == "six_bar_class3" else class4_text()
    fine = linkage.loads(text)
    sweep = np.linspace(0.0, 2 * np.pi, COARSE, endpoint=False)
    reference = linkage.analyze(fine, sweep, order=0)
    stacked = np.concatenate([reference.poses[k] for k in ("2", "3", "4", "5")], axis=1)
    moves = [pose_gap(stacked[(m + 1) % COARSE], stacked[m], fine.size) for m in range(COARSE)]
    assert max(moves) > assur.generic.TRACE_JUMP * fine.size          # the mode is fast at this sweep

    monkeypatch.setattr(linkage.kinematics.assembly, "BRANCH_SWEEP", COARSE)
    coarse = linkage.loads(text)
    angles, poses = assembly_plans(coarse)[0].track
    assert len(angles) > COARSE                                            # refined between sweep angles
    assert all(np.all(np.isfinite(v)) for v in poses.values())
    exact = linkage.analyze(fine, angles, order=0)
    for k, v in poses.items():
        np.testing.assert_allclose(v[:, :2], exact.poses[k][:, :2], atol=1e-9 * fine.size)
        turn = (v[:, 2] - exact.poses[k][:, 2] + np.pi) % (2 * np.pi) - np.pi
        np.testing.assert_allclose(turn, 0.0, atol=1e-9)
    between = np.radians(np.arange(0.0, 360.0, 7.0) + 3.0)
    got, want = (linkage.analyze(m, between, order=0, on_failure="mask") for m in (coarse, fine))
    assert np.all(want.status == OK) and np.all(got.status == OK)
    np.testing.assert_allclose(got.point("P" if scheme == "class4" else "D"),
                               want.point("P" if scheme == "class4" else "D"), atol=1e-12)

    # without the refined steps the mode cannot be followed at this sweep: it breaks into pieces that
    # the condition cannot tell apart, or the chosen piece leaves gaps
    monkeypatch.setattr(linkage.kinematics.tracing, "REFINEMENTS", 0)
    try:
        lost = assembly_plans(linkage.loads(text))[0].track[1]
    except SchemeError as exc:
        assert "does not tell its assembly modes apart" in str(exc)
    else:
        assert any(np.any(np.isnan(v)) for v in lost.values())


# ----------------------------------------------------------------------------------------------
# 3. a change point of a traced triad
# ----------------------------------------------------------------------------------------------

PHI_C = np.radians(100.3)


def _turned(p, angle=PHI_C):
    c, s = np.cos(angle), np.sin(angle)
    return (float(c * p[0] - s * p[1]), float(s * p[0] + c * p[1]))


def _change_point_triad():
    """A triad whose legs' lines AB, EC and FD meet at one point Q (the ternary link can turn
    about Q: the group is singular) at the crank angle PHI_C, where the leg AB also passes
    through the crank's pivot O (the crank then does no work on the legs' self-stress, so two
    assembly modes cross there instead of ending). Built in a frame along OA, then turned."""
    crank = 0.05
    Q, C, D = np.array([0.296, 0.0]), np.array([0.168, 0.080]), np.array([0.203, -0.191])
    E, F = Q - 0.886 * (C - Q), Q + 1.718 * (D - Q)
    along = {"A": (crank, 0.0), "B": (0.166, 0.0), "C": C, "D": D, "E": E, "F": F}
    points = {n: _turned(p) for n, p in along.items()}
    links = {"2": "AB", "3": "BCD", "4": "EC", "5": "FD"}
    pairs = {"A": ("1", "2"), "B": ("2", "3"), "C": ("3", "4"), "D": ("3", "5"), "E": ("4", "0"), "F": ("5", "0")}
    text = _scheme("change_point_triad", crank, points, links, pairs, "EF", '[assembly.D]\nright_of = ["F", "C"]')
    return text, points, links, pairs, crank


def brute_force_modes(points, links, pairs, crank, angle, starts=80, seed=0):
    """Every pose of the four moving links at a crank angle by least squares on the pin
    equations from many random starts."""
    local = local_points(crank, points, links, pairs)
    rng = np.random.default_rng(seed)
    found = []
    for _ in range(starts):
        q0 = np.concatenate([np.r_[rng.uniform(-0.2, 0.2, 2), rng.uniform(-np.pi, np.pi)] for _ in links])
        s = least_squares(lambda q: equations(pairs, local, angle, q)[0], q0,
                          jac=lambda q: equations(pairs, local, angle, q)[1], xtol=1e-15, ftol=1e-15, gtol=1e-15)
        if np.max(np.abs(s.fun)) < 1e-12:
            q = s.x.copy()
            q[2::3] = (q[2::3] + np.pi) % (2 * np.pi) - np.pi
            if not any(np.max(np.abs(q - p)) < 1e-7 for p in found):
                found.append(q)
    return found


def test_a_change_point_of_a_traced_triad_is_found_warned_and_singular():
    text, points, links, pairs, crank = _change_point_triad()
    local = local_points(crank, points, links, pairs)
    # singular by construction: the pin equations' Jacobian at the design position loses rank
    _, J = equations(pairs, local, PHI_C, np.zeros(12))
    sigma = np.linalg.svd(J, compute_uv=False)
    assert sigma[-1] < 1e-14 * sigma[0]

    mech = linkage.loads(text)
    plan = assembly_plans(mech)[0]
    np.testing.assert_allclose(plan.change_points, [PHI_C], atol=1e-6)
    # the analysed angles lie at the change point: exactly that warning, naming the group and angle
    with pytest.warns(BranchWarning, match=r"III\(2,3,4,5\) passes a change point at input angle\(s\) 100\.3 deg"):
        at = linkage.analyze(mech, [PHI_C, plan.change_points[0]], on_failure="mask")
    assert at.status.tolist() == [SINGULAR] * 2

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        motion = linkage.analyze(mech, PHI_C + np.radians(np.arange(-20.0, 20.1, 0.5)), on_failure="mask")
    said = [str(w.message) for w in caught if issubclass(w.category, BranchWarning)]
    assert any("change point at input angle(s) 100.3 deg" in s and "III(2,3,4,5)" in s for s in said)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        linkage.analyze(mech, PHI_C + np.radians(np.arange(12.0, 20.1, 0.5)), on_failure="mask")
    assert not [w for w in caught if "change point" in str(w.message)]

    # the positions near the change point are singular, farther ones OK: each OK one closes and is
    # the brute-force mode nearest to the plan's traced mode, the other mode being at least twice
    # as far (never the other mode reported OK)
    ok = motion.status == OK
    near = np.abs(motion.phi - PHI_C) < np.radians(1.0)
    assert np.all(motion.status[near] == SINGULAR) and ok.sum() >= 20
    poses = {k: motion.poses[k] for k in ("0", "1", *links)}
    assert np.max(gaps(points, pairs, local, {k: v[ok] for k, v in poses.items()})) <= 1e-12
    traced = plan.start(motion.phi)
    edge = np.flatnonzero(ok)
    for n in (edge[edge < len(ok) // 2][-1], edge[edge > len(ok) // 2][0]):      # the OK positions nearest to it
        got = np.concatenate([motion.poses[k][n] for k in links])
        want = np.concatenate([traced[k][n] for k in links])
        modes = brute_force_modes(points, links, pairs, crank, motion.phi[n])
        distance = sorted(pose_gap(m, want, mech.size) for m in modes)
        match = min(modes, key=lambda m: pose_gap(m, want, mech.size))
        assert pose_gap(got, match, mech.size) <= 1e-9 * mech.size
        assert len(distance) >= 2 and distance[1] > 2 * distance[0]


def test_a_newton_failure_is_reported_by_the_tables_and_the_feasibility_check(monkeypatch, capsys):
    """Status -4 is never shown as an empty row without a word, nor as "cannot be assembled"."""
    from linkage.cli import main
    from linkage.kinematics.feasibility import check
    from linkage.report.results import failures

    mech = linkage.loads(class4_text())
    monkeypatch.setattr(assur.generic, "NEWTON_STEPS", 1)
    motion = linkage.analyze(mech, np.radians([40.5, 200.5]), on_failure="mask")
    entries, lines = failures(motion)
    assert [e["problem"] for e in entries] == ["was not solved: Newton's method did not converge"] * 2
    assert len(lines) == 1 and "Newton's method did not converge" in lines[0] and "cannot be assembled" not in lines[0]
    monkeypatch.setattr(assur.generic, "NEWTON_STEPS", 0)      # not even the sweep's own angles converge
    verdict = check(mech)
    assert not verdict.feasible and verdict.rule == "solved" and "Newton's method did not converge" in verdict.reason
    monkeypatch.setattr(assur.generic, "NEWTON_STEPS", 1)
    monkeypatch.setattr(linkage.cli.options, "load", lambda name: mech)    # its plan was traced with every step
    code = main(["analyze", "class4", "--positions", "8", "--start", "0.5"])     # off the sweep's angles
    err = capsys.readouterr().err
    assert code == 0 and "did not converge" in err     # the rows stay, empty, with the warning
    assert "Traceback" not in err and "cannot be assembled" not in err


# ----------------------------------------------------------------------------------------------
# a group that does not assemble at the start of the sweep
# ----------------------------------------------------------------------------------------------


def _boom(stroke: str) -> str:
    return (SCHEMES / "cylinder_boom.toml").read_text().replace("range = [0.6, 1.3]", stroke)


def test_a_group_assembling_only_past_the_sweep_start_is_traced_from_there():
    """The cylinder's group (solved by Newton's method, modes found from random starts) cannot be
    assembled for s < |OC| - OB (the rod cannot reach B): a stroke starting there is refused
    naming the part of the stroke that assembles -- not as a group that assembles nowhere."""
    oc = float(np.hypot(0.6, -0.4))
    limit = oc - 0.8 if oc > 0.8 else 0.8 - oc          # |OC - OB|, the shortest CB
    with pytest.raises(linkage.SchemeError) as info:
        linkage.loads(_boom("range = [0.05, 1.3]"))
    text = str(info.value)
    assert "cannot be assembled at s = 0.05.." in text and "it assembles at" in text, text
    assembles_from = float(text.split("it assembles at ")[1].split("..")[0])
    assert limit < assembles_from < limit + 0.01, (limit, text)   # within a few sweep steps of the limit
    # a stroke wholly short of the limit: the group assembles nowhere, said in the slide's words
    with pytest.raises(linkage.SchemeError, match="cannot be assembled at any input slide"):
        linkage.loads(_boom("range = [0.01, 0.07]"))
