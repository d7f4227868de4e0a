"""Batches of design variants: many geometries of one topology analysed in one vectorised call.

A research sweep, an optimisation loop or the course-variant generator asks the same question of
thousands of mechanisms that differ only in their dimensions. :func:`analyze_variants` takes the
mechanism as the topology (links, pairs, groups, assembly conditions) and the local coordinates
of its points as arrays with a variants axis, and solves all V variants x n input angles as one
batch of V n positions through the same group solvers and checks as :func:`linkage.analyze`.

>>> import numpy as np, linkage
>>> mech = linkage.load("four_bar")
>>> crank = np.column_stack([np.linspace(0.08, 0.12, 5), np.zeros(5)])   # OA from 80 to 120 mm
>>> batch = analyze_variants(mech, np.radians([0.0, 90.0]), {"1": {"A": crank}})
>>> batch.poses["3"].shape, batch.status.shape
((5, 2, 3), (5, 2))
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, replace
from typing import Iterable, Literal, Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike

from assur.base import OK, RevoluteJoint, global_point, point_analogs

from ..errors import AssemblyError, InputError
from ..model.mechanism import Mechanism
from ..structure import Structure, structure_of
from .assembly import assembly_plans
from . import motion
from .kernel_variants import columns, variant_kernel_for
from .motion import JUMP_CHECK_STEP, BranchWarning, Motion, _kernel_results, jump_steps, links_needed, run_blocks

__all__ = ["OTHER_BRANCH", "VariantMotion", "analyze_variants", "geometry_of"]

#: status of the positions of a variant for which the group's closed-form branch (chosen by the
#: declared assembly condition on the base mechanism) does not satisfy that condition: its
#: geometry assembles the other way; analyse that variant alone
OTHER_BRANCH = -3

Geometry = Mapping[str, Mapping[str, ArrayLike]]


@dataclass(frozen=True)
class VariantMotion:
    """Kinematics of V variants at n input angles (see :func:`analyze_variants`).

    Attributes
    ----------
    mechanism : Mechanism
        The base mechanism (its topology; its own dimensions where ``geometry`` leaves them).
    geometry : dict of link -> {point -> ndarray (V, 2)}
        Local coordinates of every point of every link, m, per variant.
    phi : ndarray (n,)
        Input angles, rad.
    poses, first, second : dict of link -> ndarray (V, n, 3)
        Poses ``(x, y, theta)`` and their first / second analogs (``None`` when not computed).
    status : ndarray of int (V, n)
        0 ok, -1 cannot be assembled, -2 singular, -3 (:data:`OTHER_BRANCH`) the declared
        assembly condition is not met by this variant's branch.
    conditioning : dict of group label -> ndarray (V, n)
        As ``Motion.conditioning``.
    error_bound : ndarray (V, n)
        Bound of the relative error of the first analogs (at most 1e-8 where the status is 0).
    mode_change : ndarray of bool (V,)
        Variants whose motion passes a singular position or a change point between analysed
        angles (a group changes assembly mode): their values are right for the closed-form
        branch but the motion between the angles is not continuous.
    structure : Structure
        The mechanism's structure with pairs that carry every position's geometry (the V n
        positions flattened variant by variant), for :meth:`flat`.
    """

    mechanism: Mechanism
    geometry: dict[str, dict[str, np.ndarray]]
    phi: np.ndarray
    poses: dict[str, np.ndarray]
    first: dict[str, np.ndarray] | None
    second: dict[str, np.ndarray] | None
    status: np.ndarray
    conditioning: dict[str, np.ndarray]
    error_bound: np.ndarray
    mode_change: np.ndarray
    structure: Structure

    @property
    def count(self) -> int:
        """Number of variants V."""
        return self.status.shape[0]

    def point(self, name: str) -> np.ndarray:
        """Global position ``(V, n, 2)`` of a named point, m."""
        link, local = self._local(name)
        pose = self.poses[link].reshape(-1, 3)
        return global_point(pose, local).reshape(*self.status.shape, 2)

    def point_analogs(self, name: str) -> tuple[np.ndarray, np.ndarray | None]:
        """First and second analogs ``(V, n, 2)`` of a named point, m/rad and m/rad^2."""
        if self.first is None:
            raise InputError("analogs were not computed (analyze_variants(..., order=1 or 2))")
        link, local = self._local(name)
        flat = [None if d is None else d[link].reshape(-1, 3) for d in (self.poses, self.first, self.second)]
        d1, d2 = point_analogs(*flat, local)
        shape = (*self.status.shape, 2)
        return d1.reshape(shape), None if d2 is None else d2.reshape(shape)

    def flat(self, omega: ArrayLike | None = None, eps: ArrayLike | None = None) -> Motion:
        """The batch as one :class:`linkage.Motion` of V n positions (variant by variant; the
        arrays are views), with the input speed ``omega`` and acceleration ``eps`` given per
        flattened position ``(V n,)``, for the kinetostatics of the variants."""
        def flat(values):
            return None if values is None else {k: v.reshape(-1, 3) for k, v in values.items()}

        return Motion(self.mechanism, self.structure, np.tile(self.phi, self.count), flat(self.poses),
                      flat(self.first), flat(self.second), self.status.ravel(), omega, eps,
                      {k: v.ravel() for k, v in self.conditioning.items()}, self.error_bound.ravel())

    def _local(self, name: str):
        link = self.mechanism.point_link(name)
        if link not in self.poses:
            raise InputError(f"point '{name}' (link '{link}') was not among the requested outputs")
        return link, repeat_per_angle(self.geometry[link][name], len(self.phi))


def geometry_of(mechanisms: Sequence[Mechanism]) -> dict[str, dict[str, np.ndarray]]:
    """The ``geometry`` argument of :func:`analyze_variants` for mechanisms of one topology
    (e.g. the variants of a template, loaded one by one): their points' local coordinates
    stacked along a variants axis, ``{link: {point: (V, 2)}}``.

    Raises
    ------
    InputError
        When the mechanisms differ in links, points or pairs (the message names the first one).
    """
    if not mechanisms:
        raise InputError("geometry_of needs at least one mechanism")
    base = mechanisms[0]
    for mech in mechanisms[1:]:
        same = (mech.links.keys() == base.links.keys() and mech.pairs == base.pairs
                and all(mech.links[k].points.keys() == base.links[k].points.keys() for k in base.links))
        if not same:
            raise InputError(f"mechanism '{mech.name}' differs from '{base.name}' in its links, points or "
                             "pairs: variants of one topology differ only in dimensions")
    return {k: {p: np.array([m.links[k].points[p] for m in mechanisms], dtype=float) for p in link.points}
            for k, link in base.links.items()}


def analyze_variants(
    mech: Mechanism,
    phi: ArrayLike,
    geometry: Geometry,
    *,
    order: int = 2,
    outputs: Iterable[str] | None = None,
    on_failure: Literal["raise", "mask"] = "mask",
) -> VariantMotion:
    """Kinematics of V variants of ``mech`` at the input angles ``phi``, in one call.

    Parameters
    ----------
    mech : Mechanism
        The topology, and the dimensions that ``geometry`` does not give.
    phi : array_like (n,)
        Input angles, rad, the same for every variant.
    geometry : mapping link -> {point -> array_like (V, 2)}
        Local coordinates of points in their link's frame, m, per variant (the frame's points
        are global), as ``mech.links[link].points`` holds them; e.g. ``{"1": {"A": crank}}``
        for the crank OA of the four-bar, ``crank[:, 0]`` its lengths. A point shared by two
        links (a pin) is given on each link that it moves. Guides keep the base mechanism's
        lines. :func:`geometry_of` stacks the geometry of loaded mechanisms.
    order : {0, 1, 2}
        Highest analog order.
    outputs : iterable of str, optional
        As in :func:`linkage.analyze`: only the groups these need run.
    on_failure : {"mask", "raise"}
        ``"mask"`` (default): per-position statuses. ``"raise"``: :class:`AssemblyError` when
        any position of any variant is not OK.

    Returns
    -------
    VariantMotion

    Notes
    -----
    Every group keeps the closed-form branch that the mechanism's assembly condition chooses
    for the base dimensions; each variant's own branch is checked against that condition (the
    majority of its analysed positions must satisfy it) and marked :data:`OTHER_BRANCH`
    otherwise. Groups that follow their motion through change points (``mode = "follow"``)
    are refused: their change points differ from variant to variant.
    """

    if order not in (0, 1, 2):
        raise InputError(f"order must be 0, 1 or 2, got {order!r}")
    if on_failure not in ("raise", "mask"):
        raise InputError(f"on_failure must be 'raise' or 'mask', got {on_failure!r}")
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    if phi.ndim != 1 or not len(phi) or not np.all(np.isfinite(phi)):
        raise InputError("phi must be a non-empty 1-D array of finite angles in rad")
    base = structure_of(mech)
    if len(base.inputs) != 1:
        raise InputError(f"mechanism '{mech.name}' has {len(base.inputs)} inputs; batches need one input link")
    local = _geometry(mech, geometry)
    count = len(next(iter(next(iter(local.values())).values())))
    n = len(phi)
    plans = assembly_plans(mech)
    group_ids = list(range(len(base.groups))) if outputs is None else base.needed_groups(links_needed(mech, outputs))
    for i in group_ids:
        if plans[i].mode == "follow" and plans[i].swaps.any():
            raise InputError(f"mechanism '{mech.name}': group {base.groups[i]!r} follows its motion through change "
                             "points (mode = \"follow\"); they differ from variant to variant: analyse the variants "
                             "one by one")
    size = np.repeat(_sizes(mech, local), n)
    batch = _BatchStructure(mech, base, local, n, size)
    structure = batch.whole
    kernel = variant_kernel_for(mech, order) if outputs is None and motion.USE_KERNEL else None
    got = None if kernel is None else kernel(np.tile(phi, count), None, columns(base, batch.joints, size))
    run = None if got is None else _kernel_results(got)
    if run is None:
        run = run_blocks(mech, structure, plans, group_ids, np.tile(phi, count), order, batch.at)
    status = run.status.reshape(count, n)
    mode_change = np.zeros(count, bool)
    for i in group_ids:
        group = structure.groups[i]
        solved = run.solved[i].reshape(count, n)
        mode_change |= _sign_changes(run.signs[i].reshape(count, n), solved)
        if order >= 1:
            mode_change |= _moves_too_far(group, run.poses, run.first, solved, phi, float(np.median(size)))
        wrong = _other_branch(mech, base.groups[i], run.poses, local, count, n)
        status[wrong & (status == OK)] = OTHER_BRANCH
    if mode_change.any():
        shown = ", ".join(str(v) for v in np.flatnonzero(mode_change)[:10])
        warnings.warn(f"{int(mode_change.sum())} variant(s) change assembly mode between analysed angles (variants "
                      f"{shown}{' ...' if mode_change.sum() > 10 else ''}; see VariantMotion.mode_change)",
                      BranchWarning, stacklevel=2)
    if on_failure == "raise" and np.any(status != OK):
        bad = np.argwhere(status != OK)
        raise AssemblyError(f"mechanism '{mech.name}': {len(bad)} of {status.size} positions are not OK (first: "
                            f"variant {bad[0][0]} at {np.degrees(phi[bad[0][1]]):.6g} deg, status "
                            f"{status[tuple(bad[0])]}); use on_failure='mask'", np.degrees(phi[bad[:, 1]]))

    def shaped(values):
        return None if values is None else {k: v.reshape(count, n, 3) for k, v in values.items()}

    return VariantMotion(mech, local, phi, shaped(run.poses), shaped(run.first), shaped(run.second), status,
                         {k: v.reshape(count, n) for k, v in run.conditioning.items()},
                         run.error_bound.reshape(count, n), mode_change, structure)


# ----------------------------------------------------------------------------------------------
# the batch's geometry
# ----------------------------------------------------------------------------------------------


def _geometry(mech: Mechanism, geometry: Geometry) -> dict[str, dict[str, np.ndarray]]:
    """Every point's local coordinates ``(V, 2)``: the given ones checked, the others repeated."""
    if not isinstance(geometry, Mapping) or not geometry:
        raise InputError("geometry must map link names to {point: array (V, 2)} (at least one point)")
    given: dict[tuple[str, str], np.ndarray] = {}
    for link, point, values in link_points(mech, geometry, "geometry", "arrays (V, 2)"):
        arr = np.asarray(values, dtype=float)
        if arr.ndim != 2 or arr.shape[1] != 2 or not len(arr):
            raise InputError(f"geometry['{link}']['{point}'] must have shape (V, 2), got {arr.shape}")
        if not np.all(np.isfinite(arr)):
            row = int(np.flatnonzero(~np.all(np.isfinite(arr), axis=1))[0])
            raise InputError(f"geometry['{link}']['{point}'] of variant {row} is not finite: {arr[row].tolist()}")
        given[link, point] = arr
    counts = {len(v) for v in given.values()}
    if len(counts) != 1:
        raise InputError(f"geometry: every array needs the same number of variants V, got {sorted(counts)}")
    (count,) = counts
    return {k: {p: given.get((k, p), np.tile(np.asarray(xy_, float), (count, 1))) for p, xy_ in link.points.items()}
            for k, link in mech.links.items()}


