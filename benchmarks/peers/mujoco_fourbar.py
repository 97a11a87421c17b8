"""MuJoCo: the four-bar as a tree of z-axis hinges (crank -> coupler, rocker) in the x-y
plane with gravity along -y, the loop closed at B by an equality ``connect`` between a site
on the coupler and one on the rocker. MuJoCo's constraints are soft: ``solref`` (time
constant, damping ratio) and ``solimp`` set how fast a violation is pulled back, and the
time constant may not be below 2 steps (``refsafe``).

Swept: the defaults (Euler, dt = 2 ms, default solref/solimp: what a user gets first), RK4
with the default constraint, and RK4 with the loop stiffened to the fastest allowed
(solref = (2 dt, 1), solimp d = 0.9999).

Timed: ``mujoco.rollout.rollout`` of the whole run in C (the full physics state at every
step). Energy, loop gap and crank angle come afterwards from ``mj_forward`` on each stored
state (untimed).
"""

from __future__ import annotations

import numpy as np

from common import T_END, FourBar, Run, best_time, energy, grid_indices, loop_gap

TOOL = "MuJoCo"
PACKAGE = "mujoco"

STIFF_SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)

#: (integrator, dt in s, stiff loop constraint?)
SWEEP = (
    [("Euler", 0.002, False), ("RK4", 0.002, False), ("RK4", 0.0005, False)]
    + [("RK4", dt, True) for dt in (0.01, 0.005, 0.004, 0.0025, 0.002, 0.001, 0.0005)]
)


def version() -> str:
    import mujoco

    return mujoco.__version__


def _v(p) -> str:
    return f"{float(p[0])!r} {float(p[1])!r} 0"


def mjcf(fb: FourBar, integrator: str, dt: float, stiff: bool) -> str:
    """The MJCF text. Body frames sit at the hinges, world-aligned in the drawing; each
    body's inertia is isotropic (only Izz acts: every hinge turns about z)."""
    P, B = fb.points, fb.bodies

    def inertial(name: str, origin) -> str:
        b = B[name]
        I = float(b.inertia)
        return f'<inertial pos="{_v(b.com - origin)}" mass="{b.mass!r}" diaginertia="{I!r} {I!r} {I!r}"/>'

    eq = ""
    if stiff:
        eq = f' solref="{2 * dt!r} 1" solimp="{" ".join(repr(x) for x in STIFF_SOLIMP)}"'
    return f"""<mujoco model="four-bar under gravity">
  <option timestep="{dt!r}" integrator="{integrator}" gravity="{_v(fb.gravity)}"/>
  <worldbody>
    <body name="crank" pos="{_v(P['O'])}">
      <joint name="O" type="hinge" axis="0 0 1"/>
      {inertial('crank', P['O'])}
      <body name="coupler" pos="{_v(P['A'] - P['O'])}">
        <joint name="A" type="hinge" axis="0 0 1"/>
        {inertial('coupler', P['A'])}
        <site name="B_coupler" pos="{_v(P['B'] - P['A'])}"/>
      </body>
    </body>
    <body name="rocker" pos="{_v(P['D'])}">
      <joint name="D" type="hinge" axis="0 0 1"/>
      {inertial('rocker', P['D'])}
      <site name="B_rocker" pos="{_v(P['B'] - P['D'])}"/>
    </body>
  </worldbody>
  <equality>
    <connect site1="B_coupler" site2="B_rocker"{eq}/>
  </equality>
</mujoco>"""


def body_states(mujoco, model, data, states: np.ndarray, spec) -> tuple[dict, dict]:
    """Per-body (N, 3) CoM poses (phi from the drawing) and rates."""
    names = ("crank", "coupler", "rocker")
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


def run(fb: FourBar, setting: tuple, ref_grid: np.ndarray) -> Run:
    import mujoco
    from mujoco import rollout

    integrator, dt, stiff = setting
    method = f"{integrator}, " + ("stiffened loop" if stiff else "default loop constraint")
    r = Run(TOOL, method, f"dt={dt:g}")
    model = mujoco.MjModel.from_xml_string(mjcf(fb, integrator, dt, stiff))
    data = mujoco.MjData(model)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    s0 = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, s0, spec)
    n = int(round(T_END / dt))
    r.steps = n

    def simulate():
        state, _ = rollout.rollout(model, data, s0[None, :], nstep=n)
        return state[0]

    r.wall, states = best_time(simulate)
    states = np.vstack([s0, states])
    with np.errstate(all="ignore"):
        poses, rates = body_states(mujoco, model, data, states, spec)
        # qpos[0] is the crank hinge (relative to the drawing); state = [time, qpos, ...].
        theta = fb.theta1_0 + states[grid_indices(dt), 1]
        r = r.finish(energy(fb, poses, rates), loop_gap(fb, poses), theta, ref_grid)
    if r.ok:
        r.extra["energy_loss_pct"] = 100.0 * (energy(fb, poses, rates)[0] - energy(fb, poses, rates)[-1]) / r.e0
    return r
