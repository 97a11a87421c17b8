"""The linear rows of a model with Coulomb friction, about the previous timing, with the
least favourable value of each friction's band at rest.

The efforts with the pins' Coulomb friction are not linear in (u, x) = (s'', s'^2): a pin's
torque is mu r |F| with F its load, itself affine in (u, x) (to the friction's own small
share of it), so tau is convex or concave in (u, x) component by component. Each round of
TOPP (planardyn.plan.topp) takes the tangent plane of tau at the previous timing's (u0, x0),
by central differences of the core's inverse dynamics, from the sharp copy
(planardyn.plan.planning_model: the friction of the path's direction, theta = 1). A tangent
of a convex limit lets a little too much away from (u0, x0): the dense check finds it and
adds the limit's rows at the worst point, as it does for any limit, until every limit holds
to RATIO_TOL along the whole path and the time has settled.

Where the planned speed lies inside a friction's band (the core's tanh below 1 - BAND_TOL),
the friction is a fraction theta in [0, 1] of theta = 1's: the rows of theta = 0 (the copy
without the pins' Coulomb friction, the motors' Coulomb torque off) are added there; at rest
(s' = 0, where sign(v) is set-valued) also those of theta = -1 (the sharp copy moving
backwards, at s' = 1e-150). The limit there is the least favourable of the band, which is
what lets the rounds settle where the path starts and ends at rest: without it the tangents
chase the step of tanh(v / v_s) from round to round.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from ..mechanism import Mechanism
from .actuator_limits import CoulombShift, MotorMap
from .path_limits import X_REST, PathPoints, inverse_along
from .planning_model import PlanningModel

FloatArray = NDArray[np.float64]
Variant = tuple[PathPoints, NDArray[np.bool_] | None]

#: A friction counts as inside its band where it is below its full value by more than this
#: fraction (tanh(v / v_s) < 1 - BAND_TOL: v < 14 v_s); beyond, the sharp rows differ from the
#: core by less than RATIO_TOL of a limit.
BAND_TOL = 1e-12

#: Relative steps of the tangent planes' central differences in u and x.
STEP = 1e-6


def variants(model: PlanningModel, pts: PathPoints, u0: FloatArray, x0: FloatArray) -> list[Variant]:
    """The points' linear rows' variants (see the module), each with the mask of the points
    it holds at (None: all), about s'' = u0 and s'^2 = x0 (P,)."""
    if pts.motors is None:
        pts.motors = MotorMap.along(model.mech, pts.q, pts.p1, pts.p2, pts.x)
    x = np.maximum(x0, X_REST)
    moving = _tangent(model, pts, u0, x, 1.0)
    out: list[Variant] = [(moving, None)]
    band = _in_band(model, pts, u0, x0, moving)
    if band.any():
        bare = pts if model.bare is None else _coefficients(model.bare, pts)
        out.append((_with_motors(model, bare, pts.motors, 0.0), band))
    rest = x0 <= X_REST
    if rest.any():
        out.append((_tangent(model, pts, u0, x, -1.0), rest))
    return out


def _tangent(model: PlanningModel, pts: PathPoints, u0: FloatArray, x: FloatArray, sign: float) -> PathPoints:
    """The points with a, b, c the tangent plane at (u0, x) of the sharp copy's efforts,
    moving along the path (``sign`` 1) or against it (-1), and its motors' map alike."""
    assert pts.motors is not None
    if model.bare is None:  # no pin friction: the efforts are linear, only the motors' friction moves
        return _with_motors(model, replace(pts, exact=None), pts.motors, sign)
    du = STEP * max(float(np.abs(u0).max()), 1.0)
    dx = STEP * np.maximum(x, float(x.max()))

    def tau(u: FloatArray, xx: FloatArray) -> FloatArray:
        return inverse_along(model.sharp, pts, u, xx, sign)

    a = (tau(u0 + du, x) - tau(u0 - du, x)) / (2 * du)
    b = (tau(u0, x + dx) - tau(u0, x)) / dx[:, None]  # forward: x >= 0
    c = tau(u0, x) - a * u0[:, None] - b * x[:, None]
    return _with_motors(model, replace(pts, a=a, b=b, c=c, exact=None), pts.motors, sign)


def _coefficients(mech: Mechanism, pts: PathPoints) -> PathPoints:
    """The points with the (linear) efforts of ``mech``: a, b, c by inverse dynamics."""
    zero = np.zeros(len(pts.s))
    c = inverse_along(mech, pts, zero, zero)
    a = inverse_along(mech, pts, zero + 1.0, zero) - c
    b = inverse_along(mech, pts, zero, zero + 1.0) - c
    return replace(pts, a=a, b=b, c=c, exact=None)


def _with_motors(model: PlanningModel, pts: PathPoints, motors: MotorMap, theta: float) -> PathPoints:
    shift = CoulombShift(theta, model.coulomb, model.stiction, model.ratio, pts.p1)
    return replace(pts, motors=motors.with_coulomb(shift))


def _in_band(model: PlanningModel, pts: PathPoints, u0: FloatArray, x0: FloatArray, moving: PathPoints) -> NDArray[np.bool_]:
    """Points (P,) where some friction at s'' = u0, s'^2 = x0 is below its full value by more
    than BAND_TOL of it: a motor's tanh, or a pin's torque (the core's against the sharp one)."""
    speed = model.ratio * np.abs(pts.p1) * np.sqrt(np.maximum(x0, 0.0))[:, None] / model.stiction
    band = np.any((model.coulomb > 0) & (1.0 - np.tanh(speed) > BAND_TOL), axis=1)
    if model.bare is None:
        return np.asarray(band)
    core, sharp = pts.efforts(u0, x0), moving.efforts(u0, x0)
    scale = max(float(np.abs(sharp).max()), 1e-300)
    return np.asarray(band | np.any(np.abs(core - sharp) > BAND_TOL * scale, axis=1))