def link_points(mech: Mechanism, entries: Mapping, what: str, values: str):
    """``(link, point, value)`` of a mapping ``{link: {point: value}}``, every link and point
    checked against ``mech`` (``InputError`` naming the entry ``what``; ``values`` says what a
    value is)."""
    for link, points in entries.items():
        if link not in mech.links:
            raise InputError(f"{what}: mechanism '{mech.name}' has no link {link!r} (links {sorted(mech.links)})")
        if not isinstance(points, Mapping):
            raise InputError(f"{what}['{link}'] must map point names to {values}, got {type(points).__name__}")
        for point, value in points.items():
            if point not in mech.links[link].points:
                raise InputError(f"{what}['{link}']: link '{link}' has no point {point!r} "
                                 f"(points {sorted(mech.links[link].points)})")
            yield link, point, value


def _sizes(mech: Mechanism, local: dict) -> np.ndarray:
    """Characteristic length ``(V,)`` of every variant, m (as ``Mechanism.size``: the largest
    distance between two points, guide points included, of one link)."""
    count = len(next(iter(next(iter(local.values())).values())))
    size = np.zeros(count)
    for k, link in mech.links.items():
        points = list(local[k].values()) + [np.tile(np.asarray(g.point, float), (count, 1))
                                           for g in link.guides.values()]
        for a in range(len(points)):
            for b in range(a + 1, len(points)):
                size = np.maximum(size, np.hypot(*(points[a] - points[b]).T))
    return np.where(size > 0, size, 1.0)


