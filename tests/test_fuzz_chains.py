"""Hypothesis fuzz suite over random chains of dyads at mixed scales (issue 7, build 6).

What is generated
-----------------
A crank (link 1, pivot O on the frame 0) followed by a chain of one to three dyads of all five
kinds (RRR, RRP, RPR, PRP, RPP), declared through :class:`linkage.model.mechanism.MechanismBuilder`
(``tests/_chains.py``). Every design is *drawn* in a reference configuration (crank at
``phi0``) in global coordinates and its lengths, guide lines, pair angles and assembly
conditions are read off the drawing, as a designer would, so the reference configuration is a
known solution on a known branch, with every group at least ``REFERENCE_MARGIN`` away from a
singular position. Each dyad attaches to the frame and/or links already placed: around a pin of
two placed links (the crank pivot or any pin of an earlier group), rigidly on one moving link,
or spanning two existing points. A dyad's dimensions are the crank's times a factor
10^[-3, 3] (a third of the draws: 1), and the whole mechanism is scaled by 10^[-6, 6]; a third of
the mixed designs also carry an unused frame point 10^[2, 6] crank lengths away. Masses (at
declared centres of mass), inertias, gravity (sometimes zero), up to two external forces at
named points and two moments on links, and a signed input speed and acceleration are random.
Designs that assemble (by the oracle below) at fewer than ``MIN_ASSEMBLED`` of the ``N_ANGLES``
angles of the full turn are rejected.

What is checked (every expected value is computed here or in ``_chains.py``)
---------------------------------------------------------------------------
``_chains.oracle`` solves each design by closed forms written independently of :mod:`assur`
(circle-circle, circle-line, line-line, 2x2 linear) on the drawn branch, and gives every group's
conditioning *at its own scale* (a sine per kind, see its docstring).

1. Outcome: no exception except :class:`linkage.errors.LinkageError` subclasses (the example is
   then rejected, so a suite where it always happens fails as unsatisfiable), no numpy
   ``RuntimeWarning`` (turned into an error); statuses are 0, -1 or -2; positions with status
   != 0 have NaN analogs and NaN reactions, status-0 positions finite ones.
2. Closure at status-0 positions, from global points (``Motion.point``, the links' poses and
   the local geometry of the design): a revolute pair's two copies of its point coincide, a
   prismatic pair's slider point lies on the guide line and the relative angle equals the drawn
   one, to ``CLOSURE_TOL`` (1e-10) x (L_g + |r|): the joint spacing of the pair's own group (not
   the mechanism's size, which is larger) plus the point's distance from the origin (angles
   count x L_g).
3. Positions equal the oracle's (same branch as drawn) to a round-off budget propagated along
   the chain: ``1e3 eps (L_g + |r|) / c_g`` per group plus the upstream budget / c_g (L_g the
   group's joint spacing, c_g its conditioning; the upstream budget of a known link at the
   group's distance from it, as a guide carries its slider anywhere along it); status -1 only
   where the oracle's conditioning
   is below ``MIN_MARGIN``, status 0 only where the oracle assembles.
4. First and second analogs of every named point (``Motion.point_analogs``), link angle and
   slide (``Motion.quantity``) equal central finite differences of positions from
   ``analyze(phi + k h, order=0)``, k = -4..4, at a coarse step h and at h / 4; the reference is
   the 8th-order difference at h / 4. ``h = min(FD_STEP, delta / 8)``, where ``delta`` is the
   oracle's distance from the angle to the nearest angle where a group comes closer than
   ``FD_MARGIN`` to a singular position or passes one (PRP guides through parallel), so a
   stencil spans at most half that distance; positions with ``h < FD_MIN_STEP``, or with a
   stencil angle whose status is not 0, are skipped. Tolerance: the status-OK guarantee
   (``GUARANTEE_1`` = 1e-8 for first, ``GUARANTEE_2`` = 1e-7 for second analogs, relative to
   the group's largest analog at that angle: point speeds, slides and L_g x angle analogs,
   and for second analogs also (largest first analog)^2 / L_g) plus ``FD_SAFETY`` x the
   uncertainty of the differences: |D8 - D6| at h / 4, |D8(h) - D8(h / 4)| (bounds the fine
   one's truncation where they converge, and is large -- loosening the check -- near a singular
   position where they do not), and the positions' round-off (``FD_NOISE`` x the budget of
   check 3) amplified by the stencil (x 2.1 / h, x 6.5 / h^2 at h / 4).
5. Virtual power (Zhukovsky): ``M_b omega + sum(F . v_P + M omega_k) = 0`` at status-0
   positions, summed here over the loads declared (gravity m g at S_k, inertia -m a_S and
   -J eps_k, external forces at named points, moments on links) with velocities from
   ``Motion.point_analogs`` of the named points; relative to the sum of |F| |v| and |M| |omega|
   over the loads plus its median over the turn (the machine's typical power), a scale that
   does not vanish when the powers cancel or are all round-off; tolerance ``POWER_TOL`` divided
   by the squared smallest conditioning of the groups.
6. Scale (the contract of issue 7 items 2 and 3): the same design at unit scale (crank 1 m,
   every factor 1, no far point) has the same link angles at every angle, so at positions where
   every group is well conditioned at its own scale (conditioning >= ``WELL_CONDITIONED``) both
   must be status 0, statuses must agree wherever every group's conditioning is >= 1e-2, and
   link angles, their analogs and slides / factor agree.
7. Invariance: declaring links, points, guides, pairs and assembly conditions in shuffled order
   gives bitwise-identical statuses, poses, analogs, reactions and balancing moments.

Bounds: ``derandomize=True`` (reproducible CI), no shrinking (a failure is reported as found,
with the drawn ``ChainShape``), about half a minute in total; ``LINKAGE_FUZZ=K`` multiplies every
example count by K (K = 2: the 100 + 150 chains of the long run).
"""

