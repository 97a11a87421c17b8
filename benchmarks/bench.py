"""planardyn against the tools users would pick instead, measured in one run.

Run through ``benchmarks/run.sh`` (which makes the environment); by hand, from the
repository root with the peers' venv::

    PYTHONPATH=python benchmarks/.venv-peers/bin/python benchmarks/bench.py [--quick] [--only four-bar andrews]

For each mechanism of ``mechanisms.py`` (four-bar, five-bar, 3-RRR, Andrews' squeezer) and each
method of each tool (``variants`` of its module in peers/): the cheapest setting that meets the
mechanism's stated accuracy (energy drift or balance, loop gap), and the cheapest that meets its
stated error (with the gap), each found by ``cheapest.cheapest`` (a 1.1x scan, bisection to the
adjacent failing setting, a check of the neighbours) on the method's number of steps or tolerance.
Those settings are then timed side by side, interleaved, by ``timing.measure``; each tool's winner
is its method with the least median CPU time at the target, and its ratio to planardyn's winner is
taken round by round (``winners.py``). On the four-bar also the performance targets: planardyn's cheapest for
drift < 1e-6 J against the fastest peer at 1e-3 J, and ``simulate`` from Python against the same
run from Rust. Also runs the Rust criterion bench of one forward-dynamics evaluation. Writes
``benchmarks/results/`` (results.json, results.md, one work-precision plot per mechanism) and the
generated part of ``docs/benchmarks.md``.
"""

from __future__ import annotations

import argparse
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

import cheapest  # noqa: E402
import common  # noqa: E402
import mechanisms  # noqa: E402
import numpy as np  # noqa: E402
import overhead as overhead_mod  # noqa: E402
import report  # noqa: E402
import timing  # noqa: E402
import winners  # noqa: E402
from common import Run, Variant  # noqa: E402
from winners import CLOCKED, PLANARDYN_DRIFT_TARGET, PRE_ROUNDS, PREFILTER  # noqa: E402

PEERS = ["planardyn_peer", "mujoco_peer", "pinocchio_peer", "exudyn_peer"]
RESULTS = HERE / "results"
DOCS_PAGE = mechanisms.ROOT / "docs" / "benchmarks.md"

#: Criterion targets for one forward-dynamics evaluation (s), from the closed-form groups item of the
#: engine issue (docs/benchmarks.md, *Closed-form groups*).
FD_TARGETS = {"four-bar-gravity": 0.25e-6, "five-bar": 0.4e-6, "3-rrr": 1.5e-6, "andrews-squeezer": 1e-6}
#: Timing rounds under --quick.
QUICK_ROUNDS = 5


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



def targets_for(bm, tool: str) -> dict[str, dict]:
    """The targets a tool's methods are searched for: the mechanism's stated accuracy and its stated
    error (each with the gap), and on the four-bar planardyn's performance target as well."""
    t = {"accuracy": {"drift": bm.drift_target, "gap": bm.gap_target},
         "error": {"error": bm.error_target, "gap": bm.gap_target}}
    if bm.key == mechanisms.FOUR_BAR.key and tool == "planardyn":
        t["tight"] = {"drift": PLANARDYN_DRIFT_TARGET, "gap": bm.gap_target}
    return t


def misses(r: Run, target: dict) -> str:
    """What a run misses of a target, e.g. 'drift 1.20e-03 J'."""
    if not r.ok:
        return "failed: " + r.note
    unit = {"drift": "J", "gap": "m", "error": "rad"}
    return ", ".join(f"{k} {getattr(r, k):.5g} {unit[k]} (limit {lim:g})" for k, lim in target.items()
                     if not getattr(r, k) < lim)