def repeat_per_angle(values: np.ndarray, n: int) -> np.ndarray:
    """``(V, 2)`` per-variant coordinates repeated for n angles: ``(V n, 2)``, each coordinate
    contiguous (the solvers read them as two ``(V n,)`` columns)."""
    return np.asfortranarray(np.repeat(values, n, axis=0))


class _BatchStructure:
    """The base structure with joints that carry every position's geometry; :meth:`at` gives it
    for a slice of positions (groups re-bound to the slice's joints)."""

    def __init__(self, mech: Mechanism, base, local: dict, n: int, size: np.ndarray):
        self.base, self.size = base, size
        point_of = {name: pair.point for name, pair in mech.pairs.items()}
        self.joints = {name: self._joint(j, local, n, point_of.get(name)) for name, j in base.joints.items()}
        self.whole = self.at(slice(None))

    @staticmethod
    def _joint(joint, local: dict, n: int, point: str):
        if isinstance(joint, RevoluteJoint):
            return replace(joint, pa=repeat_per_angle(local[joint.a][point], n),
                           pb=repeat_per_angle(local[joint.b][point], n))
        return replace(joint, p=repeat_per_angle(local[joint.b][point], n))

    def at(self, rows: slice):
        joints = {}
        for name, j in self.joints.items():
            if isinstance(j, RevoluteJoint):
                joints[name] = replace(j, pa=j.pa[rows], pb=j.pb[rows])
            else:
                joints[name] = replace(j, p=j.p[rows])
        groups = tuple(type(g).bind(g.links, [joints[j.name] for j in g.joints], set(g.known_links), self.size[rows])
                       for g in self.base.groups)
        inputs = {k: joints[j.name] for k, j in self.base.input_joints.items()}
        return replace(self.base, groups=groups, joints=joints, input_joints=inputs)