from __future__ import annotations

import math
import os
import sys
import warnings
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, Phase, assume, event, given, reject, settings
from hypothesis import strategies as st

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from anywhere without install
sys.path.insert(0, str(Path(__file__).resolve().parent))

import linkage  # noqa: E402
from linkage.errors import LinkageError  # noqa: E402
from linkage.kinematics.motion import BranchWarning  # noqa: E402
from linkage.kinetostatics.reactions import solve_reactions  # noqa: E402

import _chains as C  # noqa: E402

EPS = float(np.finfo(float).eps)
N_ANGLES = 24
#: a design must assemble at this many of the N_ANGLES angles (by the oracle)
MIN_ASSEMBLED = 6
#: below this conditioning (oracle, per group) status -1 is acceptable
MIN_MARGIN = 1e-6
#: every group at least this well conditioned at its own scale: the position must be status 0
WELL_CONDITIONED = 0.05
#: closure of every pair, relative to (mechanism size + |point|)
CLOSURE_TOL = 1e-10
#: finite differences: step (rad), least conditioning checked, safety factor on the uncertainty
FD_STEP = 1e-2
FD_MIN_STEP = 1e-4
FD_WINDOW = 0.2
FD_MARGIN = 1e-3
FD_SAFETY = 3.0
#: round-off of the positions seen by the differences, as a fraction of the position budget
#: (the budget bounds the total error; its part that changes along a stencil is smaller)
FD_NOISE = 0.1
#: the status-OK guarantee (relative to the group's largest first / second analog)
GUARANTEE_1 = 1e-8
GUARANTEE_2 = 1e-7
#: virtual power residual (relative), divided by the squared least conditioning
POWER_TOL = 1e-9

FUZZ = max(1, int(os.environ.get("LINKAGE_FUZZ", "1") or 1))


def _settings(n: int):
    return settings(max_examples=n * FUZZ, deadline=None, derandomize=True, database=None,
                    phases=(Phase.explicit, Phase.generate), report_multiple_bugs=False,
                    suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])


# central differences of orders 6 and 8: weights of f(k h) - f(-k h) (first derivative) and of
# f(k h) + f(-k h) - 2 f(0) (second derivative), k = 1..4
D1 = {6: np.array([3 / 4, -3 / 20, 1 / 60, 0.0]), 8: np.array([4 / 5, -1 / 5, 4 / 105, -1 / 280])}
D2 = {6: np.array([3 / 2, -3 / 20, 1 / 90, 0.0]), 8: np.array([8 / 5, -1 / 5, 8 / 315, -1 / 560])}
K = np.arange(-4, 5)


# ==============================================================================================
# strategies
# ==============================================================================================

UNIT = st.floats(0.0, 1.0, exclude_max=True)


@st.composite
def dyad_shapes(draw, mixed: bool):
    kind = draw(st.sampled_from(C.KINDS))
    mode = draw(st.sampled_from(("anchor", "anchor", "anchor", "rigid", "span", "span")))
    factor = 1.0
    if mixed and draw(st.integers(0, 2)) > 0:
        factor = 10.0 ** draw(st.floats(-3.0, 3.0) | st.sampled_from((-3.0, -2.0, 2.0, 3.0)))
    return C.DyadShape(kind, mode, draw(UNIT), draw(UNIT), draw(st.booleans()),
                       draw(st.sampled_from((1, -1))), factor,
                       tuple(draw(st.lists(UNIT, min_size=C.N_UNIFORMS, max_size=C.N_UNIFORMS))))


