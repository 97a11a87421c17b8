"""MuJoCo: a mechanism as a tree of z-axis hinges in the x-y plane (``Drawing.tree``), each
loop closed by an equality ``connect`` between a site on each of the closing pair's bodies,
springs as spatial tendons with a stiffness and a rest length, constant drive torques as
motors with a constant control. MuJoCo's constraints are soft: ``solref`` (time constant,
damping ratio) and ``solimp`` set how fast a violation is pulled back, and the time
constant may not be below 2 steps (``refsafe``).

Variants, each searched on its number of steps: Euler and RK4 with the default soft constraint
(what a user gets first; they never close the loops to the stated gap, and are kept for the
record), and Euler, implicitfast, implicit and RK4 with the loops stiffened to the fastest
allowed (solref = (2 dt, 1), solimp d = 0.9999).

Timed: ``mujoco.rollout.rollout`` of the whole run in C (the full physics state at every
step). Energy, loop gap and coordinates come afterwards from ``mj_forward`` on each stored
state (untimed).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from common import Drawing, Reference, Run, Variant, coordinates, energy, loop_gap, one_shot
from mechanisms import Benchmark

TOOL = "MuJoCo"
PACKAGE = "mujoco"

STIFF_SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)
#: (integrator, stiffened loops?)
METHODS = [("Euler", False), ("RK4", False), ("Euler", True), ("implicitfast", True), ("implicit", True),
           ("RK4", True)]
#: (cheapest, dearest) number of steps over the run.
STEPS = {"four-bar": (20, 40000), "five-bar": (10, 40000), "3-rrr": (4, 4000), "andrews": (30, 20000)}


def variants(bm: Benchmark) -> list[Variant]:
    return [Variant(TOOL, f"{i}, " + ("stiffened loops" if stiff else "default loop constraints"), (i, stiff),
                    STEPS[bm.key]) for i, stiff in METHODS]


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
    """Per-body (N, 3) CoM poses (phi from the drawing) and rates, from MuJoCo's own kinematics of
    each stored state (the position and velocity stages of ``mj_forward``, not its dynamics)."""
    ids = [model.body(k).id for k in names]
    P, R = np.empty((len(states), len(ids), 3)), np.empty((len(states), len(ids), 3))
    vel = np.empty(6)
    for i, s in enumerate(states):
        mujoco.mj_setState(model, data, s, spec)
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        mujoco.mj_comVel(model, data)
        xmat = data.ximat[ids]
        P[i, :, 0], P[i, :, 1] = data.xipos[ids, 0], data.xipos[ids, 1]
        P[i, :, 2] = np.arctan2(xmat[:, 3], xmat[:, 0])
        for j, b in enumerate(ids):
            # 6D velocity [rot, lin] at the CoM (mjOBJ_BODY: the inertial frame), world axes.
            mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, b, vel, 0)
            R[i, j] = vel[3], vel[4], vel[2]
    P[:, :, 2] = np.unwrap(P[:, :, 2], axis=0)
    return {k: P[:, j] for j, k in enumerate(names)}, {k: R[:, j] for j, k in enumerate(names)}


class Sim:
    """The model at one setting, its start state and the rollout."""

    def __init__(self, bm: Benchmark, d: Drawing, v: Variant, n: int):
        import mujoco
        from mujoco import rollout

        integrator, stiff = v.params
        self.mujoco, self.rollout, self.n = mujoco, rollout, n
        self.model = mujoco.MjModel.from_xml_string(mjcf(d, integrator, bm.t_end / n, stiff))
        self.data = mujoco.MjData(self.model)
        self.spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
        self.s0 = np.empty(mujoco.mj_stateSize(self.model, self.spec))
        mujoco.mj_getState(self.model, self.data, self.s0, self.spec)
        efforts = np.array([c.effort for c in d.coordinates if c.effort])
        self.control = np.broadcast_to(efforts, (1, n, len(efforts))).copy() if len(efforts) else None

    def simulate(self) -> np.ndarray:
        """(n, state size): the state after every step."""
        state, _ = self.rollout.rollout(self.model, self.data, self.s0[None, :], self.control, nstep=self.n)
        return state[0]


#: MuJoCo's warnings during the run being measured (``mju_user_warning``, instead of its console).
_warnings: list[str] = []


def run(bm: Benchmark, d: Drawing, v: Variant, n: int, ref: Reference) -> Run:
    r = Run(TOOL, v.method, v.label(bm.t_end, n), value=n, steps=n)
    sim = Sim(bm, d, v, n)
    sim.mujoco.set_mju_user_warning(_warnings.append)
    _warnings.clear()
    r.wall, states = one_shot(sim.simulate)
    if _warnings:
        # An unstable run is reset to the start state and goes on: finite, but not a solution.
        return r.fail(f"MuJoCo: {_warnings[0]}")
    states = np.vstack([sim.s0, states])
    with np.errstate(all="ignore"):
        poses, rates = body_states(sim.mujoco, sim.model, sim.data, states, sim.spec, d.bodies)
        return r.finish(energy(d, poses, rates), loop_gap(d, poses), coordinates(d, poses)[bm.sample_indices(n)],
                        ref.steps(n))


def timed(bm: Benchmark, d: Drawing, v: Variant, n: int) -> Callable[[], object]:
    return Sim(bm, d, v, n).simulate
