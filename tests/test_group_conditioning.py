"""The conditioning of the groups beyond the dyads and the status-OK promise it keeps.

A class-III group is drawn in one position (:func:`draw`): the drawing is a known solution, and a
drawing whose three legs' lines of force meet in one point is singular (the triad's singular
condition). The oracle is written here: the group's closure equations from its pairs' geometry,
solved by Newton's method in 50-digit mpmath from the drawing, its Jacobian by central differences
in higher precision, the first analogs from ``J q' = -Phi_phi`` and the second from
``J q'' = -d2/dt2 Phi(q + t q', phi + t)`` (:func:`reference`). ``benchmarks/bench_guarantee_groups.py``
calibrates ``assur.generic.GROUP_ROUNDOFF_FACTOR`` with the same drawings.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest

import linkage
from assur.base import ANALOG_TOL, OK, SINGULAR, Group, PrismaticJoint, RevoluteJoint
from assur.generic import NewtonGroup
from assur.registry import solver_for

SCHEMES = Path(__file__).resolve().parent.parent / "schemes"

#: the group kinds drawn: RRR legs; a slider on the third leg (a block pinned to the ternary link
#: sliding on a frame guide); a slot (a block pinned to the frame sliding in a slot of the ternary link)
KINDS = ("RRR", "slider", "slot")
LINKS = ("2", "3", "4", "5")
KNOWN = {"0", "1"}
DIGITS = 50


# ----------------------------------------------------------------------------------------------
# drawings
# ----------------------------------------------------------------------------------------------


@dataclass
class Design:
    """A crank (pivot ``crank[:2]``, length ``crank[2]``, angle ``phi``) driving a class-III group.

    ``pairs``: ``("R", name, a, b, pa, pb)`` (local points of the pin on links a and b) or
    ``("P", name, a, b, g, u, p, beta)`` (guide of link a through its local point g along its local
    unit vector u, the slider point p of link b, ``theta_b - theta_a = beta``). ``drawing``: the
    poses ``(3,)`` (origin x, y, angle) of the group's links that close the pairs; ``size``: the
    drawing's extent (m); ``contacts``: link -> the local points of its pairs (for the analogs)."""

    kind: str
    pairs: list
    crank: tuple[float, float, float]
    phi: float
    drawing: dict
    size: float
    contacts: dict


def _rot(theta: float, v) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def _unit(angle: float) -> np.ndarray:
    return np.array([np.cos(angle), np.sin(angle)])


def _concurrency(lines) -> float:
    """``|det|`` of the three lines ``(point, direction)`` as ``a x + b y = c`` with unit normals:
    0 where they meet in one point or are parallel."""
    rows = []
    for point, direction in lines:
        normal = np.array([-direction[1], direction[0]]) / np.hypot(*direction)
        rows.append([normal[0], normal[1], normal @ point])
    return abs(float(np.linalg.det(np.array(rows))))