def angles(shape: C.ChainShape) -> np.ndarray:
    return shape.phi0 + np.linspace(0.0, 2 * np.pi, N_ANGLES, endpoint=False)


def margins_of(chain: C.Chain, phi) -> tuple[dict, np.ndarray, dict]:
    """Oracle poses, per-group conditioning, and the chain's least conditioning ``(N,)``."""
    poses, signed = C.oracle(chain, phi)
    margins = {g: np.abs(m) for g, m in signed.items()}
    least = np.min(np.array(list(margins.values())), axis=0)
    return poses, least, margins


def fd_plan(chain, phi):
    """Finite-difference steps ``h (N,)`` and the stencil angles ``(N * 18,)``.

    By the oracle (on a 1e-3 rad grid over +-``FD_WINDOW``), ``delta`` is the distance from each
    angle to the nearest angle where some group comes closer than ``FD_MARGIN`` to a singular
    position or passes one (the sign of a PRP's conditioning flips where its guides pass through
    parallel, although it stays assembled). The coarse step is ``min(FD_STEP, delta / 8)`` (the
    stencil spans half the distance to the singularity at most), the fine step a quarter of it;
    positions with a coarse step below ``FD_MIN_STEP`` are not checked (h = NaN). Rows of the
    stencil: k h (k = -4..4) then k h / 4.
    """
    phi = np.asarray(phi, dtype=float)
    offsets = np.linspace(-FD_WINDOW, FD_WINDOW, 2 * int(round(FD_WINDOW / 1e-3)) + 1)
    _, signed = C.oracle(chain, (phi[:, None] + offsets[None, :]).ravel())
    centre = len(offsets) // 2
    bad = np.zeros((len(phi), len(offsets)), bool)
    for m in signed.values():
        m = m.reshape(len(phi), len(offsets))
        bad |= (np.abs(m) < FD_MARGIN) | (np.sign(m) != np.sign(m[:, centre:centre + 1]))
    delta = np.min(np.where(bad, np.abs(offsets)[None, :], FD_WINDOW), axis=1)
    h = np.minimum(FD_STEP, delta / 8)
    h = np.where(h >= FD_MIN_STEP, h, np.nan)
    hh = np.where(np.isfinite(h), h, FD_STEP)
    stencil = np.concatenate([phi[:, None] + hh[:, None] * K[None, :],
                              phi[:, None] + 0.25 * hh[:, None] * K[None, :]], axis=1)
    return h, stencil.ravel()


@st.composite
def chain_shapes(draw, mixed: bool = True):
    n = draw(st.integers(1, 3))
    dyads = tuple(draw(dyad_shapes(mixed)) for _ in range(n))
    scale = 10.0 ** draw(st.floats(-6.0, 6.0)) if mixed else 1.0
    far = 10.0 ** draw(st.floats(2.0, 6.0)) if mixed and draw(st.integers(0, 2)) == 0 else None
    shape = C.ChainShape(draw(st.floats(-math.pi, math.pi)),
                         (draw(st.floats(-1.0, 1.0)), draw(st.floats(-1.0, 1.0))), dyads, scale, far,
                         draw(st.floats(0.0, 2 * math.pi)),
                         tuple(draw(st.lists(UNIT, min_size=64, max_size=64))))
    try:
        chain = C.realize(shape)
    except C.Reject:
        reject()
    _, least, _ = margins_of(chain, angles(shape))
    assume(np.sum(least > MIN_MARGIN) >= MIN_ASSEMBLED)
    return shape


# ==============================================================================================
# running the library (warnings as errors, LinkageError allowed)
# ==============================================================================================


