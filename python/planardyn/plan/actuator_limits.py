"""Motor limits as TOPP constraints: the torque a motor offers falls with its speed (its
torque-speed envelope), and its torque is not the joint's: the rotor turns before the gear.

Each drive's envelope T(w) (motor torque against motor speed w = n qd, planardyn's model of
the actuator) must be concave: a flat part and drooping lines, T(w) = min_j (T0_j - T1_j |w|)
up to its last speed. Along the path (u = s'', x = s'^2, qd = p' s') the joint-side effort of
coordinate k is tau = a u + b x + c, and its motor's torque (Mechanism.motor_torques)

    t_m = g(tau) + R,   R = J omega_r' + f = r_a u + r_b x + F(qd),

g the gear's inverse: tau / (n eta) while motoring (tau qd >= 0), tau eta_b / n back-driven,
i.e. two lines through 0 of slopes ``up`` (tau > 0) and ``down`` (tau < 0) fixed by the sign
of qd; r_a u + r_b x the rotor's torque J omega_r' without its convective part, which is in
F(qd) with the motor's friction (F depends on x alone along the path). |t_m| <= T is then
linear in (tau, R) on each line: t_m <= T holds on both lines where g is convex (up >= down:
g = max of its lines), t_m >= -T on both where it is concave; the other side keeps the line
its bound lies on when the rotor and friction alone are within the limit (|R| <= T), a
conservative line otherwise (a bound beyond which the motor could not even turn its rotor).
With a self-locking gear (eta_b = 0) the back-driven line is flat: the gear holds the load
and only R is bounded. The x-dependence of T - F (sqrt(x) through the motor speed) is convex
without motor friction, so its tangent at any x0 lies below it: the tangent rows are a
conservative, linear inner approximation exact at x0. TOPP is solved with the tangents at
the previous profile (first at the profile the flat peak torque allows) until the time
settles; each profile is feasible for the next tangents, so the time never grows between
rounds. The final profile is checked against the exact bounds by the caller (TimedPath.lo,
hi hold them at its speeds and accelerations).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from ..mechanism import Mechanism
from .planned import PlanError

FloatArray = NDArray[np.float64]

#: Relative step of the tangents' central differences in x = s'^2.
TANGENT_STEP = 1e-6

#: The rows are scaled by the torque the envelope line offers at x0, at least this fraction of
#: its largest along the path (where a motor runs out of torque it vanishes).
ROW_SCALE_MIN = 1e-6


@dataclass
class Drive:
    """Coordinate k's motor: ratio n, envelope lines (J, 2) [T0, T1] (T = T0 - T1 |w|, N m
    and N m s/rad) and the largest motor speed with torque (rad/s)."""

    k: int
    ratio: float
    lines: FloatArray
    max_speed: float


def drives(mech: Mechanism) -> list[Drive]:
    """Every coordinate's motor limits, or a PlanError naming what is missing."""
    out = []
    for k, (name, act) in enumerate(zip(mech.coordinate_names, mech.actuators)):
        if act is None:
            raise PlanError(f"effort='actuators': coordinate {name} has no actuator; give it one or pass effort limits")
        env = np.asarray(act.get("envelope", np.zeros((0, 2))), dtype=float).reshape(-1, 2)
        peak, top = act.get("peak_torque"), act.get("max_speed")
        if len(env) >= 2:
            slope = np.diff(env[:, 1]) / np.diff(env[:, 0])
            if np.any(np.diff(slope) > 1e-12 * max(1.0, float(np.abs(slope).max()))):
                raise PlanError(f"actuator {act['name']}: its torque-speed envelope is not concave (a flat part and "
                                "drooping lines); TOPP's linear bounds need that")
            lines = np.column_stack([env[:-1, 1] - slope * env[:-1, 0], -slope])
            w_max = float(env[-1, 0])
        elif peak is not None:
            lines = np.array([[float(peak), 0.0]])
            w_max = np.inf if top is None else float(top)
        else:
            raise PlanError(f"actuator {act['name']}: no peak torque or torque-speed envelope to plan with")
        out.append(Drive(k, float(act["gear_ratio"]), lines, w_max))
    return out


