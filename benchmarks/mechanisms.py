"""The benchmark mechanisms: which model file, which scenario, how long, which accuracy.

Each is a planardyn model file of ``examples/models/`` (the validation benchmarks of tests/data/benchmarks reproduced
exactly), optionally with top-level fields replaced (``overrides``, computed from the file) to make a scenario every
tool can run; planardyn runs the same dict (``planardyn.from_dict``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parent.parent
MODELS = ROOT / "examples" / "models"


@dataclass(frozen=True)
class Benchmark:
    key: str  # for --only and the tables
    title: str
    model: Path
    t_end: float  # s
    grid_dt: float  # s: spacing of the error samples (a fixed-step run samples its nearest steps)
    #: The stated accuracy at which tools are compared: energy drift (or balance) in J and
    #: loop gap in m; trajectory error in rad (max over the grid and the coordinates).
    drift_target: float
    gap_target: float
    error_target: float
    scenario: str  # one line: what is simulated, for the report
    #: Top-level fields of the model file to replace, from the file's dict (None: the file as it is).
    overrides: Callable[[dict], dict] | None = None
    #: A published value to check the reference against: (coordinate index, value at t_end, source).
    published_end: tuple[int, float, str] | None = None

    @cached_property
    def spec(self) -> dict:
        """The model file as a dict, with the scenario's overrides."""
        spec = yaml.safe_load(self.model.read_text())
        return {**spec, **self.overrides(spec)} if self.overrides else spec

    @property
    def changed(self) -> dict:
        """The fields the scenario replaces, with their new values."""
        return {k: v for k, v in self.spec.items() if self.overrides and k in self.overrides(self.spec)}

    @property
    def model_rel(self) -> str:
        return str(self.model.relative_to(ROOT))

    def grid_times(self) -> np.ndarray:
        n = int(round(self.t_end / self.grid_dt))
        return np.arange(n + 1) * self.grid_dt

    def sample_indices(self, n: int) -> np.ndarray:
        """Step indices of a run of n fixed steps nearest the grid times (the grid times themselves
        when dt = t_end / n divides grid_dt): the error is taken there, against the reference at
        the same times (``sample_times``), so any n can be compared exactly."""
        k = np.arange(len(self.grid_times()))
        return np.rint(k * n / k[-1]).astype(int)

    def sample_times(self, n: int) -> np.ndarray:
        """(K,) s: the times of ``sample_indices(n)``; the last is t_end (t_end * n / n can round off it)."""
        i = self.sample_indices(n)
        return np.where(i == n, self.t_end, self.t_end * i / n)


FOUR_BAR = Benchmark(
    "four-bar", "Passive four-bar under gravity", MODELS / "four-bar-gravity.yaml",
    t_end=10.0, grid_dt=0.1, drift_target=1e-3, gap_target=1e-6, error_target=1e-4,
    scenario="released from rest under gravity, 10 s (the model file as it is)",
)
FIVE_BAR = Benchmark(
    "five-bar", "Passive five-bar (5R) falling under gravity", MODELS / "five-bar-free-fall.yaml",
    t_end=1.0, grid_dt=0.01, drift_target=1e-4, gap_target=1e-6, error_target=1e-4,
    scenario="released from rest under gravity, zero torques, 1 s (of the file's 5 s: the motion "
             "is chaotic, errors grow about 10x every 0.1 s past 1 s); crosses type II singularities "
             "of the actuated mechanism from t = 0.17 s on",
)
THREE_RRR = Benchmark(
    "3-rrr", "3-RRR parallel robot, constant torque on one input", MODELS / "3-rrr.yaml",
    t_end=0.8, grid_dt=0.04, drift_target=1e-5, gap_target=1e-6, error_target=1e-4,
    scenario="the file's constant 0.2 N m drive on th1, th2 and th3 free (the file's time-table "
             "drive on th2 left out), no gravity (as in the file), from rest, 0.8 s: th1 turns "
             "1.2 rad inside the workspace, away from singularities",
    overrides=lambda spec: {"drives": [d for d in spec["drives"] if "effort" in d]},
)
ANDREWS = Benchmark(
    "andrews", "Andrews' squeezing mechanism", MODELS / "andrews-squeezer.yaml",
    t_end=0.03, grid_dt=0.0003, drift_target=1e-4, gap_target=1e-7, error_target=1e-4,
    scenario="the classical problem: 0.033 N m drive torque, stiff spring, from rest, 0.03 s",
    published_end=(0, 15.81077119629904, "IVP test set (Mazzia, Magherini), andrews, beta(0.03 s)"),
)

ALL = [FOUR_BAR, FIVE_BAR, THREE_RRR, ANDREWS]
BY_KEY = {b.key: b for b in ALL}
