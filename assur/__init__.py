"""assur: the library of Assur-group solvers (position, analogs, reactions), one kind per module.

See :mod:`assur.base` for the group protocol every kind implements.
"""

from .base import (
                   ANALOG_TOL,
                   CANNOT_ASSEMBLE,
                   NOT_CONVERGED,
                   OK,
                   SINGULAR,
                   SINGULAR_TOL,
                   Group,
                   PrismaticJoint,
                   RevoluteJoint,
)
from .registry import GROUP_KINDS, group_kind, register, solver_for

__all__ = [
    "Group", "RevoluteJoint", "PrismaticJoint", "GROUP_KINDS", "group_kind", "register",
    "solver_for", "OK", "CANNOT_ASSEMBLE", "SINGULAR", "NOT_CONVERGED", "ANALOG_TOL", "SINGULAR_TOL",
]
