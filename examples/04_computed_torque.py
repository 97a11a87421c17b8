"""Computed-torque control of the five-bar robot (examples/models/five-bar.yaml) tracking a
circle of its end effector P, with a controller whose model has every mass and inertia 10 %
too large.

The desired inputs q_d(t) come from the task-space motion (planardyn.robot: inverse
kinematics on the circle, rates and accelerations from the analogues). The control law is

    tau = inverse_dynamics_model(q, qd, qdd_d + Kp e + Kd ed),   e = q_d - q

i.e. A_model(q) (qdd_d + Kp e + Kd ed) minus the model's generalized forces (gravity, the
servo springs, the convective term): the exact linearisation when the model is right. The
plant (the true model) is integrated with the controller as a callable drive, from an input
error of 0.02 rad. Prints the end-effector tracking error after the transient and saves
out/04_computed_torque.png.
"""

import copy
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import planardyn as pdy
from planardyn import robot
from scipy.interpolate import CubicHermiteSpline

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "out"

MASS_ERROR = 1.10  # the controller's model: every mass and inertia 10 % too large
KP, KD = 1.0e4, 200.0  # 1/s^2, 1/s: critically damped error dynamics, omega_n = 100 rad/s
Q0_ERROR = 0.02  # rad, initial error of each input
T_END = 2.0  # s: two turns of the circle
TRANSIENT = 0.2  # s: the error is judged after this (20 / omega_n)


def scale_masses(model: dict, factor: float) -> dict:
    """A copy of a model dict with every mass and moment of inertia times factor."""
    model = copy.deepcopy(model)
    for body in model["bodies"].values():
        for part in [body, *body.get("parts", [])]:
            for key in ("mass", "inertia", "inertia_about_com"):
                if key in part:
                    part[key] *= factor
    return model


plant = pdy.load(ROOT / "examples" / "models" / "five-bar.yaml")
model = pdy.from_dict(scale_masses(plant.to_dict(), MASS_ERROR))
ee = robot.EndEffector(plant, "P")
home = ee.home()
circle = robot.circle(home + [0.0, 0.05], 0.05, duration=T_END, turns=2.0)
desired = robot.solve_motion(ee, circle, dt=2e-3)
print(desired)

q_d = CubicHermiteSpline(desired.t, desired.q, desired.qd)  # q_d(t), with qd_d exact at the samples
qd_d = CubicHermiteSpline(desired.t, desired.qd, desired.qdd)
qdd_d = qd_d.derivative()


def computed_torque(t, q, qd):
    e, ed = q_d(t) - q, qd_d(t) - qd
    return model.inverse_dynamics(q, qd, qdd_d(t) + KP * e + KD * ed)


start = time.perf_counter()
res = plant.simulate(T_END, method="dopri5", rtol=1e-8, atol=1e-10, t_eval=desired.t,
                     q0=desired.q[0] + Q0_ERROR, qd0=desired.qd[0], drives=computed_torque)
print(res)
assert res.success, res.message
P = desired.task_of(res.q)
err = np.linalg.norm(P - desired.X, axis=1)
after = res.t >= TRANSIENT
print(f"simulated {T_END} s in {time.perf_counter() - start:.2f} s; initial end-effector error {err[0] * 1e3:.2f} mm")
print(f"tracking error after {TRANSIENT} s: max {err[after].max() * 1e6:.1f} um, RMS "
      f"{np.sqrt(np.mean(err[after] ** 2)) * 1e6:.1f} um (model masses x {MASS_ERROR})")
assert err[after].max() < 1e-3

fig, ax = plt.subplots(1, 2, figsize=(11, 4.5))
ax[0].semilogy(res.t, err * 1e3)
ax[0].axvline(TRANSIENT, color="0.5", linestyle=":")
ax[0].set(xlabel="t (s)", ylabel="|P - P_d| (mm)", title=f"tracking error, model masses x {MASS_ERROR}")
ax[0].grid(True, which="both", alpha=0.3)
ax[1].plot(desired.X[:, 0], desired.X[:, 1], "k-", label="desired")
ax[1].plot(P[:, 0], P[:, 1], "r--", label="tracked")
ax[1].set(xlabel="x (m)", ylabel="y (m)", title="end-effector path")
ax[1].set_aspect("equal")
ax[1].legend()
fig.tight_layout()
OUT.mkdir(exist_ok=True)
fig.savefig(OUT / "04_computed_torque.png", dpi=100)
print(f"wrote {OUT / '04_computed_torque.png'}")