def search(mod, bm, d, v: Variant, ref, verbose: bool) -> tuple[dict[int, Run], dict]:
    """One method's cheapest passing setting for each of its targets: (every run made, by setting;
    per target what cheapest.py found, JSON-ready)."""
    runs: dict[int, Run] = {}

    def evaluate(s: int) -> Run:
        if s not in runs:
            try:
                r = mod.run(bm, d, v, s, ref)
            except common.ReferenceFailed:
                raise
            except Exception as e:  # a tool that cannot model or run this: reported, not dropped
                r = Run(mod.TOOL, v.method, v.label(bm.t_end, s), value=s).fail(f"{type(e).__name__}: {e}")
            r.mechanism = bm.key
            runs[s] = r
            if verbose:
                say(f"      {'ok ' if r.ok else 'FAIL'} {r.setting:26s} one call {r.wall * 1e3:9.2f} ms  drift "
                    f"{r.drift:9.2e} J  gap {r.gap:9.2e} m  error {r.error:9.2e} rad {r.note}")
        return runs[s]

    grid = v.grid()
    out = {}
    for name, target in targets_for(bm, mod.TOOL).items():
        def passes(s: int, target: dict = target) -> bool:
            return evaluate(s).meets(**target)

        if passes(grid[-1]):
            f = cheapest.cheapest(passes, grid)
        else:  # no scan below a dearest setting that fails (loops that stay open at any step)
            f = cheapest.Found(None, None, tried={grid[-1]: False},
                               note=f"fails at the dearest setting searched, {v.label(bm.t_end, grid[-1])}: "
                                    f"{misses(runs[grid[-1]], target)}")
        res = {"setting": f.setting, "label": None if f.setting is None else v.label(bm.t_end, f.setting),
               "evaluated": len(f.tried), "note": f.note, "isolated": [v.label(bm.t_end, s) for s in f.isolated],
               "below": None if f.below is None else v.label(bm.t_end, f.below),
               "below_misses": None if f.below is None else misses(runs[f.below], target)}
        out[name] = res
        what = (f"{res['label']} (one call {runs[f.setting].wall * 1e3:.3g} ms); {res['below']} misses: "
                f"{res['below_misses']}" if f.setting is not None else "none")
        say(f"  {mod.TOOL:9s} {v.method:42s} {name:8s} {what}; {len(f.tried)} settings evaluated"
            + (f"; isolated passes ignored: {', '.join(res['isolated'])}" if f.isolated else "")
            + (f" [{f.note}]" if f.note else ""))
    return runs, out



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


def bench_mechanism(bm, found: dict, rounds: int, verbose: bool) -> dict:
    say(f"== {bm.key}: {bm.title} ({bm.model_rel})")
    load_start = os.getloadavg()  # other work on the machine skews every wall time
    date = time.strftime("%Y-%m-%d %H:%M:%S %Z")
    d = common.load_drawing(bm.spec)
    ref = found["planardyn"][0].Reference(bm)
    say(f"reference: planardyn DOP853 rtol = atol = {ref.RTOL:g}")
    reference = {"q_end": ref.grid()[-1].tolist()}
    if bm.published_end:
        i, value, source = bm.published_end
        end = float(reference["q_end"][i])
        reference["published"] = {"coordinate": i, "value": value, "source": source, "difference": end - value}
        say(f"  reference at t_end {end!r} against {value!r} ({source}): {end - value:+.2e}")
    say("search: each method's cheapest setting per target; '<setting> misses' is the next cheaper one")
    runs: list[Run] = []
    methods, cands = [], {}
    for mod, _ in found.values():
        for v in mod.variants(bm):
            vruns, res = search(mod, bm, d, v, ref, verbose)
            runs += vruns.values()
            methods.append({"tool": mod.TOOL, "method": v.method, "axis": "steps" if v.steps else "tolerance",
                            "range": v.label(bm.t_end, v.grid()[0]) + " to " + v.label(bm.t_end, v.grid()[-1]),
                            "targets": res, "run_columns": RUN_COLUMNS, "runs": run_rows(list(vruns.values()))})
            winners.candidates_of(mod, v, vruns, res, cands)
    load_search = os.getloadavg()
    cands_all = list(cands.values())
    calls = {}
    for c in cands_all:
        calls[c.key] = c.mod.timed(bm, d, c.variant, c.run.value)
        if hasattr(c.mod, "clocked"):
            calls[c.key + CLOCKED] = c.mod.clocked(bm, d, c.variant, c.run.value)
    say(f"timing the {len(cands_all)} cheapest settings side by side, {PRE_ROUNDS} rounds")
    pre = timing.measure({c.key: calls[c.key] for c in cands_all}, PRE_ROUNDS, say)
    median = {k: winners.cost(e) for k, e in pre["entries"].items()}
    keep, skipped = winners.prefilter(cands_all, median)
    say(f"timing the {len(keep)} within {PREFILTER:g}x of their tool's cheapest (CPU time), {rounds} rounds")
    timed = timing.measure({k: f for k, f in calls.items() if k.removesuffix(CLOCKED) in {c.key for c in keep}},
                           rounds, say)
    for r in runs:
        r.mechanism = bm.key
    measured = {"date": date, "rounds": rounds, "load_average_at_start": load_start,
                "load_average_after_search": load_search, "load_average_at_end": os.getloadavg()}
    return {"key": bm.key, "title": bm.title, "measured": measured,
            "driven": any(c.effort for c in d.coordinates), "model": bm.model_rel, "scenario": bm.scenario,
            "changed": bm.changed, "t_end_s": bm.t_end, "grid_dt_s": bm.grid_dt,
            "coordinates": [c.name for c in d.coordinates],
            "targets": {"drift_J": bm.drift_target, "gap_m": bm.gap_target, "error_rad": bm.error_target},
            "reference": reference, "methods": methods,
            "not_timed": [{"key": c.key, "targets": c.targets, "pre_median_cpu": median[c.key]} for c in skipped],
            "timing": timed, "summary": winners.summarise(runs, cands_all, timed, list(found)), "_candidates": cands_all}


