"""A library of planar linkages and parallel robots, each a parametrised constructor.

Every mechanism comes as a pair of functions: ``<name>_model(...)`` builds the model dict
(the model-file schema, docs/model-format.md) and ``<name>(...)`` validates it into a
:class:`~planardyn.Mechanism` (``planardyn.from_dict``). The shipped files
``examples/models/library/<name>.yaml`` are these dicts at their defaults, written by
:func:`write_model` (regenerate them all with ``python -m planardyn.library``).

Conventions shared by every constructor:

- Units SI: lengths in m, angles in rad (counter-clockwise from the x axis), masses in kg.
- Links are uniform slender bars of ``rho`` kg per metre (mass rho L, inertia m L^2 / 12)
  unless said otherwise; a link with three or more pins (a ternary link, a platform) is
  the triangle (polygon) of uniform bars along its sides, each of rho kg per metre.
- The drawing is computed from the inputs (or, for the 3-DOF robots, from the platform
  pose) by circle (or line-circle) intersections; where two solutions exist an argument
  ``mode`` (+1 or -1) chooses one: +1 puts the new point on the **left** of the directed
  line from the first known centre to the second (counter-clockwise side), -1 on the right.
  Each constructor says which line that is. ``ValueError`` if the chosen geometry cannot be
  assembled (the circles do not meet).
- ``gravity`` (m/s^2), default [0, -9.81]: the mechanisms hang in a vertical plane.
- Coordinates are the input pairs' relative angles (rad) or displacements (m), with the
  drawn value of the physical quantity (a crank's absolute angle, a slider's position along
  its rail from the rail's origin, a leg's pin-to-pin length) as ``value``.
"""

from __future__ import annotations

import functools
import math
import os
import sys
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from . import models
from .arguments import array, error, positive
from .builder import Builder
from .mechanism import Mechanism, from_dict, load_example
from .model_text import model_text

Vec = tuple[float, float]
GRAVITY: Vec = (0.0, -9.81)
#: Default mass per unit length of the bars (kg/m).
RHO = 1.0

__all__ = [
    "LIBRARY",
    "andrews_squeezer",
    "biglide",
    "biglide_model",
    "circle_intersection",
    "double_parallelogram",
    "double_parallelogram_model",
    "draw_all",
    "five_bar",
    "five_bar_model",
    "four_bar",
    "four_bar_model",
    "grashof",
    "model_text",
    "slider_crank",
    "slider_crank_model",
    "slider_crank_slider_driven",
    "slider_crank_slider_driven_model",
    "stephenson_six_bar",
    "stephenson_six_bar_model",
    "three_prr",
    "three_prr_model",
    "three_rpr",
    "three_rpr_model",
    "three_rrr",
    "three_rrr_model",
    "watt_six_bar",
    "watt_six_bar_model",
    "write_all",
    "write_model",
]


# ----------------------------------------------------------------------------- geometry


def _add(p: Vec, q: Vec) -> Vec:
    return (p[0] + q[0], p[1] + q[1])


def _sub(p: Vec, q: Vec) -> Vec:
    return (p[0] - q[0], p[1] - q[1])


def _polar(r: float, angle: float) -> Vec:
    return (r * math.cos(angle), r * math.sin(angle))


def _dist(p: Vec, q: Vec) -> float:
    return math.hypot(q[0] - p[0], q[1] - p[1])


def _angle(p: Vec, q: Vec) -> float:
    return math.atan2(q[1] - p[1], q[0] - p[0])


def _rotate(v: Vec, angle: float) -> Vec:
    c, s = math.cos(angle), math.sin(angle)
    return (c * v[0] - s * v[1], s * v[0] + c * v[1])


def _unit(v: Vec) -> Vec:
    n = math.hypot(*v)
    if n == 0.0:
        raise error("direction", "a direction of zero length: give two distinct points")
    return (v[0] / n, v[1] / n)


