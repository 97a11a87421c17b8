"""Task-space motions of the two parallel robots of the library (planardyn.robot).

For the five-bar (examples/models/five-bar.yaml, end effector: point P) and the 3-RRR
(examples/models/3-rrr.yaml, end effector: the platform pose, P its centre):

1. a circle of the end effector -> inverse kinematics -> drive torques (inverse dynamics);
   checked by feeding the torques (a cubic spline in t) to the forward dynamics and
   recovering the circle;
2. the actuator sizing report;
3. the singularity maps (type I and type II) and the workspace with its dexterity;
4. a straight line through a type II singularity, refused.

Pictures go to out/ (with --docs, to docs/img/robot-*.png as well).
"""

import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import numpy as np
import planardyn as pdy
from matplotlib.figure import Figure
from planardyn import robot

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "out"
DOCS = ROOT / "docs" / "img"
OUT.mkdir(exist_ok=True)


def save(fig, name):
    for folder in [OUT] + ([DOCS] if "--docs" in sys.argv else []):
        fig.savefig(folder / f"robot-{name}.png", dpi=90)
    print(f"  wrote robot-{name}.png")


def circle_check(ee, path, label):
    start = time.perf_counter()
    motion = robot.solve_motion(ee, path)
    res = motion.simulate()
    err = np.abs(motion.task_of(res.q)[:, :2] - motion.X[:, :2]).max()
    print(f"{label}: {motion}\n  solved and re-simulated in {time.perf_counter() - start:.2f} s; "
          f"open-loop forward dynamics recovers the circle to {err:.2e} m")
    assert err < 1e-6
    return motion


# ------------------------------------------------------------------ the five-bar
five = pdy.load(ROOT / "examples" / "models" / "five-bar.yaml")
ee5 = robot.EndEffector(five, "P")
home = ee5.home()
motion5 = circle_check(ee5, robot.circle(home + [0.0, 0.06], 0.06, duration=1.0), "five-bar")
fig = Figure(figsize=(11, 7))
robot.plot_motion(motion5, fig)
save(fig, "five-bar-circle")

report = robot.size(ee5, robot.circle(home + [0.0, 0.06], 0.06, duration=1.0), payload=0.5)
print(report)
fig = Figure(figsize=(11, 7))
robot.plot_sizing(report, fig)
save(fig, "five-bar-sizing")

grid = robot.singularity_map(ee5, (-0.45, 0.45), (-0.1, 0.65), n=70)
print(f"singularity map: {grid.reachable.sum()} of {grid.reachable.size} cells reachable on the drawn working mode")
fig = Figure(figsize=(12, 5))
robot.plot_singularity_map(grid, fig)
save(fig, "five-bar-singularities")

limits = np.radians([[60.0, 200.0], [-20.0, 120.0]])  # motor ranges, rad
ws = robot.workspace(ee5, limits)
print(f"workspace for theta1 in [60, 200] deg, theta2 in [-20, 120] deg: {ws.area * 1e4:.1f} cm^2 ({ws.method})")
fig = Figure(figsize=(7, 6))
robot.plot_workspace(ws, fig.subplots())
save(fig, "five-bar-workspace")

try:
    robot.solve_motion(ee5, robot.point_to_point(home, (home[0], 0.1), duration=1.0))
except pdy.SingularityError as exc:
    print(f"refused: {exc}")
    assert exc.kind == "II" and len(exc.partial.t) > 0

# ------------------------------------------------------------------ the 3-RRR
rrr = pdy.load(ROOT / "examples" / "models" / "3-rrr.yaml")
ee3 = robot.EndEffector(rrr, "P")  # the platform pose [x, y, psi]
motion3 = circle_check(ee3, robot.circle((0.0, 0.05), 0.05, duration=1.0, angle=(0.0, 0.2)), "3-RRR")
fig = Figure(figsize=(11, 7))
robot.plot_motion(motion3, fig)
save(fig, "3rrr-circle")
print(robot.size(motion3))
grid3 = robot.singularity_map(ee3, (-0.3, 0.3), (-0.3, 0.3), n=60)
fig = Figure(figsize=(12, 5))
robot.plot_singularity_map(grid3, fig)
save(fig, "3rrr-singularities")
ws3 = robot.workspace(ee3, cells=60)
print(f"3-RRR constant-orientation workspace (psi = 0): {ws3.area * 1e4:.1f} cm^2")
fig = Figure(figsize=(7, 6))
robot.plot_workspace(ws3, fig.subplots())
save(fig, "3rrr-workspace")
