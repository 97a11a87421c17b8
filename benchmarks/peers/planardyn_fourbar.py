"""planardyn: the four-bar's model file, integrated in its one minimal coordinate.

Timed: ``Mechanism.simulate`` over 10 s with outputs at the 0.1 s error grid (101 points,
each with energies, body poses and the loop residual). Energy drift and loop gap are then
taken from a second, untimed run of the same settings that outputs every accepted step,
so they are measured at every step as for the peers.
"""

from __future__ import annotations

import numpy as np

from common import MODEL, T_END, FourBar, Run, best_time, energy, grid_times, loop_gap

TOOL = "planardyn"
PACKAGE = "planardyn (this repository)"

#: (method, rtol, dt): DOP853 and DOPRI5 over a range of tolerances (atol = rtol, the state
#: being of order 1 rad and rad/s), and fixed-step RK4.
SWEEP = (
    [("dop853", r, None) for r in (1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11)]
    + [("dopri5", r, None) for r in (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9)]
    + [("rk4", None, dt) for dt in (0.01, 0.005, 0.0025, 0.001)]
)

_mech = None


def version() -> str:
    import planardyn

    return getattr(planardyn, "__version__", "repo")


def mechanism():
    global _mech
    if _mech is None:
        import planardyn

        _mech = planardyn.load(MODEL)
    return _mech


def options(method: str, rtol: float | None, dt: float | None) -> dict:
    if method == "rk4":
        return {"method": method, "dt": dt}
    return {"method": method, "rtol": rtol, "atol": rtol}


def label(method: str, rtol: float | None, dt: float | None) -> str:
    return f"dt={dt:g}" if method == "rk4" else f"rtol={rtol:g}"


def reference(rtol: float = 1e-13) -> np.ndarray:
    """theta1 (rad) at the grid times from DOP853 at rtol = atol = 1e-13."""
    res = mechanism().simulate(T_END, method="dop853", rtol=rtol, atol=rtol, t_eval=grid_times())
    assert res.success, res.message
    return res.q[:, 0].copy()


def split(fb: FourBar, mech, x: np.ndarray, xd: np.ndarray) -> tuple[dict, dict]:
    """Per-body (N, 3) poses with phi measured from the drawing, and rates."""
    poses, rates = {}, {}
    x0 = mech.x0
    for i, name in enumerate(mech.body_names):
        p = x[:, 3 * i : 3 * i + 3].copy()
        p[:, 2] -= x0[3 * i + 2]
        poses[name] = p
        rates[name] = xd[:, 3 * i : 3 * i + 3]
    return poses, rates


def run(fb: FourBar, setting: tuple, ref_grid: np.ndarray) -> Run:
    method, rtol, dt = setting
    mech = mechanism()
    opts = options(method, rtol, dt)
    r = Run(TOOL, {"dop853": "DOP853 8(5,3)", "dopri5": "DOPRI5 5(4)", "rk4": "RK4 fixed step"}[method],
            label(method, rtol, dt))
    tgrid = grid_times()
    wall, res = best_time(lambda: mech.simulate(T_END, t_eval=tgrid, **opts))
    every = mech.simulate(T_END, **opts)  # untimed: every accepted step, for drift and gap
    r.wall, r.steps = wall, int(res.stats["naccept"])
    r.extra = {"setting": [method, rtol, dt], "nfev": int(res.stats["nfev"]),
               "max_residual_scaled": float(every.stats["max_residual"])}
    if not (res.success and every.success):
        r.ok, r.note = False, f"{res.status}: {res.message}"
        return r
    poses, rates = split(fb, mech, every.x, every.xd)
    e = np.concatenate([energy(fb, poses, rates), res.energy.total])
    gp, _ = split(fb, mech, res.x, res.xd)
    gap = np.concatenate([loop_gap(fb, poses), loop_gap(fb, gp)])
    return r.finish(e, gap, res.q[:, 0], ref_grid)