def circle_intersection(c1: Sequence[float], r1: float, c2: Sequence[float], r2: float, mode: int) -> Vec:
    """The point at distance r1 from c1 and r2 from c2 (m), on the left of c1 -> c2 for
    ``mode=+1``, on the right for ``mode=-1``. :class:`~planardyn.ArgumentError` (a
    ``ValueError``) when the circles do not meet, or an argument is not finite."""
    _check_mode(mode)
    p1, p2 = (tuple(array(n, c, shape=(2,), what="a point (x, y), m")) for n, c in (("c1", c1), ("c2", c2)))
    r1, r2 = positive("r1", r1, "m"), positive("r2", r2, "m")
    c1, c2 = (p1[0], p1[1]), (p2[0], p2[1])
    d = _dist(c1, c2)
    if d == 0.0 or d > r1 + r2 or d < abs(r1 - r2):
        raise error(None, f"cannot assemble: circles of radii r1 = {r1:g} and r2 = {r2:g} m with centres c1, c2 "
                          f"{d:g} m apart do not meet (need |r1 - r2| <= d <= r1 + r2): change the lengths or the "
                          "input values")
    a = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d)
    h = math.sqrt(max(r1 * r1 - a * a, 0.0))
    e = ((c2[0] - c1[0]) / d, (c2[1] - c1[1]) / d)
    point = (c1[0] + a * e[0] - mode * h * e[1], c1[1] + a * e[1] + mode * h * e[0])
    if not all(math.isfinite(v) for v in point):
        raise error(None, f"circles of radii r1 = {r1:g} and r2 = {r2:g} m about c1, c2 are too large to intersect "
                          "in floating point (overflow): give lengths in metres of a drawable size")
    return point


def _line_circle(origin: Vec, direction: Vec, centre: Vec, r: float, mode: int) -> float:
    """Parameter s of the point origin + s d (d unit) at distance r from centre: the larger
    root for mode=+1, the smaller for -1."""
    _check_mode(mode)
    d = _unit(direction)
    w = _sub(origin, centre)
    b = w[0] * d[0] + w[1] * d[1]
    c = w[0] ** 2 + w[1] ** 2 - r * r
    disc = b * b - c
    if disc < 0.0:
        raise error(None, f"cannot assemble: the rail through {origin} does not reach the circle of radius {r:g} m "
                          f"about {centre}: lengthen the link or move the rail")
    return -b + mode * math.sqrt(disc)


def _check_mode(mode: int) -> None:
    if isinstance(mode, bool) or mode not in (1, -1):
        raise error("mode", f"mode must be +1 or -1 (the assembly branch), got {mode!r}")


def grashof(ground: float, crank: float, coupler: float, rocker: float) -> bool:
    """Grashof's condition s + l <= p + q of a four-bar: some link turns fully."""
    links = sorted([ground, crank, coupler, rocker])
    return links[0] + links[3] <= links[1] + links[2]


def _mechanism(model_fn: Callable[..., dict[str, Any]]) -> Callable[..., Mechanism]:
    """``f(...)`` = ``from_dict(f_model(...))``, with the model function's signature and doc."""

    @functools.wraps(model_fn)
    def build(*args: Any, **kwargs: Any) -> Mechanism:
        return from_dict(model_fn(*args, **kwargs), source=f"<planardyn.library.{build.__name__}>")

    build.__name__ = build.__qualname__ = model_fn.__name__.removesuffix("_model")
    build.__doc__ = (model_fn.__doc__ or "").replace("The model dict of", "A validated Mechanism:", 1)
    return build


# ----------------------------------------------------------------------------- single loops


def four_bar_model(
    ground: float = 1.0,
    crank: float = 0.5,
    coupler: float = 1.2,
    rocker: float = 1.0,
    theta: float = math.pi / 3,
    mode: int = 1,
    rho: float = RHO,
    gravity: Sequence[float] = GRAVITY,
) -> dict[str, Any]:
    """The model dict of a four-bar: crank O-A, coupler A-B, rocker D-B, ground O-D.

    O = (0, 0), D = (ground, 0); A = O + crank (cos theta, sin theta); B where the coupler
    (from A) meets the rocker (from D), on the left of A -> D for ``mode=+1``. Input
    ``theta1``: the crank's absolute angle (rad). Defaults: the crank-rocker of
    ``four-bar-gravity.yaml``. Mobility 3*3 - 2*4 = 1.
    """
    m = Builder("four-bar", "Four-bar linkage O-A-B-D, uniform bars, crank angle input (planardyn.library.four_bar).", gravity)
    O, D = m.point("O", (0.0, 0.0)), m.point("D", (ground, 0.0))
    A = m.point("A", _polar(crank, theta))
    m.point("B", circle_intersection(m.xy(A), coupler, m.xy(D), rocker, mode))
    m.ground(O, D)
    m.bars(rho, crank=("O", "A"), coupler=("A", "B"), rocker=("D", "B"))
    m.hinges(("O", "ground", "crank"), ("A", "crank", "coupler"), ("B", "coupler", "rocker"), ("D", "ground", "rocker"))
    m.coordinate("theta1", "ground_crank", theta, "absolute angle of O->A (rad)")
    return m.model


def _slider_crank(
    m: Builder, A: Vec, B: Vec, rho: float, slider_mass: float, slider_inertia: float
) -> None:
    m.point("O", (0.0, 0.0))
    m.point("A", A)
    m.point("B", B)
    m.ground("O")
    m.bars(rho, crank=("O", "A"), rod=("A", "B"))
    m.block("slider", "B", slider_mass, slider_inertia)
    m.revolute("crank_pivot", "O", "ground", "crank")
    m.revolute("crank_pin", "A", "crank", "rod")
    m.revolute("wrist_pin", "B", "rod", "slider")
    m.prismatic("guide", "B", "ground", "slider", axis=(1.0, 0.0))


