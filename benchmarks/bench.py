"""planardyn against the tools users would pick instead, measured in one run.

Run through ``benchmarks/run.sh`` (which makes the environment); by hand, from the
repository root with the peers' venv::

    PYTHONPATH=python benchmarks/.venv-peers/bin/python benchmarks/bench.py [--quick] [--only four-bar andrews]

For each mechanism of ``mechanisms.py`` (four-bar, five-bar, 3-RRR, Andrews' squeezer):
each tool's wall time and accuracy (energy drift or balance, loop gap, error against a
tight planardyn reference) over a sweep of its step size or tolerance, and the cheapest
setting of each that meets the mechanism's stated accuracy. On the four-bar also the
performance targets: planardyn's cheapest for drift < 1e-6 J against the fastest peer at 1e-3 J, and
``simulate`` from Python against the same run from Rust. Also runs the Rust criterion bench
of one forward-dynamics evaluation. Writes ``benchmarks/results/`` (results.json,
results.md, one work-precision plot per mechanism) and the generated part of
``docs/benchmarks.md``.
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

import common  # noqa: E402
import mechanisms  # noqa: E402
import numpy as np  # noqa: E402
import overhead as overhead_mod  # noqa: E402
import report  # noqa: E402
from common import Run  # noqa: E402

PEERS = ["planardyn_peer", "mujoco_peer", "pinocchio_peer", "exudyn_peer"]
RESULTS = HERE / "results"
DOCS_PAGE = mechanisms.ROOT / "docs" / "benchmarks.md"

#: Criterion targets for one forward-dynamics evaluation (s), from the closed-form groups item of the
#: engine issue (docs/benchmarks.md, *Closed-form groups*).
FD_TARGETS = {"four-bar-gravity": 0.25e-6, "five-bar": 0.4e-6, "3-rrr": 1.5e-6, "andrews-squeezer": 1e-6}
#: Target on the four-bar: planardyn at this drift (J) in at most 1/RATIO_TARGET of the
#: wall time of the fastest peer meeting the four-bar's drift and gap targets.
PLANARDYN_DRIFT_TARGET = 1e-6
RATIO_TARGET = 20.0


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


def sweep(mod, bm, d, ref, quick: bool) -> list[Run]:
    settings = mod.SWEEPS.get(bm.key)
    if not settings:
        return [Run(mod.TOOL, "—", "—", bm.key).fail(f"{bm.key} is not modelled for {mod.TOOL} (no sweep)")]
    runs = []
    for s in settings[::2] if quick else settings:
        try:
            r = mod.run(bm, d, s, ref)
        except Exception as e:  # a tool that cannot model or run this: reported, not dropped
            r = Run(mod.TOOL, "?", repr(s)).fail(f"{type(e).__name__}: {e}")
        r.mechanism = bm.key
        flag = "ok " if r.ok else "FAIL"
        say(f"  {flag} {r.tool:9s} {r.method:40s} {r.setting:12s} wall {r.wall * 1e3:9.2f} ms  "
            f"drift {r.drift:9.2e} J  gap {r.gap:9.2e} m  error {r.error:9.2e} rad {r.note}")
        runs.append(r)
    return runs


def cheapest(runs: list[Run], **targets) -> Run | None:
    good = [r for r in runs if r.meets(**targets)]
    return min(good, key=lambda r: r.wall) if good else None


def summarise(bm, runs: list[Run], tools: list[str]) -> dict:
    """Per tool: the cheapest run at the stated accuracy (drift and gap), the cheapest at the
    stated trajectory error (and gap), and the wall-time ratios to planardyn's."""
    def per_tool(**targets):
        return {t: cheapest([r for r in runs if r.tool == t], **targets) for t in tools}

    s = {}
    for name, best in (("accuracy", per_tool(drift=bm.drift_target, gap=bm.gap_target)),
                       ("error", per_tool(error=bm.error_target, gap=bm.gap_target))):
        s[f"best_at_{name}"] = {t: dataclasses.asdict(r) if r else None for t, r in best.items()}
        pd = best.get("planardyn")
        s[f"ratio_at_{name}"] = {t: r.wall / pd.wall for t, r in best.items() if r and pd and t != "planardyn"}
        # A peer whose own dynamics calls were clocked: the ratio against those calls alone.
        s[f"dynamics_ratio_at_{name}"] = {t: r.wall * r.extra["dynamics_share"] / pd.wall for t, r in best.items()
                                          if r and pd and "dynamics_share" in r.extra}
    e0 = {t: [r.e0 for r in runs if r.tool == t and r.ok] for t in tools}
    s["start_energy"] = {t: v[0] for t, v in e0.items() if v}
    if "planardyn" in s["start_energy"]:
        pd0 = s["start_energy"]["planardyn"]
        s["start_energy_max_deviation"] = max(abs(x - pd0) for v in e0.values() for x in v)
    s["failed"] = {t: sum(not r.ok for r in runs if r.tool == t) for t in tools}
    return s


