"""A run computed in Python as the browser app plays it (:mod:`planardyn.app`): per frame the
carried points' positions and each pair's drawing, and every channel a user may plot
(coordinates, rates, accelerations, efforts, energies, the singularity measure, pair forces,
points' speeds and accelerations) with its unit, rounded to ``DIGITS`` significant digits so
that the page stays small. The page plays it without its engine (web/src/replay.js); the same
JSON opened or dropped on the app plays too.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ._core import PlanardynError, __version__
from .arguments import error
from .playback import auto_speed
from .plot import trace_points
from .units import group_unit

if TYPE_CHECKING:
    from .mechanism import Mechanism
    from .result import SimulationResult

#: Frames kept in the page at most (longer results are subsampled uniformly).
MAX_FRAMES = 1500
#: Significant digits kept for positions (relative to the mechanism's size) and channels.
DIGITS = 6
#: Smallest time scale (s) the rounding of output times is relative to: a run near t = 0
#: keeps its times to DIGITS digits of a millisecond, not of zero.
MIN_TIME_SCALE = 1e-3


def _round(a: np.ndarray, scale: float) -> list:
    """Round to DIGITS significant digits of ``scale`` (keeps the page small); NaN -> None."""
    scale = scale if scale > 0 and math.isfinite(scale) else 1.0
    dec = max(0, DIGITS - 1 - int(math.floor(math.log10(scale))))
    out = np.round(np.asarray(a, dtype=float), dec).tolist()
    return _nan_to_none(out)


def _flatten(v: Any) -> list[float]:
    """The numbers of nested tuples and lists, in order."""
    if isinstance(v, (list, tuple)):
        return [x for u in v for x in _flatten(u)]
    return [float(v)]


def _nan_to_none(v: Any) -> Any:
    if isinstance(v, list):
        return [_nan_to_none(u) for u in v]
    return None if isinstance(v, float) and not math.isfinite(v) else v


def _along_channels(mech: Mechanism, result: SimulationResult, keep: np.ndarray,
                    traces: list[str]) -> tuple[list, list]:
    """(groups, channels) of the pairs' force magnitudes (N) and the traced points' speeds
    (m/s) and accelerations (m/s²) at the frames kept, each frame on its own branch; none
    when a frame cannot be computed (a singular row of an imported motion)."""
    frames = result.take(keep)
    try:
        reactions = mech.reactions(frames, allow_singular=True)
        pts = mech.point_motion(frames, allow_singular=True)
    except (PlanardynError, ValueError):
        return [], []
    groups = [{"key": "reactions", "label": "pair forces", "unit": "N"},
              {"key": "speeds", "label": "point speeds", "unit": "m/s"},
              {"key": "point_accelerations", "label": "point accelerations", "unit": "m/s²"}]
    chans: list[dict[str, Any]] = []
    for j, name in enumerate(mech.pair_names):
        force = np.hypot(reactions[:, j, 0], reactions[:, j, 1])
        chans.append({"key": f"F_{name}", "label": f"|F| {name}", "group": "reactions", "values": force, "unit": "N"})
    for p in traces:
        if p in pts.names:
            k = pts.names.index(p)
            for key, arr, group, unit in (("v", pts.velocity, "speeds", "m/s"),
                                          ("a", pts.acceleration, "point_accelerations", "m/s²")):
                chans.append({"key": f"{key}_{p}", "label": f"|{key}| {p}", "group": group,
                              "values": np.hypot(arr[:, k, 0], arr[:, k, 1]), "unit": unit})
    return groups, chans


def _channels(result: SimulationResult, keep: np.ndarray, selected: list[str] | None,
              extra: tuple[list, list] = ([], [])) -> tuple[list, list]:
    """(groups, channels): each channel a dict key, label, group, values, and ``on`` where
    ``selected`` names the channels opened (else the page chooses); ``extra`` groups and
    channels appended (computed along the trajectory)."""
    names, kinds = result.coordinate_names, result.coordinate_kinds
    # Per coordinate group: key, values, channel names, label, unit (on an angle, on a displacement).
    per_coordinate = [
        ("q", result.q, "{}", "coordinates", ("rad", "m")),
        ("qd", result.qd, "qd_{}", "rates", ("rad/s", "m/s")),
        ("qdd", result.qdd, "qdd_{}", "accelerations", ("rad/s²", "m/s²")),
        ("tau", result.tau, "tau_{}", "drive efforts", ("N m", "N")),
    ]
    groups = [{"key": g, "label": label, "unit": group_unit(kinds, *units, mixed="mixed")}
              for g, _, _, label, units in per_coordinate]
    groups += [
        {"key": "energy", "label": "energy", "unit": "J"},
        {"key": "sigma", "label": "singularity measure", "unit": "1"},
    ]
    chans: list[dict[str, Any]] = []
    for g, arr, fmt, _, (angle, displacement) in per_coordinate:
        for k, n in enumerate(names):
            chans.append({"key": fmt.format(n), "label": fmt.format(n), "group": g, "values": arr[keep, k],
                          "unit": angle if kinds[k] == "angle" else displacement})
    e = result.energy
    for key, label, arr in (("kinetic", "T", e.kinetic), ("potential", "V", e.potential),
                            ("total", "T + V", e.total), ("work", "W", e.work), ("balance", "balance", e.balance)):
        chans.append({"key": key, "label": label, "group": "energy", "values": arr[keep], "unit": "J"})
    chans.append({"key": "sigma", "label": "sigma", "group": "sigma", "values": result.sigma[keep], "unit": "1"})
    groups += extra[0]
    chans += extra[1]
    # Without a choice the page opens the run on the channels it opens its own runs on
    # (web/src/channels.js's defaultChannels).
    chosen = set(selected or ())
    unknown = chosen - {c["key"] for c in chans}
    if unknown:
        raise error(
            "channels", f"unknown channel(s) {', '.join(sorted(unknown))}; the channels are "
            f"{', '.join(c['key'] for c in chans)}"
        )
    for c in chans:
        if selected is not None:
            c["on"] = c["key"] in chosen
        v = np.asarray(c["values"], dtype=float)
        finite = v[np.isfinite(v)]
        c["values"] = _round(v, float(np.max(np.abs(finite))) if finite.size else 1.0)
    return groups, chans


def run_data(
    mech: Mechanism,
    result: SimulationResult,
    *,
    channels: list[str] | None = None,
    traces: list[str] | None = None,
    max_frames: int = MAX_FRAMES,
    title: str | None = None,
) -> dict[str, Any]:
    """The JSON-ready data of the run for the app.

    Parameters
    ----------
    mech : Mechanism
        The model the result was computed with.
    result : SimulationResult
        The trajectory (``result.x`` gives the positions).
    channels : list of str, optional
        Channels plotted at first (the page has a checkbox for every one): coordinate names,
        ``qd_<name>``, ``qdd_<name>``, ``tau_<name>``, ``kinetic``, ``potential``, ``total``,
        ``work``, ``balance``, ``sigma``, ``F_<pair>``, ``v_<point>``, ``a_<point>``; each
        channel's ``on`` says whether it is one of them. Default: no ``on`` in the data, and
        the page opens the run on the channels it opens its own runs on (the coordinates with
        the drive efforts that are not all zero, else with the energies that are not, else with
        the singularity measure: web/src/channels.js's ``defaultChannels``).
    traces : list of str, optional
        Points whose paths are drawn (default :func:`planardyn.plot.default_trace_points`).
    max_frames : int
        Outputs kept at most (uniformly subsampled beyond).
    title : str, optional
        The run's title (default the model's name).
    """
    n = len(result.t)
    if n == 0:
        raise ValueError("the result has no output to show")
    keep = np.unique(np.linspace(0, n - 1, min(n, max_frames)).round().astype(int))
    pos = mech.point_positions(result.x[keep])  # (K, P, 2)
    finite = pos[np.all(np.isfinite(pos), axis=2)]
    lo, hi = finite.min(axis=0), finite.max(axis=0)
    L = mech.scale
    pad = 0.12 * L
    names = mech.point_names
    traces = trace_points(mech, traces)
    # Each pair's drawing per frame from the core: flat lists of pins [x, y], blocks [x, y],
    # lines [x0, y0, x1, y1] and circles [x, y, r].
    frames = [mech.pair_geometry(xk) for xk in result.x[keep]]
    parts = ("pins", "blocks", "lines", "circles")
    joints = [
        {"name": pair["name"], "kind": pair["kind"]}
        | {part: [_round(np.array(_flatten(f[j][part])), L) for f in frames] for part in parts}
        for j, pair in enumerate(mech.pairs)
    ]
    groups, chans = _channels(result, keep, channels, _along_channels(mech, result, keep, traces))
    st = result.stats
    info = (
        f"{result.status}: {n} outputs, t = {result.t[0]:.4g}..{result.t[-1]:.4g} s; "
        f"{mech.dof} coordinate{'s' if mech.dof != 1 else ''} ({', '.join(mech.coordinate_names)}), "
        f"{mech.n_bodies} bod{'ies' if mech.n_bodies != 1 else 'y'}; "
        f"energy drift {result.energy.drift:.3g} J; min sigma {st.get('min_sigma', float(np.min(result.sigma))):.3g}"
    )
    t = result.t[keep]
    return {
        "title": title or mech.name,
        "info": info,
        "version": __version__,
        "t": _round(t, max(abs(t[0]), abs(t[-1]), MIN_TIME_SCALE)),
        "speed": auto_speed(result.t),
        "scale": L,
        "names": names,
        "P": _round(pos.reshape(len(keep), -1), L),
        "bodies": [{"name": b, "pts": [names.index(p) for p, _ in pts]}
                   for b, pts in zip(mech.body_names, mech.body_points)],
        "ground": [names.index(p) for p in mech.ground_points],
        "joints": joints,
        "traces": [names.index(p) for p in traces],
        "bounds": [float(lo[0] - pad), float(hi[0] + pad), float(lo[1] - 2 * pad), float(hi[1] + pad)],
        "groups": groups,
        "channels": chans,
    }