def slider_crank_model(
    crank: float = 0.1,
    rod: float = 0.3,
    offset: float = 0.0,
    theta: float = math.pi / 3,
    mode: int = 1,
    rho: float = RHO,
    slider_mass: float = 0.5,
    slider_inertia: float = 1.0e-3,
    gravity: Sequence[float] = GRAVITY,
) -> dict[str, Any]:
    """The model dict of a slider-crank driven by its crank.

    Crank O-A (O = (0, 0), A at angle theta), connecting rod A-B, slider block B on a
    horizontal guide y = offset (mass ``slider_mass`` kg, inertia ``slider_inertia``
    kg m^2). B is right of A for ``mode=+1``, left for -1. Input ``theta``: the crank's
    absolute angle (rad). Mobility 3*3 - 2*4 = 1.
    """
    _check_mode(mode)
    A = _polar(crank, theta)
    dy = offset - A[1]
    if abs(dy) > rod:
        raise error("rod", f"cannot assemble: the rod ({rod:g} m) does not reach the guide {abs(dy):g} m from the crank pin")
    B = (A[0] + mode * math.sqrt(rod * rod - dy * dy), float(offset))
    m = Builder("slider-crank (crank input)", "Slider-crank with a horizontal guide, crank angle input (planardyn.library.slider_crank).", gravity)
    _slider_crank(m, A, B, rho, slider_mass, slider_inertia)
    m.coordinate("theta", "crank_pivot", theta, "absolute angle of O->A (rad)")
    return m.model


def slider_crank_slider_driven_model(
    crank: float = 0.1,
    rod: float = 0.3,
    offset: float = 0.0,
    s: float = 0.3,
    mode: int = -1,
    rho: float = RHO,
    slider_mass: float = 0.5,
    slider_inertia: float = 1.0e-3,
    gravity: Sequence[float] = GRAVITY,
) -> dict[str, Any]:
    """The model dict of a slider-crank driven by its slider (a piston engine's kinematics).

    As :func:`slider_crank_model` with the slider at B = (s, offset) and the crank pin A
    where the crank (from O) meets the rod (from B), on the left of O -> B for
    ``mode=+1`` (above when B is right of O), right for -1 (the default: the crank hangs
    below the guide, away from the dead centres). Input ``s``: the slider's x (m), through
    the prismatic pair ``guide``. Mobility 3*3 - 2*4 = 1.
    """
    B = (float(s), float(offset))
    A = circle_intersection((0.0, 0.0), crank, B, rod, mode)
    m = Builder("slider-crank (slider input)", "Slider-crank with a horizontal guide, slider position input (planardyn.library.slider_crank_slider_driven).", gravity)
    _slider_crank(m, A, B, rho, slider_mass, slider_inertia)
    m.coordinate("s", "guide", s, "x of the slider pin B (m)")
    return m.model


def five_bar_model(
    base: float = 0.2,
    proximal: float = 0.2,
    distal: float = 0.25,
    theta1: float = 2 * math.pi / 3,
    theta2: float = math.pi / 3,
    mode: int = 1,
    rho: float = RHO,
    gravity: Sequence[float] = GRAVITY,
) -> dict[str, Any]:
    """The model dict of the five-bar 5R parallel robot.

    Base pivots A1 = (-base/2, 0), A2 = (base/2, 0); proximal links A_i-B_i at absolute
    angles theta_i; distal links B_i-P meeting at the end-effector P, on the left of
    B1 -> B2 for ``mode=+1`` (above, with B1 left of B2). Inputs ``theta1``, ``theta2``
    (rad). Mobility 3*4 - 2*5 = 2.
    """
    m = Builder("five-bar 5R", "Five-bar 5R parallel robot, uniform bars, two base angle inputs (planardyn.library.five_bar).", gravity)
    A1, A2 = m.point("A1", (-base / 2, 0.0)), m.point("A2", (base / 2, 0.0))
    m.point("B1", _add(m.xy(A1), _polar(proximal, theta1)))
    m.point("B2", _add(m.xy(A2), _polar(proximal, theta2)))
    m.point("P", circle_intersection(m.xy("B1"), distal, m.xy("B2"), distal, mode))
    m.ground(A1, A2)
    m.bars(rho, proximal1=("A1", "B1"), distal1=("B1", "P"), proximal2=("A2", "B2"), distal2=("B2", "P"))
    m.revolute("R1", "A1", "ground", "proximal1")
    m.revolute("elbow1", "B1", "proximal1", "distal1")
    m.revolute("tip", "P", "distal1", "distal2")
    m.revolute("elbow2", "B2", "proximal2", "distal2")
    m.revolute("R2", "A2", "ground", "proximal2")
    m.coordinate("theta1", "R1", theta1, "absolute angle of A1->B1 (rad)")
    m.coordinate("theta2", "R2", theta2, "absolute angle of A2->B2 (rad)")
    return m.model