@dataclass
class MotorMap:
    """The motor torque along a path's grid (N points, m coordinates) as
    t_m = g(tau) + r_a u + r_b x + F(qd): the gear's slopes ``up``, ``down`` (N, m; 1 / (n eta)
    or eta_b / n by the direction of the motion), the rotor's ``r_a``, ``r_b`` (N, m, N m per
    unit s'' and s'^2), and the path (q, its tangent p1, the branch x) for F."""

    mech: Mechanism
    q: FloatArray
    p1: FloatArray
    x: FloatArray
    up: FloatArray
    down: FloatArray
    r_a: FloatArray
    r_b: FloatArray
    #: The motors' Coulomb torque at a fixed fraction of its band (None: the core's tanh).
    shift: CoulombShift | None = None

    @classmethod
    def along(cls, mech: Mechanism, q: FloatArray, p1: FloatArray, p2: FloatArray, x: FloatArray) -> MotorMap:
        """The map at the grid points q (N, m) with the path's derivatives p1, p2 (N, m), on the
        branch x (N, 3n), from the core's motor torques (Mechanism.motor_torques)."""
        zero = np.zeros_like(q)

        def motor(qd: FloatArray, qdd: FloatArray, tau: FloatArray) -> FloatArray:
            return np.asarray(mech.motor_torques(q, qd, qdd, tau, x=x, allow_singular=True))

        # At qd = p1 the gear's branch is the motion's (s' > 0); F(p1) cancels.
        f = motor(p1, zero, zero)
        up, down = motor(p1, zero, np.ones_like(q)) - f, f - motor(p1, zero, -np.ones_like(q))
        # At rest the rotor's torque is J omega_r' alone: linear in qdd = p1 u + p2 x.
        return cls(mech, q, p1, x, up, down, motor(zero, p1, zero), motor(zero, p2, zero))

    def friction(self, x: FloatArray) -> FloatArray:
        """F (N, m) at s'^2 = x (N,): the motors' friction and the rotors' convective torque."""
        qd = self.p1 * np.sqrt(np.maximum(x, 0.0))[:, None]
        zero = np.zeros_like(self.q)
        f = np.asarray(self.mech.motor_torques(self.q, qd, zero, zero, x=self.x, allow_singular=True))
        return f if self.shift is None else f + self.shift(qd)

    def with_coulomb(self, shift: CoulombShift) -> MotorMap:
        """The map with the motors' Coulomb torque at ``shift``'s fraction of its band."""
        return replace(self, shift=shift)

    def rotor(self, u: FloatArray, x: FloatArray) -> FloatArray:
        """R = r_a u + r_b x + F (N, m) at s'' = u and s'^2 = x (N,): all of t_m but the gear's."""
        return np.asarray(self.r_a * u[:, None] + self.r_b * x[:, None] + self.friction(x))

    def torques(self, tau: FloatArray, u: FloatArray, x: FloatArray) -> FloatArray:
        """t_m (N, m) of the joint-side efforts tau (N, m) at s'' = u and s'^2 = x (N,), on the
        gear's branch of the path's direction."""
        return np.asarray(np.where(tau >= 0, self.up, self.down) * tau + self.rotor(u, x))


@dataclass
class CoulombShift:
    """Replaces the core's T_c tanh(n qd / v_s) by theta T_c sign(p') (the path's direction):
    ``theta`` 1 as if moving beyond the band, 0 and -1 the band's other values
    (planardyn.plan.planning_model); T_c ``coulomb``, v_s ``stiction``, n ``ratio``, each (m,),
    the path's tangent ``p1`` (P, m)."""

    theta: float
    coulomb: FloatArray
    stiction: FloatArray
    ratio: FloatArray
    p1: FloatArray

    def __call__(self, qd: FloatArray) -> FloatArray:
        """The change (P, m) of the motor torques at rates qd (P, m) (rad/s or m/s)."""
        return np.asarray(self.coulomb * (self.theta * np.sign(self.p1) - np.tanh(self.ratio * qd / self.stiction)))