def four_bar_target(runs: list[Run], summary: dict) -> dict:
    """The four-bar target: planardyn at drift < 1e-6 J against the fastest peer meeting the four-bar's
    stated accuracy (drift < 1e-3 J, gap < 1e-6 m)."""
    bm = mechanisms.FOUR_BAR
    tight = cheapest([r for r in runs if r.tool == "planardyn"], drift=PLANARDYN_DRIFT_TARGET, gap=bm.gap_target)
    peers = [r for t, r in summary["best_at_accuracy"].items() if r and t != "planardyn"]
    fastest = min(peers, key=lambda r: r["wall"], default=None)
    out = {"planardyn": dataclasses.asdict(tight) if tight else None, "fastest_peer": fastest,
           "drift_target_J": PLANARDYN_DRIFT_TARGET, "ratio_target": RATIO_TARGET}
    if tight and fastest:
        out["ratio"] = fastest["wall"] / tight.wall
        out["meets"] = out["ratio"] >= RATIO_TARGET
    return out


def criterion(quick: bool) -> dict:
    """Run the Rust forward-dynamics bench and parse criterion's 'time: [lo mid hi]'."""
    cmd = ["cargo", "bench", "-p", "planardyn", "--bench", "forward_dynamics", "--",
           "--warm-up-time", "1", "--measurement-time", "2" if quick else "4"]
    say("$ " + " ".join(cmd))
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=mechanisms.ROOT, capture_output=True, text=True)
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


def python_overhead(setting: list) -> dict:
    """overhead.py in a fresh Python process (only planardyn loaded: no peer's threads)."""
    p = subprocess.run([sys.executable, str(HERE / "overhead.py"), json.dumps(setting)],
                       capture_output=True, text=True)
    if p.returncode != 0:
        return {"ok": False, "why": f"overhead.py failed: {p.stderr[-1000:]}"}
    return json.loads(p.stdout)


def bench_mechanism(bm, found: dict, quick: bool) -> dict:
    say(f"== {bm.key}: {bm.title} ({bm.model_rel})")
    load_start = os.getloadavg()  # other work on the machine skews every wall time
    date = time.strftime("%Y-%m-%d %H:%M:%S %Z")
    d = common.load_drawing(bm.spec)
    pd_mod = found["planardyn"][0]
    say("reference: planardyn DOP853 rtol = atol = 1e-13")
    ref = pd_mod.reference(bm)
    reference = {"q_end": ref[-1].tolist()}
    if bm.published_end:
        i, value, source = bm.published_end
        reference["published"] = {"coordinate": i, "value": value, "source": source,
                                  "difference": float(ref[-1, i] - value)}
        say(f"  reference at t_end {float(ref[-1, i])!r} against {value!r} ({source}): {ref[-1, i] - value:+.2e}")
    runs: list[Run] = []
    for mod, _ in found.values():
        runs += sweep(mod, bm, d, ref, quick)
    measured = {"date": date, "quick": quick,
                "load_average_at_start": load_start, "load_average_at_end": os.getloadavg()}
    return {"key": bm.key, "title": bm.title, "measured": measured,
            "driven": any(c.effort for c in d.coordinates), "model": bm.model_rel, "scenario": bm.scenario,
            "changed": bm.changed, "t_end_s": bm.t_end, "grid_dt_s": bm.grid_dt,
            "coordinates": [c.name for c in d.coordinates],
            "targets": {"drift_J": bm.drift_target, "gap_m": bm.gap_target, "error_rad": bm.error_target},
            "reference": reference, "runs": [dataclasses.asdict(r) for r in runs],
            "summary": summarise(bm, runs, list(found)), "_runs": runs}


