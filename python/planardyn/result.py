"""The result of a simulation: time-major arrays, how the run ended, and its counters."""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import extras, results_format
from ._core import DenseOutput, Run, __version__
from .arguments import error

if TYPE_CHECKING:
    import pandas

FloatArray = NDArray[np.float64]
#: What the native run returns: a ``_core.Run`` from ``simulate``, a dict from a batch.
RawRun = Mapping[str, Any] | Run


@dataclass(frozen=True, repr=False)
class Energy:
    """Energies along a trajectory, (N,) each, in J.

    ``balance`` = total - work - (its value at the first output): zero along an exact
    trajectory, so its size measures the integration error.
    """

    kinetic: FloatArray
    potential: FloatArray
    #: Work done by the non-conservative forces (drives, dampers, external loads) since t0.
    work: FloatArray
    total: FloatArray
    balance: FloatArray

    @classmethod
    def from_arrays(cls, kinetic: FloatArray, potential: FloatArray, work: FloatArray) -> Energy:
        total = kinetic + potential
        balance = total - work
        if len(balance):
            balance -= balance[0]  # in place: one temporary fewer on a short run's path
        # Every field at once, as SimulationResult.from_raw (the frozen __init__ sets them one by one).
        energy = object.__new__(cls)
        energy.__dict__.update(kinetic=kinetic, potential=potential, work=work, total=total, balance=balance)
        return energy

    @property
    def drift(self) -> float:
        """Largest |balance| (J), 0 for an empty trajectory."""
        return float(np.max(np.abs(self.balance))) if len(self.balance) else 0.0

    def __repr__(self) -> str:
        return f"Energy(N={len(self.kinetic)}, drift={self.drift:.3g} J)"


#: The output columns that are entries of :class:`Energy` (``result.energy.kinetic``, ...);
#: every other column is the result's field of its name.
ENERGY_COLUMNS = tuple(c.name for c in results_format.COLUMNS if c.name in {f.name for f in dataclasses.fields(Energy)})
#: The other columns, each a result's field of its name.
FIELD_COLUMNS = tuple(c.name for c in results_format.COLUMNS if c.name not in ENERGY_COLUMNS)


def column_fields(values: Mapping[str, Any], body_names: list[str]) -> dict[str, Any]:
    """A result's fields from its output columns by name (:data:`results_format.COLUMNS`, an
    optional one None or absent): each column is the field of its name, but the energies make
    ``energy``, and ``poses`` is ``x`` by body."""
    fields = {name: values.get(name) for name in FIELD_COLUMNS}
    fields["energy"] = Energy.from_arrays(values["kinetic"], values["potential"], values["work"])
    x = values["x"]
    fields["poses"] = x.reshape(x.shape[0], len(body_names), 3)
    return fields


def _dataframe(cols: Mapping[str, FloatArray]) -> pandas.DataFrame:
    """``cols`` as a DataFrame indexed by its ``t`` column (needs pandas)."""
    try:
        import pandas as pd
    except ImportError as e:
        raise extras.missing("pandas", "to_dataframe()", e) from e
    return pd.DataFrame(cols).set_index("t")