def draw(kind: str, rng: np.random.Generator, offset: float | None = None, parallel: bool = False) -> Design:
    """A random group of ``kind`` drawn in one position.

    ``offset=None``: random legs, their lines of force kept far from concurrent (a regular
    position); else the lines meet in one point (``parallel``: are parallel) up to a turn of the
    third by ``offset`` rad (a position that distance from singular). The drawing is then scaled by
    0.1 .. 10 and moved."""
    while True:
        pins = rng.uniform(-0.6, 0.6, (3, 2))
        sides = [np.hypot(*(pins[i] - pins[j])) for i, j in ((0, 1), (1, 2), (0, 2))]
        u, v = pins[1] - pins[0], pins[2] - pins[0]
        area = abs(u[0] * v[1] - u[1] * v[0]) / 2
        if min(sides) >= 0.35 and area >= 0.08:
            break
    B, C, D = pins
    centre = pins.mean(axis=0)
    while True:
        if offset is None:
            lines = [rng.uniform(-np.pi, np.pi) for _ in range(3)]
            directions = [_unit(a) for a in lines]
            if _concurrency(list(zip(pins, directions))) >= 0.1:
                break
        else:
            meet = centre + _unit(rng.uniform(-np.pi, np.pi)) * rng.uniform(0.6, 2.5)
            directions = [(meet - P) / np.hypot(*(meet - P)) for P in pins]
            if parallel:
                directions = [_unit(rng.uniform(-np.pi, np.pi))] * 3
            directions[2] = _rot(offset * rng.choice([-1.0, 1.0]), directions[2])
            break
    signs = rng.choice([-1.0, 1.0], 3)
    lengths = rng.uniform(0.4, 1.1, 3)
    A = B + signs[0] * lengths[0] * directions[0]
    E = C + signs[1] * lengths[1] * directions[1]
    along = np.array([-directions[2][1], directions[2][0]])      # a guide or slot normal to the third line
    crank_length = rng.uniform(0.2, 0.5)
    phi = rng.uniform(-np.pi, np.pi)
    points = {"O": A - crank_length * _unit(phi), "A": A, "B": B, "C": C, "D": D, "E": E}
    if kind == "RRR":
        points["F"] = D + signs[2] * lengths[2] * directions[2]
    elif kind == "slider":
        points["Q"] = D + rng.uniform(-0.3, 0.3) * along         # the slider point of the block
        points["G"] = D + rng.uniform(-0.5, 0.5) * along         # a point of the frame's guide
    else:
        points["F"] = D                                           # the block's pivot on the frame
        points["Q"] = D + rng.uniform(-0.3, 0.3) * along         # its slider point in the slot
    scale, shift = 10.0 ** rng.uniform(-1, 1), rng.uniform(-3, 3, 2)
    points = {k: scale * v + shift * scale for k, v in points.items()}
    crank_length *= scale
    link_points = {"2": "AB", "3": "BCD" if kind != "slot" else "BCF", "4": "CE", "5": "DQ" if kind == "slider" else
                   "FQ" if kind == "slot" else "DF"}
    poses = {}
    for link, names in link_points.items():
        middle = np.mean([points[n] for n in names], axis=0)
        poses[link] = np.array([*(middle + 0.3 * scale * rng.uniform(-1, 1, 2)), rng.uniform(-np.pi, np.pi)])

    def local(name, link):
        pose = poses[link]
        return tuple(float(v) for v in _rot(-pose[2], points[name] - pose[:2]))

    def direction_in(link):
        return tuple(float(v) for v in _rot(-poses[link][2] if link != "0" else 0.0, along))

    def pin(name, a, b):
        pa = (float(points[name][0]), float(points[name][1])) if a == "0" else local(name, a)
        pb = (float(points[name][0]), float(points[name][1])) if b == "0" else local(name, b)
        return ("R", name, a, b, pa, pb)

    pairs = [("R", "A", "1", "2", (float(crank_length), 0.0), local("A", "2")), pin("B", "2", "3"),
             pin("C", "3", "4"), pin("E", "4", "0")]
    if kind == "RRR":
        pairs += [pin("D", "3", "5"), pin("F", "5", "0")]
    elif kind == "slider":
        pairs += [pin("D", "3", "5"),
                  ("P", "G", "0", "5", tuple(float(v) for v in points["G"]), direction_in("0"), local("Q", "5"),
                   float(poses["5"][2]))]
    else:
        pairs += [pin("F", "5", "0"),
                  ("P", "G", "3", "5", local("F", "3"), direction_in("3"), local("Q", "5"),
                   float(poses["5"][2] - poses["3"][2]))]
    contacts = {link: [] for link in LINKS}
    for pair in pairs:
        if pair[0] == "R":
            for link, p in ((pair[2], pair[4]), (pair[3], pair[5])):
                if link in contacts:
                    contacts[link].append(p)
        else:
            if pair[2] in contacts:
                contacts[pair[2]].append(pair[4])
            contacts[pair[3]].append(pair[6])
    extent = np.array(list(points.values()))
    size = float(np.max(np.hypot(*(extent[:, None] - extent[None]).transpose(2, 0, 1))))
    pivot = points["O"]
    return Design(kind, pairs, (float(pivot[0]), float(pivot[1]), float(crank_length)), float(phi),
                  {k: v.astype(float) for k, v in poses.items()}, size, contacts)


