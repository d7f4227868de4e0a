"""A compiled reactions kernel per mechanism: the kinetostatics of closed-form dyads as one function.

:func:`linkage.kinetostatics.reactions.reactions_under` walks the groups from the farthest,
each solving its transposed elimination (:meth:`assur.dyad.Dyad.reactions`) on dicts of arrays,
then each input link's equilibrium. For a mechanism whose groups are all closed-form dyads
(what :mod:`linkage.kinematics.kernel` compiles) and without friction, this module records the
same steps once on symbols -- each link's pose and generalized load ``(Fx, Fy, M)`` and the
positions' validity as inputs; each pair's two multipliers and each input's balancing load as
outputs, NaN where a position is not valid -- and compiles them like the kinematics kernel
(straight-line numpy; numba where the ``fast`` extra is installed).

>>> import numpy as np, linkage
>>> from linkage.kinetostatics.reactions import solve_reactions
>>> mech = linkage.load("slider_crank")
>>> reactions = solve_reactions(linkage.analyze(mech, np.radians([30.0, 120.0]), omega=10.0))
>>> reactions_kernel_for(mech) is not None, reactions.balancing_moment.shape
(True, (2,))
"""

from __future__ import annotations

import weakref
from collections.abc import Callable

import numpy as np

from assur.rows import rows_of

from ..kinematics import motion as kinematics
from ..kinematics.kernel import _compiled, _Graph, _source, _Trace, supported
from ..kinematics.kernel_numba import numba_kernel
from ..model.mechanism import Mechanism
from ..structure import Structure, structure_of

__all__ = ["reactions_kernel_for", "run_reactions_kernel"]


def input_freedom(joint, link: str, rows) -> tuple[tuple, tuple]:
    """The motion an input ``link`` has in its ``joint`` with the frame, per unit of its coordinate
    (``(vx, vy, w)``: a turn about the pin for a crank, a slide along the guide for a slider), and
    the generalized load ``(Fx, Fy, M)`` of a unit drive (a unit moment, or a unit force along the
    slide through the link's origin) -- the drive whose value is the balancing moment or force.
    ``rows``: :func:`assur.rows.rows_of` of the joint at the motion's frames."""
    vx, vy, w = rows.null(link)
    if joint.kind == "R":
        return (vx, vy, w), (0.0, 0.0, 1.0)
    sign = 1.0 if link == joint.b else -1.0        # guide on the frame: the link slides along +u
    return (sign * vx, sign * vy, 0.0), (sign * vx, sign * vy, 0.0)


class _ReactionsTrace(_Trace):
    """The graph of a mechanism's reactions: inputs ``x, y, theta`` of every moving link, then its
    load ``Fx, Fy, M``, then the validity (1.0 or 0.0); outputs each pair's two multipliers (in
    the structure's order of pairs) and each input's balancing load."""

    def __init__(self, mech: Mechanism, structure: Structure):     # not the kinematics' __init__
        self.graph = g = _Graph()
        self.outputs = []
        self.links = [*structure.inputs, *(k for group in structure.groups for k in group.links)]
        count = iter(range(7 * len(self.links) + 1))

        def symbol():
            return g.node("input", (next(count),), "f")

        frames = {mech.frame: (0.0, 0.0, 1.0, 0.0, 0.0)}
        for k in self.links:
            x, y, theta = symbol(), symbol(), symbol()
            frames[k] = (x, y, np.cos(theta), np.sin(theta), theta)
        applied = {k: (symbol(), symbol(), symbol()) for k in self.links}
        valid = symbol() > 0.5
        self.n_params = 7 * len(self.links) + 1
        multipliers = {}
        for group in reversed(structure.groups):
            lam, transmitted = _group_reactions(group, frames, applied, valid)
            multipliers.update(lam)
            for link, load in transmitted.items():
                if link in applied:
                    applied[link] = tuple(a + b for a, b in zip(applied[link], load))
        balancing = {}
        for link in structure.inputs:
            joint = structure.input_joints[link]
            rows = rows_of(joint, frames)
            motion_per_unit, drive = input_freedom(joint, link, rows)
            load = tuple(-v for v in applied[link])
            moment = load[0] * motion_per_unit[0] + load[1] * motion_per_unit[1] + load[2] * motion_per_unit[2]
            rest = tuple(load[c] - moment * drive[c] for c in range(3))
            multipliers[joint.name] = rows.multipliers(link, rest)
            balancing[link] = moment
        bad = ~valid
        for name in structure.joints:
            self.outputs += [(f"{name} {c}", np.where(bad, np.nan, v)) for c, v in enumerate(multipliers[name])]
        self.outputs += [(f"balancing {k}", np.where(bad, np.nan, v)) for k, v in balancing.items()]


