"""One work-precision diagram per mechanism, from results.json: every run of every method's search,
at its one-call wall time (the winners' interleaved medians are in the tables)."""

from __future__ import annotations

import math
from pathlib import Path

COLORS = {"planardyn": "tab:blue", "MuJoCo": "tab:orange", "Pinocchio": "tab:green", "Exudyn": "tab:red"}
MARKERS = ["o", "s", "^", "D", "v", "P", "X"]


def plot(m: dict, runs: list[dict], path: Path) -> None:
    """The diagram of one mechanism of results.json, from its runs (report.runs)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = m["targets"]
    fig, axes = plt.subplots(1, 3, figsize=(17, 6.6), constrained_layout=True)
    series: dict[tuple[str, str], list[dict]] = {}
    for r in runs:
        if r["ok"] and all(math.isfinite(r[k]) for k in ("wall", "error", "drift", "gap")):
            series.setdefault((r["tool"], r["method"]), []).append(r)
    marker_of: dict[str, int] = {}
    for (tool, method), rs in series.items():
        k = marker_of.setdefault(tool, 0)
        marker_of[tool] = k + 1
        # Points only: a search's runs crowd near the thresholds, and accuracy need not fall
        # monotonically along the setting, so lines would zigzag.
        style = dict(color=COLORS.get(tool, "gray"), marker=MARKERS[k % len(MARKERS)], ms=3, alpha=0.6, ls="none")
        for ax, key in zip(axes, ("error", "drift", "gap")):
            y = [min(max(r[key], 1e-16), 1e3) for r in rs]  # blown-up runs at the top edge
            ax.loglog([r["wall"] for r in rs], y, label=f"{tool}: {method}", **style)
    # The winners, at their interleaved median wall time: on the drift axis those at the stated
    # accuracy, on the error axis those at the stated error.
    for ax, key, target in ((axes[1], "drift", "accuracy"), (axes[0], "error", "error")):
        for tool, r in m["summary"][f"best_at_{target}"].items():
            if r:
                ax.loglog([r["wall"]], [max(r[key], 1e-16)], marker="*", ms=14, mec="k",
                          color=COLORS.get(tool, "gray"), ls="none")
    for ax, key, label, what in ((axes[0], "error_rad", "error in the coordinates, max over the grid (rad)", "rad"),
                                 (axes[1], "drift_J", "energy drift max |E - E0| (J)", "J"),
                                 (axes[2], "gap_m", "loop gap, max over the steps (m)", "m")):
        ax.set_ylabel(label)
        ax.axhline(t[key], color="k", lw=0.8, ls="--")
        ax.text(ax.get_xlim()[0], t[key], f" stated accuracy {t[key]:g} {what}", va="bottom", fontsize=8)
        ax.set_xlabel(f"wall time of one call for {m['t_end_s']:g} s simulated (s); stars: the winners' medians")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_title("work-precision: trajectory error")
    axes[1].set_title("work-precision: energy " + ("balance" if m["driven"] else "drift"))
    axes[2].set_title("loop closure")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=4, fontsize=8)
    fig.suptitle(f"{m['title']}, {m['t_end_s']:g} s ({m['model']}): every run of the search; lower left is better",
                 fontsize=11)
    fig.savefig(path, dpi=100)
    plt.close(fig)
