"""Robot tools on top of a :class:`~planardyn.Mechanism`: task-space motions (inverse
kinematics and dynamics along a prescribed end-effector path), actuator sizing, singularity
maps and workspaces. See ``docs/robot.md``.

    from planardyn import robot

    ee = robot.EndEffector(mech, "P")            # a point (m = 2) or a pose (m = 3)
    motion = robot.solve_motion(ee, robot.circle((0.0, 0.4), 0.05, duration=1.0))
    motion.tau                                   # (N, m) drive efforts
    robot.plot_sizing(robot.size(motion))        # peak/RMS effort, speed, power per drive
"""

from __future__ import annotations

from .capability import CapabilityMap, capability_at, capability_map
from .cli import size_cli
from .effector import EffectorState, EndEffector
from .maps import TaskGrid, Workspace, flood, singularity_map, workspace
from .modes import Mode, assembly_modes, working_modes
from .motion import TaskMotion, solve_motion
from .paths import TaskPath, circle, from_functions, line, point_to_point, table, time_law
from .plots import plot_capability, plot_modes, plot_motion, plot_singularity_map, plot_sizing, plot_workspace
from .sampling import SamplingError, SizingError
from .sizing import DriveSizing, LimitCheck, MotorSizing, SizingReport, envelope, motor_sizing, size, with_payload
from .tolerances import SINGULAR_TOL

__all__ = [
    "SINGULAR_TOL",
    "SamplingError",
    "SizingError",
    "DriveSizing",
    "SizingReport",
    "TaskGrid",
    "Workspace",
    "envelope",
    "flood",
    "singularity_map",
    "size",
    "size_cli",
    "with_payload",
    "workspace",
    "EffectorState",
    "EndEffector",
    "TaskMotion",
    "TaskPath",
    "circle",
    "from_functions",
    "line",
    "point_to_point",
    "solve_motion",
    "table",
    "time_law",
    "CapabilityMap",
    "Mode",
    "assembly_modes",
    "capability_at",
    "capability_map",
    "plot_capability",
    "plot_modes",
    "plot_motion",
    "plot_singularity_map",
    "plot_sizing",
    "LimitCheck",
    "MotorSizing",
    "motor_sizing",
    "plot_workspace",
    "working_modes",
]