def _group_reactions(group, frames, applied, valid):
    """:meth:`assur.dyad.Dyad.reactions` on symbols (its elimination ``_transposed`` run as it
    is): the multipliers of the group's pairs and the loads transmitted to its known links, NaN
    where the group's system is singular or the position not valid."""
    ok, lam, transmitted = group._transposed(frames, {k: applied[k] for k in group.links}, valid)
    bad = ~ok
    multipliers = {name: tuple(np.where(bad, np.nan, v) for v in values) for name, values in lam.items()}
    transmitted = {k: tuple(np.where(bad, np.nan, v) for v in load) for k, load in transmitted.items()}
    return multipliers, transmitted


class ReactionsKernel:
    """The compiled reactions of one mechanism (see the module): call it with the motion's poses
    and the generalized loads (link -> ``(N, 3)``) and the validity ``(N,)``."""

    def __init__(self, mech: Mechanism, structure: Structure):
        self.structure = structure
        self.trace = _ReactionsTrace(mech, structure)
        self.function: Callable = numba_kernel(self.trace, list(range(len(self.trace.outputs))),
                                               [True] * len(self.trace.outputs), _compiled(_source(self.trace)))

    def __call__(self, poses: dict, applied: dict, valid: np.ndarray) -> tuple[dict, dict]:
        """``(multipliers, balancing)``: pair -> ``(N, 2)`` and input link -> ``(N,)``."""
        links = self.trace.links
        inputs = [poses[k][:, c] for k in links for c in range(3)]
        inputs += [applied[k][:, c] for k in links for c in range(3)]
        inputs.append(np.asarray(valid, dtype=float))
        n = len(valid)
        floats = np.empty((len(self.trace.outputs), n))
        whole = getattr(self.function, "whole", None)
        if whole is None or not whole(inputs, floats, np.empty((0, n), dtype=int)):
            self.function(inputs, list(floats))
        multipliers = {name: floats[2 * i:2 * i + 2].T for i, name in enumerate(self.structure.joints)}
        start = 2 * len(self.structure.joints)
        balancing = {k: floats[start + i] for i, k in enumerate(self.structure.inputs)}
        return multipliers, balancing


_KERNELS: dict[int, tuple[weakref.ref, ReactionsKernel | None]] = {}


def reactions_kernel_for(mech: Mechanism) -> ReactionsKernel | None:
    """The compiled reactions of ``mech``, or None where they do not apply (a group that is not a
    closed-form dyad, a driven cylinder: :func:`linkage.kinematics.kernel.supported`)."""
    entry = _KERNELS.get(id(mech))
    if entry is None or entry[0]() is not mech:
        structure = structure_of(mech)
        entry = _KERNELS[id(mech)] = (weakref.ref(mech),
                                      ReactionsKernel(mech, structure) if supported(mech, structure) else None)
        weakref.finalize(mech, _KERNELS.pop, id(mech), None)
    return entry[1]


def run_reactions_kernel(motion, applied: dict, valid: np.ndarray) -> tuple[dict, dict] | None:
    """The multipliers of every pair and the balancing load of every input of ``motion`` under the
    generalized loads ``applied`` (link -> ``(N, 3)``), NaN where ``valid`` is False, by the
    mechanism's reactions kernel; None where it does not apply (or the kernels are switched off:
    :data:`linkage.kinematics.motion.USE_KERNEL`)."""
    kernel = reactions_kernel_for(motion.mechanism) if kinematics.USE_KERNEL else None
    if kernel is None or motion.structure is not kernel.structure or any(k not in motion.poses
                                                                         for k in kernel.trace.links):
        return None      # (a batch of variants has its own structure: its geometry per position)
    return kernel(motion.poses, applied, valid)
