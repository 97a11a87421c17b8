"""Exudyn: the four-bar in redundant coordinates, three ``ObjectRigidBody2D`` (node at the
centre of mass, [x, y, phi]) and four ``RevoluteJoint2D`` (the loop's four pins as algebraic
constraints), gravity by ``Gravity`` loads; integrated by Exudyn's implicit generalized-
alpha solver with index-3 constraints (its default), Newton to relative 1e-8.

Swept: the number of steps, at spectral radius 0.9. (At spectral radius 1, no numerical
damping, Newton diverges around t = 2.55 s at every step size tried; the index-2 Newmark
variant and one run at spectral radius 1 are included, for the record.)

Timed: ``mbs.SolveDynamic`` (the C++ loop) with node sensors storing position, angle and
their rates at every step. Energy and loop gap come afterwards from the sensors (untimed).
"""

from __future__ import annotations

import numpy as np

from common import T_END, FourBar, Run, best_time, energy, grid_indices, loop_gap

TOOL = "Exudyn"
PACKAGE = "exudyn"

#: (steps over 10 s, spectral radius, index-2 Newmark?)
SWEEP = ([(n, 0.9, False) for n in (1000, 2000, 4000, 8000, 10000, 12500, 20000, 40000)]
         + [(10000, 1.0, True), (2000, 1.0, False)])


def version() -> str:
    import exudyn

    return exudyn.__version__


def build(fb: FourBar):
    """The system and, per body, its sensors (position, angle, velocity, angular velocity)."""
    import exudyn as exu
    from exudyn.itemInterface import (
        Gravity, MarkerBodyMass, MarkerBodyPosition, NodeRigidBody2D, ObjectGround,
        ObjectRigidBody2D, RevoluteJoint2D, SensorNode,
    )

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    ground = mbs.AddObject(ObjectGround(referencePosition=[0.0, 0.0, 0.0]))
    body, sensors = {}, {}
    O = exu.OutputVariableType
    for name, b in fb.bodies.items():
        node = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[float(b.com[0]), float(b.com[1]), 0.0],
                                           initialVelocities=[0.0, 0.0, 0.0]))
        body[name] = mbs.AddObject(ObjectRigidBody2D(nodeNumber=node, mass=b.mass, inertia=b.inertia))
        mass = mbs.AddMarker(MarkerBodyMass(bodyNumber=body[name]))
        mbs.AddLoad(Gravity(markerNumber=mass, loadVector=[float(fb.gravity[0]), float(fb.gravity[1]), 0.0]))
        sensors[name] = [mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True, outputVariableType=t))
                         for t in (O.Position, O.Rotation, O.Velocity, O.AngularVelocity)]

    def marker(name: str, point: str):
        p = fb.points[point]
        if name == "ground":
            return mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=[float(p[0]), float(p[1]), 0.0]))
        s = p - fb.bodies[name].com
        return mbs.AddMarker(MarkerBodyPosition(bodyNumber=body[name], localPosition=[float(s[0]), float(s[1]), 0.0]))

    for point, a, b in (("O", "ground", "crank"), ("A", "crank", "coupler"),
                        ("B", "coupler", "rocker"), ("D", "ground", "rocker")):
        mbs.AddObject(RevoluteJoint2D(markerNumbers=[marker(a, point), marker(b, point)]))
    mbs.Assemble()
    return exu, sc, mbs, sensors


def settings(exu, n: int, rho: float, index2: bool):
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.numberOfSteps, ti.endTime, ti.verboseMode = n, T_END, 0
    ti.generalizedAlpha.spectralRadius = rho
    ti.generalizedAlpha.useNewmark = index2
    ti.generalizedAlpha.useIndex2Constraints = index2
    s.show.computationTime = False
    s.show.statistics = False
    s.solution.file.write = False
    s.solution.sensors.writePeriod = 0.0  # every step
    return s


def run(fb: FourBar, setting: tuple, ref_grid: np.ndarray) -> Run:
    import io
    from contextlib import redirect_stdout

    n, rho, index2 = setting
    method = "Newmark, index 2" if index2 else f"gen.-alpha index 3, rho={rho:g}"
    r = Run(TOOL, method, f"dt={T_END / n:g}")
    exu, sc, mbs, sensors = build(fb)
    s = settings(exu, n, rho, index2)
    r.steps = n
    try:
        with redirect_stdout(io.StringIO()):
            r.wall, _ = best_time(lambda: mbs.SolveDynamic(s), max_repeats=3)
    except Exception as e:  # Exudyn raises SolverError when Newton fails for good
        r.ok, r.note = False, f"solver failed: {e}"
        return r
    poses, rates = {}, {}
    for name, (sp, sr, sv, sw) in sensors.items():
        P, R, V, W = (mbs.GetSensorStoredData(k) for k in (sp, sr, sv, sw))
        poses[name] = np.c_[P[:, 1], P[:, 2], R[:, 3]]
        rates[name] = np.c_[V[:, 1], V[:, 2], W[:, 3]]
    # Sensors hold t = 0 and every step (n + 1 rows).
    if len(poses["crank"]) != n + 1:
        r.ok, r.note = False, f"{len(poses['crank'])} sensor rows for {n} steps"
        return r
    theta = fb.theta1_0 + poses["crank"][grid_indices(T_END / n), 2]
    return r.finish(energy(fb, poses, rates), loop_gap(fb, poses), theta, ref_grid)
