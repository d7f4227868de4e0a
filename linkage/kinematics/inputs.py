"""The inputs of a mechanism (its class-I mechanisms): each input link's coordinate, pose and
analogs at the first input's coordinates ``phi``, the frame's included.

What the assembly plans (:mod:`linkage.kinematics.assembly`) and the motion
(:mod:`linkage.kinematics.motion`) both start from; reads the mechanism and its structure.
"""

from __future__ import annotations

import numpy as np

from assur.base import DrivenPrismaticJoint, rotate
from assur.rows import xy

from ..model.mechanism import Mechanism
from ..structure import Structure

__all__ = ["input_angles", "input_poses", "input_state", "slider_state"]


def input_state(mech: Mechanism, structure: Structure, phi: np.ndarray, poses: dict, first: dict | None = None,
                 second: dict | None = None) -> dict:
    """Write the poses and analogs of the input links at the first input's angles ``phi`` into the
    ``(N, 3)`` arrays of ``poses`` / ``first`` / ``second`` (the frame's are zeros; arrays are
    allocated when missing). Returns the frames ``(x, y, c, s, theta)`` of the frame and the inputs."""
    N = len(phi)
    for d in (poses, first, second):
        if d is not None:
            if mech.frame not in d:
                d[mech.frame] = np.zeros((N, 3))
            for link in structure.inputs:
                if link not in d:
                    d[link] = np.empty((N, 3))
    zeros = np.zeros(N)
    frames = {mech.frame: (zeros, zeros, np.ones(N), zeros, zeros)}
    for name, (q, rate, accel) in input_angles(mech, structure, phi).items():
        joint = structure.input_joints[name]
        out = poses[name]
        if isinstance(joint, DrivenPrismaticJoint):    # a cylinder's driver: pose (s, 0, 0)
            for values, d in ((q, poses), (rate, first), (accel, second)):
                if d is not None:
                    d[name][:, 0], d[name][:, 1:] = values, 0.0
            frames[name] = (out[:, 0], zeros, np.ones(N), zeros, zeros)
            continue
        if joint.kind == "P":
            slider_state(joint, name, q, rate, accel, out, first and first[name], second and second[name])
            c, s = np.cos(out[:, 2]), np.sin(out[:, 2])
            frames[name] = (out[:, 0], out[:, 1], c, s, out[:, 2])
            continue
        p_input, _, p_frame = joint.local(name)
        (px, py), (fx, fy) = xy(p_input), xy(p_frame)
        c, s = np.cos(q), np.sin(q)
        rx, ry = c * px - s * py, s * px + c * py
        out[:, 0], out[:, 1], out[:, 2] = fx - rx, fy - ry, q
        frames[name] = (out[:, 0], out[:, 1], c, s, out[:, 2])
        if first is not None:
            first[name][:, 0], first[name][:, 1], first[name][:, 2] = ry * rate, -rx * rate, rate
        if second is not None:
            # d2/dphi2 of fx - R(theta) p: rate^2 (R p) - accel (R p turned by 90 deg)
            second[name][:, 0] = rx * rate**2 + ry * accel
            second[name][:, 1] = ry * rate**2 - rx * accel
            second[name][:, 2] = accel
    return frames


def slider_state(joint, link: str, s, rate, accel, pose, first, second) -> None:
    """Pose and analogs ``(N, 3)`` of an input ``link`` driven along a frame guide by the slide
    ``s`` of its prismatic ``joint`` (rate ``ds/dphi`` and ``d2s/dphi2``): the slide ``s = u . d``
    of :class:`assur.base.PrismaticJoint` solved for the link's pose, whether the guide is on the
    frame (the link is the slider) or on the link (the frame's point slides in the link's guide)."""
    if joint.b == link:             # guide on the frame: r = g + s u - Rot(beta) p
        theta, sign = joint.beta, 1.0
        u = np.asarray(joint.u, float)
        start = np.asarray(joint.g, float) - rotate(theta, joint.p)
    else:                           # guide on the link: r = p - Rot(-beta) g - s u
        theta, sign = -joint.beta, -1.0
        u = rotate(theta, joint.u)
        start = np.asarray(joint.p, float) - rotate(theta, joint.g)
    along = sign * np.asarray(s, float)
    pose[:, 0], pose[:, 1], pose[:, 2] = start[0] + along * u[0], start[1] + along * u[1], theta
    for analogs, value in ((first, rate), (second, accel)):
        if analogs is not None:
            analogs[:, 0], analogs[:, 1], analogs[:, 2] = sign * value * u[0], sign * value * u[1], 0.0


def input_angles(mech: Mechanism, structure: Structure, phi: np.ndarray) -> dict[str, tuple]:
    """Each input link's coordinate (its angle, rad, or its slide, m) and the coordinate's first and
    second analogs ``(q, dq/dphi, d2q/dphi2)``, ``(N,)`` each, at the first input's coordinates
    ``phi`` (the first input: ``phi``, 1, 0; further inputs: their
    :class:`~linkage.model.input_laws.InputLaw`, declared under the input's name)."""
    ones, zeros = np.ones(len(phi)), np.zeros(len(phi))
    out = {}
    for k, (name, declared) in enumerate(zip(structure.inputs, mech.inputs)):
        out[name] = (phi, ones, zeros) if k == 0 else mech.input_laws[declared].angles(phi)
    return out


def input_poses(mech: Mechanism, structure: Structure, phi: np.ndarray) -> dict[str, np.ndarray]:
    """Poses ``(N, 3)`` of the frame and the input link at the angles ``phi``."""
    poses: dict[str, np.ndarray] = {}
    input_state(mech, structure, phi, poses)
    return poses
