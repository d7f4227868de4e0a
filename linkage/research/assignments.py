"""Pair kinds of a chain: every R/P assignment of its pairs, and the source's reference positions.

A chain is a scheme's topology: its links, which pair joins which two links, the frame and the
input link. Its input pair (input link - frame) stays revolute; each other pair is either
revolute (``R``) or prismatic (``P``), and a prismatic pair carries its guide on one of its two
links (``P3``: the guide is on link 3, the other link slides on it): :func:`assignments` lists
every assignment. Every combination takes its geometry from the source at a reference position
(:func:`reference_positions`), which is therefore a position of every combination.

>>> import linkage
>>> found = assignments(linkage.load("four_bar"))
>>> len(found), found[0].id, found[-1].id
(27, 'A=R,B=R,C=R', 'A=P2,B=P3,C=P3')
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass

import numpy as np

from assur.base import OK

from ..errors import InputError, LinkageError
from ..kinematics.extremes import extreme_positions
from ..kinematics.motion import analyze, input_sweep
from ..model.mechanism import Mechanism, Revolute

__all__ = [
    "Assignment",
    "PairKind",
    "Reference",
    "assignments",
    "reference_angle",
    "reference_positions",
]


# ----------------------------------------------------------------------------------------------
# assignments
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PairKind:
    """The kind of one pair in an assignment: ``"R"``, or ``"P"`` with the link that carries the guide."""

    pair: str
    kind: str
    guide_link: str | None = None

    @property
    def label(self) -> str:
        """``"B=R"`` or ``"B=P3"`` (prismatic, guide on link 3)."""
        return f"{self.pair}={self.kind}" + (self.guide_link if self.kind == "P" else "")

    @property
    def words(self) -> str:
        """``"B revolute"`` or ``"B prismatic, guide on link 3"``."""
        if self.kind == "R":
            return f"{self.pair} revolute"
        return f"{self.pair} prismatic, guide on link {self.guide_link}"


@dataclass(frozen=True)
class Assignment:
    """Pair kinds of every pair but the input's, in the order of the pair names."""

    kinds: tuple[PairKind, ...]

    @property
    def id(self) -> str:
        """``"A=R,B=P3,C=R"``: the labels joined by commas (no spaces: a word of the shell)."""
        return ",".join(k.label for k in self.kinds)

    @property
    def file_name(self) -> str:
        """The id as a file name (characters other than letters, digits and ``_.,=-`` become ``_``)."""
        return re.sub(r"[^A-Za-z0-9_.,=-]", "_", self.id) + ".toml"

    def of(self, pair: str) -> PairKind | None:
        """The kind given to ``pair`` (None for the input pair)."""
        return next((k for k in self.kinds if k.pair == pair), None)


def input_pair(mech: Mechanism) -> str:
    """The revolute pair that pins the input link to the frame (the first by name)."""
    (link,) = one_input(mech)
    return min(name for name, p in mech.pairs.items()
                  if isinstance(p, Revolute) and set(p.links) == {link, mech.frame})


def one_input(mech: Mechanism) -> tuple[str]:
    """The one input link of ``mech``: a crank pinned to the frame by a revolute pair; an
    :class:`InputError` naming the inputs otherwise (several, or a slide: a piston or a cylinder)."""
    if len(mech.inputs) != 1:
        raise InputError(f"scheme '{mech.name}' has {len(mech.inputs)} input links {list(mech.inputs)}; "
                         "pair kinds are enumerated for a chain with one input link")
    (link,) = mech.inputs
    pair = mech.input_pair(link)
    if mech.input_kind(link) != "angle" or pair is None or set(mech.pairs[pair].links) != {link, mech.frame}:
        driven = f"driven by the prismatic pair '{pair}'" if pair is not None else "not pinned to the frame"
        raise InputError(f"scheme '{mech.name}': input '{link}' is a slide ({driven}); pair kinds are enumerated "
                         "for a crank input, a link pinned to the frame by a revolute pair (docs/enumerate.md)")
    return (link,)


