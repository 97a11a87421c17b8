"""Exudyn: a mechanism in redundant coordinates, one ``ObjectRigidBody2D`` per body (node at
the centre of mass, [x, y, phi]) and one ``RevoluteJoint2D`` per pair (every pin an
algebraic constraint: no tree needed), gravity by ``Gravity`` loads, springs by
``ObjectConnectorSpringDamper``, drive torques by ``LoadTorqueVector``; integrated by
Exudyn's implicit generalized-alpha solver with index-3 constraints (its default), Newton to
relative 1e-8.

Swept: the number of steps, at spectral radius 0.9. (On the four-bar at spectral radius 1,
no numerical damping, Newton diverges around t = 2.55 s at every step size tried; the
index-2 Newmark variant and one run at spectral radius 1 are included, for the record.)

Timed: ``mbs.SolveDynamic`` (the C++ loop) with node sensors storing position, angle and
their rates at every step. Energy and loop gap come afterwards from the sensors (untimed).
"""

from __future__ import annotations

import io
from contextlib import redirect_stdout

import numpy as np
from common import Drawing, Run, best_time, coordinates, energy, loop_gap
from mechanisms import Benchmark

TOOL = "Exudyn"
PACKAGE = "exudyn"


def _sweep(dts: tuple, records: list[tuple] = ()) -> list[tuple]:
    """(dt in s, spectral radius, index-2 Newmark?)"""
    return [(dt, 0.9, False) for dt in dts] + list(records)


SWEEPS = {
    "four-bar": _sweep((0.01, 0.005, 0.0025, 0.00125, 0.001, 0.0008, 0.0005, 0.00025),
                       [(0.001, 1.0, True), (0.005, 1.0, False)]),
    "five-bar": _sweep((0.001, 0.0005, 0.0002, 0.0001, 0.00005, 0.00002), [(0.0005, 1.0, True), (0.0005, 1.0, False)]),
    "3-rrr": _sweep((0.01, 0.005, 0.002, 0.001, 0.0005), [(0.001, 1.0, True), (0.001, 1.0, False)]),
    "andrews": _sweep((2e-5, 1e-5, 5e-6, 2e-6), [(5e-6, 1.0, True), (5e-6, 1.0, False)]),
}


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


def run(bm: Benchmark, d: Drawing, setting: tuple, ref_grid: np.ndarray) -> Run:
    dt, rho, index2 = setting
    r = Run(TOOL, "Newmark, index 2" if index2 else f"gen.-alpha index 3, rho={rho:g}", f"dt={dt:g}")
    exu, mbs, sensors = build(d)
    n = r.steps = bm.steps(dt)
    s = settings(exu, n, bm.t_end, rho, index2)
    try:
        with redirect_stdout(io.StringIO()):
            r.wall, _ = best_time(lambda: mbs.SolveDynamic(s), max_repeats=3)
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
    q = coordinates(d, poses)[bm.grid_indices(dt)]
    return r.finish(energy(d, poses, rates), loop_gap(d, poses), q, ref_grid)
