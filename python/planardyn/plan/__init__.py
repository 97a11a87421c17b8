"""Motion planning: time-optimal timing of a path (:func:`time_optimal`)."""

from .topp import PlanError, TimedPath, task_waypoints, time_optimal

__all__ = ["PlanError", "TimedPath", "task_waypoints", "time_optimal"]
