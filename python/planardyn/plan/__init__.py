"""Motion planning: time-optimal timing of a path (:func:`time_optimal`)."""

from .topp import PlanError, TimedPath, time_optimal

__all__ = ["PlanError", "TimedPath", "time_optimal"]
