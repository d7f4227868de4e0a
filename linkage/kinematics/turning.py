"""Why the input cannot turn fully, in words: the angles where the mechanism assembles and the
dimensional reason.

A crank turns fully only when every group assembles at every angle of the turn (or of the
declared input range). When one does not, a person asks first whether the input can turn at
all, before any assembly condition, load or diagram is judged; :func:`turning_reason` says it in
one sentence:

    the input link '1' cannot turn fully: the mechanism assembles only for φ from 130.24° to
    49.76° (through 0°), because the rod AB = 0.07 m is shorter than the crank OA plus the offset
    of B's line of sliding from O: 0.0742 + 0.01335 = 0.08755 m

The angles are input angles φ (CCW from +x, docs/conventions.md) in [0°, 360°) over a turn, as
given over a declared range; the dimensional reason is the Grashof condition for a four-bar loop
(an RRR dyad on the crank and the frame), the rod against crank plus offset for a slider-crank (an
RRP dyad on the crank and a guide of the frame), else the group's own
:meth:`assur.base.Group.assembly_failure` where it does not assemble. Reads the structure and the
inputs' poses only, so the assembly plans (:mod:`~.assembly`) can call it;
:func:`~.full_turn.input_cannot_turn` asks it of a loaded mechanism.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np

from assur.base import CANNOT_ASSEMBLE, Group, PrismaticJoint, RevoluteJoint, cross

from ..model.mechanism import Mechanism
from ..structure import Structure, structure_of
from .inputs import input_poses

__all__ = ["assembled_spans", "dimensional_reason", "turning_reason", "turning_sentence"]

TWO_PI = 2 * np.pi
#: bisection of an edge between an angle that assembles and one that does not: rounds and samples
#: per round (32**4: about 1e-6 of the sweep's step)
REFINE_ROUNDS, REFINE_SAMPLES = 4, 32
#: a gap between the spans where the mechanism assembles narrower than this (rad; times the size
#: for a slide, m) is a single position where it stops
POINT = 1e-5


def turning_reason(mech: Mechanism, group: Group, known_poses: Mapping[str, np.ndarray], phi: np.ndarray,
                   assembled: np.ndarray) -> str:
    """The sentence that says the input cannot turn fully, where it can and why not.

    Parameters
    ----------
    mech : Mechanism
    group : assur.base.Group
        The first group (in the order of analysis) that does not assemble at some angles.
    known_poses : dict of link -> ndarray (M, 3)
        Poses of (at least) the group's known links at ``phi`` (as the assembly plans have them).
    phi : ndarray (M,)
        The sweep of the input coordinate, rad (m for a slide): a turn in equal steps (the end
        2 pi left out or included) or the declared input range.
    assembled : ndarray of bool (M,)
        Where the group assembles.

    Returns
    -------
    str
        ``"the input link '1' cannot turn fully: the mechanism assembles only for φ from A° to B°
        [and C° to D°], because <dimensional reason>"``. The edges are refined between the
        sweep's angles (to about 1e-6 of its step) when the group's known links are the frame and
        the inputs; else they are the sweep's last angles that assemble.
    """
    structure = structure_of(mech)
    phi = np.asarray(phi, dtype=float)
    assembled = np.asarray(assembled, bool)
    at = None
    if set(group.known_links) <= {mech.frame, *structure.inputs} and not getattr(group, "tracked", False):
        def at(x: np.ndarray) -> np.ndarray:
            placed = group.position(input_poses(mech, structure, x), group.branches[0])
            return placed.status != CANNOT_ASSEMBLE
    failing = {k: np.asarray(known_poses[k])[~assembled] for k in group.known_links if k in known_poses}
    reason = dimensional_reason(mech, structure, group, failing)
    return turning_sentence(mech, assembled_spans(mech, phi, assembled, at), reason)


def turning_sentence(mech: Mechanism, spans: list[tuple[float, float]], reason: str) -> str:
    """``"the input ... cannot turn fully: the mechanism assembles only for φ from ..., because
    <reason>"`` for the spans ``(start, end)`` (rad, or m for a slide) where it assembles."""
    coordinate = mech.coordinate
    name = mech.inputs[0] if mech.inputs else "?"
    if coordinate.is_angle:
        subject = f"the input link '{name}' cannot turn "
        subject += "fully" if mech.input_range is None else f"over its whole range {_range_text(mech)}"
    else:
        subject = f"the input '{name}' cannot travel its whole stroke {_range_text(mech)}"
    symbol = "φ" if coordinate.is_angle else "s"
    points = _stops_at_points(mech, spans)
    if not spans:
        told = "assembles at none of its input positions"
    elif points is not None:
        told = f"assembles at every {symbol} but " + " and ".join(_at_text(mech, x) for x in points)
    else:
        told = f"assembles only for {symbol} " + " and ".join(_span_text(mech, a, b) for a, b in spans[:4])
        told += f" and {len(spans) - 4} more spans" if len(spans) > 4 else ""
    return f"{subject}: the mechanism {told}, because {reason}"


