"""Cycle time of the 5R pick-and-place against payload, by time-optimal path timing.

The 5R robot of the library (planardyn.library.five_bar_model: 0.2 m base, 0.2 m proximal and
0.25 m distal uniform bars) moves its end effector P along a straight line from
(-0.08, 0.28) m to (0.08, 0.36) m and back, starting and stopping at rest, each motor within
|tau| <= 3 N m and |qd| <= 12 rad/s. The payload is a point mass at P, carried by the distal
bar of the left leg. planardyn.plan.time_optimal times the path (toppra, fed planardyn's
exact closed-chain efforts a(s) s'' + b(s) s'^2 + c(s)); the cycle is out and back. The
efforts it plans are replayed through forward dynamics as a check (open loop, within 1e-6 m
of the path). Prints the table and saves out/06_cycle_time.png.
"""

import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import planardyn as pdy
from planardyn import library, robot
from planardyn.plan import task_waypoints, time_optimal

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "out"
PICK, PLACE = np.array([-0.08, 0.28]), np.array([0.08, 0.36])  # m
TAU_MAX, SPEED_MAX = np.array([3.0, 3.0]), np.array([12.0, 12.0])  # N m, rad/s
PAYLOADS = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5]  # kg


def with_payload(mass: float) -> pdy.Mechanism:
    """The 5R with a point mass at P on distal1: mass, centre of mass and inertia combined
    (parallel axes)."""
    model = library.five_bar_model()
    b, p = np.array(model["points"]["B1"]), np.array(model["points"]["P"])
    bar = model["bodies"]["distal1"]["mass"]
    length = np.linalg.norm(p - b)
    total = bar + mass
    com = (bar * (b + p) / 2 + mass * p) / total
    inertia = bar * length**2 / 12 + bar * np.sum(((b + p) / 2 - com) ** 2) + mass * np.sum((p - com) ** 2)
    model["bodies"]["distal1"] = {"points": ["B1", "P"], "mass": total, "inertia": float(inertia), "com": com.tolist()}
    return pdy.from_dict(model)


def main() -> None:
    start = time.perf_counter()
    rows = []
    for payload in PAYLOADS:
        mech = with_payload(payload)
        ee = robot.EndEffector(mech, "P")
        out = time_optimal(mech, task_waypoints(ee, [PICK, PLACE], 0.01), TAU_MAX, SPEED_MAX)
        back = time_optimal(mech, task_waypoints(ee, [PLACE, PICK], 0.01), TAU_MAX, SPEED_MAX)
        task = np.array([ee.state(q).X for q in out.q])
        d = PLACE - PICK
        rel = task - PICK
        off_line = np.abs(d[0] * rel[:, 1] - d[1] * rel[:, 0]).max() / np.linalg.norm(d)
        rows.append((payload, out.duration, back.duration, off_line))
        if payload == PAYLOADS[-1]:
            res = out.simulate()
            drift = max(np.linalg.norm(mech.point_positions(x) - mech.point_positions(xp), axis=-1).max()
                        for x, xp in zip(res.x, out.x))
            print(f"replayed efforts, {payload} kg, out: largest point drift {drift:.2e} m")
            assert drift < 1e-6
    print(f"{'payload kg':>10} {'out s':>8} {'back s':>8} {'cycle s':>8} {'off line m':>11}")
    for payload, t_out, t_back, off in rows:
        print(f"{payload:>10.2f} {t_out:>8.4f} {t_back:>8.4f} {t_out + t_back:>8.4f} {off:>11.1e}")
    cycle = np.array([r[1] + r[2] for r in rows])
    assert np.all(np.diff(cycle) > 0), "a heavier payload takes longer"
    OUT.mkdir(exist_ok=True)
    fig, ax = plt.subplots(figsize=(5, 3.2))
    ax.plot(PAYLOADS, cycle, "o-")
    ax.set_xlabel("payload at P (kg)")
    ax.set_ylabel("cycle time (s)")
    ax.set_title("5R pick-and-place, |tau| <= 3 N m")
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(OUT / "06_cycle_time.png", dpi=120)
    print(f"saved {OUT / '06_cycle_time.png'} ({time.perf_counter() - start:.1f} s)")


if __name__ == "__main__":
    main()
