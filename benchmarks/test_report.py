"""The generated summary of docs/benchmarks.md says what its tables say: every ratio it
quotes is a table's "× planardyn" cell, for the same tool, mechanism and target. Run with
``.venv/bin/python -m pytest -q benchmarks``."""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import report  # noqa: E402

RESULTS = json.loads((HERE / "results" / "results.json").read_text())


def table_ratios(m: dict, tool: str) -> tuple[str, str]:
    """The two "× planardyn" cells of the tool's row of best_table."""
    row = next(r for r in report.best_table(m).splitlines() if r.startswith(f"| {tool} |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    return cells[4], cells[7]


def test_summary_ratios_are_the_tables():
    text = report.summary_sentences(RESULTS)
    mechs = RESULTS["mechanisms"]
    for line in text.splitlines():
        tool = re.match(r"- \*\*(\w+)\*\*", line)[1]
        # "lo to hi (four-bar a, five-bar b, ...) at each mechanism's stated accuracy, and ... at its stated error"
        groups = re.findall(r"\(([^()]*)\) at (each mechanism's stated accuracy|its stated error)", line)
        assert len(groups) == 2, line
        for (each, what), col in zip(groups, (0, 1)):
            for item in each.split(", "):
                key, value = item.rsplit(" ", 1)
                assert table_ratios(mechs[key], tool)[col] == value, (tool, key, what)
        lo_hi = [float(v) for v in re.findall(r"is ([\d.]+)(?: to ([\d.]+))? \(", line)[0] if v]
        quoted = [float(item.rsplit(" ", 1)[1]) for item in groups[0][0].split(", ")]
        assert lo_hi[0] == min(quoted) and lo_hi[-1] == max(quoted), line


def test_dynamics_share_ratio_is_the_share_of_the_wall_time():
    # A made-up Pinocchio run whose calls were clocked: the ratio to its calls alone is the
    # share times its ratio, and the sentence quotes both.
    m = json.loads(json.dumps(RESULTS["mechanisms"]["four-bar"]))
    s = m["summary"]
    s["best_at_accuracy"]["Pinocchio"]["extra"] = {"dynamics_share": 0.5}
    s["dynamics_ratio_at_accuracy"] = {"Pinocchio": 0.5 * s["ratio_at_accuracy"]["Pinocchio"]}
    text = report.summary_sentences({"mechanisms": {"four-bar": m}})
    line = next(x for x in text.splitlines() if "Pinocchio" in x)
    assert "calls are 50 % (four-bar 50 %) of its time" in line
    assert f"alone the ratio is {0.5 * s['ratio_at_accuracy']['Pinocchio']:.1f}" in line