def biglide_model(
    length: float = 0.3,
    s1: float = -0.2,
    s2: float = 0.2,
    rail_offset: float = 0.1,
    mode: int = 1,
    rho: float = RHO,
    slider_mass: float = 0.5,
    slider_inertia: float = 1.0e-3,
    gravity: Sequence[float] = GRAVITY,
) -> dict[str, Any]:
    """The model dict of the biglide (2-PRR): two sliders on parallel horizontal rails, two
    bars of equal ``length`` meeting at P.

    Sliders B1 = (s1, 0) and B2 = (s2, rail_offset) (blocks of ``slider_mass`` kg); P on
    the left of B1 -> B2 for ``mode=+1`` (above when s1 < s2). Inputs ``s1``, ``s2``: the
    sliders' x (m). With ``rail_offset=0`` the rails are one line and the sliders can meet
    (B1 = B2: the bars then fold onto each other, a change point of the passive
    mechanism); the default 0.1 m keeps them apart. Mobility 3*4 - 2*5 = 2.
    """
    m = Builder("biglide 2-PRR", "Biglide: two sliders on parallel horizontal rails, two bars to the end-effector (planardyn.library.biglide).", gravity)
    m.point("B1", (float(s1), 0.0))
    m.point("B2", (float(s2), float(rail_offset)))
    m.point("P", circle_intersection(m.xy("B1"), length, m.xy("B2"), length, mode))
    for i in (1, 2):
        m.block(f"slider{i}", f"B{i}", slider_mass, slider_inertia)
        m.bar(f"bar{i}", [f"B{i}", "P"], rho=rho)
    m.prismatic("rail1", "B1", "ground", "slider1", axis=(1.0, 0.0))
    m.revolute("hinge1", "B1", "slider1", "bar1")
    m.revolute("tip", "P", "bar1", "bar2")
    m.revolute("hinge2", "B2", "slider2", "bar2")
    m.prismatic("rail2", "B2", "ground", "slider2", axis=(1.0, 0.0))
    m.coordinate("s1", "rail1", s1, "x of slider 1 (m)")
    m.coordinate("s2", "rail2", s2, "x of slider 2 (m)")
    return m.model


# ----------------------------------------------------------------------------- 3-DOF robots


def _platform(m: Builder, base_radius: float, platform_radius: float, pose: Sequence[float], base_offset: float) -> None:
    """Base points A_i on a circle (angles 90 + 120 i deg + base_offset), the platform's
    centre P and its pins C_i at angles 90 + 120 i deg + pose[2] about P."""
    x, y, phi = (float(v) for v in pose)
    m.point("P", (x, y))
    for i in (1, 2, 3):
        a = math.pi / 2 + 2 * math.pi * (i - 1) / 3
        m.point(f"A{i}", _polar(base_radius, a + base_offset))
        m.point(f"C{i}", _add((x, y), _polar(platform_radius, a + phi)))


def _platform_body(m: Builder, rho: float) -> None:
    m.polygon("platform", ["P", "C1", "C2", "C3"], ["C1", "C2", "C3"], rho,
              about="triangle C1 C2 C3 of uniform bars, end-effector point P at its centre")