#: The fields of every run of a method's search kept in results.json (the winners keep all of theirs).
RUN_COLUMNS = ("value", "ok", "note", "wall", "steps", "drift", "gap", "error")


def run_rows(runs: list[Run]) -> list[list]:
    """A method's runs as rows of RUN_COLUMNS (thousands in all), by setting, the floats to 6 digits."""
    def cell(v):
        return float(f"{v:.6g}") if isinstance(v, float) else v

    return [[cell(getattr(r, c)) for c in RUN_COLUMNS] for r in sorted(runs, key=lambda r: r.value)]


def dumps(result: dict) -> str:
    """results.json, indented, but each list of plain values on one line (the thousands of runs of
    the searches, the timing samples). JSON strings hold no raw line breaks, so only the layout
    changes."""
    def one_line(m: re.Match) -> str:
        return re.sub(r"\[\s+", "[", re.sub(r"\s+\]", "]", re.sub(r",\n\s*", ", ", m.group(0))))

    return re.sub(r"\[[^\[\]{}]*\]", one_line, json.dumps(result, indent=1, default=_json))


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
    ap.add_argument("--quick", action="store_true",
                    help=f"{QUICK_ROUNDS} timing rounds instead of {timing.ROUNDS}, shorter criterion run "
                         "(the search is the same)")
    ap.add_argument("--verbose", action="store_true", help="print every run of the search")
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
    rounds = QUICK_ROUNDS if a.quick else timing.ROUNDS
    mechs = {bm.key: bench_mechanism(bm, found, rounds, a.verbose) for bm in benches}

    four_bar, overhead = None, {"ok": False, "why": "the four-bar was not run (--only)"}
    if "four-bar" in mechs:
        m = mechs["four-bar"]
        four_bar = winners.four_bar_target(m)
        say("Python overhead: simulate from Python against the same run from Rust")
        overhead = (python_overhead(four_bar["planardyn"]["extra"]["setting"]) if four_bar["planardyn"]
                    else {"ok": False, "why": f"no planardyn setting met {PLANARDYN_DRIFT_TARGET:g} J"})
        overhead["date"] = four_bar["date"] = m["measured"]["date"]
    for m in mechs.values():
        del m["_candidates"]
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
    (a.out / "results.json").write_text(dumps(result))
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