@dataclass(frozen=True, repr=False)
class PointMotion:
    """Positions, velocities and accelerations of named points along a trajectory
    (``Mechanism.point_motion``); each array (N, P, 2), points in the order of ``names``."""

    t: FloatArray
    names: list[str]
    position: FloatArray
    velocity: FloatArray
    acceleration: FloatArray

    def __getitem__(self, name: str) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Position (m), velocity (m/s) and acceleration (m/s^2) of one point, (N, 2) each."""
        if name not in self.names:
            raise KeyError(f"no point {name!r}; the points carried by a link are {', '.join(self.names)}")
        k = self.names.index(name)
        return self.position[:, k], self.velocity[:, k], self.acceleration[:, k]

    def describe(self, name: str) -> str:
        """One line on point ``name``: its range in x and in y (m; the travel, e.g. a ram's
        stroke, is max - min), its largest speed (m/s) and acceleration (m/s^2)."""
        position, velocity, acceleration = self[name]
        if not len(self.t):
            return f"{name}: no output"
        lo, hi = position.min(axis=0), position.max(axis=0)
        travel = ", ".join(f"{axis} {lo[j]:.6g} .. {hi[j]:.6g} m (travel {hi[j] - lo[j]:.4g} m)"
                           for j, axis in enumerate("xy"))
        speed, accel = np.hypot(*velocity.T).max(), np.hypot(*acceleration.T).max()
        return f"{name}: {travel}; peak speed {speed:.4g} m/s, peak acceleration {accel:.4g} m/s^2"

    def __repr__(self) -> str:
        span = f"t = {self.t[0]:.6g}..{self.t[-1]:.6g} s" if len(self.t) else "no output"
        return f"PointMotion(N={len(self.t)}, {span}, points=({', '.join(self.names)}))"

    def to_dataframe(self) -> pandas.DataFrame:
        """Indexed by ``t``: per point ``<name>_x``, ``<name>_y``, ``<name>_vx``, ``<name>_vy``,
        ``<name>_ax``, ``<name>_ay`` (m, m/s, m/s^2)."""
        cols: dict[str, FloatArray] = {"t": self.t}
        for k, name in enumerate(self.names):
            for prefix, arr in (("", self.position), ("v", self.velocity), ("a", self.acceleration)):
                cols[f"{name}_{prefix}x"] = arr[:, k, 0]
                cols[f"{name}_{prefix}y"] = arr[:, k, 1]
        return _dataframe(cols)


class SimulationInterrupted(KeyboardInterrupt):
    """Ctrl-C during ``Mechanism.simulate``: still a KeyboardInterrupt (loops stop), carrying
    the trajectory computed so far as ``result`` (status ``'cancelled'``)."""

    def __init__(self, result: SimulationResult) -> None:
        super().__init__(result.message)
        self.result = result


@dataclass(frozen=True)
class ChangePoint:
    """A change point the run crossed: where the pair constraints lost rank and the passive
    mechanism's mobility jumped, and the motion went on along the branch it arrived on."""

    #: Time of the crossing (s).
    t: float
    #: (m,) coordinates and (3n,) body coordinates there.
    q: FloatArray
    x: FloatArray
    #: Rank the pair constraints lost there: the mobility jumps by this much.
    rank_drop: int

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> ChangePoint:
        """From the native dict or a results file's metadata entry."""
        return cls(t=float(d["t"]), q=np.asarray(d["q"], dtype=float), x=np.asarray(d["x"], dtype=float),
                   rank_drop=int(d["rank_drop"]))

    def to_dict(self) -> dict[str, Any]:
        """Plain values, for a results file's metadata."""
        return {"t": self.t, "q": self.q.tolist(), "x": self.x.tolist(), "rank_drop": self.rank_drop}