def _stops_at_points(mech: Mechanism, spans: list[tuple[float, float]]) -> list[float] | None:
    """The single coordinates where the mechanism stops when every gap between the spans is
    narrower than :data:`POINT` (a dead position, such as parallel guides), else None."""
    periodic = mech.input_range is None and mech.coordinate.is_angle
    if periodic:    # in the order of their starts over the turn, the last gap closing it
        spans = sorted(spans, key=lambda span: span[0] % TWO_PI)
    gaps = [(end, start) for (_, end), (start, _) in zip(spans, spans[1:])]
    if periodic and spans:
        gaps.append((spans[-1][1], spans[0][0]))
    width = POINT if mech.coordinate.is_angle else POINT * mech.size

    def gap(end: float, start: float) -> float:
        return (start - end + np.pi) % TWO_PI - np.pi if periodic else start - end

    if not gaps or any(abs(gap(*g)) > width for g in gaps):
        return None
    middles = [end + 0.5 * gap(end, start) for end, start in gaps]
    return sorted(x % TWO_PI for x in middles) if periodic else middles


def _at_text(mech: Mechanism, x: float) -> str:
    if not mech.coordinate.is_angle:
        return f"{_number(x, 6)} m"
    deg = round(float(np.degrees(x)), 2)
    return f"{(deg % 360.0 if mech.input_range is None else deg) + 0.0:g}°"


def _number(value: float, digits: int) -> str:
    return f"{round(float(value), digits) + 0.0:g}"


def _range_text(mech: Mechanism) -> str:
    a, b = mech.input_range
    if mech.coordinate.is_angle:
        return f"{_number(np.degrees(a), 2)}° to {_number(np.degrees(b), 2)}°"
    return f"{_number(a, 6)} m to {_number(b, 6)} m"


def _span_text(mech: Mechanism, start: float, end: float) -> str:
    """``"from 130.24° to 49.76° (through 0°)"`` (a turn: angles folded into [0°, 360°)), as given
    over a range, ``"from 0.1 m to 0.2 m"`` for a slide."""
    if not mech.coordinate.is_angle:
        return f"from {_number(start, 6)} m to {_number(end, 6)} m"
    a, b = (round(float(np.degrees(x)), 2) for x in (start, end))
    if mech.input_range is not None:
        return f"from {a + 0.0:g}° to {b + 0.0:g}°"
    a, b = a % 360.0 + 0.0, b % 360.0 + 0.0
    if a == b:
        return f"at {a:g}° alone"
    return f"from {a:g}° to {b:g}°" + (" (through 0°)" if b < a else "")