def run(chain: C.Chain, phi, *, order=2, reactions=False, declaration=None):
    """``(mechanism, motion, reactions or None)``; rejects the example on a LinkageError."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        # expected where a PRP's guides pass through parallel or a change point lies between
        # angles; not what this suite checks
        warnings.simplefilter("ignore", BranchWarning)
        try:
            mech = C.build(chain, declaration)
            motion = linkage.analyze(mech, phi, order=order, on_failure="mask",
                                     omega=chain.omega if order == 2 else None,
                                     eps=chain.eps if order == 2 else None)
            react = solve_reactions(motion, C.loads_of(chain)) if reactions else None
        except LinkageError as exc:  # allowed by the contract; counted, and the example rejected
            event(f"LinkageError {type(exc).__name__}")
            reject()
    return mech, motion, react


def describe(chain: C.Chain) -> str:
    parts = [f"{d.kind}{d.links}@{d.known} x{d.factor:.3g}" for d in chain.dyads]
    return f"scale {chain.crank:.3g} m, " + ", ".join(parts)


# ==============================================================================================
# independent checks
# ==============================================================================================


def check_outcome(chain, motion, react):
    status = motion.status
    assert status.shape == (N_ANGLES,)
    assert set(np.unique(status)) <= {0, -1, -2}, np.unique(status)
    ok = status == 0
    for k in chain.moving:
        assert np.all(np.isfinite(motion.poses[k][ok])), f"link {k}: non-finite pose at status 0"
        for order, arr in ((1, motion.first[k]), (2, motion.second[k])):
            assert np.all(np.isnan(arr[~ok])), f"link {k}: analog {order} not NaN where status != 0"
            assert np.all(np.isfinite(arr[ok])), f"link {k}: analog {order} not finite at status 0"
    if react is not None:
        for name, arr in [("M_b", react.balancing_moment), *react.multipliers.items()]:
            assert np.all(np.isnan(arr[~ok])), f"reaction {name} not NaN where status != 0"
            assert np.all(np.isfinite(arr[ok])), f"reaction {name} not finite at status 0"


def closure_errors(chain, motion, ok) -> dict:
    """Per pair: largest closure error at the ``ok`` positions over its tolerance
    ``CLOSURE_TOL x (L_g + |r|)`` (L_g the joint spacing of the pair's group, r the point; the
    relative angle of a prismatic pair counts as that angle x L_g)."""
    out = {}
    P = motion.poses
    for pair in chain.pairs:
        a, b = chain.links[pair.a], chain.links[pair.b]
        pa, pb = P[pair.a][ok], P[pair.b][ok]
        # the pair's own scale: the joint spacing of its group (the crank's for the pivot)
        own = chain.group_scale(max(chain.group_of_link(pair.a), chain.group_of_link(pair.b)))
        if pair.kind == "R":
            xa, xb = C.gpt(pa, a.local(pair.point)), C.gpt(pb, b.local(pair.point))
            reported = motion.point(pair.point)[ok]
            err = np.maximum(C.norm(xa - xb), np.minimum(C.norm(reported - xa), C.norm(reported - xb)))
            scale = own + C.norm(xa)
        else:
            g_loc, g_ang = a.local_guide(pair.guide)
            xs = motion.point(pair.point)[ok]
            mine = C.gpt(pb, b.local(pair.point))
            G, U = C.gpt(pa, g_loc), C.direction(pa[:, 2] + g_ang)
            beta = b.pose[2] - a.pose[2]
            err = np.maximum.reduce([np.abs(C.cross(U, xs - G)), C.norm(xs - mine),
                                     np.abs(C.wrap(pb[:, 2] - pa[:, 2] - beta)) * own])
            scale = own + C.norm(xs)
        out[pair.name] = float(np.max(err / (CLOSURE_TOL * scale), initial=0.0))
    return out


def position_budget(chain, oracle_poses, margins) -> dict:
    """Round-off budget ``(N,)`` of every group's joint positions (m), propagated along the chain.

    A group of joint spacing L_g and conditioning c_g places its joints to about
    ``1e3 eps (L_g + |r|) / c_g`` (r: where it lies) plus its inputs' error / c_g; its links'
    angles to that / L_g, so a point at distance rho from the joints of its link is off by about
    the budget x (1 + rho / L_g) (see :func:`link_budget`).
    """
    n = len(next(iter(margins.values())))
    budget = {0: np.full(n, 1e3 * EPS * (chain.crank + np.abs(chain.links["1"].points["O"]).max()))}
    for d in chain.dyads:
        reach = np.max([C.norm(oracle_poses[k][:, :2]) for k in d.links], axis=0) + d.scale
        # a known link's error reaches the group where its pairs act on that link: for a guide,
        # wherever along it the slider is, so the lever is the group's distance from the link
        upstream = np.max([link_budget(chain, budget, k, lever_arm(chain, oracle_poses, d, k)) for k in d.known],
                          axis=0)
        m = np.maximum(margins[d.index], 1e-300)
        budget[d.index] = (1e3 * EPS * reach + upstream) / m
    return budget


def link_budget(chain, budget, link, lever: np.ndarray | float = 0.0) -> np.ndarray:
    """Round-off budget ``(N,)`` of any point of ``link`` (m) within ``lever`` (m, ``(N,)``) of
    its origin, or within its own points where that is farther: its group's joint budget plus
    its angle's (that budget over the group's joint spacing) times the distance."""
    g = chain.group_of_link(link)
    if link == "0":
        return np.zeros_like(budget[0])
    return budget[g] * (1.0 + np.maximum(C.extent(chain.links[link]), lever) / chain.group_scale(g))


def lever_arm(chain, oracle_poses, dyad, link) -> np.ndarray | float:
    """``(N,)`` m: where the known ``link`` guides a slider of ``dyad`` (a prismatic pair with its
    guide on it), how far from the link's origin the dyad acts on it (its links' origins, plus its
    joint spacing), from the oracle's poses; else 0 (a pin of the link: within its own points)."""
    if not any(p.kind == "P" and p.a == link for p in (dyad.ext1, dyad.ext2)):
        return 0.0
    return np.max([C.norm(oracle_poses[k][:, :2] - oracle_poses[link][:, :2]) for k in dyad.links],
                  axis=0) + dyad.scale


