"""Pinocchio (PyPI ``pin``): a mechanism as a kinematic tree of RZ joints
(``Drawing.tree``) with each loop closed by a ``RigidConstraintModel`` (CONTACT_3D between
the closing pair's two bodies), forward dynamics by ``pin.constraintDynamics`` (index-1 KKT
with the proximal solver, which copes with each constraint's redundant z row), Baumgarte
stabilisation with Kp = w^2, Kd = 2 w (critical), and classic RK4 written in Python over q, v.
Drive torques enter as joint torques; a spring's force enters as J^T f through the frame
Jacobians of its two ends (the way a Pinocchio user adds a force element).

Variants: the Baumgarte gain w on a half-decade grid (w = 0: no stabilisation), each searched
on its number of steps.

Timed: the RK4 loop, storing q and v at every step. Energy, loop gap and coordinates are
computed afterwards from the stored states (untimed). A second timed call (``clocked``) clocks
each ``constraintDynamics`` call inside the loop: the sum is the part of Pinocchio's cost that
is its C++ dynamics (the rest is the Python loop, the RK4 arithmetic on numpy arrays and the
springs' Jacobians).
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
from common import Drawing, Reference, Run, Variant, coordinates, energy, loop_gap, one_shot
from mechanisms import Benchmark

TOOL = "Pinocchio"
PACKAGE = "pin"

#: Baumgarte gains w (1/s) per mechanism: Kp = w^2, Kd = 2 w.
GAINS = {"four-bar": (0.0, 1.0, 3.0, 10.0, 30.0, 100.0), "five-bar": (0.0, 3.0, 10.0, 30.0, 100.0, 300.0),
         "3-rrr": (0.0, 3.0, 10.0, 30.0, 100.0, 300.0),
         "andrews": (0.0, 100.0, 300.0, 1e3, 3e3, 1e4, 3e4)}
#: (cheapest, dearest) number of RK4 steps over the run.
STEPS = {"four-bar": (20, 20000), "five-bar": (10, 10000), "3-rrr": (4, 2000), "andrews": (30, 6000)}


def variants(bm: Benchmark) -> list[Variant]:
    return [Variant(TOOL, "RK4 + constraintDynamics" + (f", Baumgarte w={w:g}" if w else ""), (w,), STEPS[bm.key])
            for w in GAINS[bm.key]]


#: Proximal solver settings: absolute and relative accuracy, mu, iterations.
PROX = (1e-12, 1e-12, 1e-8, 20)


def version() -> str:
    import pinocchio

    return pinocchio.__version__


def v3(p) -> np.ndarray:
    return np.array([p[0], p[1], 0.0])


class Model:
    """The tree, its data, the loop constraints and the force elements. Joint frames are
    world-aligned in the drawing, so q = 0 there and each q is a relative angle (RZ joints,
    not wrapped)."""

    def __init__(self, d: Drawing, w: float):
        import pinocchio as pin

        self.pin, self.d = pin, d
        tree, closing = d.tree()
        model = pin.Model()
        model.gravity = pin.Motion(np.array([d.gravity[0], d.gravity[1], 0.0, 0.0, 0.0, 0.0]))
        self.origin = {"ground": np.zeros(2)} | {p.b: d.points[p.point] for p in tree}
        self.jid = {"ground": 0}
        for p in tree:
            pos = v3(self.origin[p.b] - self.origin[p.a])
            j = model.addJoint(self.jid[p.a], pin.JointModelRZ(), pin.SE3(np.eye(3), pos), p.name)
            b = d.bodies[p.b]
            inertia = pin.Inertia(b.mass, v3(b.com - self.origin[p.b]), np.diag([b.inertia] * 3))
            model.appendBodyToJoint(j, inertia, pin.SE3.Identity())
            self.jid[p.b] = j
        self.springs = [(s, self._frame(model, s.a, s.point_a), self._frame(model, s.b, s.point_b)) for s in d.springs]
        self.model, self.data = model, model.createData()
        self.cmodels = pin.StdVec_RigidConstraintModel()
        self.cdatas = pin.StdVec_RigidConstraintData()
        for p in closing:
            cm = pin.RigidConstraintModel(
                pin.ContactType.CONTACT_3D, model,
                self.jid[p.a], self._at(p.a, p.point), self.jid[p.b], self._at(p.b, p.point),
                pin.ReferenceFrame.LOCAL,
            )
            # The list holds a copy: set the corrector before appending.
            cm.setBaumgarteCorrectorParameters(pin.BaumgarteCorrectorParameters(w * w, 2.0 * w))
            self.cmodels.append(cm)
            self.cdatas.append(cm.createData())
        pin.initConstraintDynamics(model, self.data, self.cmodels, self.cdatas)
        self.prox = pin.ProximalSettings(*PROX)
        self.tau = np.zeros(model.nv)
        for c in d.coordinates:
            self.tau[model.joints[self.jid[c.pair.b]].idx_v] = c.effort

    def _at(self, body: str, point: str):
        return self.pin.SE3(np.eye(3), v3(self.d.points[point] - self.origin[body]))

    def _frame(self, model, body: str, point: str) -> int:
        pin = self.pin
        return model.addFrame(pin.Frame(f"{point}@{body}", self.jid[body], 0, self._at(body, point), pin.FrameType.OP_FRAME))

    def spring_tau(self, q: np.ndarray) -> np.ndarray:
        """Joint torques of the springs at q: J_a^T f - J_b^T f, f the force on a's end."""
        pin, model, data = self.pin, self.model, self.data
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        tau = self.tau.copy()
        for s, fa, fb in self.springs:
            delta = data.oMf[fa].translation - data.oMf[fb].translation
            length = np.linalg.norm(delta)
            f = -s.stiffness * (length - s.rest_length) * delta / length
            for fid, sign in ((fa, 1.0), (fb, -1.0)):
                J = pin.getFrameJacobian(model, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
                tau += sign * (J[:3].T @ f)
        return tau

    def simulate(self, dt: float, n: int, clock: list[float] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Classic RK4 over (q, v), n steps of dt; (n+1, nq) q and v. With ``clock``, the
        time spent inside ``constraintDynamics`` (s) is added to ``clock[0]``."""
        pin, model, data = self.pin, self.model, self.data
        cm, cd, prox = self.cmodels, self.cdatas, self.prox
        torques = self.spring_tau if self.springs else (lambda q: self.tau)

        def f(q, v):
            return pin.constraintDynamics(model, data, q, v, torques(q), cm, cd, prox)

        if clock is not None:
            def f(q, v):  # noqa: F811 - the same, with the call clocked
                tau = torques(q)
                t0 = time.perf_counter()
                a = pin.constraintDynamics(model, data, q, v, tau, cm, cd, prox)
                clock[0] += time.perf_counter() - t0
                return a

        q = np.zeros(model.nq)
        v = np.zeros(model.nv)
        Q = np.empty((n + 1, model.nq))
        V = np.empty((n + 1, model.nv))
        Q[0], V[0] = q, v
        h2, h6 = 0.5 * dt, dt / 6.0
        for i in range(n):
            a1 = f(q, v)
            v2 = v + h2 * a1
            a2 = f(q + h2 * v, v2)
            v3_ = v + h2 * a2
            a3 = f(q + h2 * v2, v3_)
            v4 = v + dt * a3
            a4 = f(q + dt * v3_, v4)
            q = q + h6 * (v + 2.0 * v2 + 2.0 * v3_ + v4)
            v = v + h6 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
            Q[i + 1], V[i + 1] = q, v
        return Q, V

    def body_states(self, Q: np.ndarray, V: np.ndarray) -> tuple[dict, dict]:
        """Per-body (N, 3) CoM poses (phi from the drawing) and rates from the stored q and v, down
        the tree as the model chains it (each joint at its drawn offset in its parent's frame,
        every frame world-aligned in the drawing), vectorised over the states: Pinocchio's forward
        kinematics state by state from Python took five times the simulation itself
        (test_common.py checks the two agree)."""
        def turn(phi: np.ndarray, r: np.ndarray) -> np.ndarray:  # (N, 2): r (2,) turned by phi (N,)
            c, s = np.cos(phi), np.sin(phi)
            return np.c_[c * r[0] - s * r[1], s * r[0] + c * r[1]]

        def cross(w: np.ndarray, r: np.ndarray) -> np.ndarray:  # (N, 2): w e_z x r
            return w[:, None] * np.c_[-r[:, 1], r[:, 0]]

        n = len(Q)
        phi, w = {"ground": np.zeros(n)}, {"ground": np.zeros(n)}
        o, vo = {"ground": np.zeros((n, 2))}, {"ground": np.zeros((n, 2))}  # joint origins and their rates
        poses, rates = {}, {}
        for p in self.d.tree()[0]:  # depth-first: every parent before its children
            a, b, joint = p.a, p.b, self.model.joints[self.jid[p.b]]
            r = turn(phi[a], self.origin[b] - self.origin[a])
            o[b], vo[b] = o[a] + r, vo[a] + cross(w[a], r)
            phi[b], w[b] = phi[a] + Q[:, joint.idx_q], w[a] + V[:, joint.idx_v]
            c = turn(phi[b], self.d.bodies[b].com - self.origin[b])
            poses[b] = np.c_[o[b] + c, phi[b]]
            rates[b] = np.c_[vo[b] + cross(w[b], c), w[b]]
        return {k: poses[k] for k in self.d.bodies}, {k: rates[k] for k in self.d.bodies}


_models: dict = {}


def model(bm: Benchmark, d: Drawing, w: float) -> Model:
    if (bm.key, w) not in _models:
        _models[bm.key, w] = Model(d, w)
    return _models[bm.key, w]


def run(bm: Benchmark, d: Drawing, v: Variant, n: int, ref: Reference) -> Run:
    r = Run(TOOL, v.method, v.label(bm.t_end, n), value=n, steps=n)
    m = model(bm, d, *v.params)
    with np.errstate(all="ignore"):
        r.wall, (Q, V) = one_shot(lambda: m.simulate(bm.t_end / n, n))
        poses, rates = m.body_states(Q, V)
        q = coordinates(d, poses)[bm.sample_indices(n)]
        return r.finish(energy(d, poses, rates), loop_gap(d, poses), q, ref.steps(n))


def timed(bm: Benchmark, d: Drawing, v: Variant, n: int) -> Callable[[], object]:
    m, dt = model(bm, d, *v.params), bm.t_end / n
    return lambda: m.simulate(dt, n)


def clocked(bm: Benchmark, d: Drawing, v: Variant, n: int) -> Callable[[], float]:
    """The same run, returning the seconds spent inside ``constraintDynamics``."""
    m, dt = model(bm, d, *v.params), bm.t_end / n

    def call() -> float:
        clock = [0.0]
        m.simulate(dt, n, clock)
        return clock[0]

    return call