# ----------------------------------------------------------------------------------------------
# per-variant checks
# ----------------------------------------------------------------------------------------------


def _sign_changes(signs: np.ndarray, solved: np.ndarray) -> np.ndarray:
    """``(V,)``: the sign of the group's Jacobian determinant differs between OK positions."""
    ok = solved == OK
    positive, negative = np.any(ok & (signs > 0), axis=1), np.any(ok & (signs < 0), axis=1)
    return positive & negative


def _moves_too_far(group, poses, first, solved: np.ndarray, phi: np.ndarray, scale: float) -> np.ndarray:
    """``(V,)``: between two analysed angles at most 10 deg apart a link moves more than its
    analogs allow (the jump check of :func:`linkage.analyze`, variant by variant; ``scale``,
    m, weighs the links' turns)."""
    count, n = solved.shape
    if n < 2:
        return np.zeros(count, bool)
    dphi = np.diff(phi)
    pairs = (solved[:, :-1] == OK) & (solved[:, 1:] == OK) & (np.abs(dphi) <= JUMP_CHECK_STEP) & (dphi != 0)
    # flattened over variants: the step from one variant's last angle to the next variant is no step
    flat_pairs = np.column_stack([pairs, np.zeros(count, bool)]).ravel()[:-1]
    flat_dphi = np.tile(np.append(dphi, 0.0), count)[:-1]
    bad = jump_steps(group, poses, first, flat_pairs, flat_dphi, scale)
    return np.append(bad, False).reshape(count, n)[:, :-1].any(axis=1)


