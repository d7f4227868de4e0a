"""Machine dynamics of a one-degree-of-freedom mechanism, from its kinetostatics.

Reads the motion and the loads (:mod:`linkage.kinematics`, :mod:`linkage.kinetostatics`).
Reduced moments and moment of inertia (:mod:`~.reduced`), motors reduced to the input
(:mod:`~.motors`), the course pipeline with Mertsalov's and the exact cycle method, the equation
of motion with a motor and its steady state (:mod:`~.pipeline`), the stroke of a slide input
(:mod:`~.stroke`).
"""

from .pipeline import (
                       DynamicsReport,
                       DynamicsSpec,
                       LawOfMotion,
                       Transient,
                       course_method,
                       dynamics_of,
                       exact_method,
                       run_dynamics,
                       simulate,
                       steady_state,
)
from .reduced import Reduced, reduced_characteristics
from .stroke import StrokeMotion, stroke_motion

__all__ = ["DynamicsReport", "DynamicsSpec", "LawOfMotion", "Reduced", "StrokeMotion", "Transient", "course_method",
           "dynamics_of", "exact_method", "reduced_characteristics", "run_dynamics", "simulate", "steady_state",
           "stroke_motion"]
