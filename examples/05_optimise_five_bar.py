"""Link lengths of a five-bar robot for the lowest peak drive torque on a task.

Design: planardyn.library.five_bar(base, proximal, distal) (uniform bars of 1 kg/m, so
longer links are heavier) with a 0.5 kg payload at the end effector P. Task: P goes round
a circle of radius 5 cm about (0, 0.30) m in 0.4 s (quintic time law), starting from the
drawing's working mode. Problem, in epigraph form (the peak is a maximum over motors and
samples, not smooth; each sample is):

    minimise z  over (base, proximal, distal, z)
    subject to  -z <= tau_k(t_i) <= z             every motor k and sample t_i (N m)
                sigma_I(t_i), sigma_II(t_i) >= 0.15   every sample
                (inside the workspace, away from both kinds of singularity)
                0.08 m <= each length <= 0.40 m

Every constraint Jacobian is one batch of 4 p + 1 = 13 task-space inverse-dynamics
solutions on Rust threads (planardyn.sensitivity.objective); scipy's SLSQP does the rest. Prints both
designs, their peak torques and the improvement; saves out/optimise-five-bar.png (with
--docs, docs/img/optimise-five-bar.png as well).
"""

import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import numpy as np
import planardyn as pdy
from matplotlib.figure import Figure
from planardyn import batch, library, robot
from planardyn import sensitivity as sens
from planardyn.plot import draw_mechanism
from scipy.optimize import minimize

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "out"
OUT.mkdir(exist_ok=True)

NAMES = ["base", "proximal", "distal"]
START = np.array([0.20, 0.20, 0.25])  # m: the library's default five-bar
BOUNDS = [(0.08, 0.40)] * 3
PAYLOAD = 0.5  # kg at P
SIGMA_MIN = 0.15  # smallest allowed singularity measure along the path (dimensionless)
PATH = robot.circle((0.0, 0.30), 0.05, duration=0.4)
DT = 0.004  # s: 101 samples


def design(base, proximal, distal):
    return robot.with_payload(library.five_bar(base=base, proximal=proximal, distal=distal), "P", PAYLOAD)


def measures(motion):
    """Every sample's efforts tau (N m, motor after motor), then sigma_I and sigma_II."""
    return np.concatenate([motion.tau.T.ravel(), motion.sigma_I, motion.sigma_II])


cache = {}


def evaluate(lengths):
    """Measures and their derivatives at these lengths: one batch (cached for fun and jac).
    None where the design has no drawing, or the path meets a singularity or leaves its
    workspace."""
    key = tuple(lengths)
    if key not in cache:
        try:
            cache[key] = sens.objective(design, dict(zip(NAMES, lengths)), PATH, measures, dt=DT)
        except (pdy.SingularityError, pdy.AssemblyError, ValueError):  # ValueError: no drawing
            cache[key] = None
    return cache[key]


# SLSQP's first steps come from an identity Hessian: scale the variables so that unit
# steps are sensible, lengths in LENGTH_UNIT and z in units of the start's peak torque.
LENGTH_UNIT = 0.1  # m
N_TAU = 2 * (round(PATH.duration / DT) + 1)


def unscale(v):
    return v[:3] * LENGTH_UNIT, v[3] * history[0]


def constraints(v):
    lengths, z = unscale(v)
    s = evaluate(lengths)
    if s is None:  # a trial step too far: strongly violated, so SLSQP's line search steps back
        return np.full(2 * N_TAU + N_TAU, -1.0)
    tau = s.value[:N_TAU] / history[0]
    return np.concatenate([v[3] - tau, v[3] + tau, s.value[N_TAU:] - SIGMA_MIN])


def constraints_jac(v):
    s = evaluate(unscale(v)[0]) or evaluate(START)
    d = s.derivative.T * LENGTH_UNIT  # (measures, 3 scaled lengths)
    dtau, ones = d[:N_TAU] / history[0], np.ones((N_TAU, 1))
    return np.block([[-dtau, ones], [dtau, ones], [d[N_TAU:], np.zeros((N_TAU, 1))]])


