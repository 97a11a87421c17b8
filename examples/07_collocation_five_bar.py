"""Point-to-point motions of the 5R pick-and-place by collocation, against TOPP on fixed paths.

The 5R robot of the library moves its end effector P from (-0.08, 0.28) m to (0.08, 0.36) m,
from rest to rest, each motor within |tau| <= 3 N m and |qd| <= 12 rad/s. Three motions:

- TOPP (planardyn.plan.time_optimal) along the straight line of P, and along the straight
  line in joint space: the fastest timing of a path fixed in advance;
- minimum time by collocation (planardyn.plan.collocate): the path is free too;
- minimum effort (integral of tau^2) by collocation in 1.5 x that minimum time, against the
  straight line of P timed by TOPP and stretched to the same time.

Checks: IPOPT converged; the minimum-time efforts replayed open loop reach every node within
the accuracy the solution states; TOPP on the collocation's own path takes the same time
within 0.5 %. Prints the figures and saves out/07_collocation.png.
"""

import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import planardyn as pdy
from planardyn import robot
from planardyn.plan import collocate, task_waypoints, time_optimal

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "out"
PICK, PLACE = np.array([-0.08, 0.28]), np.array([0.08, 0.36])  # m
LIMITS = dict(effort=[3.0, 3.0], speed=[12.0, 12.0])  # N m, rad/s


def effort_integral(plan, T: float) -> float:
    """Integral of sum tau^2 (N^2 m^2 s) of a planned motion stretched to T s (inverse dynamics)."""
    t = np.linspace(0.0, T, 2001)
    r = plan.duration / T
    q, qd, qdd = plan.state(t * r)
    tau = plan.mech.inverse_dynamics(q, qd * r, qdd * r**2)
    return float(np.trapezoid((tau**2).sum(axis=1), t))


def main() -> None:
    start = time.perf_counter()
    mech = pdy.load(ROOT / "examples" / "models" / "library" / "five-bar-5r.yaml")
    ee = robot.EndEffector(mech, "P")
    qa = ee.inverse(PICK).q
    qb = ee.inverse(PLACE, qa).q
    line = time_optimal(mech, task_waypoints(ee, [PICK, PLACE], 0.01), n_grid=400, **LIMITS)
    joint = time_optimal(mech, [qa, qb], n_grid=400, **LIMITS)
    fast = collocate(mech, qa, qb, n_intervals=60, **LIMITS)
    assert fast.success, fast.status
    replay = fast.simulate()
    drift = np.abs(replay.q - fast.q).max(axis=0)
    assert np.all(drift <= fast.error), (drift, fast.error)
    again = time_optimal(mech, fast.q, n_grid=801, **LIMITS)
    gap = again.duration / fast.duration - 1
    assert abs(gap) < 5e-3, gap
    T = 1.5 * fast.duration
    calm = collocate(mech, qa, qb, objective="effort", duration=T, n_intervals=40, **LIMITS)
    assert calm.success, calm.status
    line_effort = effort_integral(line, T)
    assert calm.cost < line_effort

    print(f"{'motion':<36} {'time s':>8}")
    print(f"{'TOPP, straight line of P':<36} {line.duration:>8.4f}")
    print(f"{'TOPP, straight line in joint space':<36} {joint.duration:>8.4f}")
    print(f"{'collocation, minimum time (N = 60)':<36} {fast.duration:>8.4f}")
    print(f"{'TOPP on the collocation path':<36} {again.duration:>8.4f}  ({100 * gap:+.2f} %)")
    print(f"minimum time: IPOPT {fast.status}, {fast.iterations} iterations, max defect {fast.max_defect:.1e}; "
          f"replay drift {drift.max():.1e} rad within the stated {fast.error.max():.1e} rad")
    print(f"minimum effort in {T:.4f} s: {calm.cost:.4f} N^2 m^2 s (IPOPT {calm.status}, {calm.iterations} "
          f"iterations); the line of P stretched to {T:.4f} s: {line_effort:.4f}")

    OUT.mkdir(exist_ok=True)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.4))
    for plan, label in [(line, "TOPP, line of P"), (joint, "TOPP, joint line"), (fast, "min time"),
                        (calm, "min effort")]:
        q = plan.state(np.linspace(0.0, plan.duration, 200))[0]
        X = np.array([ee.state(qi).X for qi in q])
        ax1.plot(X[:, 0], X[:, 1], label=label)
    ax1.set_xlabel("x (m)")
    ax1.set_ylabel("y (m)")
    ax1.set_aspect("equal")
    ax1.legend(fontsize=7)
    ax1.set_title("paths of P")
    t = np.linspace(0.0, fast.duration, 400)
    tau = fast.efforts(t)
    ax2.plot(t, tau[:, 0], label="tau1, min time")
    ax2.plot(t, tau[:, 1], label="tau2, min time")
    ax2.set_xlabel("t (s)")
    ax2.set_ylabel("N m")
    ax2.legend(fontsize=7)
    ax2.set_title("bang-bang efforts")
    fig.tight_layout()
    fig.savefig(OUT / "07_collocation.png", dpi=120)
    print(f"saved {OUT / '07_collocation.png'} ({time.perf_counter() - start:.1f} s)")


if __name__ == "__main__":
    main()