def assembled_spans(mech: Mechanism, phi: np.ndarray, assembled: np.ndarray,
                    at: Callable[[np.ndarray], np.ndarray] | None = None) -> list[tuple[float, float]]:
    """The runs of the sweep ``phi`` (rad or m, in the order travelled) where ``assembled``
    holds, as ``(start, end)`` in the sweep's unit; over a turn a run through the sweep's first
    angle is one run, its end a turn after its start's angle.

    ``at(x) -> (K,) bool`` tells whether the mechanism assembles at the coordinates ``x``: each
    edge between an angle that assembles and one that does not is then refined by bisection
    (:data:`REFINE_ROUNDS` rounds of :data:`REFINE_SAMPLES` samples) and the span ends at the last
    sample that assembles; without it the spans end at the sweep's own angles.
    """
    phi = np.asarray(phi, dtype=float)
    assembled = np.asarray(assembled, bool)
    periodic = mech.input_range is None and mech.coordinate.is_angle
    if periodic and len(phi) > 1 and abs(phi[-1] - phi[0] - TWO_PI) < 1e-9:
        phi, assembled = phi[:-1], assembled[:-1]    # 2 pi is 0 again
    n = len(phi)
    index = np.flatnonzero(assembled)
    if not len(index):
        return []
    if len(index) == n:
        return [(float(phi[0]), float(phi[0] + TWO_PI if periodic else phi[-1]))]
    breaks = np.flatnonzero(np.diff(index) > 1)
    runs = list(zip(np.concatenate([[index[0]], index[breaks + 1]]).tolist(),
                    np.concatenate([index[breaks], [index[-1]]]).tolist()))
    if periodic and len(runs) > 1 and runs[0][0] == 0 and runs[-1][1] == n - 1:
        runs = [(runs[-1][0], runs[0][1] + n)] + runs[1:-1]

    def angle(k: int) -> float:     # a sweep index, wrapped a turn on either side over a turn
        return float(phi[k % n] + TWO_PI * (k // n)) if periodic else float(phi[k])

    edges = []       # (index of the run, 0 start / 1 end, angle inside, angle outside)
    for r, (first, last) in enumerate(runs):
        if periodic or first > 0:
            edges.append((r, 0, angle(first), angle(first - 1)))
        if periodic or last < n - 1:
            edges.append((r, 1, angle(last), angle(last + 1)))
    inside = np.array([e[2] for e in edges])
    if at is not None and len(edges):
        inside = _refine(inside, np.array([e[3] for e in edges]), at)
    ends = [[angle(first), angle(last)] for first, last in runs]
    for (r, side, _, _), value in zip(edges, inside):
        ends[r][side] = float(value)
    return [(a, b) for a, b in ends]


def _refine(inside: np.ndarray, outside: np.ndarray, at: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """Bisect every edge between a coordinate that assembles (``inside``) and one that does not
    (``outside``), all edges at once; returns the last samples that assemble."""
    t = np.linspace(0.0, 1.0, REFINE_SAMPLES + 1)[1:-1]
    inside, outside = inside.copy(), outside.copy()
    for _ in range(REFINE_ROUNDS):
        x = inside[:, None] + (outside - inside)[:, None] * t[None, :]          # (E, S - 1)
        ok = np.asarray(at(x.ravel()), bool).reshape(x.shape)
        # the first sample from the inside that does not assemble closes the edge
        first_out = np.where(ok.all(axis=1), len(t), np.argmin(ok, axis=1))
        rows = np.arange(len(inside))
        new_inside = np.where(first_out > 0, x[rows, np.maximum(first_out - 1, 0)], inside)
        new_outside = np.where(first_out < len(t), x[rows, np.minimum(first_out, len(t) - 1)], outside)
        inside, outside = new_inside, new_outside
    return inside


# ----------------------------------------------------------------------------------------------
# the dimensional reason
# ----------------------------------------------------------------------------------------------


def dimensional_reason(mech: Mechanism, structure: Structure, group: Group,
                       failing: Mapping[str, np.ndarray]) -> str:
    """Why ``group`` cannot close at some input angles, with the numbers: the Grashof condition of
    a four-bar loop, the rod against crank plus offset of a slider-crank, else the group's own
    :meth:`~assur.base.Group.assembly_failure` at the known poses ``failing`` ``{link: (K, 3)}``
    where it does not assemble, else a plain "group X cannot close there"."""
    crank = _crank(mech, structure, group)
    if crank is not None:
        told = _four_bar(mech, structure, group, crank) or _slider_crank(mech, structure, group, crank)
        if told:
            return told
    rows = None
    if failing and all(k in failing for k in group.known_links):
        rows = np.all(np.concatenate([np.isfinite(failing[k]) for k in group.known_links], axis=1), axis=1)
    if rows is not None and rows.any():
        reason = group.assembly_failure({k: failing[k][rows] for k in group.known_links})
        if reason:
            return f"where it does not assemble, group {group!r} cannot close: {reason}"
    return f"group {group!r} cannot close there (check the dimensions of its links)"


def _crank(mech: Mechanism, structure: Structure, group: Group) -> str | None:
    """The input crank (a link pinned to the frame) when the group's known links are it and the
    frame, else None."""
    if len(group.links) != 2 or len(group.known_links) != 2 or mech.frame not in group.known_links:
        return None
    other = next(k for k in group.known_links if k != mech.frame)
    joint = structure.input_joints.get(other)
    return other if isinstance(joint, RevoluteJoint) else None


def _dyad_pairs(group: Group) -> tuple | None:
    """A dyad's pairs ``(external, inner, external)``, None for a group that is not a dyad: the
    loops below are told by their pairs' kinds, never by the group solver's name."""
    pairs = tuple(getattr(group, name, None) for name in ("ext1", "inner", "ext2"))
    return None if any(p is None for p in pairs) else pairs


def _point(joint, link: str) -> np.ndarray | None:
    """``joint``'s local point on ``link`` (m, ``(2,)``), None when not one point (a batch)."""
    p = np.asarray(joint.local(link)[0], dtype=float)
    return p if p.shape == (2,) else None


def _distance(joint_a, joint_b, link: str) -> float | None:
    pa, pb = _point(joint_a, link), _point(joint_b, link)
    return None if pa is None or pb is None else float(np.hypot(*(pb - pa)))


def _m(value: float) -> str:
    return f"{value:.6g} m"


def _four_bar(mech: Mechanism, structure: Structure, group: Group, crank: str) -> str | None:
    """The Grashof condition of the loop frame - crank - RRR dyad, when the crank does not turn by
    it: s + l > p + q (no link turns fully), or a Grashof chain whose shortest link is neither the
    crank nor the frame."""
    pairs = _dyad_pairs(group)
    if pairs is None or not all(isinstance(j, RevoluteJoint) for j in pairs):
        return None     # not a loop of four revolute pairs
    pivot = structure.input_joints[crank]
    ext1, inner, ext2 = pairs
    on_crank = [j for j in (ext1, ext2) if crank in (j.a, j.b)]
    on_frame = [j for j in (ext1, ext2) if mech.frame in (j.a, j.b)]
    if len(on_crank) != 1 or len(on_frame) != 1:
        return None
    A, C = on_crank[0], on_frame[0]
    coupler = next(k for k in group.links if k in (A.a, A.b))
    rocker = next(k for k in group.links if k in (C.a, C.b))
    lengths = {
        f"crank {pivot.name}{A.name}": _distance(pivot, A, crank),
        f"coupler {A.name}{inner.name}": _distance(A, inner, coupler),
        f"rocker {C.name}{inner.name}": _distance(C, inner, rocker),
        f"frame {pivot.name}{C.name}": _distance(pivot, C, mech.frame),
    }
    if any(v is None for v in lengths.values()):
        return None
    order = sorted(lengths, key=lengths.get)
    s, p, q, l = (lengths[k] for k in order)
    loop = f"{pivot.name}{A.name}{inner.name}{C.name}"
    tol = 1e-9 * mech.size
    if s + l > p + q + tol:
        return (f"the four-bar {loop} is not a Grashof chain: its shortest and longest links, {order[0]} = "
                f"{_m(s)} and {order[3]} = {_m(l)}, add up to s + l = {_m(s + l)}, more than the other two, "
                f"{order[1]} + {order[2]} = {_m(p + q)}, so none of its links turns fully")
    shortest = {k for k, v in lengths.items() if v <= s + tol}
    if any(k.startswith(("crank ", "frame ")) for k in shortest):
        return None      # the crank turns by Grashof: the failure is elsewhere
    crank_name = next(k for k in lengths if k.startswith("crank "))
    frame_name = next(k for k in lengths if k.startswith("frame "))
    return (f"the four-bar {loop} is a Grashof chain (s + l = {_m(s + l)} <= p + q = {_m(p + q)}) whose shortest "
            f"link is the {order[0]} = {_m(s)}, not the {crank_name} = {_m(lengths[crank_name])} nor the "
            f"{frame_name} = {_m(lengths[frame_name])}: a crank turns fully only when it or the frame is the "
            "shortest link")


def _slider_crank(mech: Mechanism, structure: Structure, group: Group, crank: str) -> str | None:
    """The rod against crank plus offset of an RRP dyad on the crank and a guide of the frame: B
    slides on a fixed line, A turns on a circle of radius r about O at the offset e from that line,
    and the rod AB = l reaches the line at every angle only when r + |e| <= l."""
    pairs = _dyad_pairs(group)
    if pairs is None:
        return None
    pivot = structure.input_joints[crank]
    pin, inner, guide = pairs
    if (crank not in (pin.a, pin.b) or not isinstance(pin, RevoluteJoint) or not isinstance(inner, RevoluteJoint)
            or not isinstance(guide, PrismaticJoint) or guide.a != mech.frame):
        return None
    rod, slider = group.links if group.links[0] in (pin.a, pin.b) else group.links[::-1]
    r, l = _distance(pivot, pin, crank), _distance(pin, inner, rod)
    O, B, g, p = _point(pivot, mech.frame), _point(inner, slider), np.asarray(guide.g, float), np.asarray(guide.p, float)
    if r is None or l is None or O is None or B is None or g.shape != (2,) or p.shape != (2,):
        return None
    u = np.asarray(guide.u, dtype=float) / np.hypot(*guide.u)
    c, s = np.cos(guide.beta), np.sin(guide.beta)
    d = B - p
    line = g + np.array([c * d[0] - s * d[1], s * d[0] + c * d[1]])      # a point of B's line of sliding
    e = abs(float(cross(u, O - line)))
    if r + e <= l + 1e-9 * mech.size:
        return None
    O_, A_, B_ = pivot.name, pin.name, inner.name
    if e <= 1e-12 * mech.size:
        return (f"the rod {A_}{B_} = {_m(l)} is shorter than the crank {O_}{A_} = {_m(r)} (B's line of sliding "
                f"passes through {O_}): A gets farther than {A_}{B_} from that line")
    return (f"the rod {A_}{B_} = {_m(l)} is shorter than the crank {O_}{A_} plus the offset of {B_}'s line of "
            f"sliding from {O_}: {r:.6g} + {e:.6g} = {_m(r + e)}, so {A_} gets farther than {A_}{B_} from that line")