def position_errors(chain, motion, oracle_poses, margins, ok) -> dict:
    """Per moving link: largest |library - oracle| over the budget (points, and angle x L_g)."""
    budget = position_budget(chain, oracle_poses, margins)
    out = {}
    for k in chain.moving:
        g = chain.group_of_link(k)
        lk = chain.links[k]
        mine, theirs = oracle_poses[k][ok], motion.poses[k][ok]
        points = np.max([C.norm(C.gpt(theirs, lk.local(p)) - C.gpt(mine, lk.local(p))) for p in lk.points],
                        axis=0) / link_budget(chain, budget, k)[ok]
        angle = np.abs(C.wrap(theirs[:, 2] - mine[:, 2])) * chain.group_scale(g) / budget[g][ok]
        out[k] = float(max(np.max(points, initial=0.0), np.max(angle, initial=0.0)))
    return out


def _slide(chain, pair, poses):
    a, b = chain.links[pair.a], chain.links[pair.b]
    g_loc, g_ang = a.local_guide(pair.guide)
    xs = C.gpt(poses[pair.b], b.local(pair.point))
    return C.dot(C.direction(poses[pair.a][:, 2] + g_ang), xs - C.gpt(poses[pair.a], g_loc))


def finite_differences(values, h):
    """(D8, D6) of the first and second derivatives from stencil values ``(N, 9, ...)`` at
    steps ``h (N,)``."""
    c = values[:, 4]
    plus, minus = values[:, 5:], values[:, 3::-1]  # k = 1..4 and -1..-4
    odd, even = plus - minus, plus + minus - 2 * c[:, None]
    shape = (1, 4) + (1,) * (values.ndim - 2)
    h = np.asarray(h, dtype=float).reshape((-1,) + (1,) * (values.ndim - 2))
    d1 = {o: np.sum(D1[o].reshape(shape) * odd, axis=1) / h for o in (6, 8)}
    d2 = {o: np.sum(D2[o].reshape(shape) * even, axis=1) / h**2 for o in (6, 8)}
    return d1, d2


