"""Which of a tool's cheapest settings wins, and the ratios between the winners.

Every method's cheapest passing setting for a target (bench.py's search) is a *candidate*; the
candidates are timed side by side (timing.py); a tool's winner at a target is its candidate with
the least ``cost``, and its ratios to planardyn's winner are taken round by round.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np
import timing
from common import Run, Variant

#: Target on the four-bar: planardyn at this drift (J) in at most 1/RATIO_TARGET of the
#: wall time of the fastest peer meeting the four-bar's drift and gap targets.
PLANARDYN_DRIFT_TARGET = 1e-6
RATIO_TARGET = 20.0
#: Every method's cheapest passing settings are first timed side by side in PRE_ROUNDS rounds;
#: those within PREFILTER times their tool's cheapest at one of their targets (``cost``) are then
#: timed in full, the others listed with their cost in the first rounds.
PRE_ROUNDS = 3
PREFILTER = 2.0

#: The key suffix of a timed call that returns the seconds spent in a tool's own C++ dynamics.
CLOCKED = " | clocked"


@dataclass
class Candidate:
    """A method's cheapest passing setting, for one target or more: a call timing.py times."""

    mod: Any  # the tool's module in peers/
    variant: Variant
    run: Run  # the search's run at that setting
    targets: list[str]

    @property
    def tool(self) -> str:
        return self.mod.TOOL

    @property
    def key(self) -> str:
        return f"{self.tool} | {self.run.method} | {self.run.setting}"



def candidates_of(mod, v: Variant, runs: dict[int, Run], found: dict, into: dict) -> None:
    """Add a method's cheapest settings to the candidates (one per setting, with its targets)."""
    for name, f in found.items():
        if f["setting"] is not None:
            c = into.setdefault((mod.TOOL, v.method, f["setting"]), Candidate(mod, v, runs[f["setting"]], []))
            c.targets.append(name)


def prefilter(cands: list[Candidate], median: dict[str, float]) -> tuple[list[Candidate], list[Candidate]]:
    """(to time in full, not): a candidate is kept if at one of its targets its cost is at most
    PREFILTER times its tool's cheapest there."""
    fastest: dict[tuple[str, str], float] = {}
    for c in cands:
        for t in c.targets:
            fastest[c.tool, t] = min(fastest.get((c.tool, t), np.inf), median[c.key])
    keep = [c for c in cands if any(median[c.key] <= PREFILTER * fastest[c.tool, t] for t in c.targets)]
    return keep, [c for c in cands if c not in keep]


def cost(e: dict) -> float:
    """What decides between candidates: the median CPU time of the process (all of a tool's threads).
    On a quiet machine it ranks as the wall time does; on a shared one a call's wall time also
    holds the time it waited for a core, which falls on a short call's batch by chance."""
    return e["process_cpu_stats"]["median"]


def winner(cands: list[Candidate], tool: str, target: str, E: dict) -> Candidate | None:
    """The tool's timed candidate for the target with the least cost."""
    timed = [c for c in cands if c.tool == tool and target in c.targets and c.key in E]
    return min(timed, key=lambda c: cost(E[c.key]), default=None)


def winner_dict(c: Candidate, E: dict) -> dict:
    """The winner's search run, its wall time the median of the interleaved rounds."""
    e = E[c.key]
    out = dataclasses.asdict(c.run)
    out.update(wall=e["wall_stats"]["median"], one_call_wall=c.run.wall, key=c.key,
               timing={k: e[f"{k}_stats"] for k in ("wall", "thread_cpu", "process_cpu")} | {"batch": e["batch"]})
    if c.key + CLOCKED in E:
        k = E[c.key + CLOCKED]
        out["extra"] = {**out["extra"], "dynamics_share": timing.paired(k["value"], k["wall"])["median"],
                        "dynamics_s": timing.quartiles(k["value"])}
    return out


