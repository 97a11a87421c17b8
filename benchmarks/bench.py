"""planardyn against the tools users would pick instead, measured in one run (issue 6).

Run through ``benchmarks/run.sh`` (which makes the environment); by hand, from the
repository root with the peers' venv::

    PYTHONPATH=python benchmarks/.venv-peers/bin/python benchmarks/bench.py [--quick]

Measures, on the passive four-bar of ``examples/models/four-bar-gravity.yaml`` over 10 s:
each tool's wall time and accuracy (energy drift, loop gap, error against a tight
planardyn reference) over a sweep of its step size or tolerance; the cheapest setting
of each that meets the peers' target (drift < 1e-3 J, gap < 1e-6 m) and planardyn's
cheapest for drift < 1e-6 J. Also runs the Rust criterion bench of one forward-dynamics
evaluation and compares ``simulate`` from Python with the same run from Rust.
Writes ``benchmarks/results/results.json``, ``results.md`` and ``work_precision.png``.
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import json
import os
import platform
import re
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import numpy as np  # noqa: E402

import common  # noqa: E402
import overhead as overhead_mod  # noqa: E402
import report  # noqa: E402
from common import Run  # noqa: E402

PEERS = ["planardyn_fourbar", "mujoco_fourbar", "pinocchio_fourbar", "exudyn_fourbar"]
RESULTS = HERE / "results"

#: Criterion targets of issue 6 for one forward-dynamics evaluation (s).
FD_TARGETS = {"four-bar-gravity": 1e-6, "3-rrr": 2e-6, "andrews-squeezer": 3e-6}
#: The error (rad) at which the tools are also compared: the crank angle within 1e-4 rad of
#: the reference over the whole 10 s.
ERROR_TARGET = 1e-4


def say(msg: str) -> None:
    print(msg, flush=True)


def tools() -> tuple[dict, dict]:
    """The peer modules that import, and for the others the reason."""
    ok, missing = {}, {}
    for name in PEERS:
        mod = importlib.import_module(f"peers.{name}")
        try:
            ok[mod.TOOL] = (mod, mod.version())
        except Exception as e:  # ImportError, or a broken wheel
            missing[mod.TOOL] = f"{mod.PACKAGE}: {type(e).__name__}: {e}"
    return ok, missing


def sweep(mod, fb, ref, quick: bool) -> list[Run]:
    settings = mod.SWEEP[::2] if quick else mod.SWEEP
    runs = []
    for s in settings:
        try:
            r = mod.run(fb, s, ref)
        except Exception as e:
            r = Run(mod.TOOL, "?", repr(s), ok=False, note=f"{type(e).__name__}: {e}")
        flag = "ok " if r.ok else "FAIL"
        say(f"  {flag} {r.method:42s} {r.setting:16s} wall {r.wall * 1e3:9.2f} ms  drift {r.drift:9.2e} J  "
            f"gap {r.gap:9.2e} m  error {r.error:9.2e} rad {r.note}")
        runs.append(r)
    return runs


def cheapest(runs: list[Run], drift: float, gap: float | None) -> Run | None:
    good = [r for r in runs if r.meets(drift, gap)]
    return min(good, key=lambda r: r.wall) if good else None


def cheapest_by_error(runs: list[Run]) -> Run | None:
    good = [r for r in runs if r.ok and r.error < ERROR_TARGET and r.gap < common.PEER_GAP_TARGET]
    return min(good, key=lambda r: r.wall) if good else None


def criterion(quick: bool) -> dict:
    """Run the Rust forward-dynamics bench and parse criterion's 'time: [lo mid hi]'."""
    cmd = ["cargo", "bench", "-p", "planardyn", "--bench", "forward_dynamics", "--",
           "--warm-up-time", "1", "--measurement-time", "2" if quick else "4"]
    say("$ " + " ".join(cmd))
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=common.ROOT, capture_output=True, text=True)
    out = p.stdout + p.stderr
    if p.returncode != 0:
        return {"ok": False, "command": " ".join(cmd), "error": out[-3000:]}
    unit = {"ps": 1e-12, "ns": 1e-9, "µs": 1e-6, "us": 1e-6, "ms": 1e-3, "s": 1.0}
    num = r"([\d.]+)\s*(ps|ns|µs|us|ms|s)"
    res = {}
    for m in re.finditer(r"forward_dynamics/(\S+)\s+time:\s+\[" + num + r"\s+" + num + r"\s+" + num + r"\]", out):
        name = m.group(1)
        lo, mid, hi = (float(m.group(i)) * unit[m.group(i + 1)] for i in (2, 4, 6))
        target = FD_TARGETS.get(name)
        res[name] = {"low_s": lo, "estimate_s": mid, "high_s": hi, "target_s": target,
                     "meets": None if target is None else mid < target}
    if not res:
        return {"ok": False, "command": " ".join(cmd), "error": "no criterion 'time:' lines in:\n" + out[-3000:]}
    return {"ok": True, "command": " ".join(cmd), "seconds": time.perf_counter() - t0, "results": res}