def merge_previous(result: dict, path: Path) -> dict:
    """Keep from the previous results.json what this run did not measure (the mechanisms left
    out by --only, the four-bar's targets, criterion under --no-criterion); each part keeps
    its own date."""
    if not path.exists():
        return result
    old = json.loads(path.read_text())
    new = dict(result)
    mechs = {**old.get("mechanisms", {}), **result["mechanisms"]}
    new["mechanisms"] = {k: mechs[k] for k in mechanisms.BY_KEY if k in mechs}
    if result["four_bar_target"] is None:
        new["four_bar_target"] = old.get("four_bar_target")
        new["python_overhead"] = old.get("python_overhead", result["python_overhead"])
    if not result["criterion"].get("ok") and old.get("criterion", {}).get("ok"):
        new["criterion"] = old["criterion"]
    return new


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="every other setting, shorter criterion run")
    ap.add_argument("--only", nargs="+", choices=list(mechanisms.BY_KEY), metavar="MECHANISM",
                    help="only these mechanisms (" + ", ".join(mechanisms.BY_KEY) + ")")
    ap.add_argument("--no-criterion", action="store_true", help="skip cargo bench")
    ap.add_argument("--out", type=Path, default=RESULTS)
    ap.add_argument("--docs", type=Path, default=DOCS_PAGE,
                    help="page whose generated section is rewritten ('-' for none)")
    a = ap.parse_args()
    t_start = time.perf_counter()
    found, missing = tools()
    say("tools: " + ", ".join(f"{k} {v}" for k, (_, v) in found.items()))
    for k, why in missing.items():
        say(f"NOT AVAILABLE {k}: {why}")
    if "planardyn" not in found:
        say("planardyn itself does not import: run ./dev setup (or benchmarks/run.sh)")
        return 2
    benches = [mechanisms.BY_KEY[k] for k in a.only] if a.only else mechanisms.ALL
    mechs = {bm.key: bench_mechanism(bm, found, a.quick) for bm in benches}

    four_bar, overhead = None, {"ok": False, "why": "the four-bar was not run (--only)"}
    if "four-bar" in mechs:
        m = mechs["four-bar"]
        four_bar = four_bar_target(m["_runs"], m["summary"])
        say("Python overhead: simulate from Python against the same run from Rust")
        overhead = (python_overhead(four_bar["planardyn"]["extra"]["setting"]) if four_bar["planardyn"]
                    else {"ok": False, "why": f"no planardyn setting met {PLANARDYN_DRIFT_TARGET:g} J"})
        overhead["date"] = four_bar["date"] = m["measured"]["date"]
    for m in mechs.values():
        del m["_runs"]
    crit = {"ok": False, "error": "skipped (--no-criterion)"} if a.no_criterion else criterion(a.quick)

    if not a.no_criterion:
        crit["date"] = time.strftime("%Y-%m-%d %H:%M:%S %Z")
    env = {"python": sys.version.split()[0], "platform": platform.platform(), "cpus": os.cpu_count(),
           "versions": {k: v for k, (_, v) in found.items()}, "not_available": missing}
    result = {"environment": env, "mechanisms": mechs, "four_bar_target": four_bar,
              "targets": {"forward_dynamics_s": FD_TARGETS, "python_overhead": overhead_mod.OVERHEAD_TARGET},
              "python_overhead": overhead, "criterion": crit, "bench_seconds": time.perf_counter() - t_start}
    a.out.mkdir(parents=True, exist_ok=True)
    if a.only or a.no_criterion:
        result = merge_previous(result, a.out / "results.json")
    (a.out / "results.json").write_text(json.dumps(result, indent=1, default=_json))
    report.write(result, a.out, None if str(a.docs) == "-" else a.docs)
    say(report.summary_text(result))
    say(f"wrote {a.out}/results.json, results.md and the plots in {result['bench_seconds']:.0f} s")
    return 0


def _json(v):
    if isinstance(v, (np.floating, np.integer)):
        return v.item()
    if isinstance(v, np.ndarray):
        return v.tolist()
    raise TypeError(type(v).__name__)


if __name__ == "__main__":
    sys.exit(main())