def analog_errors(chain, mech, motion, stencil, h, oracle_poses, margins) -> dict:
    """Per quantity: largest |library analog - FD| over its tolerance (first, second).

    The reference is the 8th-order difference at the fine step h/4; its uncertainty is the gap
    to the 6th-order one at h/4, plus the gap to the 8th-order one at h (the coarse estimate
    is far less accurate than the fine one where the differences converge, so the gap bounds the
    fine one's error; where they do not converge -- near a singular position -- it is large and
    loosens the check), plus the positions' round-off budget / (h/4) (/ (h/4)^2).
    """
    rows = stencil.status.reshape(N_ANGLES, 18)
    use = np.isfinite(h) & (motion.status == 0) & np.all(rows == 0, axis=1)
    if not use.any():
        return {}
    hf = np.where(use, h, FD_STEP)
    budget = position_budget(chain, oracle_poses, margins)
    # quantities: name -> (group, library first, second, stencil values (N, 18, ...), kind)
    quantities, carriers, noise = {}, {}, {}
    sp = {k: v.reshape(N_ANGLES, 18, 3) for k, v in stencil.poses.items()}
    for p in mech.point_names:
        link = mech.point_link(p)
        if link == "0":
            continue
        d1, d2 = motion.point_analogs(p)
        quantities[p] = (chain.group_of_link(link), d1, d2,
                         stencil.point(p).reshape(N_ANGLES, 18, 2), "point")
        noise[p] = link_budget(chain, budget, link)
        # a pin shared with a link of a later group counts in that group's analog scale too
        carriers[p] = {chain.group_of_link(k) for k in mech.point_links(p) if k != "0"}
    for k in chain.moving:
        th = sp[k][:, :, 2]
        th = th[:, 4:5] + C.wrap(th - th[:, 4:5])  # unwrapped about the centre
        quantities[f"{k}.theta"] = (chain.group_of_link(k), motion.first[k][:, 2],
                                    motion.second[k][:, 2], th, "angle")
    flat = {k: v.reshape(-1, 3) for k, v in sp.items()}
    for pair in chain.pairs:
        if pair.kind == "P":
            _, s1, s2 = motion.quantity(f"{pair.name}.s")
            sv = _slide(chain, pair, flat).reshape(N_ANGLES, 18)
            quantities[f"{pair.name}.s"] = (chain.group_of_link(pair.b), s1, s2, sv, "slide")
            noise[f"{pair.name}.s"] = link_budget(chain, budget, pair.a) + link_budget(chain, budget, pair.b)
    # finite differences, and each group's analog scales at every position: the largest first
    # analog v1 (point speeds, slides, L x angle analogs) and the largest second analog a2
    fd = {}
    groups = range(len(chain.dyads) + 1)
    v1 = {g: np.zeros(N_ANGLES) for g in groups}
    a2 = {g: np.zeros(N_ANGLES) for g in groups}
    for name, (g, l1, l2, vals, kind) in quantities.items():
        coarse = finite_differences(vals[:, :9], hf)
        fine = finite_differences(vals[:, 9:], hf / 4)
        fd[name] = (coarse, fine)
        f = chain.group_scale(g) if kind == "angle" else 1.0
        d1, d2 = fine[0][8], fine[1][8]
        m1, m2 = (C.norm(d1), C.norm(d2)) if kind == "point" else (np.abs(d1), np.abs(d2))
        for c in carriers.get(name, {g}):
            v1[c] = np.fmax(v1[c], f * m1)
            a2[c] = np.fmax(a2[c], f * m2)
    out = {}
    for name, (g, l1, l2, vals, kind) in quantities.items():
        (c1, c2), (f1, f2) = fd[name]
        L = chain.group_scale(g)
        f = L if kind == "angle" else 1.0
        delta = FD_NOISE * (budget[g] / L if kind == "angle" else noise[name])
        s1, s2 = v1[g] / f, np.fmax(a2[g], v1[g] ** 2 / L) / f
        step = hf / 4
        if vals.ndim == 3:
            delta, s1, s2, step = delta[:, None], s1[:, None], s2[:, None], step[:, None]
        err1 = np.abs(f1[8] - f1[6]) + np.abs(f1[8] - c1[8]) + 2.1 * delta / step
        err2 = np.abs(f2[8] - f2[6]) + np.abs(f2[8] - c2[8]) + 6.5 * delta / step**2
        r1 = np.abs(l1 - f1[8]) / (GUARANTEE_1 * s1 + FD_SAFETY * err1)
        r2 = np.abs(l2 - f2[8]) / (GUARANTEE_2 * s2 + FD_SAFETY * err2)
        out[name] = (float(np.max(r1[use])), float(np.max(r2[use])))
    return out


def power_residual(chain, motion, react) -> np.ndarray:
    """Relative virtual-power residual ``(N,)`` summed here over the declared loads.

    Each power is a product (force . velocity, moment x angular velocity); the scale is the sum
    of the products of the *magnitudes* (|F| |v|, |M| |omega_k|), which does not vanish when
    the powers cancel or all are round-off (e.g. a rigid body turning uniformly), plus its
    median over the turn (the machine's typical power).
    """
    w, e = motion.omega, motion.eps
    g = np.asarray(chain.gravity)
    powers, sizes = [], []

    def add(force, velocity):  # force . velocity, (N, 2) or (N,)
        if np.ndim(force) == 2 or np.ndim(velocity) == 2:
            force, velocity = np.broadcast_arrays(force, velocity)
            powers.append(C.dot(force, velocity))
            sizes.append(C.norm(force) * C.norm(velocity))
        else:
            powers.append(force * velocity)
            sizes.append(np.abs(force * velocity))

    add(react.balancing_moment, w)
    for k, (mass, inertia) in chain.masses.items():
        v1, v2 = motion.point_analogs(f"S{k}")
        th1, th2 = motion.first[k][:, 2], motion.second[k][:, 2]
        vel = v1 * w[:, None]
        acc = v2 * (w**2)[:, None] + v1 * e[:, None]
        add(mass * g[None, :], vel)  # gravity
        add(-mass * acc, vel)  # inertia force
        add(-inertia * (th2 * w**2 + th1 * e), th1 * w)  # inertia moment
    for point, link, force in chain.forces:
        add(np.asarray(force)[None, :], motion.point_analogs(point)[0] * w[:, None])
    for link, moment in chain.moments:
        add(np.full(len(w), moment), motion.first[link][:, 2] * w)
    ok = motion.status == 0
    size = np.sum(sizes, axis=0)
    typical = np.median(size[ok])
    return np.where(ok, np.abs(np.sum(powers, axis=0)) / (size + typical), np.nan)