def peak(lengths):
    s = evaluate(lengths)
    return float(np.abs(s.value[:N_TAU]).max()) if s is not None else float("nan")


start = time.perf_counter()
s0 = evaluate(START)
print("sensitivities of tau(t) and sigma(t) along the path at the start design (largest entry):")
print(s0)
history = [peak(START)]
v0 = np.append(START / LENGTH_UNIT, 1.0)
result = minimize(lambda v: v[3], v0, jac=lambda v: np.array([0.0, 0.0, 0.0, 1.0]), method="SLSQP",
                  bounds=[(lo / LENGTH_UNIT, hi / LENGTH_UNIT) for lo, hi in BOUNDS] + [(0.0, None)],
                  callback=lambda v: history.append(peak(unscale(v)[0])),
                  constraints=[{"type": "ineq", "fun": constraints, "jac": constraints_jac}],
                  options={"ftol": 1e-6, "maxiter": 50})
best = unscale(result.x)[0]
elapsed = time.perf_counter() - start
print(f"SLSQP: {result.message} after {result.nit} iterations, {len(cache)} gradient batches of "
      f"{4 * len(NAMES) + 1} designs, {elapsed:.1f} s")

# Check the optimum with the serial task-space solver (robot.solve_motion in Python).
motions = {}
for label, lengths in (("start", START), ("optimum", best)):
    mech = design(*lengths)
    motions[label] = robot.solve_motion(robot.EndEffector(mech, "P"), PATH, dt=DT)
    m = motions[label]
    print(f"{label:>8}: base {lengths[0]:.4f} m, proximal {lengths[1]:.4f} m, distal {lengths[2]:.4f} m; "
          f"peak torques {np.abs(m.tau).max(axis=0).round(3)} N m; min sigma_I {m.sigma_I.min():.3f}, "
          f"min sigma_II {m.sigma_II.min():.3f}")
p0, p1 = sens.peak_effort(motions["start"]), sens.peak_effort(motions["optimum"])
print(f"peak drive torque {p0:.3f} N m -> {p1:.3f} N m ({100 * (1 - p1 / p0):.1f} % lower)")
assert result.success, result.message
assert p1 < 0.9 * p0
assert min(motions["optimum"].sigma_I.min(), motions["optimum"].sigma_II.min()) >= SIGMA_MIN - 1e-6
assert all(lo - 1e-9 <= x <= hi + 1e-9 for x, (lo, hi) in zip(best, BOUNDS))
# The batch solution of the optimum equals robot.solve_motion's to round-off.
fast = batch.inverse_dynamics([design(*best)], PATH, dt=DT)[0]
assert np.abs(fast.tau - motions["optimum"].tau).max() < 1e-8 * p1

# ------------------------------------------------------------------ the figure
fig = Figure(figsize=(13, 4.2))
ax_draw, ax_tau, ax_hist = fig.subplots(1, 3)
for (label, m), color in zip(motions.items(), ("tab:gray", "tab:blue")):
    draw_mechanism(m.mech, m.mech.assemble(m.q[0]), ax=ax_draw, labels=False, color=color, alpha=0.8)
    for k, style in enumerate(("-", "--")):
        ax_tau.plot(m.t, m.tau[:, k], style, color=color, label=f"{label}, motor {k + 1}")
ax_draw.plot(*PATH.sample(np.linspace(0, PATH.duration, 200))[0].T, "k:", lw=1)
ax_draw.set_title("start (grey) and optimum (blue), path dotted")
ax_tau.set(xlabel="t (s)", ylabel="drive torque (N m)", title="torques along the circle")
ax_tau.legend(fontsize=7)
ax_hist.plot(history, "o-")
ax_hist.set(xlabel="SLSQP iteration", ylabel="peak torque (N m)", title="optimisation")
fig.tight_layout()
for folder in [OUT] + ([ROOT / "docs" / "img"] if "--docs" in sys.argv else []):
    fig.savefig(folder / "optimise-five-bar.png", dpi=90)
print("wrote optimise-five-bar.png")