@dataclass(frozen=True, repr=False)
class SimulationResult:
    """A trajectory, kept whole even when the run stopped early (see ``status``).

    Shapes: N outputs, m coordinates, n bodies. Its output columns, declared once in the core
    (:data:`planardyn.results_format.COLUMNS`), each the field of its name, the energies
    entries of ``energy``:

    """

    t: FloatArray
    q: FloatArray
    qd: FloatArray
    qdd: FloatArray
    tau: FloatArray
    x: FloatArray
    xd: FloatArray
    #: (N, n, 3) the same as x, one row per body.
    poses: FloatArray
    energy: Energy
    sigma: FloatArray
    residual: FloatArray
    partitioned: NDArray[np.bool_]
    #: True when the run reached t_end or a terminal event.
    success: bool
    #: 'success', 'event' (a terminal event ended it), 'event_failed', 'assembly_failed', 'passive_singularity', 'step_size_underflow',
    #: 'non_finite', 'drive_failed', 'too_many_steps', 'step_size_too_small' (the steps are
    #: too small to reach t_end within max_steps: stopped early) or 'cancelled'. A stopped
    #: run's last row is its last accepted state, on the output grid or not.
    status: str
    message: str
    #: Counters: nfev, naccept, nreject, njev, nlu, chart_switches, partition_steps, alt_steps
    #: (steps in another set of joint angles near a type II singularity), failed_evaluations,
    #: max_residual, min_sigma, min_passive_sigma, energy_drift (J).
    stats: dict[str, Any] = field(default_factory=dict)
    coordinate_names: list[str] = field(default_factory=list)
    #: 'angle' or 'displacement' per coordinate.
    coordinate_kinds: list[str] = field(default_factory=list)
    body_names: list[str] = field(default_factory=list)
    #: The change points crossed, in time order (see :meth:`change_points_frame`).
    change_points: list[ChangePoint] = field(default_factory=list)
    #: Where the result came from, for reproducing and re-plotting it: ``model`` (the model
    #: as a dict, ``Mechanism.to_dict()``, one dict shared by the results of a mechanism: edit a
    #: ``to_dict()`` copy), ``settings`` (keyword arguments of
    #: ``Mechanism.simulate``), ``planardyn_version``, ``kind`` ('simulation' or 'inverse').
    #: Empty unless attached (:func:`planardyn.results_io.attach_metadata`) or read from a file.
    metadata: dict[str, Any] = field(default_factory=dict)
    #: Per event of ``simulate(events=...)``, in order: the times of its zeros (k,) (s), and
    #: q and qd there (k, m) each (scipy's ``y_events`` is ``hstack`` of the two).
    t_events: list[FloatArray] = field(default_factory=list)
    q_events: list[FloatArray] = field(default_factory=list)
    qd_events: list[FloatArray] = field(default_factory=list)
    #: With ``simulate(dense_output=True)``: ``sol(t) -> (q, qd)`` at any time(s) t of the run
    #: ((m,) each for a number, (K, m) for (K,) times; a ValueError outside [sol.t_min,
    #: sol.t_max]), from each step's own interpolant. None otherwise, and when read from a file
    #: (which keeps the events). A default factory, not a default: a default is a class
    #: attribute, found before ``__getattr__``, and a native run's ``sol`` is made at its first read.
    sol: DenseOutput | None = field(default_factory=lambda: None)
    #: None for a model without actuators (the column ``tau_motor``, what identification reads).
    tau_motor: FloatArray | None = None

    @classmethod
    def from_raw(
        cls,
        raw: RawRun,
        *,
        coordinate_names: list[str],
        coordinate_kinds: list[str],
        body_names: list[str],
        metadata: Mapping[str, Any] | Callable[[], Mapping[str, Any]] | None = None,
        tau_motor: FloatArray | None = None,
        message_note: str = "",
    ) -> SimulationResult:
        """Wrap the native ``Mechanism.simulate``'s result (a ``_core.Run``, or the dict a
        batch returns). Every field but ``tau_motor``, how the run ended too, is made at its
        first read (:data:`LAZY_FIELDS`), ``metadata`` given or made by a callable;
        ``message_note`` is added to the run's message (rows without motor torques)."""
        # The frozen dataclass's __init__ sets every field one by one through
        # object.__setattr__, and making every array up front was most of a short run's fixed
        # cost in Python (issue 25 item 4): nothing is read from the run now, every field at
        # its first read, even how the run ended (each read of the native run costs as much).
        result = object.__new__(cls)
        values = result.__dict__
        values["_pending"] = (raw, metadata, (coordinate_names, coordinate_kinds, body_names))
        # A field with a default is a class attribute, found before __getattr__: set when not the default.
        if tau_motor is not None:
            values["tau_motor"] = tau_motor
        if message_note:
            values["message"] = raw["message"] + message_note
        return result

    def __getattr__(self, name: str) -> Any:
        # Only reached for an attribute not yet in __dict__: a field made at its first read.
        pending = self.__dict__.get("_pending")
        if pending is None or name not in LAZY_FIELDS:
            raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
        value = _lazy_field(self, name, *pending)
        self.__dict__[name] = value
        return value

    def __getstate__(self) -> dict[str, Any]:
        # Pickled and copied with every field made (the native run itself does not pickle).
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}

    def change_points_frame(self) -> pandas.DataFrame:
        """The change points as a DataFrame: ``t``, ``rank_drop`` and the coordinates (needs
        pandas)."""
        cols: dict[str, Any] = {"t": np.array([c.t for c in self.change_points])}
        cols["rank_drop"] = np.array([c.rank_drop for c in self.change_points], dtype=int)
        for k, name in enumerate(self.coordinate_names):
            cols[name] = np.array([c.q[k] for c in self.change_points])
        return _dataframe(cols)

    def __len__(self) -> int:
        return len(self.t)

    def __repr__(self) -> str:
        span = f"t = {self.t[0]:.6g}..{self.t[-1]:.6g} s" if len(self.t) else "no output"
        return (
            f"SimulationResult(status={self.status!r}, N={len(self.t)}, {span}, "
            f"coordinates=({', '.join(self.coordinate_names)}), "
            f"steps={self.stats.get('naccept', 0)}, energy drift={self.energy.drift:.3g} J)"
        )

    def take(self, rows: ArrayLike) -> SimulationResult:
        """The result at some of its rows: indices or a boolean mask, e.g. every tenth row
        ``res.take(np.arange(0, len(res), 10))``. The energy balance keeps its reference
        (the first output of the whole run)."""
        try:
            r = np.asarray(rows)
        except ValueError:  # a ragged list
            raise TypeError("rows must be integer indices or a boolean mask, not a ragged list") from None
        n = len(self.t)
        if r.dtype.kind not in "biu":
            raise TypeError(f"rows must be integer indices or a boolean mask of the {n} rows, got {r.dtype}")
        if r.dtype.kind == "b" and r.shape != (n,):
            raise error("rows", f"rows as a boolean mask has one entry per row ({n},), got shape {r.shape}")
        if r.dtype.kind != "b" and r.size and not (-n <= r.min() and r.max() < n):
            raise error("rows", f"rows must be indices of the {n} rows (from -{n} to {n - 1}), got "
                                f"{r.min() if r.min() < -n else r.max()}")
        k = np.arange(n)[r]

        def rows_of(obj: Any) -> dict[str, Any]:  # every per-row array field, at rows k
            return {f.name: v[k] for f in dataclasses.fields(obj) if isinstance(v := getattr(obj, f.name), np.ndarray)}

        return dataclasses.replace(self, **rows_of(self), energy=Energy(**rows_of(self.energy)))

    @property
    def power(self) -> FloatArray:
        """(N, m) power of each drive, tau * qd (W): positive where the drive gives energy."""
        return self.tau * self.qd

    def columns(self) -> dict[str, FloatArray]:
        """The table of :meth:`to_dataframe` as a dict of (N,) arrays, in column order:
        ``t``, the coordinate names, ``qd_<name>``, ``qdd_<name>``, ``tau_<name>``, with
        actuators ``tau_motor_<name>``, then ``kinetic``, ``potential``, ``work``, ``sigma``."""
        cols: dict[str, FloatArray] = {"t": self.t}
        arrays = (("", self.q), ("qd_", self.qd), ("qdd_", self.qdd), ("tau_", self.tau),
                  *((("tau_motor_", self.tau_motor),) if self.tau_motor is not None else ()))
        for prefix, arr in arrays:
            for k, name in enumerate(self.coordinate_names):
                cols[prefix + name] = arr[:, k]
        cols["kinetic"] = self.energy.kinetic
        cols["potential"] = self.energy.potential
        cols["work"] = self.energy.work
        cols["sigma"] = self.sigma
        return cols

    def to_dataframe(self) -> pandas.DataFrame:
        """A pandas DataFrame indexed by ``t`` (s) with the other columns of :meth:`columns`,
        then ``power_<name>`` (W) per drive (needs pandas)."""
        cols = self.columns()
        for k, name in enumerate(self.coordinate_names):
            cols["power_" + name] = self.power[:, k]
        return _dataframe(cols)

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write a results file (``.csv``, ``.parquet`` or ``.npz``, by the name's extension;
        format in :mod:`planardyn.results_io`): every array, exactly, and the metadata
        (model, settings, version when attached), read back by :func:`planardyn.read_results`,
        ``planardyn plot`` and ``planardyn animate``. Written whole or not at all. Returns
        the path."""
        return self._write(path, None)

    def to_csv(self, path: str | os.PathLike[str]) -> Path:
        """:meth:`save` in the CSV form whatever the name: the file's columns, full double
        precision, a table a spreadsheet opens; the metadata as JSON beside it, in the file
        named ``<path>.json`` (:mod:`planardyn.results_io`)."""
        return self._write(path, ".csv")

    def _write(self, path: str | os.PathLike[str], ext: str | None) -> Path:
        groups = {c.name: v for c in results_format.COLUMNS
                  if (v := getattr(self.energy if c.name in ENERGY_COLUMNS else self, c.name)) is not None}
        layout = results_format.columns(self.coordinate_names, self.body_names, groups)
        meta = {
            "format": results_format.FORMAT,
            "format_version": results_format.FORMAT_VERSION,
            "kind": "simulation",
            "planardyn_version": __version__,
            "model": None,
            "settings": None,
            **{k: v for k, v in self.metadata.items() if k != "path"},
            "status": self.status,
            "success": self.success,
            "message": self.message,
            "stats": {k: results_format.plain(v) for k, v in self.stats.items()},
            "change_points": [c.to_dict() for c in self.change_points],
            "coordinate_names": self.coordinate_names,
            "coordinate_kinds": self.coordinate_kinds,
            "body_names": self.body_names,
            "layout": [[g, len(cols)] for g, cols in layout],
        }
        if self.t_events:
            meta["events"] = {"t": [a.tolist() for a in self.t_events], "q": [a.tolist() for a in self.q_events],
                              "qd": [a.tolist() for a in self.qd_events]}
        return results_format.write(path, meta, groups, layout, ext)


#: The fields of a result from a native run made at their first read (``from_raw``).
LAZY_FIELDS = frozenset(FIELD_COLUMNS) - {"tau_motor"} | {
    "success", "status", "message", "energy", "poses", "stats", "change_points", "t_events", "q_events",
    "qd_events", "sol", "metadata", "coordinate_names", "coordinate_kinds", "body_names"}
#: The mechanism's names a result holds, in ``from_raw``'s order.
NAME_FIELDS = ("coordinate_names", "coordinate_kinds", "body_names")


def _lazy_field(result: SimulationResult, name: str, raw: RawRun,
                metadata: Mapping[str, Any] | Callable[[], Mapping[str, Any]] | None,
                names: tuple[list[str], list[str], list[str]]) -> Any:
    """Field ``name`` of ``result`` from its native run ``raw`` and the mechanism's ``names``
    (coordinates, their kinds, bodies; see ``from_raw``)."""
    if name in NAME_FIELDS:
        return list(names[NAME_FIELDS.index(name)])  # the result's own copy
    if name == "success":
        return result.status in ("success", "event")
    if name == "sol":
        return raw.get("sol")
    if name == "energy":
        return Energy.from_arrays(raw["kinetic"], raw["potential"], raw["work"])
    if name == "poses":
        x = result.x
        return x.reshape(x.shape[0], len(result.body_names), 3)
    if name == "stats":
        return dict(raw["stats"])
    if name == "change_points":
        return [ChangePoint.from_dict(c) for c in raw.get("change_points", [])]
    if name in ("t_events", "q_events", "qd_events"):
        return list(raw.get(name, []))
    if name == "metadata":
        return dict((metadata() if callable(metadata) else metadata) or {})
    return raw[name]  # status, message or an output column


SimulationResult.__doc__ = f"{(SimulationResult.__doc__ or '').rstrip(' ')}{results_format.columns_doc('    ')}"
