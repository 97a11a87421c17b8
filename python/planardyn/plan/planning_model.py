"""The model a plan is timed on: which parts of the user's model planning keeps, replaces or
refuses, and the copies its Coulomb friction is bounded with.

- **Drive laws are replaced.** The planned efforts are the drives: the model's ``drives`` are
  not used, and neither is a drive's servo, written in model files as a spring-damper
  (``torsional_spring`` with ``damping``) at the pair of a driven coordinate: a PD law about a
  reference is what a plan replaces (tracking the plan exactly, its error and its effort are
  zero). Such loads are left out and listed (``TimedPath.ignored``).
- **Passive loads are kept**: gravity, springs, the pins' Coulomb friction, the motors'
  friction. A damper that is not a servo (a spring-damper elsewhere, a pair's viscous
  friction) adds c s', which is not of TOPP's form a s'' + b s'^2 + c: it is refused with its
  name and the fix.
- **Coulomb friction is a step at rest.** The core regularises sign(v) by tanh(v / v_s); its
  friction at a point of the path is a fraction theta in [0, 1] of the friction of the
  path's direction (theta = 1 beyond a few v_s), and at rest (s' = 0) sign(v) is set-valued:
  the friction can take any value of its band, theta in [-1, 1]. The rows of the limits are
  built for theta = 1 from a copy with the regularisation made sharp (:data:`SHARP`), and
  where the planned speed lies inside the band also for theta = 0 (a copy without the pins'
  Coulomb friction, the motors' Coulomb torque taken off) and at rest for theta = -1: the
  limit there is the least favourable of the band (planardyn.plan.friction_rows).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..mechanism import Mechanism, from_dict
from .planned import PlanError

FloatArray = NDArray[np.float64]

#: The regularising speed of every Coulomb friction in the sharp copy (m/s, rad/s): at the
#: smallest speed the rows are taken at (s' = 1e-150 at s'^2 = X_REST) tanh(v / SHARP) is 1.
SHARP = 1e-200

#: Spring-damper load types whose damping a servo is written with.
SPRING_TYPES = ("torsional_spring", "spring")


@dataclass
class PlanningModel:
    """The model planned (``mech``: the user's without its servos), the sharp copy its rows
    of theta = 1 come from (``sharp``), the copy without the pins' Coulomb friction
    (``bare``; None when it has none: then ``sharp`` is ``mech``), the motors' Coulomb
    torques ``coulomb`` (m,) (N m, 0 without one), regularising speeds ``stiction`` (m,)
    (rad/s) and gear ratios ``ratio`` (m,), and what was left out (``ignored``, one sentence
    each)."""

    mech: Mechanism
    sharp: Mechanism
    bare: Mechanism | None
    coulomb: FloatArray
    stiction: FloatArray
    ratio: FloatArray
    ignored: list[str]

    @property
    def has_coulomb(self) -> bool:
        """Whether any pin or motor has Coulomb friction (the rows then take its band)."""
        return self.bare is not None or bool(np.any(self.coulomb > 0))


def planning_model(mech: Mechanism) -> PlanningModel:
    """The model ``mech`` is planned on (see the module); a PlanError names a damper that is
    not a servo and says how to plan without it."""
    model = mech.to_dict()
    loads = model.get("loads", [])
    pair_of = {c["name"]: c.get("pair") for c in model.get("coordinates", [])}
    driven = {pair_of.get(d.get("coordinate")) for d in model.get("drives", [])} - {None}
    kept, ignored = [], []
    for i, ld in enumerate(loads):
        damping = float(ld.get("damping", 0.0) or 0.0)
        if ld["type"] in SPRING_TYPES and damping > 0 and ld.get("pair") in driven:
            ignored.append(f"loads[{i}] ({ld['type']} at pair {ld['pair']}, the servo of its drive): the planned "
                           "efforts replace the drive law")
            continue
        viscous = damping if ld["type"] in SPRING_TYPES else float(ld.get("viscous", 0.0) or 0.0)
        if viscous > 0:
            where = f"at pair {ld['pair']}" if "pair" in ld else f"between {ld.get('between')}"
            raise PlanError(f"{mech.name}: loads[{i}] ({ld['type']} {where}) damps with {viscous:g}: its effort c s' is "
                            "not of TOPP's form a s'' + b s'^2 + c; plan on a copy with its "
                            f"{'damping' if ld['type'] in SPRING_TYPES else 'viscous'} set to 0 (or, if it is a "
                            "drive's servo, give its coordinate a drive: then planning replaces it)")
        kept.append(ld)
    if model.get("drives"):
        ignored.insert(0, "drives: the planned efforts are the drives")
    model["loads"] = kept
    planned = from_dict(model) if len(kept) < len(loads) else mech
    acts = [a or {} for a in planned.actuators]
    coulomb = np.array([float(a.get("coulomb", 0.0) or 0.0) for a in acts])
    stiction = np.array([float(a.get("stiction_speed", 1.0) or 1.0) for a in acts])
    ratio = np.array([float(a.get("gear_ratio", 1.0) or 1.0) for a in acts])
    pins = [ld for ld in kept if ld["type"] == "friction" and float(ld.get("mu", 0.0) or 0.0) > 0]
    if not pins:
        return PlanningModel(planned, planned, None, coulomb, stiction, ratio, ignored)
    sharp, bare = dict(model), dict(model)
    sharp["loads"] = [{**ld, "stiction_speed": SHARP} if ld in pins else ld for ld in kept]
    bare["loads"] = [ld for ld in kept if ld not in pins]
    return PlanningModel(planned, from_dict(sharp), from_dict(bare), coulomb, stiction, ratio, ignored)