def three_rrr_model(
    base_radius: float = 0.5,
    platform_radius: float = 0.1,
    proximal: float = 0.3,
    distal: float = 0.3,
    pose: Sequence[float] = (0.0, 0.0, 0.0),
    modes: Sequence[int] = (1, 1, 1),
    rho: float = RHO,
    gravity: Sequence[float] = GRAVITY,
) -> dict[str, Any]:
    """The model dict of the symmetric 3-RRR planar parallel robot, drawn at a platform pose.

    Base pivots A_i on a circle of ``base_radius`` (at 90, 210, 330 deg), platform pins C_i
    on a circle of ``platform_radius`` about the platform centre P = (x, y), turned by phi
    (``pose = (x, y, phi)``, m, m, rad). Elbow B_i: at ``proximal`` from A_i and ``distal``
    from C_i, on the left of A_i -> C_i for ``modes[i] = +1`` (the working mode of leg i).
    Inputs ``theta1..3``: absolute angles of A_i -> B_i (rad). Mobility 3*7 - 2*9 = 3.
    """
    m = Builder("3-RRR", "Symmetric 3-RRR planar parallel robot, uniform bars, three base angle inputs (planardyn.library.three_rrr).", gravity)
    _platform(m, base_radius, platform_radius, pose, 0.0)
    for i in (1, 2, 3):
        m.point(f"B{i}", circle_intersection(m.xy(f"A{i}"), proximal, m.xy(f"C{i}"), distal, modes[i - 1]))
    m.ground("A1", "A2", "A3")
    for i in (1, 2, 3):
        m.bar(f"proximal{i}", [f"A{i}", f"B{i}"], rho=rho)
        m.bar(f"distal{i}", [f"B{i}", f"C{i}"], rho=rho)
    _platform_body(m, rho)
    for i in (1, 2, 3):
        m.revolute(f"R{i}", f"A{i}", "ground", f"proximal{i}")
        m.revolute(f"elbow{i}", f"B{i}", f"proximal{i}", f"distal{i}")
        m.revolute(f"wrist{i}", f"C{i}", f"distal{i}", "platform")
    for i in (1, 2, 3):
        m.coordinate(f"theta{i}", f"R{i}", _angle(m.xy(f"A{i}"), m.xy(f"B{i}")), f"absolute angle of A{i}->B{i} (rad)")
    return m.model


def three_rpr_model(
    base_radius: float = 0.5,
    platform_radius: float = 0.1,
    pose: Sequence[float] = (0.0, 0.0, 0.5),
    barrel: float = 0.3,
    rod: float = 0.3,
    rho: float = RHO,
    gravity: Sequence[float] = GRAVITY,
) -> dict[str, Any]:
    """The model dict of the 3-RPR planar parallel robot with actuated legs.

    Base pivots A_i and platform pins C_i as in :func:`three_rrr_model` (no elbow: the
    drawing is fixed by the pose). Each leg is two bodies: a cylinder barrel A_i-E_i
    (``barrel`` m long, pivoted to ground at A_i) and a rod K_i-C_i (``rod`` m long, pinned
    to the platform at C_i) sliding in it along A_i -> C_i: a relative prismatic pair at
    the piston point K_i. Inputs ``L1..3``: the legs' pin-to-pin lengths |A_i C_i| (m).
    The default pose turns the platform by 0.5 rad so that the legs are not concurrent
    (a type II singularity). Mobility 3*7 - 2*9 = 3.
    """
    m = Builder("3-RPR", "3-RPR planar parallel robot, legs are cylinders (barrel + rod) with a relative prismatic input (planardyn.library.three_rpr).", gravity)
    _platform(m, base_radius, platform_radius, pose, 0.0)
    lengths = []
    for i in (1, 2, 3):
        A, C = m.xy(f"A{i}"), m.xy(f"C{i}")
        L = _dist(A, C)
        if not L - rod < barrel:
            raise error("rod", f"leg {i}: length {L:g} m leaves the rod's end outside the barrel (rod + barrel = {rod + barrel:g} m)")
        u = _unit(_sub(C, A))
        m.point(f"E{i}", _add(A, (barrel * u[0], barrel * u[1])))
        m.point(f"K{i}", _add(A, ((L - rod) * u[0], (L - rod) * u[1])))
        lengths.append((L, u))
    m.ground("A1", "A2", "A3")
    for i in (1, 2, 3):
        m.bar(f"barrel{i}", [f"A{i}", f"E{i}"], rho=rho, about=f"cylinder barrel of leg {i}")
        m.bar(f"rod{i}", [f"K{i}", f"C{i}"], rho=rho, about=f"piston rod of leg {i}, piston at K{i}")
    _platform_body(m, rho)
    for i, (_, u) in zip((1, 2, 3), lengths):
        m.revolute(f"base{i}", f"A{i}", "ground", f"barrel{i}")
        m.prismatic(f"leg{i}", f"K{i}", f"barrel{i}", f"rod{i}", axis=u)
        m.revolute(f"wrist{i}", f"C{i}", f"rod{i}", "platform")
    for i, (L, _u) in zip((1, 2, 3), lengths):
        m.coordinate(f"L{i}", f"leg{i}", L, f"pin-to-pin length |A{i} C{i}| of leg {i} (m)")
    return m.model


