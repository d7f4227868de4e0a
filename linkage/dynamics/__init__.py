"""Machine dynamics of a one-degree-of-freedom mechanism, from its kinetostatics.

Reads the motion and the loads (:mod:`linkage.kinematics`, :mod:`linkage.kinetostatics`).
The ``[dynamics]`` section of a scheme and its checks (:mod:`~.spec`), reduced moments and moment
of inertia (:mod:`~.reduced`), motors reduced to the input (:mod:`~.motors`), the law of motion
over a cycle by Mertsalov's course method and the exact energy method (:mod:`~.cycle`), the
equation of motion with a motor and its steady state (:mod:`~.equation`), the whole course
pipeline with the coefficient of dynamics (:mod:`~.pipeline`), the stroke of a slide input
(:mod:`~.stroke`).
"""

from .cycle import LawOfMotion, course_method, exact_method
from .equation import Transient, simulate, steady_state
from .pipeline import DynamicsReport, run_dynamics
from .reduced import Reduced, reduced_characteristics
from .spec import DynamicsSpec, dynamics_of
from .stroke import StrokeMotion, stroke_motion

__all__ = ["DynamicsReport", "DynamicsSpec", "LawOfMotion", "Reduced", "StrokeMotion", "Transient", "course_method",
           "dynamics_of", "exact_method", "reduced_characteristics", "run_dynamics", "simulate", "steady_state",
           "stroke_motion"]