def assignments(mech: Mechanism) -> list[Assignment]:
    """Every assignment of R or P to the pairs of ``mech`` other than its input pair.

    Each pair is ``R``, ``P`` with the guide on its first link or ``P`` with the guide on its
    second link (links in name order): ``3**n`` assignments for ``n`` pairs, in the order of
    :func:`itertools.product` over the pairs sorted by name.
    """
    fixed = input_pair(mech)
    options = []
    for name in sorted(mech.pairs):
        if name == fixed:
            continue
        links = sorted(mech.pairs[name].links)
        options.append([PairKind(name, "R")] + [PairKind(name, "P", link) for link in links])
    return [Assignment(tuple(choice)) for choice in itertools.product(*options)]


# ----------------------------------------------------------------------------------------------
# the reference position of the source
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Reference:
    """The source scheme at one assembled position, from which every combination takes its geometry.

    Attributes
    ----------
    phi : float
        Input angle of the position, rad.
    poses : dict of str -> ndarray, shape (3,)
        Every link's pose ``(x, y, theta)`` (m, m, rad).
    joints : dict of str -> (str, ndarray of shape (2,))
        Every pair's point name (a revolute pair's pin; a prismatic pair's slider point) and its
        global position, m.
    size : float
        The source's characteristic length, m.
    """

    phi: float
    poses: dict[str, np.ndarray]
    joints: dict[str, tuple[str, np.ndarray]]
    size: float

    def to_local(self, link: str, point: np.ndarray) -> tuple[float, float]:
        """Local coordinates (m) on ``link`` of a global point ``(2,)`` of the reference position."""
        x, y, theta = self.poses[link]
        dx, dy = point[0] - x, point[1] - y
        c, s = math.cos(theta), math.sin(theta)
        return (c * dx + s * dy, -s * dx + c * dy)

    def to_global(self, link: str, local) -> np.ndarray:
        """Global position ``(2,)`` of ``link``'s local point at the reference position, m."""
        x, y, theta = self.poses[link]
        c, s = math.cos(theta), math.sin(theta)
        return np.array([x + c * local[0] - s * local[1], y + s * local[0] + c * local[1]])


def reference_angle(mech: Mechanism) -> float | None:
    """Input angle (rad, in [0, 2 pi)) halfway from the extreme position "max" of the source's
    output to its extreme position "min", turning counter-clockwise: the position farthest (in
    input angle) from both dead points, where the joints are least in line. None without an
    output, with an input range, or when the output has no extreme positions."""
    if mech.output is None or mech.input_range is not None:
        return None
    try:
        ext = extreme_positions(mech)
    except LinkageError:
        return None
    return float((ext.phi_max + ((ext.phi_min - ext.phi_max) % (2 * np.pi)) / 2) % (2 * np.pi))


#: reference positions tried: the first reference angle and the angles a quarter, a half and three
#: quarters of a turn further
REFERENCE_STEPS = 4


def reference_positions(mech: Mechanism) -> list[Reference]:
    """The reference positions from which the combinations take their geometry, in the order tried.

    The first angle is :func:`reference_angle` (or, without one, or where the source is not
    assembled and regular there, the first angle of the 1 deg sweep from 0 at which it is); then
    the angles 90, 180 and 270 deg further, those at which the source is assembled and regular.

    Raises
    ------
    InputError
        When the scheme is assembled and regular at no angle of the sweep.
    """
    first = reference_angle(mech)
    if first is None or analyze(mech, [first], order=0, on_failure="mask").status[0] != OK:
        sweep = input_sweep(mech)
        ok = np.flatnonzero(sweep.status == OK)
        if not len(ok):
            raise InputError(f"scheme '{mech.name}' is assembled and regular at none of the {len(sweep.phi)} "
                             "input angles of its travel: it has no reference position to take a geometry from")
        first = float(sweep.phi[ok[0]])
    phi = (first + np.arange(REFERENCE_STEPS) * 2 * np.pi / REFERENCE_STEPS) % (2 * np.pi)
    motion = analyze(mech, phi, order=0, on_failure="mask")
    return [_reference(mech, motion, i) for i in np.flatnonzero(motion.status == OK)]


def _reference(mech: Mechanism, motion, i: int) -> Reference:
    """The :class:`Reference` of position ``i`` of an analysed motion."""
    poses = {link: np.array(pose[i], dtype=float) for link, pose in motion.poses.items()}
    ref = Reference(float(motion.phi[i]), poses, {}, mech.size)
    for name, pair in mech.pairs.items():
        on = pair.links[0] if isinstance(pair, Revolute) else pair.links[1]
        ref.joints[name] = (pair.point, ref.to_global(on, mech.links[on].points[pair.point]))
    return ref