def three_prr_model(
    base_radius: float = 0.3,
    platform_radius: float = 0.1,
    distal: float = 0.3,
    pose: Sequence[float] = (0.0, 0.0, 0.0),
    modes: Sequence[int] = (1, 1, 1),
    rho: float = RHO,
    slider_mass: float = 0.5,
    slider_inertia: float = 1.0e-3,
    gravity: Sequence[float] = GRAVITY,
) -> dict[str, Any]:
    """The model dict of the 3-PRR planar parallel robot: three sliders on fixed rails.

    Rail i passes through A_i (on a circle of ``base_radius`` at 90, 210, 330 deg) along
    the circle's tangent (the rails are the sides of an equilateral triangle), direction
    t_i = (-sin, cos) of A_i's angle. Platform pins C_i as in :func:`three_rrr_model`. The
    slider B_i is where the rail meets the circle of radius ``distal`` about C_i: the
    larger s_i (further along t_i) for ``modes[i] = +1``. Inputs ``s1..3``: B_i's position
    along its rail from A_i (m). Mobility 3*7 - 2*9 = 3.
    """
    m = Builder("3-PRR", "3-PRR planar parallel robot, sliders on three fixed rails (planardyn.library.three_prr).", gravity)
    _platform(m, base_radius, platform_radius, pose, 0.0)
    s, t = [], []
    for i in (1, 2, 3):
        a = math.pi / 2 + 2 * math.pi * (i - 1) / 3
        ti = (-math.sin(a), math.cos(a))
        si = _line_circle(m.xy(f"A{i}"), ti, m.xy(f"C{i}"), distal, modes[i - 1])
        m.point(f"B{i}", _add(m.xy(f"A{i}"), (si * ti[0], si * ti[1])))
        s.append(si)
        t.append(ti)
    m.ground("A1", "A2", "A3")
    for i in (1, 2, 3):
        m.block(f"slider{i}", f"B{i}", slider_mass, slider_inertia)
        m.bar(f"distal{i}", [f"B{i}", f"C{i}"], rho=rho)
    _platform_body(m, rho)
    for i in (1, 2, 3):
        m.prismatic(f"rail{i}", f"B{i}", "ground", f"slider{i}", axis=t[i - 1])
        m.revolute(f"hinge{i}", f"B{i}", f"slider{i}", f"distal{i}")
        m.revolute(f"wrist{i}", f"C{i}", f"distal{i}", "platform")
    for i in (1, 2, 3):
        m.coordinate(f"s{i}", f"rail{i}", s[i - 1], f"position of slider {i} along rail {i} from A{i} (m)")
    return m.model


# ----------------------------------------------------------------------------- six-bars


def watt_six_bar_model(
    crank: float = 0.3,
    coupler1: float = 1.0,
    rocker: float = 0.8,
    rocker_arm: float = 0.5,
    arm_angle: float = -math.pi / 2,
    coupler2: float = 0.9,
    output: float = 0.7,
    o2: Sequence[float] = (1.0, 0.0),
    o3: Sequence[float] = (1.8, 0.0),
    theta: float = math.pi / 3,
    modes: Sequence[int] = (1, 1),
    rho: float = RHO,
    gravity: Sequence[float] = GRAVITY,
) -> dict[str, Any]:
    """The model dict of a Watt six-bar (Watt II): two four-bars in series sharing the
    ternary rocker.

    Crank O1-A (O1 = (0, 0), angle theta), coupler A-B, ternary rocker O2-B-C (arm O2-C of
    ``rocker_arm`` m at ``arm_angle`` rad from O2 -> B), second coupler C-E, output rocker
    O3-E. B on the left of A -> O2 for ``modes[0] = +1``, E on the left of C -> O3 for
    ``modes[1] = +1``. The ternary rocker is the triangle O2 B C of uniform bars. Input
    ``theta1``: the crank's absolute angle (rad). The two ternary links (ground O1 O2 O3
    and the rocker) are joined at O2: Watt's chain. Mobility 3*5 - 2*7 = 1.
    """
    m = Builder("Watt six-bar", "Watt six-bar (Watt II): four-bar O1-A-B-O2 driving four-bar O2-C-E-O3 through the ternary rocker O2-B-C (planardyn.library.watt_six_bar).", gravity)
    O1, O2, O3 = m.point("O1", (0.0, 0.0)), m.point("O2", (o2[0], o2[1])), m.point("O3", (o3[0], o3[1]))
    m.point("A", _polar(crank, theta))
    m.point("B", circle_intersection(m.xy("A"), coupler1, m.xy(O2), rocker, modes[0]))
    m.point("C", _add(m.xy(O2), _polar(rocker_arm, _angle(m.xy(O2), m.xy("B")) + arm_angle)))
    m.point("E", circle_intersection(m.xy("C"), coupler2, m.xy(O3), output, modes[1]))
    m.ground(O1, O2, O3)
    m.bars(rho, crank=("O1", "A"), coupler1=("A", "B"))
    m.polygon("rocker", ["O2", "B", "C"], ["O2", "B", "C"], rho, about="ternary rocker O2-B-C")
    m.bars(rho, coupler2=("C", "E"), output=("O3", "E"))
    m.hinges(("O1", "ground", "crank"), ("A", "crank", "coupler1"), ("B", "coupler1", "rocker"),
             ("O2", "ground", "rocker"), ("C", "rocker", "coupler2"), ("E", "coupler2", "output"),
             ("O3", "ground", "output"))
    m.coordinate("theta1", "ground_crank", theta, "absolute angle of O1->A (rad)")
    return m.model