def _other_branch(mech: Mechanism, group, poses: dict, local: dict, count: int, n: int) -> np.ndarray:
    """``(V, 1)`` bool: the variant's placement of the group fails the declared assembly
    condition at most of its analysed positions (ties count as met)."""
    rules = [r for r in mech.assembly
             if r.rule != "branch" and any(r.point in mech.links[k].points for k in group.links)]
    if not rules:
        return np.zeros((count, 1), bool)
    rule = rules[0]

    def at(point):
        link = next(k for k in mech.point_links(point) if k in poses)
        pose = poses[link].reshape(count, n, 3)
        c, s = np.cos(pose[..., 2]), np.sin(pose[..., 2])
        px, py = local[link][point][:, 0:1], local[link][point][:, 1:2]
        return pose[..., 0] + c * px - s * py, pose[..., 1] + s * px + c * py

    P = at(rule.point)
    X = at(rule.refs[0])
    if rule.rule in ("left_of", "right_of"):
        Y = at(rule.refs[1])
        score = (Y[0] - X[0]) * (P[1] - X[1]) - (Y[1] - X[1]) * (P[0] - X[0])
        with np.errstate(divide="ignore", invalid="ignore"):
            score = score / np.hypot(Y[0] - X[0], Y[1] - X[1])
        score = score if rule.rule == "left_of" else -score
    else:
        score = (P[0] - X[0]) * np.cos(rule.angle) + (P[1] - X[1]) * np.sin(rule.angle)
    with np.errstate(invalid="ignore"):
        met, failed = np.sum(score > 1e-9 * mech.size, axis=1), np.sum(score < -1e-9 * mech.size, axis=1)
    return (failed > met)[:, None]