# ==============================================================================================
# the tests
# ==============================================================================================


def test_generator_covers_every_kind_and_mode():
    """The generator draws every registered kind, in every attachment mode, and the oracle
    reproduces each drawing at its reference angle (which checks the oracle itself)."""
    import assur

    dyad_kinds = {k for k, cls in assur.GROUP_KINDS.items() if issubclass(cls, assur.dyad.Dyad)}
    assert set(C.KINDS) == dyad_kinds
    rng = np.random.default_rng(7)
    seen = set()
    for _ in range(400):
        dyads = []
        for _ in range(3):
            factor = 1.0 if rng.random() < 0.5 else 10.0 ** rng.uniform(-3, 3)
            dyads.append(C.DyadShape(str(rng.choice(C.KINDS)), str(rng.choice(["anchor", "rigid", "span"])),
                                     *rng.random(2), bool(rng.integers(2)), int(rng.choice([1, -1])),
                                     factor, tuple(rng.random(C.N_UNIFORMS))))
        shape = C.ChainShape(float(rng.uniform(-3, 3)), tuple(rng.uniform(-1, 1, 2)), tuple(dyads),
                             10.0 ** rng.uniform(-6, 6), None, 0.0, tuple(rng.random(64)))
        try:
            chain = C.realize(shape)
        except C.Reject:
            continue
        poses, margins = C.oracle(chain, [shape.phi0])
        for d in chain.dyads:
            assert abs(margins[d.index][0]) >= C.REFERENCE_MARGIN * 0.999, (d.kind, margins[d.index])
            seen.add(d.kind)
            seen.add(d.mode)
        for k in chain.moving:
            got, want = poses[k][0], chain.links[k].pose
            assert np.all(np.abs(got[:2] - want[:2]) <= 1e-9 * (chain.size + np.abs(want[:2]).max()))
            assert abs(C.wrap(got[2] - want[2])) <= 1e-9
    assert seen == set(C.KINDS) | {"anchor", "rigid", "span"}


@_settings(50)
@given(data=st.data())
def test_chain_contract_at_unit_scale(data):
    """Checks 1-5 of the module docstring on random chains with crank 1 m, every factor 1."""
    check_contract(data.draw(chain_shapes(False), label="shape"))


@_settings(75)
@given(data=st.data())
def test_chain_contract_at_mixed_scales(data):
    """Checks 1-5 of the module docstring on random chains at mixed scales."""
    check_contract(data.draw(chain_shapes(True), label="shape"))


def check_contract(shape: C.ChainShape) -> None:
    chain = C.realize(shape)
    phi = angles(shape)
    for d in chain.dyads:
        event(d.kind)
        event(d.mode)
    sizes = [chain.crank] + [d.scale for d in chain.dyads]
    event(f"sizes span 10^{int(np.log10(max(sizes) / min(sizes)))}")
    mech, motion, react = run(chain, phi, reactions=True)
    h, stencil_phi = fd_plan(chain, phi)
    _, stencil, _ = run(chain, stencil_phi, order=0)
    what = describe(chain)
    # 1. outcome
    check_outcome(chain, motion, react)
    ok = motion.status == 0
    oracle_poses, least, margins = margins_of(chain, phi)
    # 3. statuses against the oracle
    assert not np.any((motion.status == -1) & (least > MIN_MARGIN)), \
        (what, "status -1 where the oracle assembles every group", motion.status, least)
    assert not np.any(ok & (least <= 0)), (what, "status 0 where the oracle does not assemble")
    if not ok.any():
        event("no status-0 position")
        return
    # 2. closure
    closure = closure_errors(chain, motion, ok)
    assert max(closure.values()) <= 1.0, (what, "closure / tolerance", closure)
    # 3. positions on the drawn branch
    pos = position_errors(chain, motion, oracle_poses, margins, ok)
    assert max(pos.values()) <= 1.0, (what, "position error / budget", pos)
    # 4. analogs against finite differences
    errs = analog_errors(chain, mech, motion, stencil, h, oracle_poses, margins)
    bad = {q: e for q, e in errs.items() if max(e) > 1.0}
    assert not bad, (what, "analog error / tolerance (first, second)", bad)
    # 5. virtual power
    residual = power_residual(chain, motion, react)
    limit = POWER_TOL / np.maximum(least, 1e-150) ** 2
    assert np.all(residual[ok] <= limit[ok]), (what, "virtual power residual", residual, limit)