def stephenson_six_bar_model(
    o1: Sequence[float] = (0.0, 0.0),
    o2: Sequence[float] = (0.6, 0.0),
    o3: Sequence[float] = (1.2, 0.0),
    crank: float = 0.25,
    theta: float = -math.pi / 3,
    triangle: Sequence[Sequence[float]] = ((-0.15, 0.0), (0.15, 0.0), (0.2, -0.15)),
    pose: Sequence[float] = (0.3, -0.6, 0.0),
    rho: float = RHO,
    gravity: Sequence[float] = GRAVITY,
) -> dict[str, Any]:
    """The model dict of a Stephenson six-bar whose inputs leave a triad (class III group).

    Stephenson's chain: the two ternary links (the ground, pivots O1 O2 O3, and the
    floating triangle J1 J2 J3) are not joined to each other. Here the ground carries the
    crank O3-D (input ``theta1``, its absolute angle), and the triangle hangs from O1 and
    O2 by the binary links O1-J1 and O2-J2 and is driven by the link D-J3. With the crank
    fixed, the triangle and its three binary links form one Assur triad: no circle
    intersection gives the drawing, so it is given by the triangle's pose instead:
    ``triangle`` the vertices J1 J2 J3 in its own frame (m), ``pose = (x, y, phi)`` where it
    is drawn (m, m, rad); the binary links' lengths follow. Mobility 3*5 - 2*7 = 1.
    """
    m = Builder("Stephenson six-bar", "Stephenson six-bar: ground O1 O2 O3 and the triangle J1 J2 J3 are the ternary links; crank O3-D input; the triangle with links O1-J1, O2-J2, D-J3 is an Assur triad (planardyn.library.stephenson_six_bar).", gravity)
    for name, p in (("O1", o1), ("O2", o2), ("O3", o3)):
        m.point(name, (float(p[0]), float(p[1])))
    m.point("D", _add(m.xy("O3"), _polar(crank, theta)))
    x, y, phi = (float(v) for v in pose)
    for k, v in enumerate(triangle, start=1):
        m.point(f"J{k}", _add((x, y), _rotate((float(v[0]), float(v[1])), phi)))
    m.ground("O1", "O2", "O3")
    m.bars(rho, crank=("O3", "D"), link1=("O1", "J1"), link2=("O2", "J2"), link3=("D", "J3"))
    m.polygon("triangle", ["J1", "J2", "J3"], ["J1", "J2", "J3"], rho, about="floating ternary link")
    m.hinges(("O3", "ground", "crank"), ("D", "crank", "link3"), ("O1", "ground", "link1"), ("O2", "ground", "link2"),
             ("J1", "link1", "triangle"), ("J2", "link2", "triangle"), ("J3", "link3", "triangle"))
    m.coordinate("theta1", "ground_crank", theta, "absolute angle of O3->D (rad)")
    return m.model


def double_parallelogram_model(
    crank: float = 0.3,
    spacing: float = 0.4,
    theta: float = -math.pi / 3,
    rho: float = RHO,
    gravity: Sequence[float] = GRAVITY,
) -> dict[str, Any]:
    """The model dict of a double parallelogram: three equal parallel cranks O_i-A_i
    (O_i = ((i - 1) spacing, 0), angle theta) carrying one coupler A1-A2-A3.

    A mechanism with a redundant constraint: Grubler counts 3*4 - 2*6 = 0, yet it moves
    with one degree of freedom (the third crank repeats the motion the first parallelogram
    already imposes; the rank of the constraint Jacobian is 11, not 12). The loader
    requires independent constraints and refuses it (see ``planardyn.structure`` for the
    analysis). Input ``theta1``: the first crank's absolute angle (rad); the default
    hangs the cranks at -60 deg, so that the passive swing stays away from theta = 0 and pi
    where the parallelograms fold (a change point).
    """
    m = Builder("double parallelogram", "Double parallelogram: three parallel cranks and one coupler; one redundant constraint (planardyn.library.double_parallelogram).", gravity)
    for i in (1, 2, 3):
        m.point(f"O{i}", ((i - 1) * spacing, 0.0))
        m.point(f"A{i}", _add(m.xy(f"O{i}"), _polar(crank, theta)))
    m.ground("O1", "O2", "O3")
    for i in (1, 2, 3):
        m.bar(f"crank{i}", [f"O{i}", f"A{i}"], rho=rho)
    m.bar("coupler", ["A1", "A3", "A2"], rho=rho)
    for i in (1, 2, 3):
        m.hinges((f"O{i}", "ground", f"crank{i}"), (f"A{i}", f"crank{i}", "coupler"))
    m.coordinate("theta1", "ground_crank1", theta, "absolute angle of O1->A1 (rad)")
    return m.model


