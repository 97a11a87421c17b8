"""Robot tools on top of a :class:`~planardyn.Mechanism`: task-space motions (inverse
kinematics and dynamics along a prescribed end-effector path), actuator sizing, singularity
maps and workspaces. See ``docs/robot.md``.

    from planardyn import robot

    ee = robot.EndEffector(mech, "P")            # a point (m = 2) or a pose (m = 3)
    motion = robot.solve_motion(ee, robot.circle((0.0, 0.4), 0.05, duration=1.0))
    motion.tau                                   # (N, m) drive efforts
    robot.size(motion).plot()                    # peak/RMS effort, speed, power per drive
"""

from __future__ import annotations

from .cli import size_cli
from .effector import EffectorState, EndEffector
from .maps import TaskGrid, Workspace, flood, singularity_map, workspace
from .motion import SINGULAR_TOL, TaskMotion, singularity_message, solve_motion
from .paths import TaskPath, circle, line, point_to_point, table, time_law
from .sizing import DriveSizing, SizingReport, envelope, size, with_payload

__all__ = [
    "SINGULAR_TOL",
    "DriveSizing",
    "SizingReport",
    "TaskGrid",
    "Workspace",
    "envelope",
    "flood",
    "singularity_map",
    "singularity_message",
    "size",
    "size_cli",
    "with_payload",
    "workspace",
    "EffectorState",
    "EndEffector",
    "TaskMotion",
    "TaskPath",
    "circle",
    "line",
    "point_to_point",
    "solve_motion",
    "table",
    "time_law",
]

from .capability import CapabilityMap, capability_at, capability_map, plot_capability
from .modes import Mode, assembly_modes, plot_modes, working_modes

__all__ += ["CapabilityMap", "Mode", "assembly_modes", "capability_at", "capability_map", "plot_capability",
            "plot_modes", "working_modes"]
