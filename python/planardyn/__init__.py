"""planardyn: exact minimal-coordinate dynamics of planar closed-chain mechanisms.

A mechanism is described as it is drawn, in a model file (YAML or JSON, see
``planardyn docs model-format``), and validated once into an immutable :class:`Mechanism`::

    import planardyn as pdy

    mech = pdy.load_example("five-bar")   # a shipped model; pdy.load("my-linkage.yaml") for a file
    res = mech.simulate(t_end=1.0)
    res.q          # (N, m) coordinates, rad or m
    res.to_csv("five-bar.csv")

Units are SI throughout (m, kg, s, rad, N, N m); arrays are float64 and time-major.
Errors raise subclasses of :class:`PlanardynError`: :class:`ModelError` (also a
``ValueError``) for a model that cannot be built, :class:`ArgumentError` (also a
``ValueError``) for an argument of the wrong shape or value, :class:`DataError` (also a
``ValueError``) for a data file or measured motion that cannot be used,
:class:`AssemblyError`, :class:`SingularityError` and :class:`SimulationError`.
"""

from __future__ import annotations

from . import batch, models, notebook, sensitivity
from ._core import (
    ArgumentError,
    AssemblyError,
    DataError,
    ModelError,
    PlanardynError,
    SimulationError,
    SingularityError,
    __version__,
)
from .builder import Builder
from .events import Crossing
from .mechanism import Mechanism, PlanardynWarning, from_dict, from_result, load, load_example, loads
from .result import ChangePoint, Energy, PointMotion, SimulationInterrupted, SimulationResult
from .results_io import read_results

__all__ = [
    "ArgumentError",
    "AssemblyError",
    "Builder",
    "ChangePoint",
    "Crossing",
    "DataError",
    "Energy",
    "Mechanism",
    "ModelError",
    "PlanardynError",
    "PlanardynWarning",
    "PointMotion",
    "SimulationError",
    "SimulationInterrupted",
    "SimulationResult",
    "SingularityError",
    "__version__",
    "batch",
    "from_dict",
    "from_result",
    "load",
    "load_example",
    "loads",
    "models",
    "read_results",
    "sensitivity",
]

# Inside IPython or Jupyter, mechanisms and results show themselves as HTML.
notebook.register_display()