# ----------------------------------------------------------------------------------------------
# the library
# ----------------------------------------------------------------------------------------------


def library_group(design: Design) -> Group:
    """The library's solver for the design's group (the registry's choice)."""
    joints = [RevoluteJoint(*pair[1:]) if pair[0] == "R" else PrismaticJoint(*pair[1:]) for pair in design.pairs]
    return solver_for(LINKS, joints, KNOWN, design.size)


def library_solution(design: Design) -> dict:
    """The library's status, bound, conditioning and analogs (``solved``: NaN unless OK) at the
    drawing (started from it), its Hadamard ratio (the measure of the dyads), and its analogs
    solved with the singular flag off (``first``, ``second``)."""
    group = library_group(design)
    known = {"0": np.zeros((1, 3)), "1": np.array([[design.crank[0], design.crank[1], design.phi]])}
    first = {"0": np.zeros((1, 3)), "1": np.array([[0.0, 0.0, 1.0]])}
    second = {"0": np.zeros((1, 3)), "1": np.zeros((1, 3))}
    start = {k: v[None] for k, v in design.drawing.items()}
    solved = group.solve(known, first, second, start=start)
    placed = group.position(known, start=start)
    merged = {**known, **placed.poses}
    closed = np.all(np.isfinite(np.concatenate(list(placed.poses.values()), axis=1)), axis=1)
    d1, d2 = group.analogs(merged, first, second, valid=closed)
    hadamard = np.nan
    if closed[0]:
        hadamard = float(Group.conditioning(group, group.jacobians(merged)[0], merged)[0][0])
    return {"group": group, "status": int(solved.status[0]), "bound": float(solved.error_bound[0]),
            "conditioning": float(placed.conditioning[0]), "hadamard": hadamard,
            "poses": {k: v[0] for k, v in placed.poses.items()},
            "first": {k: v[0] for k, v in d1.items()}, "second": {k: v[0] for k, v in d2.items()},
            "solved": {"first": {k: v[0] for k, v in solved.first.items()},
                       "second": {k: v[0] for k, v in solved.second.items()}}}


# ----------------------------------------------------------------------------------------------
# the 50-digit oracle
# ----------------------------------------------------------------------------------------------


def _mp_point(pose, p):
    """Global point of the local point ``p`` on a link at ``pose`` ``(x, y, theta, cos, sin)``."""
    x, y, _, c, s = pose
    return x + c * p[0] - s * p[1], y + s * p[0] + c * p[1]


def closure(design: Design, q, phi) -> list:
    """The group's 12 closure equations (mpmath) at the group's poses ``q`` (x, y, theta of links
    2, 3, 4, 5) and the crank angle ``phi``: a pin's two points coincide; a slider point lies on
    its guide, and the slider turns with the guide."""
    zero = mp.mpf(0)
    pose = {"0": (zero, zero, zero, mp.mpf(1), zero),
            "1": (mp.mpf(design.crank[0]), mp.mpf(design.crank[1]), phi, mp.cos(phi), mp.sin(phi))}
    for i, link in enumerate(LINKS):
        x, y, theta = q[3 * i:3 * i + 3]
        pose[link] = (x, y, theta, mp.cos(theta), mp.sin(theta))
    out = []
    for pair in design.pairs:
        if pair[0] == "R":
            _, _, a, b, pa, pb = pair
            (xa, ya), (xb, yb) = _mp_point(pose[a], pa), _mp_point(pose[b], pb)
            out += [xa - xb, ya - yb]
        else:
            _, _, a, b, g, u, p, beta = pair
            c, s = pose[a][3], pose[a][4]
            nx, ny = -(s * u[0] + c * u[1]), c * u[0] - s * u[1]
            (xg, yg), (xp, yp) = _mp_point(pose[a], g), _mp_point(pose[b], p)
            turn = pose[b][2] - pose[a][2] - beta
            out += [nx * (xp - xg) + ny * (yp - yg), turn - 2 * mp.pi * mp.nint(turn / (2 * mp.pi))]
    return out