def dynamics_ratio(key: str, pd_key: str, E: dict) -> dict:
    """Quartiles over the rounds of a tool's C++ dynamics time over planardyn's wall time: in each
    round the share of the clocked call's time spent in the dynamics calls (both clocks in one call,
    so a slowed call slows both) times the unclocked call's wall time, over planardyn's."""
    k, w, p = E[key + CLOCKED], E[key]["wall"], E[pd_key]["wall"]
    return timing.quartiles([v / kw * x / y for v, kw, x, y in zip(k["value"], k["wall"], w, p)])


def summarise(runs: list[Run], cands: list[Candidate], timed: dict, tools: list[str]) -> dict:
    """Per target and tool: the winner, and against planardyn's winner the per-round ratios of wall
    time (median and quartiles), of thread CPU time, and for a tool whose dynamics calls were
    clocked, of those calls alone."""
    E, s = timed["entries"], {}
    for target in ("accuracy", "error"):
        best = {t: winner(cands, t, target, E) for t in tools}
        pd = best.get("planardyn")
        s[f"best_at_{target}"] = {t: winner_dict(c, E) if c else None for t, c in best.items()}
        peers = {t: c for t, c in best.items() if c and pd and t != "planardyn"}
        wall = {t: timing.paired(E[c.key]["wall"], E[pd.key]["wall"]) for t, c in peers.items()}
        s[f"ratio_at_{target}"] = {t: q["median"] for t, q in wall.items()}
        s[f"ratio_quartiles_at_{target}"] = {t: [q["q1"], q["q3"]] for t, q in wall.items()}
        s[f"cpu_ratio_at_{target}"] = {t: timing.paired(E[c.key]["thread_cpu"], E[pd.key]["thread_cpu"])["median"]
                                       for t, c in peers.items()}
        dyn = {t: dynamics_ratio(c.key, pd.key, E) for t, c in peers.items() if c.key + CLOCKED in E}
        s[f"dynamics_ratio_at_{target}"] = {t: q["median"] for t, q in dyn.items()}
        s[f"dynamics_ratio_quartiles_at_{target}"] = {t: [q["q1"], q["q3"]] for t, q in dyn.items()}
    e0 = {t: [r.e0 for r in runs if r.tool == t and r.ok] for t in tools}
    s["start_energy"] = {t: v[0] for t, v in e0.items() if v}
    if "planardyn" in s["start_energy"]:
        pd0 = s["start_energy"]["planardyn"]
        s["start_energy_max_deviation"] = max(abs(x - pd0) for v in e0.values() for x in v)
    s["failed"] = {t: sum(not r.ok for r in runs if r.tool == t) for t in tools}
    return s


def four_bar_target(m: dict) -> dict:
    """The four-bar target: planardyn's winner at drift < 1e-6 J against the fastest peer winner at
    the four-bar's stated accuracy (drift < 1e-3 J, gap < 1e-6 m), their ratio taken per round."""
    E, s = m["timing"]["entries"], m["summary"]
    tight = winner(m["_candidates"], "planardyn", "tight", E)
    peers = [r for t, r in s["best_at_accuracy"].items() if r and t != "planardyn"]
    fastest = min(peers, key=lambda r: r["timing"]["process_cpu"]["median"], default=None)
    out = {"planardyn": winner_dict(tight, E) if tight else None, "fastest_peer": fastest,
           "drift_target_J": PLANARDYN_DRIFT_TARGET, "ratio_target": RATIO_TARGET}
    if tight and fastest:
        q = timing.paired(E[fastest["key"]]["wall"], E[tight.key]["wall"])
        out["ratio"], out["ratio_quartiles"] = q["median"], [q["q1"], q["q3"]]
        out["cpu_ratio"] = timing.paired(E[fastest["key"]]["thread_cpu"], E[tight.key]["thread_cpu"])["median"]
        if fastest["key"] + CLOCKED in E:
            q = dynamics_ratio(fastest["key"], tight.key, E)
            out["dynamics_ratio"], out["dynamics_ratio_quartiles"] = q["median"], [q["q1"], q["q3"]]
        out["meets"] = out["ratio"] >= RATIO_TARGET
    return out
