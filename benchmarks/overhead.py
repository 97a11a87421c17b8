"""Python-call overhead: ``Mechanism.simulate`` from Python against the same run from Rust.

The Rust side is ``benchmarks/rust-sim`` (``planardyn::simulate::simulate_prepared``, the model
prepared once as a Python ``Mechanism`` does, with the same settings, timed inside the
process). Both sides take the best of 3 runs, alternated for
REPEATS rounds so that both see the same machine load; the medians are compared. Run by
bench.py in a process of its own (only planardyn loaded); by hand::

    PYTHONPATH=python benchmarks/.venv-peers/bin/python benchmarks/overhead.py '["dop853", 1e-9, null]'
"""

from __future__ import annotations

import json
import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from mechanisms import FOUR_BAR  # noqa: E402
from peers import planardyn_peer as P  # noqa: E402

RUST_SIM = Path(os.environ.get("RUST_SIM", HERE / ".target" / "release" / "planardyn-rust-sim"))
#: Python simulate may be at most this much slower than the same run from Rust (a performance target).
OVERHEAD_TARGET = 0.10
REPEATS = 15


def measure(setting: tuple, repeats: int = REPEATS) -> dict:
    """For 0.1 s outputs and for every step: median over the rounds of the best of 3 (s)
    from Python and from Rust, and the relative overhead."""
    method, rtol, dt = setting
    if not RUST_SIM.exists():
        return {"ok": False, "why": f"{RUST_SIM} is not built (run.sh builds it with cargo)"}
    mech = P.mechanism(FOUR_BAR)
    opts = P.options(method, rtol, dt)
    out = {"ok": True, "setting": f"{method} {P.label(method, rtol, dt)}", "cases": {}}
    for case, output_dt in (("0.1 s outputs", FOUR_BAR.grid_dt), ("every step", None)):
        args = [str(RUST_SIM), str(FOUR_BAR.model), method, repr(rtol or 1e-8), repr(rtol or 1e-10),
                "-" if dt is None else repr(dt), repr(FOUR_BAR.t_end), "-" if output_dt is None else repr(output_dt)]
        kw = dict(opts, output_dt=output_dt) if output_dt else opts
        py, rs = [], []
        for _ in range(repeats):
            # Best of 3 on each side (the Rust binary does its 3 in one process), alternated.
            best = math.inf
            for _ in range(3):
                t0 = time.perf_counter()
                res = mech.simulate(FOUR_BAR.t_end, **kw)
                best = min(best, time.perf_counter() - t0)
            py.append(best)
            p = subprocess.run(args + ["3"], capture_output=True, text=True)
            if p.returncode != 0:
                return {"ok": False, "why": f"{' '.join(args)} failed: {p.stderr[-500:]}"}
            rs.append(json.loads(p.stdout)["best_s"])
        rust = json.loads(p.stdout)
        same = rust["naccept"] == res.stats["naccept"] and rust["nfev"] == res.stats["nfev"]
        py_med, rs_med = statistics.median(py), statistics.median(rs)
        out["cases"][case] = {
            "python_s": py_med, "rust_s": rs_med, "overhead": py_med / rs_med - 1.0,
            "meets": py_med / rs_med - 1.0 <= OVERHEAD_TARGET, "same_steps": same,
            "steps_python": int(res.stats["naccept"]), "steps_rust": rust["naccept"],
            "outputs": len(res.t),
        }
    return out


if __name__ == "__main__":
    print(json.dumps(measure(tuple(json.loads(sys.argv[1])))))
