"""The graphical method as data: plans of velocities and accelerations, force polygons and
Zhukovsky's lever (docs/plans.md).

A plan is built group by group, in the order a student draws it (the input link, then each Assur
group in the order of the structure), from the exact kinematics: every vector is a number, not a
measurement. Each point P has an *image* p, the vector from the pole to it (its absolute velocity
or acceleration); a link's relative vectors join the images of its points; a slider adds the
relative slide along its guide and, on a turning guide, the Coriolis acceleration.

>>> import numpy as np, linkage
>>> from linkage.kinetostatics.plans import build_plans
>>> mech = linkage.load("slider_crank")
>>> plans = build_plans(linkage.analyze(mech, np.radians([30.0, 120.0]), omega=-10.0))
>>> bool(np.allclose(plans.velocity.images["B"], plans.motion.velocity("B")))
True
>>> [f"{v.start}->{v.end} {v.kind}" for v in plans.velocity.vectors if v.step == "II-RRP(2,3)"][:3]
['A->B relative', 'pole->B absolute', 'A->S2 relative']
>>> bool(np.allclose(plans.lever.balancing_moment, plans.reactions.balancing_moment))
True
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from assur.base import OK, PrismaticJoint, RevoluteJoint, cross, perp

from ..errors import InputError
from ..kinematics.motion import Motion, table_positions_deg
from ..model.mechanism import Prismatic, Revolute
from .loads import LoadTerm
from .reactions import solve_reactions

__all__ = ["POLE", "VELOCITY_KINDS", "ACCELERATION_KINDS", "PlanVector", "Plan", "PolygonForce", "PolygonMoment",
           "ForcePolygon", "LeverForce", "LeverMoment", "Lever", "Plans", "build_plans",
           "require_crank_input"]

#: the label of the pole of both plans (p of the velocity plan, pi of the acceleration plan)
POLE = "pole"
#: kinds of the vectors of a velocity plan
VELOCITY_KINDS = ("absolute", "relative", "relative-slide")
#: kinds of the vectors of an acceleration plan
ACCELERATION_KINDS = ("absolute", "relative", "normal", "tangential", "coriolis", "relative-slide")


# ----------------------------------------------------------------------------------------------
# the data
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PlanVector:
    """One vector of a plan: from the image ``start`` to the image ``end`` (labels of
    :attr:`Plan.images`; :data:`POLE` is the pole).

    Attributes
    ----------
    start, end : str
        Image labels.
    kind : str
        ``absolute`` (from the pole: the point's velocity or acceleration), ``relative`` (of
        ``end`` about ``start`` on one ``link``), ``normal`` / ``tangential`` (the two parts of a
        relative acceleration: ``-omega_k^2 r`` and ``eps_k x r``), ``relative-slide`` (along the
        guide of ``pair``), ``coriolis`` (``2 omega_g x v_rel`` of ``pair``, g its guide link).
    vector : ndarray, shape (N, 2)
        The vector at every analysed position, m/s (velocity plan) or m/s^2 (acceleration plan).
    link : str or None
        The link it belongs to: the link of a relative vector, the guide link of a slide.
    pair : str or None
        The prismatic pair of a slide or Coriolis vector.
    step : str
        The step of the construction: ``I(0,1)`` for an input link, else the group (``II-RRR(2,3)``).
    role : str
        ``equation`` (a vector equation that locates the step's pair points), ``absolute``, or
        ``similarity`` (between points of one link once its pair points are known).
    point, about : str
        Whose motion it is, and about which point: ``v_BA`` (and its parts) has ``point`` B and
        ``about`` A (a frame point when ``start`` is the pole); a slide has the slider's point
        and the guide's point under it, ``A(3)`` (``about`` is empty for an absolute vector).
    """

    start: str
    end: str
    kind: str
    vector: np.ndarray
    link: str | None = None
    pair: str | None = None
    step: str = ""
    role: str = "equation"
    point: str = ""
    about: str = ""


@dataclass(frozen=True)
class Plan:
    """A plan of velocities or accelerations at N positions.

    Attributes
    ----------
    quantity : {"velocity", "acceleration"}
    unit : str
        ``"m/s"`` or ``"m/s^2"``.
    images : dict of label -> ndarray (N, 2)
        The image of every point from the pole (frame points: zero): named points by their name
        (a name declared on links not pinned together at it gets ``P(k)`` for link k); a centre of
        mass that is not a named point ``S<k>``; the point of guide link g under slider point P
        ``P(g)``; in the acceleration plan also the end of a normal part ``n(Q,B)`` and of a
        Coriolis part ``k(P,g)``.
    vectors : tuple of PlanVector
        In the order of the construction; the vector of each equals ``images[end] -
        images[start]``.
    links : dict of link -> tuple of str
        The image labels of each moving link's points: their figure on either plan is similar to
        the link (the theorem of similarity).
    """

    quantity: str
    unit: str
    images: dict[str, np.ndarray]
    vectors: tuple[PlanVector, ...]
    links: dict[str, tuple[str, ...]]

    def image(self, label: str) -> np.ndarray:
        """``(N, 2)`` the image of ``label`` (zero for the pole)."""
        if label == POLE:
            return np.zeros_like(next(iter(self.images.values())))
        return self.images[label]


@dataclass(frozen=True)
class PolygonForce:
    """A force of a force polygon: ``vector`` ``(N, 2)``, N, acting on ``link``.

    ``kind`` is ``gravity``, ``external``, ``driving``, ``inertia`` (the loads of
    :mod:`linkage.kinetostatics.loads`) or ``reaction``. A reaction's ``label`` is ``R[i,j]``, the force of
    link j (``other``) on link i (docs/conventions.md), and ``pair`` its pair (the label ends
    with ``(pair)`` when several pairs join the two links); ``unknown`` marks the reactions the
    step finds (in pairs with the links placed before it), as opposed to the reactions of later
    groups, known when it is solved. A load's ``point`` is the image label of the point it acts
    at.
    """

    label: str
    kind: str
    link: str
    vector: np.ndarray
    point: str | None = None
    pair: str | None = None
    other: str | None = None
    unknown: bool = False


@dataclass(frozen=True)
class PolygonMoment:
    """A moment on a link that a force polygon does not draw, N m, CCW positive: an inertia
    moment (``Mi<k>``), an applied moment, the moment a prismatic pair carries (``M[i,j]``: of
    link j on link i about the slider's point) or the balancing moment (``Mb``, ``Mb<k>``)."""

    label: str
    kind: str
    link: str
    value: np.ndarray
    pair: str | None = None


@dataclass(frozen=True)
class ForcePolygon:
    """The force polygon of one step (an Assur group, or an input link with its balancing moment).

    Attributes
    ----------
    step : str
        ``II-RRR(2,3)``, ``I(0,1)`` ...
    links : tuple of str
    forces : tuple of PolygonForce
        In the order they are drawn, head to tail. For the first link: the reactions this step
        finds (in its pairs with the links placed before it), its loads, then the reactions of
        the links of later groups on it (known: the groups are solved from the last); for each
        further link: those known reactions, its loads, then the reactions this step finds. For
        an input link: the reactions of the links it drives, its loads, the frame's reaction.
        The unknown reactions thus open and close the polygon; the forces sum to zero.
    internal : tuple of PolygonForce
        The reaction in each pair between two links of the group: ``R[i,j]`` on the link i that
        comes first in ``links`` (for a dyad, the vector that closes the polygon of its first
        link: from the end of that link's loads back to the start).
    moments : tuple of PolygonMoment
    """

    step: str
    links: tuple[str, ...]
    forces: tuple[PolygonForce, ...]
    internal: tuple[PolygonForce, ...]
    moments: tuple[PolygonMoment, ...]

    def closure(self) -> np.ndarray:
        """``(N,)`` ``|sum F| / sum |F|`` over :attr:`forces` (0 where there is no force)."""
        return _closure([f.vector for f in self.forces])

    def on_link(self, link: str) -> tuple[PolygonForce, ...]:
        """Every force on ``link`` (its loads, its external reactions and the internal reactions
        of the other links on it): its own polygon, which closes too."""
        own = [f for f in self.forces if f.link == link]
        for f in self.internal:
            if f.link == link:
                own.append(f)
            elif f.other == link:
                own.append(PolygonForce(f"R[{link},{f.link}]" + f.label[f.label.index("]") + 1:], "reaction", link,
                                        -f.vector, f.point, f.pair, f.link, True))
        return tuple(own)


@dataclass(frozen=True)
class LeverForce:
    """A force on Zhukovsky's lever: ``force`` (N, 2), N, applied at the image of ``point``
    turned by -90 degrees, ``arm`` (N, 2), m/s; ``moment`` (N,) its moment about the pole, N m/s:
    ``arm x force``, equal to the force's power ``v . F``."""

    label: str
    kind: str
    link: str
    point: str
    force: np.ndarray
    arm: np.ndarray
    moment: np.ndarray


@dataclass(frozen=True)
class LeverMoment:
    """A moment ``value`` (N,), N m, on ``link`` carried to the lever as ``value * omega_k``
    (``contribution``, N m/s): a couple of forces at the images of two points of the link."""

    label: str
    kind: str
    link: str
    value: np.ndarray
    angular_velocity: np.ndarray
    contribution: np.ndarray


@dataclass(frozen=True)
class Lever:
    """Zhukovsky's lever: the velocity plan turned by -90 degrees (clockwise), every force at the
    image of its point; its moments about the pole balance.

    Attributes
    ----------
    forces : tuple of LeverForce
    moments : tuple of LeverMoment
        The load moments (inertia and applied) and, with several inputs, the balancing moments of
        the further inputs (from the kinetostatics), carried as known loads.
    omega : ndarray (N,)
        The first input's angular velocity, rad/s.
    balancing_moment : ndarray (N,)
        ``M_b = -(sum of the moments about the pole) / omega``, N m, CCW positive: the
        balancing moment on the first input link.
    """

    forces: tuple[LeverForce, ...]
    moments: tuple[LeverMoment, ...]
    omega: np.ndarray
    balancing_moment: np.ndarray
    turned_deg: float = -90.0


@dataclass(frozen=True)
class Plans:
    """Plans of velocities and accelerations, force polygons and the lever at N positions.

    Attributes
    ----------
    motion : Motion
    reactions : Reactions
    velocity, acceleration : Plan
    angular_velocity, angular_acceleration : dict of link -> ndarray (N,)
        omega_k (rad/s) and eps_k (rad/s^2) of every moving link.
    polygons : tuple of ForcePolygon
        One per step: the input links, then the groups.
    lever : Lever
    notes : tuple of str
    """

    motion: Motion
    reactions: Any
    velocity: Plan
    acceleration: Plan
    angular_velocity: dict[str, np.ndarray]
    angular_acceleration: dict[str, np.ndarray]
    polygons: tuple[ForcePolygon, ...]
    lever: Lever
    notes: tuple[str, ...] = field(default=())

    def summary(self, i: int, direction: int | None = None) -> dict[str, Any]:
        """The numbers of position ``i`` (an index of ``motion.phi``) as plain Python values (the
        JSON of ``linkage plans``): ``phi_deg`` (turned from the first analysed position, in
        ``direction``, deg), ``input_angle_deg``, ``omega``, ``eps``, ``velocity`` and
        ``acceleration`` (point name -> [x, y], m/s and m/s^2), ``angular_velocity``,
        ``angular_acceleration``, ``velocity_plan``, ``acceleration_plan``, ``force_polygons``,
        ``lever``, ``lever_balancing_moment`` and ``balancing_moment`` (N m; with several
        inputs also ``balancing_moments``)."""
        motion = self.motion
        direction = motion.direction if direction is None else direction
        mech = motion.mechanism
        named = [p for p in mech.point_names]

        def xy(a):
            return [float(a[i, 0]), float(a[i, 1])]

        def plan(p: Plan):
            return [{"from": v.start, "to": v.end, "kind": v.kind, "point": v.point, "about": v.about or None,
                     "link": v.link, "pair": v.pair, "step": v.step, "role": v.role, "vector": xy(v.vector),
                     "magnitude": float(np.hypot(*v.vector[i]))}
                    for v in p.vectors]

        def force(f: PolygonForce):
            return {"label": f.label, "kind": f.kind, "link": f.link, "point": f.point, "pair": f.pair,
                    "unknown": f.unknown, "vector": xy(f.vector), "magnitude": float(np.hypot(*f.vector[i]))}

        polygons = [{"step": g.step, "links": list(g.links), "forces": [force(f) for f in g.forces],
                     "internal": [force(f) for f in g.internal],
                     "moments": [{"label": m.label, "kind": m.kind, "link": m.link, "pair": m.pair,
                                  "value": float(m.value[i])} for m in g.moments],
                     "closure": float(g.closure()[i])} for g in self.polygons]
        lever = {"turned_deg": self.lever.turned_deg,
                 "forces": [{"label": f.label, "kind": f.kind, "link": f.link, "point": f.point,
                             "force": xy(f.force), "arm": xy(f.arm), "moment": float(f.moment[i])}
                            for f in self.lever.forces],
                 "moments": [{"label": m.label, "kind": m.kind, "link": m.link, "value": float(m.value[i]),
                              "angular_velocity": float(m.angular_velocity[i]),
                              "contribution": float(m.contribution[i])} for m in self.lever.moments],
                 "balancing_moment": float(self.lever.balancing_moment[i])}
        out = {"phi_deg": float(table_positions_deg(motion.phi, direction)[i]),
               "input_angle_deg": float(np.degrees(motion.phi[i])),
               "omega": float(motion.omega[i]), "eps": float(motion.eps[i]),
               "velocity": {p: xy(self.velocity.images[p]) for p in named},
               "acceleration": {p: xy(self.acceleration.images[p]) for p in named},
               "angular_velocity": {k: float(w[i]) for k, w in self.angular_velocity.items()},
               "angular_acceleration": {k: float(e[i]) for k, e in self.angular_acceleration.items()},
               "velocity_plan": plan(self.velocity), "acceleration_plan": plan(self.acceleration),
               "force_polygons": polygons, "lever": lever,
               "lever_balancing_moment": float(self.lever.balancing_moment[i]),
               "balancing_moment": float(self.reactions.balancing_moment[i])}
        if len(motion.structure.inputs) > 1:
            out["balancing_moments"] = {k: float(v[i]) for k, v in self.reactions.balancing_moments.items()}
        return out


# ----------------------------------------------------------------------------------------------
# building
# ----------------------------------------------------------------------------------------------


def require_crank_input(mech) -> None:
    """Refuse a mechanism driven by a slide (a piston along a frame guide, a cylinder between two
    links, docs/inputs.md): the plans here start from the angular velocity of a crank (rad/s) and
    the lever gives a balancing moment (N m); a slide input would need its velocity (m/s) as the
    pole's first vector, a cylinder's group solved on the plans by Assur's special points and a
    balancing force on the lever, which are not implemented.

    Raises
    ------
    InputError
        Naming the scheme, its input and why; what to use instead.
    """
    if mech.inputs and not mech.coordinate.is_angle:
        first = mech.inputs[0]
        how = (f"the cylinder '{first}'" if first in mech.pairs else
               f"the slider '{first}' along the guide of pair '{mech.input_pair(first)}'")
        raise InputError(f"mechanism '{mech.name}' is driven by a slide ({how}, m): the plans of velocities and "
                         "accelerations and Zhukovsky's lever are built for a crank input only (they start from its "
                         "angular velocity, rad/s, and give a balancing moment, N m); use `linkage analyze` for the "
                         "analogs per m of the slide and `linkage forces --omega M_S` for the reactions and the "
                         "balancing force")


def build_plans(motion: Motion, reactions=None) -> Plans:
    """Plans of velocities and accelerations, force polygons and Zhukovsky's lever of ``motion``.

    Parameters
    ----------
    motion : Motion
        Analysed with second analogs and a nonzero ``omega`` (``analyze(..., omega=..., eps=...)``).
    reactions : Reactions, optional
        The kinetostatics the force polygons are drawn from (default: :func:`solve_reactions` of
        ``motion`` under the mechanism's declared loads and inertia).

    Returns
    -------
    Plans
        Arrays over the N analysed positions; NaN where the motion's status is not OK.

    Raises
    ------
    InputError
        No speed, no second analogs, or omega = 0 at some position (the plans need a moving input);
        a motion or reactions of only some links or pairs; a mechanism driven by a slide
        (:func:`require_crank_input`).
    """

    require_crank_input(motion.mechanism)
    if motion.omega is None or motion.second is None:
        raise InputError("plans need real velocities and accelerations: analyze(..., order=2, omega=..., eps=...)")
    still = np.flatnonzero(motion.omega == 0)
    if len(still):
        raise InputError(f"mechanism '{motion.mechanism.name}': plans need a moving input, but omega = 0 at the "
                         f"input angle(s) {', '.join(f'{np.degrees(motion.phi[k]):.6g}' for k in still[:5])} deg")
    missing = sorted(set(motion.mechanism.links) - set(motion.poses))
    if missing:
        raise InputError(f"plans need every link, but the motion does not place {missing} (analyze without outputs=)")
    reactions = solve_reactions(motion) if reactions is None else reactions
    missing = sorted(set(motion.mechanism.pairs) - set(reactions.multipliers))
    if missing:
        raise InputError(f"force polygons need the reactions in every pair, but pairs {missing} were not solved "
                         "(solve_reactions without pairs=)")
    builder = _Builder(motion, reactions.terms)
    velocity, acceleration = builder.plans()
    polygons = tuple(_polygon(motion, reactions, step, links, builder) for step, links, _ in builder.steps)
    lever = _lever(motion, reactions, velocity, builder)
    return Plans(motion, reactions, velocity, acceleration, builder.omega_k, builder.eps_k, polygons, lever)


class _Builder:
    """The images of every point and the relations between them, step by step."""

    def __init__(self, motion: Motion, terms: list[LoadTerm]):
        self.motion = motion
        mech = self.mech = motion.mechanism
        structure = motion.structure
        self.frame = mech.frame
        self.w, self.e = motion.omega[:, None], motion.eps[:, None]
        self.omega_k = {k: motion.first[k][:, 2] * motion.omega for k in mech.moving_links}
        self.eps_k = {k: motion.second[k][:, 2] * motion.omega**2 + motion.first[k][:, 2] * motion.eps
                      for k in mech.moving_links}
        # an input link's step: its revolute pairs (its pins give the equations v_A = omega_1 x OA)
        self.steps = [(f"I({self.frame},{k})", (k,), tuple(j for j in structure.joints.values()
                                                           if isinstance(j, RevoluteJoint) and k in (j.a, j.b)))
                      for k in structure.inputs]
        self.steps += [(repr(g), tuple(g.links), tuple(g.joints)) for g in structure.groups]
        self.labels = _point_labels(mech)           # (link, point) -> image label
        self.position: dict[str, np.ndarray] = {}   # image label -> global position (N, 2)
        self.owner: dict[str, str] = {}             # image label -> the link it is a point of
        self.link_labels: dict[str, list[str]] = {k: [] for k in mech.moving_links}
        self.unnamed: dict[tuple, str] = {}         # (link, x, y) of an unnamed load point -> its label
        for (link, name), label in self.labels.items():
            local = mech.links[link].points[name]
            self._add_point(label, link, motion.poses[link][:, :2] + motion.arm(link, local))
        for t in terms:                             # the points loads act at (centres of mass)
            if np.any(t.force != 0):
                self.label_at(t.link, t.local)

    def _add_point(self, label: str, link: str, position: np.ndarray) -> None:
        if label not in self.position:
            self.position[label] = position
            self.owner[label] = link
        if link != self.frame and label not in self.link_labels[link]:
            self.link_labels[link].append(label)

    def label_at(self, link: str, local) -> str:
        """The image label of the point with local coordinates ``local`` on ``link`` (a named point
        there, else a new label ``S<link>``)."""
        key = (link, float(local[0]), float(local[1]))
        if key in self.unnamed:
            return self.unnamed[key]
        points = self.mech.links[link].points
        tol = 1e-12 * self.mech.size
        for name, p in points.items():
            if abs(p[0] - local[0]) <= tol and abs(p[1] - local[1]) <= tol:
                return self.labels[(link, name)]
        label = f"S{link}"
        while label in self.position:
            label += "'"
        self._add_point(label, link, self.motion.poses[link][:, :2] + self.motion.arm(link, local))
        self.unnamed[key] = label
        return label

    def fixed(self, label: str) -> bool:
        return label == POLE or self.owner.get(label) == self.frame

    # -- the rigid motion of a link at given global points --------------------------------------
    def rigid(self, link: str, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Velocity and acceleration ``(N, 2)`` of the points of ``link`` at the global positions ``x``."""
        m = self.motion
        rho = x - m.poses[link][:, :2]
        d1 = m.first[link][:, :2] + perp(rho) * m.first[link][:, 2:3]
        d2 = m.second[link][:, :2] + perp(rho) * m.second[link][:, 2:3] - rho * m.first[link][:, 2:3] ** 2
        return d1 * self.w, d2 * self.w**2 + d1 * self.e

    # -- relations -----------------------------------------------------------------------------
    def relations(self) -> list[tuple]:
        """The construction as relations, in order: ``("rel", step, role, link, B, Q)`` (Q about B
        on one link), ``("slide", step, pair, guide, P(g), P)``, ``("abs", step, role, P)``."""
        known = {label for label, link in self.owner.items() if link == self.frame}
        base: dict[str, str] = {}
        out: list[tuple] = []
        for step, links, joints in self.steps:
            out += self._step(step, links, joints, known, base)
        return out

    def _step(self, step, links, joints, known, base) -> list[tuple]:
        out: list[tuple] = []
        solved: list[str] = []
        sides_done: set[tuple[str, str]] = set()
        slides_done: set[str] = set()

        def learn(label):
            if label not in known:
                known.add(label)
                solved.append(label)

        def pin_label(joint: RevoluteJoint, link: str) -> str:
            return self.labels[(link, self.mech.pairs[joint.name].point)]

        while True:
            progress = False
            for k in links:
                if k not in base:
                    ready = [lab for lab in self.link_labels[k] if lab in known]
                    if ready:
                        base[k] = ready[0]
                        progress = True
            for j in joints:
                if isinstance(j, RevoluteJoint):
                    for k in (j.a, j.b):
                        if k in links and k in base and (j.name, k) not in sides_done:
                            sides_done.add((j.name, k))
                            target = pin_label(j, k)
                            if target != base[k]:
                                out.append(("rel", step, "equation", k, base[k], target))
                            learn(target)
                            progress = True
                elif j.name not in slides_done and (j.a not in links or j.a in base):
                    slides_done.add(j.name)
                    target = self.labels[(j.b, self.mech.pairs[j.name].point)]
                    under = self._under(j, target)
                    if not self.fixed(under):
                        out.append(("rel", step, "equation", j.a, base[j.a], under))
                    out.append(("slide", step, j.name, j.a, under, target))
                    learn(target)
                    progress = True
            pending = [k for k in links if k not in base]
            done = (not pending and all((j.name, k) in sides_done for j in joints if isinstance(j, RevoluteJoint)
                                        for k in (j.a, j.b) if k in links)
                    and all(j.name in slides_done for j in joints if isinstance(j, PrismaticJoint)))
            if done:
                break
            if not progress:   # nothing follows from what is known: start a link from its absolute image
                k = pending[0]
                learn(self.link_labels[k][0])
        for label in solved:
            out.append(("abs", step, "absolute", label))
        for k in links:
            figure = self.link_labels[k]
            for q in figure:
                if q not in known:
                    out.append(("rel", step, "similarity", k, base[k], q))
                    known.add(q)
                    out.append(("abs", step, "absolute", q))
            for a_i, a in enumerate(figure):
                for b in figure[a_i + 1:]:
                    if base[k] not in (a, b) and not (self.fixed(a) and self.fixed(b)):
                        out.append(("rel", step, "similarity", k, a, b))
        return out

    def _under(self, joint: PrismaticJoint, target: str) -> str:
        """The label of the point of the guide link under the slider's point ``target``."""
        if joint.a == self.frame:
            return POLE
        label = f"{target}({joint.a})"
        if label not in self.position:
            self.position[label] = self.position[target]
            self.owner[label] = joint.a
        return label

    # -- the two plans -------------------------------------------------------------------------
    def plans(self) -> tuple[Plan, Plan]:
        relations = self.relations()
        v_img, a_img = {}, {}
        for label, pos in self.position.items():
            v_img[label], a_img[label] = self.rigid(self.owner[label], pos)
        v_vectors: list[PlanVector] = []
        a_vectors: list[PlanVector] = []
        v_abs: set[str] = set()
        a_abs: set[str] = set()

        def absolute(label, step, link, vectors, done, images):
            if label not in done:
                done.add(label)
                vectors.append(PlanVector(POLE, label, "absolute", images[label], link, None, step, "absolute", label))

        for rel in relations:
            if rel[0] == "abs":
                _, step, _, q = rel
                absolute(q, step, self.owner[q], v_vectors, v_abs, v_img)
                absolute(q, step, self.owner[q], a_vectors, a_abs, a_img)
            elif rel[0] == "rel":
                _, step, role, k, b, q = rel
                d = self.position[q] - self.position[b]
                w, e = self.omega_k[k][:, None], self.eps_k[k][:, None]
                if self.fixed(b):
                    if role == "equation":
                        absolute(q, step, self.owner[q], v_vectors, v_abs, v_img)
                else:
                    v_vectors.append(PlanVector(b, q, "relative", w * perp(d), k, None, step, role, q, b))
                if role == "similarity":
                    if not self.fixed(b):
                        a_vectors.append(PlanVector(b, q, "relative", -(w**2) * d + e * perp(d), k, None, step,
                                                    role, q, b))
                    continue
                n = f"n({q},{b})"
                start = POLE if self.fixed(b) else b
                a_img[n] = a_img[b] - w**2 * d if start != POLE else -(w**2) * d
                a_vectors.append(PlanVector(start, n, "normal", -(w**2) * d, k, None, step, role, q, b))
                a_vectors.append(PlanVector(n, q, "tangential", e * perp(d), k, None, step, role, q, b))
                if start != POLE:
                    a_vectors.append(PlanVector(b, q, "relative", -(w**2) * d + e * perp(d), k, None, step, role, q,
                                                b))
                else:
                    absolute(q, step, self.owner[q], a_vectors, a_abs, a_img)
            else:
                _, step, pair, g, under, p = rel
                joint = self.motion.joints[pair]
                u = joint.frame(self.motion.poses)[0]
                _, s1, s2 = joint.slide(self.motion.poses, self.motion.first, self.motion.second)
                v_rel = (s1[:, None] * self.w) * u
                a_rel = (s2[:, None] * self.w**2 + s1[:, None] * self.e) * u
                if self.fixed(under):
                    absolute(p, step, self.owner[p], v_vectors, v_abs, v_img)
                    absolute(p, step, self.owner[p], a_vectors, a_abs, a_img)
                    continue
                v_vectors.append(PlanVector(under, p, "relative-slide", v_rel, g, pair, step, "equation", p, under))
                k_label = f"k({p},{g})"
                coriolis = 2 * self.omega_k[g][:, None] * perp(v_rel)
                a_img[k_label] = a_img[under] + coriolis
                a_vectors.append(PlanVector(under, k_label, "coriolis", coriolis, g, pair, step, "equation", p, under))
                a_vectors.append(PlanVector(k_label, p, "relative-slide", a_rel, g, pair, step, "equation", p, under))
        links = {k: tuple(v) for k, v in self.link_labels.items()}
        return (Plan("velocity", "m/s", v_img, tuple(v_vectors), links),
                Plan("acceleration", "m/s^2", a_img, tuple(a_vectors), links))


def _point_labels(mech) -> dict[tuple[str, str], str]:
    """(link, point name) -> image label: the name, shared by the links pinned together at it;
    ``P(k)`` for links that carry the name without a revolute pair there to its first owner."""
    out: dict[tuple[str, str], str] = {}
    for name in mech.point_names:
        owners = mech.point_links(name)
        group = {owners[0]}
        grew = True
        while grew:
            grew = False
            for pair in mech.pairs.values():
                if isinstance(pair, Revolute) and pair.point == name and (set(pair.links) & group) \
                        and not set(pair.links) <= group:
                    group |= set(pair.links)
                    grew = True
        for link in owners:
            out[(link, name)] = name if link in group else f"{name}({link})"
    return out


# ----------------------------------------------------------------------------------------------
# force polygons
# ----------------------------------------------------------------------------------------------


def _closure(vectors: list[np.ndarray]) -> np.ndarray:
    if not vectors:
        return np.zeros(0)
    total = np.sum(vectors, axis=0)
    scale = np.sum([np.hypot(v[:, 0], v[:, 1]) for v in vectors], axis=0)
    return np.hypot(total[:, 0], total[:, 1]) / np.where(scale > 0, scale, 1.0)


def _reaction_on(reactions, pair: str, link: str) -> np.ndarray:
    """The force of pair ``pair`` on ``link`` (one of its links), N."""
    f = reactions.force(pair)
    return f if reactions.motion.mechanism.pairs[pair].links[0] == link else -f


def _reaction(reactions, pair: str, link: str, label_pairs: bool, earlier=frozenset()) -> PolygonForce:
    mech = reactions.motion.mechanism
    other = [x for x in mech.pairs[pair].links if x != link][0]
    label = f"R[{link},{other}]" + (f"({pair})" if label_pairs else "")
    point = mech.pairs[pair].point
    return PolygonForce(label, "reaction", link, _reaction_on(reactions, pair, link), point, pair, other,
                        other in earlier)


def _loads(terms: list[LoadTerm], link: str, builder: _Builder) -> tuple[list[PolygonForce], list[PolygonMoment]]:
    forces, moments = [], []
    for t in terms:
        if t.link != link:
            continue
        if np.any(t.force != 0):
            forces.append(PolygonForce(t.label, t.kind, link, t.force, builder.label_at(link, t.local)))
        if np.any(t.moment != 0):
            label = f"Mi{link}" if t.kind == "inertia" else t.label
            moments.append(PolygonMoment(label, t.kind, link, t.moment))
    return forces, moments


def _placed_before(structure, links: tuple[str, ...]) -> set[str]:
    """The frame and the links placed by the steps before the one of ``links``."""
    before = {structure.frame}
    if links[0] in structure.inputs:
        return before
    before |= set(structure.inputs)
    for g in structure.groups:
        if set(g.links) == set(links):
            break
        before |= set(g.links)
    return before


def _polygon(motion: Motion, reactions, step: str, links: tuple[str, ...], builder: _Builder) -> ForcePolygon:
    mech = motion.mechanism
    inside = set(links)
    pairs = [name for name, p in sorted(mech.pairs.items()) if inside & set(p.links)]
    external = [n for n in pairs if not set(mech.pairs[n].links) <= inside]
    internal = [n for n in pairs if set(mech.pairs[n].links) <= inside]
    joined: dict[frozenset, int] = {}
    for n in pairs:
        key = frozenset(mech.pairs[n].links)
        joined[key] = joined.get(key, 0) + 1
    several = {n for n in pairs if joined[frozenset(mech.pairs[n].links)] > 1}
    earlier = _placed_before(motion.structure, links)
    forces: list[PolygonForce] = []
    moments: list[PolygonMoment] = []
    for idx, k in enumerate(links):
        own = [_reaction(reactions, n, k, n in several, earlier) for n in external if k in mech.pairs[n].links]
        unknown = [f for f in own if f.unknown]     # found with this step
        known = [f for f in own if not f.unknown]   # of the steps solved before it (farther groups)
        loads, load_moments = _loads(reactions.terms, k, builder)
        forces += (unknown + loads + known) if idx == 0 and len(links) > 1 else (known + loads + unknown)
        moments += load_moments
    inner = []
    for n in internal:
        a, b = mech.pairs[n].links
        first = a if links.index(a) < links.index(b) else b
        inner.append(_reaction(reactions, n, first, n in several, set(links)))
    for n in pairs:
        if isinstance(mech.pairs[n], Prismatic):
            guide, slider = mech.pairs[n].links
            on = slider if slider in inside else guide
            other = guide if on == slider else slider
            value = reactions.moment(n) * (1.0 if on == guide else -1.0)
            moments.append(PolygonMoment(f"M[{on},{other}]", "reaction", on, value, n))
    if len(links) == 1:
        k = links[0]
        moments.append(PolygonMoment("Mb" if k == motion.structure.inputs[0] else f"Mb{k}", "balancing", k,
                                     reactions.balancing_moments.get(k, reactions.balancing_moment)))
    return ForcePolygon(step, links, tuple(forces), tuple(inner), tuple(moments))


# ----------------------------------------------------------------------------------------------
# Zhukovsky's lever
# ----------------------------------------------------------------------------------------------


def _lever(motion: Motion, reactions, velocity: Plan, builder: _Builder) -> Lever:
    forces, moments = [], []
    total = np.zeros(len(motion.phi))
    for t in reactions.terms:
        if np.any(t.force != 0):
            point = builder.label_at(t.link, t.local)
            v = velocity.images[point]
            arm = np.column_stack([v[:, 1], -v[:, 0]])     # the plan turned by -90 degrees
            moment = cross(arm, t.force)
            forces.append(LeverForce(t.label, t.kind, t.link, point, t.force, arm, moment))
            total = total + moment
        if np.any(t.moment != 0):
            w = builder.omega_k[t.link]
            label = f"Mi{t.link}" if t.kind == "inertia" else t.label
            moments.append(LeverMoment(label, t.kind, t.link, t.moment, w, t.moment * w))
            total = total + t.moment * w
    for k in motion.structure.inputs[1:]:
        w = builder.omega_k[k]
        value = reactions.balancing_moments[k]
        moments.append(LeverMoment(f"Mb{k}", "balancing", k, value, w, value * w))
        total = total + value * w
    balancing = -total / motion.omega
    balancing = np.where(motion.status == OK, balancing, np.nan)
    return Lever(tuple(forces), tuple(moments), motion.omega, balancing)
