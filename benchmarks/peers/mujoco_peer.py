"""MuJoCo: a mechanism as a tree of z-axis hinges in the x-y plane (``Drawing.tree``), each
loop closed by an equality ``connect`` between a site on each of the closing pair's bodies,
springs as spatial tendons with a stiffness and a rest length, constant drive torques as
motors with a constant control. MuJoCo's constraints are soft: ``solref`` (time constant,
damping ratio) and ``solimp`` set how fast a violation is pulled back, and the time
constant may not be below 2 steps (``refsafe``).

Swept: the defaults (Euler, the default soft constraint: what a user gets first), RK4 with
the default constraint, and RK4 with the loops stiffened to the fastest allowed
(solref = (2 dt, 1), solimp d = 0.9999), over the step.

Timed: ``mujoco.rollout.rollout`` of the whole run in C (the full physics state at every
step). Energy, loop gap and coordinates come afterwards from ``mj_forward`` on each stored
state (untimed).
"""

from __future__ import annotations

import numpy as np
from common import Drawing, Run, best_time, coordinates, energy, loop_gap
from mechanisms import Benchmark

TOOL = "MuJoCo"
PACKAGE = "mujoco"

STIFF_SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)


def _sweep(default_dt: float, soft_rk4: tuple, stiff: tuple) -> list[tuple]:
    """(integrator, dt in s, stiff loop constraint?)"""
    return ([("Euler", default_dt, False)] + [("RK4", dt, False) for dt in soft_rk4]
            + [("RK4", dt, True) for dt in stiff])


SWEEPS = {
    "four-bar": _sweep(0.002, (0.002, 0.0005), (0.01, 0.005, 0.004, 0.0025, 0.002, 0.001, 0.0005)),
    "five-bar": _sweep(0.002, (0.002, 0.0005), (0.001, 0.0005, 0.0002, 0.0001, 0.00005)),
    "3-rrr": _sweep(0.002, (0.002, 0.0005), (0.02, 0.01, 0.005, 0.002, 0.001)),
    "andrews": _sweep(1e-5, (1e-5,), (1e-4, 5e-5, 3e-5, 2e-5, 1e-5, 5e-6)),
}


def version() -> str:
    import mujoco

    return mujoco.__version__


def _v(p) -> str:
    return f"{float(p[0])!r} {float(p[1])!r} 0"


def mjcf(d: Drawing, integrator: str, dt: float, stiff: bool) -> str:
    """The MJCF text. Body frames sit at their tree joint, world-aligned in the drawing;
    each body's inertia is isotropic (only Izz acts: every hinge turns about z)."""
    tree, closing = d.tree()
    origin = {"ground": np.zeros(2)} | {p.b: d.points[p.point] for p in tree}
    sites: dict[str, list[str]] = {}  # body -> site elements

    def site(body: str, point: str) -> str:
        name = f"{point}_{body}"
        element = f'<site name="{name}" pos="{_v(d.points[point] - origin[body])}"/>'
        if element not in sites.setdefault(body, []):  # one site for all the pairs at a point
            sites[body].append(element)
        return name

    eq_opts = f' solref="{2 * dt!r} 1" solimp="{" ".join(repr(x) for x in STIFF_SOLIMP)}"' if stiff else ""
    equalities = [f'<connect site1="{site(p.a, p.point)}" site2="{site(p.b, p.point)}"{eq_opts}/>' for p in closing]
    tendons = [f'<spatial stiffness="{s.stiffness!r}" springlength="{s.rest_length!r}">'
               f'<site site="{site(s.a, s.point_a)}"/><site site="{site(s.b, s.point_b)}"/></spatial>'
               for s in d.springs]
    motors = [f'<motor joint="{c.pair.name}" gear="1"/>' for c in d.coordinates if c.effort]

    def body(p) -> str:
        b = d.bodies[p.b]
        inner = "\n".join(body(c) for c in tree if c.a == p.b)
        return (f'<body name="{p.b}" pos="{_v(origin[p.b] - origin[p.a])}">'
                f'<joint name="{p.name}" type="hinge" axis="0 0 1"/>'
                f'<inertial pos="{_v(b.com - origin[p.b])}" mass="{b.mass!r}" '
                f'diaginertia="{b.inertia!r} {b.inertia!r} {b.inertia!r}"/>'
                + "".join(sites.get(p.b, [])) + inner + "</body>")

    world = "\n".join(body(p) for p in tree if p.a == "ground")
    return f"""<mujoco model="{d.name}">
  <option timestep="{dt!r}" integrator="{integrator}" gravity="{_v(d.gravity)}"/>
  <worldbody>{"".join(sites.get("ground", []))}
{world}
  </worldbody>
  <equality>{"".join(equalities)}</equality>
  <tendon>{"".join(tendons)}</tendon>
  <actuator>{"".join(motors)}</actuator>
</mujoco>"""


def body_states(mujoco, model, data, states: np.ndarray, spec, names) -> tuple[dict, dict]:
    """Per-body (N, 3) CoM poses (phi from the drawing) and rates."""
    ids = {k: model.body(k).id for k in names}
    poses = {k: np.empty((len(states), 3)) for k in names}
    rates = {k: np.empty((len(states), 3)) for k in names}
    vel = np.empty(6)
    for i, s in enumerate(states):
        mujoco.mj_setState(model, data, s, spec)
        mujoco.mj_forward(model, data)
        for k, b in ids.items():
            R = data.ximat[b].reshape(3, 3)
            poses[k][i] = data.xipos[b][0], data.xipos[b][1], np.arctan2(R[1, 0], R[0, 0])
            # 6D velocity [rot, lin] at the CoM (mjOBJ_BODY: the inertial frame), world axes.
            mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, b, vel, 0)
            rates[k][i] = vel[3], vel[4], vel[2]
    for p in poses.values():
        p[:, 2] = np.unwrap(p[:, 2])
    return poses, rates


def run(bm: Benchmark, d: Drawing, setting: tuple, ref_grid: np.ndarray) -> Run:
    import mujoco
    from mujoco import rollout

    integrator, dt, stiff = setting
    r = Run(TOOL, f"{integrator}, " + ("stiffened loops" if stiff else "default loop constraints"), f"dt={dt:g}")
    model = mujoco.MjModel.from_xml_string(mjcf(d, integrator, dt, stiff))
    data = mujoco.MjData(model)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    s0 = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, s0, spec)
    n = r.steps = bm.steps(dt)
    efforts = np.array([c.effort for c in d.coordinates if c.effort])
    control = np.broadcast_to(efforts, (1, n, len(efforts))).copy() if len(efforts) else None

    def simulate():
        state, _ = rollout.rollout(model, data, s0[None, :], control, nstep=n)
        return state[0]

    r.wall, states = best_time(simulate)
    states = np.vstack([s0, states])
    with np.errstate(all="ignore"):
        poses, rates = body_states(mujoco, model, data, states, spec, d.bodies)
        return r.finish(energy(d, poses, rates), loop_gap(d, poses), coordinates(d, poses)[bm.grid_indices(dt)],
                        ref_grid)
