"""Motion planning: time-optimal timing of a path (:func:`time_optimal`), point-to-point
trajectory optimisation by collocation (:func:`collocate`)."""

from .collocation import CollocatedMotion, collocate
from .collocation_problem import Workspace
from .planned import InfeasiblePlan, PlanError, PlannedMotion
from .topp import TimedPath, task_waypoints, time_optimal

__all__ = ["CollocatedMotion", "InfeasiblePlan", "PlanError", "PlannedMotion", "TimedPath", "Workspace", "collocate",
           "task_waypoints", "time_optimal"]
