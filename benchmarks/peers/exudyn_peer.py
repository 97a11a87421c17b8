"""Exudyn: a mechanism in redundant coordinates, one ``ObjectRigidBody2D`` per body (node at
the centre of mass, [x, y, phi]) and one ``RevoluteJoint2D`` per pair (every pin an
algebraic constraint: no tree needed), gravity by ``Gravity`` loads, springs by
``ObjectConnectorSpringDamper``, drive torques by ``LoadTorqueVector``; integrated by
Exudyn's implicit generalized-alpha solver with index-3 constraints (its default), Newton to
relative 1e-8.

Variants, each searched on its number of steps: generalized-alpha with index-3 constraints at
spectral radius 0.8, 0.9, 0.95 and 1 (no numerical damping; on the four-bar Newton then diverges
around t = 2.55 s at every step size tried), and Newmark with index-2 constraints.

Timed: ``mbs.SolveDynamic`` (the C++ loop) with node sensors storing position, angle and
their rates at every step. Energy and loop gap come afterwards from the sensors (untimed).
"""

from __future__ import annotations

import io
from collections.abc import Callable
from contextlib import redirect_stdout

import numpy as np
from common import Drawing, Reference, Run, Variant, coordinates, energy, loop_gap, one_shot
from mechanisms import Benchmark

TOOL = "Exudyn"
PACKAGE = "exudyn"

#: (spectral radius, index-2 Newmark?)
METHODS = [(0.8, False), (0.9, False), (0.95, False), (1.0, False), (1.0, True)]
#: (cheapest, dearest) number of steps over the run.
STEPS = {"four-bar": (50, 80000), "five-bar": (10, 100000), "3-rrr": (4, 8000), "andrews": (30, 40000)}


def variants(bm: Benchmark) -> list[Variant]:
    return [Variant(TOOL, "Newmark, index 2" if index2 else f"gen.-alpha index 3, rho={rho:g}", (rho, index2),
                    STEPS[bm.key]) for rho, index2 in METHODS]


def version() -> str:
    import exudyn

    return exudyn.__version__


def build(d: Drawing):
    """The system and, per body, its sensors (position, angle, velocity, angular velocity)."""
    import exudyn as exu
    from exudyn.itemInterface import (
        Gravity,
        LoadTorqueVector,
        MarkerBodyMass,
        MarkerBodyPosition,
        MarkerBodyRigid,
        NodeRigidBody2D,
        ObjectConnectorSpringDamper,
        ObjectGround,
        ObjectRigidBody2D,
        RevoluteJoint2D,
        SensorNode,
    )

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    body = {"ground": mbs.AddObject(ObjectGround(referencePosition=[0.0, 0.0, 0.0]))}
    sensors = {}
    O = exu.OutputVariableType
    for name, b in d.bodies.items():
        node = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[float(b.com[0]), float(b.com[1]), 0.0],
                                           initialVelocities=[0.0, 0.0, 0.0]))
        body[name] = mbs.AddObject(ObjectRigidBody2D(nodeNumber=node, mass=b.mass, inertia=b.inertia))
        if np.any(d.gravity):
            mass = mbs.AddMarker(MarkerBodyMass(bodyNumber=body[name]))
            mbs.AddLoad(Gravity(markerNumber=mass, loadVector=[float(d.gravity[0]), float(d.gravity[1]), 0.0]))
        sensors[name] = [mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True, outputVariableType=t))
                         for t in (O.Position, O.Rotation, O.Velocity, O.AngularVelocity)]

    def marker(name: str, point: str):
        s = d.point_on(name, point)
        return mbs.AddMarker(MarkerBodyPosition(bodyNumber=body[name], localPosition=[float(s[0]), float(s[1]), 0.0]))

    for p in d.pairs:
        mbs.AddObject(RevoluteJoint2D(markerNumbers=[marker(p.a, p.point), marker(p.b, p.point)]))
    for s in d.springs:
        mbs.AddObject(ObjectConnectorSpringDamper(markerNumbers=[marker(s.a, s.point_a), marker(s.b, s.point_b)],
                                                  stiffness=s.stiffness, damping=0.0, referenceLength=s.rest_length))
    for c in d.coordinates:
        if c.effort:  # on b, reacting on a
            for name, sign in ((c.pair.b, 1.0), (c.pair.a, -1.0)):
                if name != "ground":
                    m = mbs.AddMarker(MarkerBodyRigid(bodyNumber=body[name]))
                    mbs.AddLoad(LoadTorqueVector(markerNumber=m, loadVector=[0.0, 0.0, sign * c.effort]))
    mbs.Assemble()
    return exu, mbs, sensors


def settings(exu, n: int, t_end: float, rho: float, index2: bool):
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.numberOfSteps, ti.endTime, ti.verboseMode = n, t_end, 0
    ti.generalizedAlpha.spectralRadius = rho
    ti.generalizedAlpha.useNewmark = index2
    ti.generalizedAlpha.useIndex2Constraints = index2
    s.show.computationTime = False
    s.show.statistics = False
    s.solution.file.write = False
    s.solution.sensors.writePeriod = 0.0  # every step
    return s


def run(bm: Benchmark, d: Drawing, v: Variant, n: int, ref: Reference) -> Run:
    r = Run(TOOL, v.method, v.label(bm.t_end, n), value=n, steps=n)
    exu, mbs, sensors = build(d)
    s = settings(exu, n, bm.t_end, *v.params)
    try:
        with redirect_stdout(io.StringIO()):
            r.wall, _ = one_shot(lambda: mbs.SolveDynamic(s))
    except Exception as e:  # Exudyn raises SolverError when Newton fails for good
        return r.fail(f"solver failed: {e}")
    poses, rates = {}, {}
    for name, (sp, sr, sv, sw) in sensors.items():
        P, R, V, W = (mbs.GetSensorStoredData(k) for k in (sp, sr, sv, sw))
        poses[name] = np.c_[P[:, 1], P[:, 2], R[:, 3]]
        rates[name] = np.c_[V[:, 1], V[:, 2], W[:, 3]]
    # Sensors hold t = 0 and every step (n + 1 rows).
    rows = len(next(iter(poses.values())))
    if rows != n + 1:
        return r.fail(f"{rows} sensor rows for {n} steps")
    q = coordinates(d, poses)[bm.sample_indices(n)]
    return r.finish(energy(d, poses, rates), loop_gap(d, poses), q, ref.steps(n))


def timed(bm: Benchmark, d: Drawing, v: Variant, n: int) -> Callable[[], object]:
    exu, mbs, _ = build(d)
    s = settings(exu, n, bm.t_end, *v.params)

    def call() -> None:
        with redirect_stdout(io.StringIO()):
            mbs.SolveDynamic(s)

    return call