def _jacobian(design: Design, q, phi):
    """``(Phi_q (12 x 12), Phi_phi (12))`` by central differences in twice the precision."""
    with mp.workdps(2 * DIGITS + 20):
        h = mp.mpf(10) ** -(DIGITS + 5)
        columns = []
        for j in range(len(q) + 1):
            ahead, behind = list(q) + [phi], list(q) + [phi]
            ahead[j] += h
            behind[j] -= h
            plus, minus = closure(design, ahead[:-1], ahead[-1]), closure(design, behind[:-1], behind[-1])
            columns.append([(x - y) / (2 * h) for x, y in zip(plus, minus)])
    m = len(q)
    return mp.matrix([[columns[j][i] for j in range(m)] for i in range(m)]), mp.matrix(columns[m])


def reference(design: Design, start: dict | None = None) -> dict | None:
    """Exact poses and first and second analogs (float arrays ``(3,)`` per link) at the drawing's
    crank angle: Newton's method in mpmath from the drawing (or from ``start``, poses ``(3,)`` per
    link: the assembly mode nearest to them), then linear solves of the Jacobian. None where
    Newton's method does not converge (next to a limit position the rounded geometry may not
    assemble at all)."""
    start = design.drawing if start is None else start
    with mp.workdps(DIGITS):
        q = [mp.mpf(float(v)) for k in LINKS for v in start[k]]
        phi = mp.mpf(design.phi)
        settled = 0
        for _ in range(60):
            jac, _ = _jacobian(design, q, phi)
            step = mp.lu_solve(jac, mp.matrix(closure(design, q, phi)))
            q = [a - b for a, b in zip(q, step)]
            settled = settled + 1 if mp.norm(step, mp.inf) <= mp.mpf(10) ** -(DIGITS - 20) * design.size else 0
            if settled == 3:      # two more steps once within 1e-30 (quadratic convergence)
                break
        else:
            return None
        jac, along_phi = _jacobian(design, q, phi)
        first = mp.lu_solve(jac, -along_phi)
        with mp.workdps(3 * DIGITS):
            h = mp.mpf(10) ** -(DIGITS // 2 + 5)
            moved = [closure(design, [a + t * b for a, b in zip(q, first)], phi + t) for t in (h, 0, -h)]
            curvature = mp.matrix([(x - 2 * y + z) / h**2 for x, y, z in zip(*moved)])
        second = mp.lu_solve(jac, -curvature)
    as_links = lambda v: {k: np.array([float(v[3 * i + c]) for c in range(3)]) for i, k in enumerate(LINKS)}  # noqa: E731
    return {"poses": as_links(q), "first": as_links(first), "second": as_links(second)}


def pose_distance(design: Design, a: dict, b: dict) -> float:
    """Largest difference between poses ``(3,)`` of the group's links, relative to the size
    (angles wrapped, in rad)."""
    gaps = []
    for k in LINKS:
        d = np.asarray(a[k], float) - np.asarray(b[k], float)
        gaps += [abs(d[0]) / design.size, abs(d[1]) / design.size, abs((d[2] + np.pi) % (2 * np.pi) - np.pi)]
    return float(max(gaps))


def _point_analogs(pose, first, second, p):
    rho = _rot(pose[2], p)
    turned = np.array([-rho[1], rho[0]])
    return first[:2] + turned * first[2], second[:2] + turned * second[2] - rho * first[2] ** 2


def relative_errors(design: Design, got: dict, exact: dict) -> tuple[float, float]:
    """Largest errors of the library's first and second analogs (``got["first"]``,
    ``got["second"]``) against ``exact``: every link's angle and every pair point's coordinates (in
    units of the group's own scale, the largest distance between its pairs' points), relative to
    the largest exact first analog of the group and its crank (at least the crank's 1), and the
    second ones to the largest second analog (at least that)."""
    where = np.array([exact["poses"][link][:2] + _rot(exact["poses"][link][2], p)
                      for link in LINKS for p in design.contacts[link]])
    scale = float(np.max(np.hypot(*(where[:, None] - where[None]).transpose(2, 0, 1))))
    crank = design.crank[2] / scale
    errors1, errors2, sizes1, sizes2 = [], [], [1.0, crank], [crank]
    for link in LINKS:
        w1, w2 = exact["first"][link], exact["second"][link]
        g1, g2 = got["first"][link], got["second"][link]
        errors1.append(abs(g1[2] - w1[2]))
        errors2.append(abs(g2[2] - w2[2]))
        sizes1.append(abs(w1[2]))
        sizes2.append(abs(w2[2]))
        for p in design.contacts[link]:
            v1, v2 = _point_analogs(exact["poses"][link], w1, w2, p)
            u1, u2 = _point_analogs(exact["poses"][link], g1, g2, p)
            errors1.append(np.max(np.abs(u1 - v1)) / scale)
            errors2.append(np.max(np.abs(u2 - v2)) / scale)
            sizes1.append(np.max(np.abs(v1)) / scale)
            sizes2.append(np.max(np.abs(v2)) / scale)
    scale1 = max(sizes1)
    return float(max(errors1) / scale1), float(max(errors2) / max(max(sizes2), scale1))


def design_of(motion, n: int) -> Design:
    """The design of ``motion``'s class-III group (links 2-5, crank 1) at its ``n``-th position:
    the pairs' geometry as the scheme declares it, the crank's pose, the group's poses (a start
    for the reference)."""
    (group,) = motion.structure.groups
    pairs = [("R", j.name, j.a, j.b, j.pa, j.pb) if isinstance(j, RevoluteJoint) else
             ("P", j.name, j.a, j.b, j.g, j.u, j.p, j.beta) for j in group.joints]
    contacts = {link: [] for link in LINKS}
    crank_pin = 0.0
    for pair in pairs:
        if pair[0] == "R":
            for link, p in ((pair[2], pair[4]), (pair[3], pair[5])):
                contacts.get(link, []).append(p)
                crank_pin = float(np.hypot(*p)) if link == "1" else crank_pin
        else:
            contacts.get(pair[2], []).append(pair[4])
            contacts[pair[3]].append(pair[6])
    x, y, phi = motion.poses["1"][n]
    return Design("scheme", pairs, (float(x), float(y), crank_pin), float(phi),
                  {k: motion.poses[k][n] for k in LINKS}, float(np.max(group.size)), contacts)


@functools.lru_cache(maxsize=None)
def slider_triad(slider_point: float = 0.765, range_deg=(25, 97)):
    """``six_bar_class3`` with its leg DF replaced by a block pinned to the ternary link at D that
    slides on a frame guide (the issue's triad with a slider on its third leg); the block's slider
    point S lies ``slider_point`` m from D along the guide. The group's Hadamard ratio falls to
    2.5e-4 at 94-97 deg, where the legs' lines are far from concurrent."""
    text = (SCHEMES / "six_bar_class3.toml").read_text()
    text = text.replace('F = [-0.04, 0.44] }', 'F = [-0.04, 0.44] }\nguides.way = { through = [0.19, 0.31], '
                        'angle_deg = -29.47588900324573 }')
    start, end = text.index("[links.5]"), text.index("[pairs.O]")
    text = (text[:start] + f'[links.5]\npoints = {{ D = [0.0, 0.0], S = [{slider_point!r}, 0.0] }}\n'
            'mass = 1.0\ncom = "D"\n\n' + text[end:])
    text = text.replace('[pairs.F]\nlinks = ["5", "0"]',
                        '[pairs.F]\nkind = "P"\nlinks = ["0", "5"]\nguide = "way"\nat = "S"')
    text = text.replace('input = "1"', f'input = "1"\nrange_deg = [{range_deg[0]}, {range_deg[1]}]')
    text = text.replace('[assembly.D]', '[assembly.B]').replace('left_of = ["F", "C"]', 'from = "A"\ntowards_deg = 158')
    return linkage.loads(text)


# ----------------------------------------------------------------------------------------------
# the tests
# ----------------------------------------------------------------------------------------------


def test_the_issue_slider_triad_is_ok_at_94_to_97_deg_with_exact_analogs():
    """The triad with a slider on its third leg was refused as singular at 94-97 deg (its Hadamard
    ratio 2.5e-4, below the dyads' cutoff 2.6e-4): the legs' lines of force are far from
    concurrent there (checked here), so the position is regular; it is OK now, with first and
    second analogs equal to the 50-digit reference."""
    mech = slider_triad()
    phi = np.radians([94.0, 95.0, 96.0, 97.0])
    motion = linkage.analyze(mech, phi)               # raises on any status but OK
    (group,) = motion.structure.groups
    assert type(group) is NewtonGroup
    for n in range(len(phi)):
        merged = {k: v[n:n + 1] for k, v in motion.poses.items()}
        assert Group.conditioning(group, group.jacobians(merged)[0], merged)[0][0] < 2.6e-4   # the old measure
        # lines of force: legs AB and EC along themselves, the block's normal to the guide at D
        A, B, C, D, E = (motion.point(p)[n] for p in "ABCDE")
        guide = np.radians(-29.47588900324573)
        lines = [(A, B - A), (E, C - E), (D, np.array([-np.sin(guide), np.cos(guide)]))]
        assert _concurrency([(p / 0.3, v) for p, v in lines]) > 0.05
        design = design_of(motion, n)
        exact = reference(design)
        assert pose_distance(design, exact["poses"], design.drawing) <= 1e-12
        got = {"first": {k: motion.first[k][n] for k in LINKS}, "second": {k: motion.second[k][n] for k in LINKS}}
        e1, e2 = relative_errors(design, got, exact)
        assert e1 <= ANALOG_TOL and e2 <= 10 * ANALOG_TOL, (n, e1, e2)
    assert np.all(motion.conditioning[repr(group)] > 0.01)


@pytest.mark.parametrize("name", ["six_bar_class3", "slider_triad"])
def test_a_regular_triad_is_never_flagged_over_its_motion(name):
    """The shipped class-III six-bar over a whole turn and the slider triad over its range: every
    position OK (the Hadamard ratio of the shipped one is 3e-4 at its least, next to the cutoff)."""
    mech = linkage.load(name) if name == "six_bar_class3" else slider_triad()
    phi = np.radians(np.arange(0.0, 360.0, 1.0) if name == "six_bar_class3" else np.arange(25.0, 97.5, 0.5))
    motion = linkage.analyze(mech, phi)
    assert np.all(motion.status == OK)
    assert np.all(motion.error_bound <= ANALOG_TOL / 1e3)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("parallel", [False, True], ids=["concurrent", "parallel"])
def test_a_triad_next_to_a_singular_position_is_flagged(kind, parallel):
    """Drawn with its legs' lines of force concurrent (or parallel) up to 1e-7 rad: status -2, the
    bound above the promise, and the analogs NaN."""
    for seed in range(3):
        design = draw(kind, np.random.default_rng(seed), 1e-7, parallel)
        got = library_solution(design)
        assert got["status"] == SINGULAR, (seed, got["conditioning"])
        assert got["bound"] > ANALOG_TOL
        assert all(np.all(np.isnan(v)) for v in got["solved"]["first"].values())


@pytest.mark.parametrize("kind", KINDS)
def test_status_ok_analogs_agree_with_the_50_digit_reference(kind):
    """Regular drawings and drawings 1e-1 .. 1e-3 rad from singular: where the status is OK the
    first analogs agree with the reference to ANALOG_TOL and the second to ten times that, the
    bound bounds the error, and the regular drawings are OK."""
    oks = 0
    for seed, offset in enumerate([None, None, 1e-1, 1e-2, 1e-2, 10**-2.5, 1e-3]):
        design = draw(kind, np.random.default_rng(100 + seed), offset)
        got = library_solution(design)
        if offset is None:
            assert got["status"] == OK
        if got["status"] != OK:
            continue
        oks += 1
        exact = reference(design)
        assert pose_distance(design, got["poses"], exact["poses"]) <= 1e-9
        e1, e2 = relative_errors(design, got["solved"], exact)
        assert e1 <= ANALOG_TOL and e2 <= 10 * ANALOG_TOL, (seed, e1, e2)
        assert e1 <= got["bound"]
    assert oks >= 4
