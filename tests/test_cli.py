"""The command line, run as a user would: ``python -m planardyn`` in a subprocess.

Exit status: 0 success, 1 the computation failed, 2 usage or model error (cli.py).
"""

from __future__ import annotations

import csv
import json
import subprocess
import sys

import pytest
from conftest import four_bar_dict


def run(*args: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "planardyn", *map(str, args)],
        capture_output=True, text=True, timeout=120, cwd=cwd,
    )


def write_model(tmp_path, d: dict, name="model.json"):
    path = tmp_path / name
    path.write_text(json.dumps(d, indent=1))
    return path


def test_simulate_writes_csv(tmp_path):
    model = write_model(tmp_path, four_bar_dict())
    out = tmp_path / "sub" / "results.csv"
    p = run("simulate", model, "--t-end", "0.2", "--output-dt", "0.01", "-o", out)
    assert p.returncode == 0, p.stderr
    assert p.stdout.startswith("success:") and "energy drift" in p.stdout and "min sigma" in p.stdout
    rows = list(csv.reader(out.open()))
    assert rows[0] == ["t", "theta", "qd_theta", "qdd_theta", "tau_theta", "kinetic", "potential", "work", "sigma"]
    assert len(rows) == 1 + 21  # t = 0, 0.01, ..., 0.2
    assert float(rows[-1][0]) == pytest.approx(0.2)
    assert float(rows[1][1]) == pytest.approx(four_bar_dict()["coordinates"][0]["value"], abs=1e-12)


def test_simulate_with_method_and_progress(tmp_path):
    model = write_model(tmp_path, four_bar_dict())
    p = run("simulate", model, "--t-end", "0.1", "--method", "rk4", "--dt", "0.001", "--progress")
    assert p.returncode == 0, p.stderr
    assert "100.0%" in p.stderr  # the bar ends full


def test_bad_model_exit_2_names_file_and_field(tmp_path):
    d = four_bar_dict()
    d["bodies"]["crank"]["mass"] = -1.0
    model = write_model(tmp_path, d, "bad.json")
    p = run("simulate", model)
    assert p.returncode == 2
    assert "bad.json" in p.stderr and "bodies.crank.mass" in p.stderr
    assert "Traceback" not in p.stderr


def test_malformed_yaml_and_missing_file_exit_2(tmp_path):
    bad = tmp_path / "broken.yaml"
    bad.write_text("name: x\npoints: {A: [0, 0]\n")
    p = run("simulate", bad)
    assert p.returncode == 2 and "broken.yaml" in p.stderr and "Traceback" not in p.stderr
    p = run("simulate", tmp_path / "nothere.yaml")
    assert p.returncode == 2 and "nothere.yaml" in p.stderr and "Traceback" not in p.stderr


def test_impossible_start_exit_2(tmp_path):
    # q0 = 0 for the rocker angle: |OB| = 1.7 m > b + a = 1.3 m, cannot be assembled,
    # which the model check reports under `coordinates`.
    d = four_bar_dict()
    d["coordinates"] = [{"name": "psi", "pair": "rocker_pivot", "value": 1.4515633094543714, "q0": 0.0}]
    d["drives"] = []
    p = run("simulate", write_model(tmp_path, d))
    assert p.returncode == 2 and "coordinates" in p.stderr and "Traceback" not in p.stderr


def test_failed_simulation_exit_1_keeps_partial_csv(tmp_path):
    model = write_model(tmp_path, four_bar_dict())
    out = tmp_path / "partial.csv"
    p = run("simulate", model, "--max-steps", "5", "-o", out)
    assert p.returncode == 1
    assert p.stdout.startswith("too_many_steps:")
    assert "stopped early" in p.stderr and "Traceback" not in p.stderr
    assert len(out.read_text().splitlines()) >= 2


def test_bad_option_exit_2(tmp_path):
    model = write_model(tmp_path, four_bar_dict())
    p = run("simulate", model, "--method", "euler")
    assert p.returncode == 2 and "unknown integration method" in p.stderr and "Traceback" not in p.stderr
    p = run("simulate", model, "--t-end", "soon")
    assert p.returncode == 2  # argparse
    p = run()
    assert p.returncode == 2


def test_demo_writes_plots(tmp_path):
    p = run("demo", "--out", tmp_path / "demo")
    assert p.returncode == 0, p.stderr
    for name in ("coordinates.png", "efforts.png", "energy.png", "mechanism.png", "results.csv"):
        f = tmp_path / "demo" / name
        assert f.is_file() and f.stat().st_size > 1000, name
