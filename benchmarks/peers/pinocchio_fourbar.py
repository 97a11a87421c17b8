"""Pinocchio (PyPI ``pin``): the four-bar as a kinematic tree (crank -> coupler, rocker) with
the loop closed at B by a ``RigidConstraintModel`` (CONTACT_3D between the coupler and the
rocker), forward dynamics by ``pin.constraintDynamics`` (index-1 KKT with the proximal
solver, which copes with the constraint's redundant z row), Baumgarte stabilisation with
Kp = w^2, Kd = 2 w (critical), and classic RK4 written in Python over q, v.

Timed: the RK4 loop, storing q and v at every step. Energy, loop gap and the crank angle
are computed afterwards from the stored states (untimed).
"""

from __future__ import annotations

import numpy as np

from common import T_END, FourBar, Run, best_time, energy, grid_indices

TOOL = "Pinocchio"
PACKAGE = "pin"

#: (dt in s, Baumgarte w in 1/s): w = 0 is no stabilisation.
SWEEP = [(dt, w) for w in (0.0, 10.0, 30.0) for dt in (0.01, 0.005, 0.004, 0.0025, 0.002, 0.001)]

#: Proximal solver settings: absolute and relative accuracy, mu, iterations.
PROX = (1e-12, 1e-12, 1e-8, 20)


def version() -> str:
    import pinocchio

    return pinocchio.__version__


def v3(p) -> np.ndarray:
    return np.array([p[0], p[1], 0.0])


class Model:
    """The tree, its data and the loop constraint. Joint frames are world-aligned in the
    drawing, so q = 0 there and each q is a relative angle (RZ joints, not wrapped)."""

    def __init__(self, fb: FourBar, w: float):
        import pinocchio as pin

        self.pin, self.fb = pin, fb
        P, B = fb.points, fb.bodies
        model = pin.Model()
        model.gravity = pin.Motion(np.array([fb.gravity[0], fb.gravity[1], 0.0, 0.0, 0.0, 0.0]))
        self.joint_at = {"crank": P["O"], "coupler": P["A"], "rocker": P["D"]}
        parent_pos = {"crank": (0, P["O"]), "coupler": ("crank", P["A"] - P["O"]), "rocker": (0, P["D"])}
        self.jid = {}
        for name in ("crank", "coupler", "rocker"):
            parent, pos = parent_pos[name]
            pj = 0 if parent == 0 else self.jid[parent]
            j = model.addJoint(pj, pin.JointModelRZ(), pin.SE3(np.eye(3), v3(pos)), name)
            b = B[name]
            c = v3(b.com - self.joint_at[name])
            model.appendBodyToJoint(j, pin.Inertia(b.mass, c, np.diag([b.inertia] * 3)), pin.SE3.Identity())
            self.jid[name] = j
        self.model, self.data = model, model.createData()
        cm = pin.RigidConstraintModel(
            pin.ContactType.CONTACT_3D, model,
            self.jid["coupler"], pin.SE3(np.eye(3), v3(P["B"] - P["A"])),
            self.jid["rocker"], pin.SE3(np.eye(3), v3(P["B"] - P["D"])),
            pin.ReferenceFrame.LOCAL,
        )
        # The list holds a copy: set the corrector before appending.
        cm.setBaumgarteCorrectorParameters(pin.BaumgarteCorrectorParameters(w * w, 2.0 * w))
        self.cmodels = pin.StdVec_RigidConstraintModel()
        self.cmodels.append(cm)
        self.cdatas = pin.StdVec_RigidConstraintData()
        self.cdatas.append(cm.createData())
        pin.initConstraintDynamics(model, self.data, self.cmodels, self.cdatas)
        self.prox = pin.ProximalSettings(*PROX)
        self.tau = np.zeros(model.nv)

    def simulate(self, dt: float, n: int) -> tuple[np.ndarray, np.ndarray]:
        """Classic RK4 over (q, v), n steps of dt; (n+1, 3) q and v."""
        pin, model, data = self.pin, self.model, self.data
        cm, cd, prox, tau = self.cmodels, self.cdatas, self.prox, self.tau
        def f(q, v):
            return pin.constraintDynamics(model, data, q, v, tau, cm, cd, prox)
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
        """Per-body (N, 3) CoM poses (phi from the drawing) and rates, from Pinocchio's
        forward kinematics."""
        pin, model, data = self.pin, self.model, self.data
        poses = {k: np.empty((len(Q), 3)) for k in self.jid}
        rates = {k: np.empty((len(Q), 3)) for k in self.jid}
        for i in range(len(Q)):
            pin.forwardKinematics(model, data, Q[i], V[i])
            for name, j in self.jid.items():
                M, vel = data.oMi[j], data.v[j]  # vel: joint frame, local coordinates
                c = v3(self.fb.bodies[name].com - self.joint_at[name])
                R = M.rotation
                poses[name][i, :2] = (M.translation + R @ c)[:2]
                poses[name][i, 2] = np.arctan2(R[1, 0], R[0, 0])
                rates[name][i, :2] = (R @ (vel.linear + np.cross(vel.angular, c)))[:2]
                rates[name][i, 2] = vel.angular[2]
        for p in poses.values():
            p[:, 2] = np.unwrap(p[:, 2])
        return poses, rates


def run(fb: FourBar, setting: tuple, ref_grid: np.ndarray) -> Run:
    dt, w = setting
    r = Run(TOOL, "RK4 + constraintDynamics" + (f", Baumgarte w={w:g}" if w else ""), f"dt={dt:g}")
    n = int(round(T_END / dt))
    m = Model(fb, w)
    with np.errstate(all="ignore"):
        r.wall, (Q, V) = best_time(lambda: m.simulate(dt, n))
        r.steps = n
        from common import loop_gap

        poses, rates = m.body_states(Q, V)
        theta = fb.theta1_0 + Q[grid_indices(dt), 0]
        return r.finish(energy(fb, poses, rates), loop_gap(fb, poses), theta, ref_grid)
