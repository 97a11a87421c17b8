"""planardyn: the model file (with the benchmark's overrides), integrated in its minimal
coordinates.

Timed: ``Mechanism.simulate`` with outputs at the error grid (each with energies, body poses
and the loop residual). Energy drift and loop gap are then taken from a second, untimed run
of the same settings that outputs every accepted step, so they are measured at every step
as for the peers.
"""

from __future__ import annotations

import numpy as np
from common import Drawing, Run, best_time, energy, loop_gap
from mechanisms import Benchmark

TOOL = "planardyn"
PACKAGE = "planardyn (this repository)"

_RTOLS_DOP853 = (1e-5, 1e-6, 1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 1e-10, 1e-11)
_RTOLS_DOPRI5 = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9)


def _sweep(rk4_dts: tuple, extra: list | None = None, loose: int = 0) -> list[tuple]:
    """(method, rtol, dt): DOP853 and DOPRI5 over a range of tolerances (atol = rtol, the
    state being of order 1 rad and rad/s), starting ``loose`` decades looser, and fixed-step RK4."""
    def rtols(tight):
        return [tight[0] * 10.0 ** k for k in range(loose, 0, -1)] + list(tight)

    return ([("dop853", r, None) for r in rtols(_RTOLS_DOP853)] + [("dopri5", r, None) for r in rtols(_RTOLS_DOPRI5)]
            + [("rk4", None, dt) for dt in rk4_dts] + (extra or []))


SWEEPS = {
    "four-bar": _sweep((0.01, 0.005, 0.0025, 0.001)),
    "five-bar": _sweep((0.002, 0.001, 0.0005, 0.0002)),
    "3-rrr": _sweep((0.04, 0.02, 0.01, 0.005), loose=1),
    "andrews": _sweep((1e-4, 5e-5, 2e-5, 1e-5), [("radau5", r, None) for r in (1e-5, 1e-7, 1e-9)]),
}
METHODS = {"dop853": "DOP853 8(5,3)", "dopri5": "DOPRI5 5(4)", "rk4": "RK4 fixed step", "radau5": "Radau IIA 5"}

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


def reference(bm: Benchmark, rtol: float = 1e-13) -> np.ndarray:
    """(K, m) coordinates at the grid times from DOP853 at rtol = atol = 1e-13."""
    res = mechanism(bm).simulate(bm.t_end, method="dop853", rtol=rtol, atol=rtol, t_eval=bm.grid_times())
    assert res.success, res.message
    return res.q.copy()


def split(mech, x: np.ndarray, xd: np.ndarray) -> tuple[dict, dict]:
    """Per-body (N, 3) poses with phi measured from the drawing, and rates."""
    poses, rates = {}, {}
    for i, name in enumerate(mech.body_names):
        p = x[:, 3 * i : 3 * i + 3].copy()
        p[:, 2] -= mech.x0[3 * i + 2]
        poses[name] = p
        rates[name] = xd[:, 3 * i : 3 * i + 3]
    return poses, rates


def run(bm: Benchmark, d: Drawing, setting: tuple, ref_grid: np.ndarray) -> Run:
    method, rtol, dt = setting
    mech = mechanism(bm)
    opts = options(method, rtol, dt)
    r = Run(TOOL, METHODS[method], label(method, rtol, dt))
    wall, res = best_time(lambda: mech.simulate(bm.t_end, t_eval=bm.grid_times(), **opts))
    every = mech.simulate(bm.t_end, **opts)  # untimed: every accepted step, for drift and gap
    r.wall, r.steps = wall, int(res.stats["naccept"])
    r.extra = {"setting": [method, rtol, dt], "nfev": int(res.stats["nfev"]),
               "max_residual_scaled": float(every.stats["max_residual"])}
    if not (res.success and every.success):
        return r.fail(f"{res.status}: {res.message}")
    poses, rates = split(mech, every.x, every.xd)
    gp, gr = split(mech, res.x, res.xd)
    e = np.concatenate([energy(d, poses, rates), energy(d, gp, gr)])
    gap = np.concatenate([loop_gap(d, poses), loop_gap(d, gp)])
    return r.finish(e, gap, res.q, ref_grid)