def joint_bounds(motor: MotorMap, u: FloatArray, x: FloatArray, torque: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Joint-side (lo, hi) (N, m) that keep |t_m| <= torque (N, m) at s'' = u and s'^2 = x
    (N,), through the gear's inverse: tau in [g^-1(-T - R), g^-1(T - R)] (infinite where a
    self-locking gear holds any load)."""
    rotor = motor.rotor(u, x)

    def inverse(y: FloatArray) -> FloatArray:
        slope = np.where(y >= 0, motor.up, motor.down)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(slope > 0, y / np.where(slope > 0, slope, 1.0), np.copysign(np.inf, y))

    return inverse(-torque - rotor), inverse(torque - rotor)


def exact_bounds(mech: Mechanism, motor: MotorMap, u: FloatArray, x: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Joint-side (lo, hi) (N, m) at s'' = u, s'^2 = x (N,) from the core's available torque
    at the motor speed n qd."""
    qd = motor.p1 * np.sqrt(x)[:, None]
    torque = np.column_stack([
        np.asarray(mech.available_torque(d.k, d.ratio * qd[:, d.k]), dtype=float) for d in drives(mech)])
    return joint_bounds(motor, u, x, torque)


def tangent_rows(motor: MotorMap, ds: list[Drive], a: FloatArray, b: FloatArray, c: FloatArray,
                 x0: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Rows (N, R) of A u + B x + C <= 0: for each drive, envelope line and gear line,
    side (s tau + R) <= T - side F with T - side F replaced by its tangent at x0 (N,)."""
    x0 = np.maximum(x0, 1e-6 * max(float(x0.max()), 1e-12))
    dx = TANGENT_STEP * x0
    points = (x0, x0 + dx, x0 - dx)
    friction = [motor.friction(x) for x in points]
    rows_a, rows_b, rows_c = [], [], []
    for d in ds:
        k, p1 = d.k, np.abs(motor.p1[:, d.k])
        gear = _gear_lines(motor, k)
        for t0, t1 in d.lines:
            # Scaled by the torque the line offers at x0, so that C is of order one.
            torque = np.abs(t0 - t1 * d.ratio * p1 * np.sqrt(x0))
            scale = np.maximum(torque, ROW_SCALE_MIN * max(float(torque.max()), 1e-300))
            for slope, side in gear:
                # h(x) = T(x) - side F(x) at the three points, its tangent at x0.
                h = [t0 - t1 * d.ratio * p1 * np.sqrt(x) - side * f[:, k] for x, f in zip(points, friction)]
                dh = (h[1] - h[2]) / (2 * dx)
                rows_a.append(side * (slope * a[:, k] + motor.r_a[:, k]) / scale)
                rows_b.append((side * (slope * b[:, k] + motor.r_b[:, k]) - dh) / scale)
                rows_c.append((side * slope * c[:, k] - h[0] + dh * x0) / scale)
    return np.column_stack(rows_a), np.column_stack(rows_b), np.column_stack(rows_c)


def _gear_lines(motor: MotorMap, k: int) -> list[tuple[FloatArray, FloatArray]]:
    """Coordinate k's gear lines as (slope, side) (N,) each: side (slope tau + R) <= T - side F.
    The upper side (t_m <= T) on ``up``, the lower (t_m >= -T) on ``down``, and the third on
    the other line of the side where both hold: the upper side where g is convex (up >= down),
    the lower where it is concave (three rows, none repeated: a stage's LP takes no duplicate)."""
    up, down = motor.up[:, k], motor.down[:, k]
    convex = up >= down
    one = np.ones_like(up)
    return [(up, one), (down, -one), (np.where(convex, down, up), np.where(convex, one, -one))]
