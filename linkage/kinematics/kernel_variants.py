"""Compiled kernels for batches of design variants: the geometry as inputs of the kernel.

:mod:`.kernel` folds a mechanism's dimensions into its kernel as constants. A batch of variants
(:func:`linkage.kinematics.batch.analyze_variants`) gives every position its own local
coordinates of the pairs' points and its own size, so this module traces the same kinematics with
those as symbols: each pair's points (two coordinates each: ``pa`` and ``pb`` of a revolute pair,
``p`` of a prismatic one; the guides' lines stay the base mechanism's) and each group's size
become further ``(N,)`` inputs after the input angle. The kernel is kept per mechanism and order
beside the plain one, and the batch passes its per-position geometry as :func:`columns`.

>>> import numpy as np, linkage
>>> from linkage.kinematics.batch import analyze_variants
>>> mech = linkage.load("four_bar")
>>> crank = np.column_stack([[0.08, 0.1, 0.12], np.zeros(3)])
>>> batch = analyze_variants(mech, np.radians([0.0, 90.0]), {"1": {"A": crank}})
>>> batch.status.tolist()
[[0, 0], [0, 0], [0, 0]]
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from assur.base import RevoluteJoint

from ..model.mechanism import Mechanism
from ..structure import Structure, structure_of
from .kernel import _KERNELS, Kernel, kernel_for, supported

__all__ = ["variant_kernel_for", "columns"]


def _points(joint) -> tuple[str, ...]:
    """The attributes of ``joint`` that hold a local point varied per variant."""
    return ("pa", "pb") if isinstance(joint, RevoluteJoint) else ("p",)


def _geometry(structure: Structure):
    """The function a :class:`~.kernel.Kernel` calls while tracing: ``structure`` with every
    pair's points and every group's size as input symbols (numbered from ``first``)."""

    def symbolic(graph, first: int) -> Structure:
        def symbol() -> Any:
            nonlocal first
            first += 1
            return graph.node("input", (first - 1,), "f")

        joints = {name: replace(j, **{a: (symbol(), symbol()) for a in _points(j)})
                  for name, j in structure.joints.items()}
        size = symbol()
        size.nonneg = True
        groups = tuple(type(g).bind(g.links, [joints[j.name] for j in g.joints], set(g.known_links))
                       for g in structure.groups)
        for group in groups:
            group.size = size      # after binding: the constructor takes a number or an array
        inputs = {k: joints[j.name] for k, j in structure.input_joints.items()}
        return replace(structure, groups=groups, joints=joints, input_joints=inputs)

    return symbolic


def variant_kernel_for(mech: Mechanism, order: int = 2) -> Kernel | None:
    """The compiled kinematics of batches of ``mech``'s variants to analog ``order``: a
    :class:`~.kernel.Kernel` called with the tiled input angles and :func:`columns`; None where
    the kernel does not apply (as :func:`~.kernel.kernel_for`, and a batch's one input must be a
    crank)."""
    if kernel_for(mech, order) is None:
        return None
    kernels = _KERNELS[id(mech)][1]
    key = ("variants", order)
    if key not in kernels:
        structure = structure_of(mech)
        crank = len(structure.inputs) == 1 and all(isinstance(j, RevoluteJoint)
                                                    for j in structure.input_joints.values())
        kernels[key] = Kernel(mech, structure, order, _geometry(structure)) \
            if crank and supported(mech, structure) else None
    return kernels[key]


def columns(structure: Structure, joints: dict, size: np.ndarray) -> list[np.ndarray]:
    """The inputs of a kernel of variants after the input angle, each ``(N,)``: the points of
    ``joints`` (pair name -> joint whose points are ``(N, 2)``, in ``structure``'s order of pairs)
    and ``size`` ``(N,)``, m."""
    out = []
    for name, joint in structure.joints.items():
        for attribute in _points(joint):
            values = np.asarray(getattr(joints[name], attribute), dtype=float)
            out += [values[:, 0], values[:, 1]]
    return out + [np.asarray(size, dtype=float)]