@_settings(200)
@given(data=st.data())
def test_scale_does_not_flag_a_well_conditioned_chain(data):
    """Check 6: the mixed-scale design and its unit twin (crank 1 m, every factor 1, no far
    point) have the same link angles; where every group is well conditioned at its own scale
    both are status 0, and their statuses, angles, angle analogs and slides agree."""
    shape = data.draw(chain_shapes(True), label="shape")
    chain, twin = C.realize(shape), C.realize(shape, unit=True)
    phi = angles(shape)
    _, m_mixed, _ = run(chain, phi)
    _, m_unit, _ = run(twin, phi)
    _, least, _ = margins_of(twin, phi)
    _, least_mixed, _ = margins_of(chain, phi)
    firm = (least >= 1e-2) & (least_mixed >= 1e-2)
    np.testing.assert_allclose(least_mixed[firm], least[firm], rtol=1e-6)  # the oracle agrees
    what = describe(chain) + (f", far point {shape.far:.3g} crank lengths" if shape.far else "")
    well = least >= WELL_CONDITIONED
    for name, m in (("unit twin", m_unit), ("mixed scales", m_mixed)):
        flagged = well & (m.status != 0)
        assert not flagged.any(), (what, f"{name}: well-conditioned positions (every group's "
                                   f"conditioning >= {WELL_CONDITIONED}) not status 0",
                                   np.degrees(phi[flagged]), m.status, least)
    np.testing.assert_array_equal(m_mixed.status[firm], m_unit.status[firm], err_msg=what)
    both = (m_mixed.status == 0) & (m_unit.status == 0)
    for k in chain.moving:
        dth = C.wrap(m_mixed.poses[k][both, 2] - m_unit.poses[k][both, 2])
        assert np.all(np.abs(dth) <= 1e-9 / least[both]), (what, k, dth)
        for arr_m, arr_u in ((m_mixed.first, m_unit.first), (m_mixed.second, m_unit.second)):
            a, b = arr_m[k][both, 2], arr_u[k][both, 2]
            assert np.all(np.abs(a - b) <= 1e-8 * (1 + np.abs(b)) / least[both] ** 2), (what, k, a, b)
    for d_mixed in chain.dyads:
        for pair in (d_mixed.ext1, d_mixed.inner, d_mixed.ext2):
            if pair.kind == "P":
                s_m = m_mixed.quantity(f"{pair.name}.s")[0][both] / (chain.crank * d_mixed.factor)
                s_u = m_unit.quantity(f"{pair.name}.s")[0][both]
                assert np.all(np.abs(s_m - s_u) <= 1e-9 * (1 + np.abs(s_u)) / least[both]), (what, pair)


@_settings(80)
@given(data=st.data(), seed=st.integers(0, 2**32 - 1))
def test_declaration_order_gives_bitwise_identical_results(data, seed):
    """Check 7: shuffled declarations, bitwise-identical statuses, poses, analogs, reactions."""
    shape = data.draw(chain_shapes(True), label="shape")
    chain = C.realize(shape)
    phi = angles(shape)
    _, m1, r1 = run(chain, phi, reactions=True)
    _, m2, r2 = run(chain, phi, reactions=True, declaration=seed)
    np.testing.assert_array_equal(m1.status, m2.status)
    for d1, d2 in ((m1.poses, m2.poses), (m1.first, m2.first), (m1.second, m2.second)):
        assert set(d1) == set(d2)
        for k in d1:
            np.testing.assert_array_equal(d1[k], d2[k], err_msg=k)
    np.testing.assert_array_equal(r1.balancing_moment, r2.balancing_moment)
    assert set(r1.multipliers) == set(r2.multipliers)
    for k in r1.multipliers:
        np.testing.assert_array_equal(r1.multipliers[k], r2.multipliers[k], err_msg=k)
