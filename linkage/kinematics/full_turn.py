"""Whether a loaded mechanism's input turns over its whole travel, and if not, why (in words).

What the refusals after the assembly plans ask first (the loads' diagrams and cycle tables, the
feasibility of a variant, the extreme positions): :func:`input_cannot_turn` analyses the travel
(:func:`~.motion.input_sweep`: a turn, or the declared input range) and returns the sentence of
:func:`~.turning.turning_sentence` -- where the mechanism assembles, refined between the sweep's
angles, and the dimensional reason -- or None when the input turns. Angles within a sweep step of
a change point, where a group's two assembly modes meet (and the deltoid's closed form gives up
at the one angle where its pivots coincide), do not count as angles where it stops.

>>> import linkage
>>> input_cannot_turn(linkage.load("four_bar")) is None
True
"""

from __future__ import annotations

import warnings

import numpy as np

from assur.base import CANNOT_ASSEMBLE

from ..model.mechanism import Mechanism
from .assembly import CROSSING_STEP, assembly_plans
from .motion import BranchWarning, Motion, analyze, input_sweep
from .turning import assembled_spans, dimensional_reason, turning_sentence

__all__ = ["cannot_turn_sentence", "input_cannot_turn", "near_change_points"]

TWO_PI = 2 * np.pi


def input_cannot_turn(mech: Mechanism) -> str | None:
    """The sentence saying that the input of ``mech`` cannot turn fully (over its declared range),
    where it can and why not (:func:`~.turning.turning_sentence`); None when the mechanism
    assembles at every angle of its travel. Computed once per mechanism (``mech.cache``).

    Raises
    ------
    linkage.errors.LinkageError
        What the assembly plans raise (a group that never assembles ...).
    """
    cache = mech.cache
    if "cannot_turn" not in cache:
        motion = input_sweep(mech)
        failed = (motion.status == CANNOT_ASSEMBLE) & ~near_change_points(mech, motion.phi)
        cache["cannot_turn"] = cannot_turn_sentence(motion, failed) if failed.any() else None
    return cache["cannot_turn"]


def near_change_points(mech: Mechanism, phi: np.ndarray) -> np.ndarray:
    """``(N,)`` bool: the sweep's coordinates ``phi`` within one step of it (at least
    :data:`~.assembly.CROSSING_STEP`) of a change point of any group (angles modulo a turn)."""
    phi = np.asarray(phi, dtype=float)
    points = [plan.change_points for plan in assembly_plans(mech) if len(plan.change_points)]
    if not points or len(phi) < 2:
        return np.zeros(len(phi), bool)
    window = max(float(np.max(np.abs(np.diff(phi)))), CROSSING_STEP) * (1 + 1e-9)
    gap = phi[:, None] - np.concatenate(points)[None, :]
    if mech.coordinate.is_angle:
        gap = (gap + np.pi) % TWO_PI - np.pi
    return np.any(np.abs(gap) <= window, axis=1)


def cannot_turn_sentence(motion: Motion, failed: np.ndarray) -> str:
    """The sentence of :func:`input_cannot_turn` for a sweep ``motion`` of the whole travel (every
    group analysed) that fails to assemble where ``failed`` ``(N,)`` holds: the first group that
    does not assemble there with its known links placed gives the dimensional reason; the spans
    where the mechanism assembles are refined between the sweep's coordinates by analysing it."""
    mech, structure = motion.mechanism, motion.structure
    failed = np.asarray(failed, bool)
    reason_group, failing = structure.groups[0], {}
    for group in structure.groups:
        known = np.all(np.concatenate([np.isfinite(motion.poses[k]) for k in group.known_links], axis=1), axis=1)
        stops = failed & known & ~np.isfinite(motion.conditioning[repr(group)])
        if stops.any():
            reason_group, failing = group, {k: motion.poses[k][stops] for k in group.known_links}
            break

    def assembles(x: np.ndarray) -> np.ndarray:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", BranchWarning)
            return analyze(mech, x, order=0, on_failure="mask").status != CANNOT_ASSEMBLE

    spans = assembled_spans(mech, motion.phi, ~failed, assembles)
    return turning_sentence(mech, spans, dimensional_reason(mech, structure, reason_group, failing))