four_bar = _mechanism(four_bar_model)
slider_crank = _mechanism(slider_crank_model)
slider_crank_slider_driven = _mechanism(slider_crank_slider_driven_model)
five_bar = _mechanism(five_bar_model)
biglide = _mechanism(biglide_model)
three_rrr = _mechanism(three_rrr_model)
three_rpr = _mechanism(three_rpr_model)
three_prr = _mechanism(three_prr_model)
watt_six_bar = _mechanism(watt_six_bar_model)
stephenson_six_bar = _mechanism(stephenson_six_bar_model)
double_parallelogram = _mechanism(double_parallelogram_model)

#: Where the shipped model files are (package data, ``planardyn.models``).
MODELS_DIR = models.directory()
#: The library's own files, written from the constructors' defaults.
LIBRARY_DIR = MODELS_DIR / models.LIBRARY


def andrews_squeezer() -> Mechanism:
    """Andrews' squeezing mechanism: the shipped model ``andrews-squeezer``
    (7 bodies, 10 revolute pairs, crank angle ``beta``; Hairer & Wanner's benchmark)."""
    return load_example("andrews-squeezer")


#: File stem -> model function (at its defaults), for every mechanism built here.
LIBRARY: dict[str, Callable[..., dict[str, Any]]] = {
    "four-bar": four_bar_model,
    "slider-crank": slider_crank_model,
    "slider-crank-slider-driven": slider_crank_slider_driven_model,
    "five-bar-5r": five_bar_model,
    "biglide": biglide_model,
    "3-rrr": three_rrr_model,
    "3-rpr": three_rpr_model,
    "3-prr": three_prr_model,
    "watt-six-bar": watt_six_bar_model,
    "stephenson-six-bar": stephenson_six_bar_model,
    "double-parallelogram": double_parallelogram_model,
}


# ----------------------------------------------------------------------------- writing files

def write_model(mech_or_model: Mechanism | Mapping[str, Any], path: str | os.PathLike[str], header: str | None = None) -> Path:
    """Write a mechanism (its :meth:`~planardyn.Mechanism.to_dict`) or a model dict as a
    YAML model file (:func:`model_text`); returns the path."""
    model = mech_or_model.to_dict() if isinstance(mech_or_model, Mechanism) else mech_or_model
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(model_text(model, header))
    return path


def file_header(stem: str) -> str:
    fn = LIBRARY[stem].__name__.removesuffix("_model")
    return (
        f"planardyn model file, generated by planardyn.library.{fn}() at its defaults.\n"
        "Do not edit: regenerate with `python -m planardyn.library` (tests/test_library.py\n"
        "checks that this file is what the constructor gives). Units SI; docs/library.md."
    )


def write_all(directory: str | os.PathLike[str] = LIBRARY_DIR) -> list[Path]:
    """Write every library mechanism at its defaults to ``directory/<stem>.yaml``."""
    return [write_model(fn(), Path(directory) / f"{stem}.yaml", file_header(stem)) for stem, fn in LIBRARY.items()]


def draw_all(directory: str | os.PathLike[str]) -> list[Path]:
    """Draw every library mechanism (and Andrews' squeezer) at its defaults into
    ``directory/library-<stem>.png`` with :func:`planardyn.plot.draw_mechanism` (the
    pictures of docs/library.md)."""
    import warnings

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .plot import draw_mechanism

    out = []
    items: list[tuple[str, Callable[[], Mechanism]]] = [
        (stem, functools.partial(lambda f, source: from_dict(f(), source=source), fn, stem)) for stem, fn in LIBRARY.items()
    ]
    items.append(("andrews-squeezer", andrews_squeezer))
    for stem, make in items:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the double parallelogram's redundancy warning
            mech = make()
        fig, ax = plt.subplots(figsize=(4.5, 4.0), dpi=100)
        draw_mechanism(mech, ax=ax)
        ax.set_title(mech.name)
        path = Path(directory) / f"library-{stem}.png"
        path.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path, bbox_inches="tight")
        plt.close(fig)
        out.append(path)
    return out


if __name__ == "__main__":
    # python -m planardyn.library [MODEL_DIR [PICTURE_DIR]], run from the repository's root
    for p in write_all(sys.argv[1] if len(sys.argv) > 1 else LIBRARY_DIR):
        print(p)
    for p in draw_all(sys.argv[2] if len(sys.argv) > 2 else Path("docs") / "img"):
        print(p)
