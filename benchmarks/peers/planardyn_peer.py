"""planardyn: the model file (with the benchmark's overrides), integrated in its minimal
coordinates.

Variants: DOP853 and DOPRI5 (Radau IIA too on Andrews' squeezer) searched on their tolerance
(rtol = atol, the state being of order 1 rad and rad/s), and fixed-step RK4 on its number of steps.

Timed: ``Mechanism.simulate`` with outputs at the error grid (each with energies, body poses
and the loop residual). Energy drift and loop gap are then taken from a second, untimed run
of the same settings that outputs every accepted step, so they are measured at every step
as for the peers.
"""

from __future__ import annotations

from collections.abc import Callable

import cheapest
import common
import numpy as np
from common import Drawing, Run, Variant, energy, loop_gap, one_shot
from mechanisms import Benchmark

TOOL = "planardyn"
PACKAGE = "planardyn (this repository)"

METHODS = {"dop853": "DOP853 8(5,3)", "dopri5": "DOPRI5 5(4)", "rk4": "RK4 fixed step", "radau5": "Radau IIA 5"}
#: The adaptive methods searched on each mechanism (default: the explicit pair).
ADAPTIVE = {"andrews": ("dop853", "dopri5", "radau5")}
#: Fixed-step RK4: (cheapest, dearest) number of steps over the run.
RK4_STEPS = {"four-bar": (20, 40000), "five-bar": (10, 20000), "3-rrr": (4, 2000), "andrews": (30, 30000)}


def variants(bm: Benchmark) -> list[Variant]:
    return ([Variant(TOOL, METHODS[m], (m,), None) for m in ADAPTIVE.get(bm.key, ("dop853", "dopri5"))]
            + [Variant(TOOL, METHODS["rk4"], ("rk4",), RK4_STEPS[bm.key])])


def setting(bm: Benchmark, v: Variant, s: int) -> tuple[str, float | None, float | None]:
    """(method, rtol, dt) of setting s of variant v: the form results.json and overhead.py keep."""
    (method,) = v.params
    return (method, None, bm.t_end / s) if v.steps else (method, cheapest.rtol(s), None)


_mechs: dict = {}


def version() -> str:
    import planardyn

    return getattr(planardyn, "__version__", "repo")


def mechanism(bm: Benchmark):
    if bm.key not in _mechs:
        import planardyn

        m = planardyn.from_dict(bm.spec, source=bm.model_rel)
        assert np.allclose(m.q0, m.drawn_q) and not np.any(m.qd0), "the peers start from rest in the drawing"
        _mechs[bm.key] = m
    return _mechs[bm.key]


def options(method: str, rtol: float | None, dt: float | None) -> dict:
    if method == "rk4":
        return {"method": method, "dt": dt}
    return {"method": method, "rtol": rtol, "atol": rtol}


def label(method: str, rtol: float | None, dt: float | None) -> str:
    return f"dt={dt:g}" if method == "rk4" else f"rtol={rtol:g}"


class Reference(common.Reference):
    """planardyn with DOP853 at rtol = atol = RTOL at the times a run is sampled at: the grid, or
    for a run of n fixed steps its steps nearest the grid (``Benchmark.sample_times``)."""

    #: The reference's tolerance: at the grid times it agrees with DOP853 at 3e-14 and DOPRI5 at
    #: 1e-13 to 1.7e-11, 1.3e-9, 6e-14 and 2.6e-12 rad (four-bar, five-bar, 3-RRR, Andrews'
    #: squeezer; 2026-11-25), far below the stated errors of 1e-4 rad.
    RTOL = 1e-13

    def __init__(self, bm: Benchmark):
        self.bm = bm
        self._at: dict[bytes, np.ndarray] = {}

    def at(self, times: np.ndarray) -> np.ndarray:
        """(K, m) coordinates (rad) at the times (s)."""
        key = times.tobytes()
        if key not in self._at:
            # A run of fewer steps than grid intervals samples a step more than once.
            t, back = np.unique(times, return_inverse=True)
            try:
                res = mechanism(self.bm).simulate(self.bm.t_end, method="dop853", rtol=self.RTOL, atol=self.RTOL,
                                                  t_eval=t)
            except Exception as e:
                raise common.ReferenceFailed(f"{self.bm.key}: {type(e).__name__}: {e}") from e
            if not res.success:
                raise common.ReferenceFailed(f"{self.bm.key}: {res.message}")
            self._at[key] = res.q[back]
        return self._at[key]

    def grid(self) -> np.ndarray:
        return self.at(self.bm.grid_times())

    def steps(self, n: int) -> np.ndarray:
        return self.at(self.bm.sample_times(n))


def split(mech, x: np.ndarray, xd: np.ndarray) -> tuple[dict, dict]:
    """Per-body (N, 3) poses with phi measured from the drawing, and rates."""
    poses, rates = {}, {}
    for i, name in enumerate(mech.body_names):
        p = x[:, 3 * i : 3 * i + 3].copy()
        p[:, 2] -= mech.x0[3 * i + 2]
        poses[name] = p
        rates[name] = xd[:, 3 * i : 3 * i + 3]
    return poses, rates


def run(bm: Benchmark, d: Drawing, v: Variant, s: int, ref: Reference) -> Run:
    method, rtol, dt = setting(bm, v, s)
    mech = mechanism(bm)
    opts = options(method, rtol, dt)
    r = Run(TOOL, v.method, v.label(bm.t_end, s), value=s)
    r.wall, res = one_shot(lambda: mech.simulate(bm.t_end, t_eval=bm.grid_times(), **opts))
    every = mech.simulate(bm.t_end, **opts)  # untimed: every accepted step, for drift and gap
    r.steps = int(res.stats["naccept"])
    r.extra = {"setting": [method, rtol, dt], "nfev": int(res.stats["nfev"]),
               "max_residual_scaled": float(every.stats["max_residual"])}
    if not (res.success and every.success):
        return r.fail(f"{res.status}: {res.message}")
    poses, rates = split(mech, every.x, every.xd)
    gp, gr = split(mech, res.x, res.xd)
    e = np.concatenate([energy(d, poses, rates), energy(d, gp, gr)])
    gap = np.concatenate([loop_gap(d, poses), loop_gap(d, gp)])
    return r.finish(e, gap, res.q, ref.grid())


def timed(bm: Benchmark, d: Drawing, v: Variant, s: int) -> Callable[[], object]:
    """The call timing.py times: the run with outputs at the error grid."""
    mech, t, opts = mechanism(bm), bm.grid_times(), options(*setting(bm, v, s))
    return lambda: mech.simulate(bm.t_end, t_eval=t, **opts)