def python_overhead(setting: tuple) -> dict:
    """overhead.py in a fresh Python process (only planardyn loaded: no peer's threads)."""
    p = subprocess.run([sys.executable, str(HERE / "overhead.py"), json.dumps(list(setting))],
                       capture_output=True, text=True)
    if p.returncode != 0:
        return {"ok": False, "why": f"overhead.py failed: {p.stderr[-1000:]}"}
    return json.loads(p.stdout)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="every other setting, shorter criterion run")
    ap.add_argument("--no-criterion", action="store_true", help="skip cargo bench")
    ap.add_argument("--out", type=Path, default=RESULTS)
    a = ap.parse_args()
    t_start = time.perf_counter()
    load_start = os.getloadavg()  # other work on the machine skews every wall time
    fb = common.load_four_bar()
    found, missing = tools()
    say("tools: " + ", ".join(f"{k} {v}" for k, (_, v) in found.items()))
    for k, why in missing.items():
        say(f"NOT AVAILABLE {k}: {why}")
    if "planardyn" not in found:
        say("planardyn itself does not import: run ./dev setup (or benchmarks/run.sh)")
        return 2
    P = found["planardyn"][0]
    say("reference: planardyn DOP853 rtol = atol = 1e-13")
    ref = P.reference()
    runs: list[Run] = []
    for tool, (mod, ver) in found.items():
        say(f"{tool} {ver}")
        runs += sweep(mod, fb, ref, a.quick)

    peers = [t for t in found if t != "planardyn"]
    best = {t: cheapest([r for r in runs if r.tool == t], common.PEER_DRIFT_TARGET, common.PEER_GAP_TARGET)
            for t in found}
    pd_runs = [r for r in runs if r.tool == "planardyn"]
    pd_tight = cheapest(pd_runs, common.PLANARDYN_DRIFT_TARGET, common.PEER_GAP_TARGET)
    fastest_peer = min((best[t] for t in peers if best[t]), key=lambda r: r.wall, default=None)
    summary = {"best_at_peer_target": {t: (dataclasses.asdict(r) if r else None) for t, r in best.items()},
               "planardyn_at_1e-6J": dataclasses.asdict(pd_tight) if pd_tight else None,
               "fastest_peer": dataclasses.asdict(fastest_peer) if fastest_peer else None}
    if fastest_peer and pd_tight:
        ratio = fastest_peer.wall / pd_tight.wall
        summary["speedup_1e-6J_vs_fastest_peer_1e-3J"] = ratio
        summary["meets_1_over_20"] = ratio >= 20.0
    if best.get("planardyn"):
        summary["speedup_equal_accuracy"] = {t: best[t].wall / best["planardyn"].wall for t in peers if best[t]}
    # Equal accuracy in the trajectory itself: the cheapest run of each tool whose crank
    # angle stays within ERROR_TARGET of the reference (and whose loop is closed).
    by_error = {t: cheapest_by_error([r for r in runs if r.tool == t]) for t in found}
    summary["best_at_error"] = {t: (dataclasses.asdict(r) if r else None) for t, r in by_error.items()}
    if by_error.get("planardyn"):
        summary["speedup_equal_error"] = {t: by_error[t].wall / by_error["planardyn"].wall
                                          for t in peers if by_error[t]}

    say("Python overhead: simulate from Python against the same run from Rust")
    overhead = (python_overhead(tuple(pd_tight.extra["setting"])) if pd_tight
                else {"ok": False, "why": "no planardyn setting met 1e-6 J"})
    crit = {"ok": False, "error": "skipped (--no-criterion)"} if a.no_criterion else criterion(a.quick)

    env = {"python": sys.version.split()[0], "platform": platform.platform(), "cpus": os.cpu_count(),
           "versions": {k: v for k, (_, v) in found.items()}, "not_available": missing,
           "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"), "quick": a.quick,
           "load_average_at_start": load_start, "load_average_at_end": os.getloadavg()}
    result = {"environment": env, "model": str(common.MODEL.relative_to(common.ROOT)),
              "t_end_s": common.T_END, "targets": {"peer_drift_J": common.PEER_DRIFT_TARGET,
              "peer_gap_m": common.PEER_GAP_TARGET, "planardyn_drift_J": common.PLANARDYN_DRIFT_TARGET,
              "error_rad": ERROR_TARGET,
              "forward_dynamics_s": FD_TARGETS, "python_overhead": overhead_mod.OVERHEAD_TARGET},
              "reference_theta1_end": float(ref[-1]), "runs": [dataclasses.asdict(r) for r in runs],
              "summary": summary, "python_overhead": overhead, "criterion": crit,
              "bench_seconds": time.perf_counter() - t_start}
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "results.json").write_text(json.dumps(result, indent=1, default=_json))
    report.write(result, a.out)
    say(report.ratios_text(result))
    say(f"wrote {a.out}/results.json, results.md, work_precision.png in {result['bench_seconds']:.0f} s")
    return 0


def _json(v):
    if isinstance(v, (np.floating, np.integer)):
        return v.item()
    if isinstance(v, np.ndarray):
        return v.tolist()
    raise TypeError(type(v).__name__)


if __name__ == "__main__":
    sys.exit(main())
