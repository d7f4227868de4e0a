"""Registry of group kinds: name -> solver class. The decomposition asks it who solves a group."""

from __future__ import annotations

from typing import Sequence

from .base import Group, Joint
from .generic import NewtonGroup
from .prp import PRP
from .rpp import RPP
from .rpr import RPR
from .rrp import RRP
from .rrr import RRR
from .triad import Triad

__all__ = ["GROUP_KINDS", "group_kind", "register", "solver_for"]

GROUP_KINDS: dict[str, type[Group]] = {}


def register(cls: type[Group]) -> type[Group]:
    """Add a group kind to the registry (usable as a class decorator)."""
    GROUP_KINDS[cls.kind] = cls
    return cls


# the closed forms first; the generic Newton solver binds every statically determinate group left
for _cls in (RRR, RRP, RPR, PRP, RPP, Triad, NewtonGroup):
    register(_cls)


def group_kind(name: str) -> type[Group]:
    """The solver class registered as ``name``; ``ValueError`` lists the known kinds."""
    try:
        return GROUP_KINDS[name]
    except KeyError:
        raise ValueError(f"unknown group kind {name!r}; known kinds: {sorted(GROUP_KINDS)}") from None


def solver_for(links: Sequence[str], joints: Sequence[Joint], known: set[str], size: float = 1.0):
    """The first registered kind that binds this group (in registry order), or ``None``."""
    for cls in GROUP_KINDS.values():
        group = cls.bind(links, joints, known, size)
        if group is not None:
            return group
    return None
