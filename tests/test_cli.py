"""The command line, run as a user would: ``python -m planardyn`` in a subprocess.

Exit status: 0 success, 1 the computation failed, 2 usage or model error (cli.py).
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import re
import subprocess
import sys
import zipfile

import numpy as np
import planardyn as pd
import pytest
import yaml
from conftest import MODELS, ROOT, cli_run, four_bar_dict
from PIL import Image
from planardyn import cli, models
from planardyn.mechanism import Mechanism
from planardyn.results_io import inverse_result, read_results, write_results
from wheel_smoke import BLOCK


def run(*args: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "planardyn", *map(str, args)],
        capture_output=True, text=True, timeout=120, cwd=cwd,
    )


def write_model(tmp_path, d: dict, name="model.json"):
    path = tmp_path / name
    path.write_text(json.dumps(d, indent=1))
    return path


def csv_rows(path):
    return list(csv.reader(path.open()))


def test_simulate_writes_csv(tmp_path):
    model = write_model(tmp_path, four_bar_dict())
    out = tmp_path / "sub" / "results.csv"
    p = run("simulate", model, "--t-end", "0.2", "--output-dt", "0.01", "-o", out)
    assert p.returncode == 0, p.stderr
    assert p.stdout.startswith("success:") and "energy drift" in p.stdout and "min sigma" in p.stdout
    rows = csv_rows(out)
    assert rows[0][:9] == ["t", "theta", "qd_theta", "qdd_theta", "tau_theta", "kinetic", "potential", "work", "sigma"]
    assert rows[0][9:14] == ["residual", "partitioned", "X_crank", "Y_crank", "phi_crank"]
    assert len(rows[0]) == 11 + 2 * 9  # then x and xd of the three bodies
    assert len(rows) == 1 + 21  # t = 0, 0.01, ..., 0.2
    assert float(rows[-1][0]) == pytest.approx(0.2)
    assert float(rows[1][1]) == pytest.approx(four_bar_dict()["coordinates"][0]["value"], abs=1e-12)
    meta = json.loads(out.with_name(out.name + ".json").read_text())
    assert meta["settings"]["t_end"] == 0.2 and meta["settings"]["output_dt"] == 0.01
    assert meta["model"]["name"] == "crank-rocker four-bar"


@pytest.mark.parametrize("ext", [".npz", ".parquet"])
def test_simulate_writes_other_formats(tmp_path, ext):
    model = write_model(tmp_path, four_bar_dict())
    out = tmp_path / f"results{ext}"
    p = run("simulate", model, "--t-end", "0.1", "--output-dt", "0.01", "-o", out)
    assert p.returncode == 0, p.stderr
    res = read_results(out)
    assert len(res.t) == 11 and res.t[-1] == pytest.approx(0.1)
    assert res.tau[0, 0] == 1.5  # the model's constant drive effort
    assert res.metadata["settings"]["t_end"] == 0.1


def test_simulate_unknown_extension_exit_2(tmp_path):
    model = write_model(tmp_path, four_bar_dict())
    p = run("simulate", model, "-o", tmp_path / "results.xlsx")
    assert p.returncode == 2 and "results files end in .csv, .parquet, .npz" in p.stderr
    assert "Traceback" not in p.stderr


def test_simulate_with_method_and_progress(tmp_path):
    model = write_model(tmp_path, four_bar_dict())
    p = run("simulate", model, "--t-end", "0.1", "--method", "rk4", "--dt", "0.001", "--progress")
    assert p.returncode == 0, p.stderr
    # tqdm's bar ends full, once (issue 26: the old bar printed 100 % twice), with the run's
    # span and the elapsed time < time left.
    assert p.stderr.count("100%") == 1 and p.stderr.rstrip().endswith("0.1/0.1 s [00:00<00:00]"), p.stderr


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
    assert len(csv_rows(out)) >= 2
    assert read_results(out).status == "too_many_steps"


def test_hopeless_model_stops_early_exit_1(tmp_path):
    # Constant 1e12 N m on both motors in the file: stopped after ~10,000 attempts, the
    # last accepted state written as the last row.
    d = yaml.safe_load((MODELS / "five-bar.yaml").read_text())
    d["drives"] = [{"coordinate": c, "effort": 1e12} for c in ("theta1", "theta2")]
    out = tmp_path / "hopeless.csv"
    p = run("simulate", write_model(tmp_path, d), "-o", out)
    assert p.returncode == 1 and "Traceback" not in p.stderr
    assert p.stdout.startswith("step_size_too_small:")
    res = read_results(out)
    assert res.status == "step_size_too_small" and "efforts or rates are too large" in res.message
    assert len(res.t) == 2 and res.t[-1] > 0 and np.isfinite(res.energy.balance[-1])


def test_bad_option_exit_2(tmp_path):
    model = write_model(tmp_path, four_bar_dict())
    p = run("simulate", model, "--method", "euler")
    assert p.returncode == 2 and "unknown integration method" in p.stderr and "Traceback" not in p.stderr
    p = run("simulate", model, "--t-end", "soon")
    assert p.returncode == 2  # argparse
    p = run()
    assert p.returncode == 2


# ------------------------------------------------------------------ the other commands

FIVE_BAR = MODELS / "five-bar.yaml"


@pytest.mark.parametrize("command", ["check", "simulate", "inverse", "plot", "animate", "demo"])
def test_every_command_has_help_with_examples(command):
    p = run(command, "--help")
    assert p.returncode == 0
    assert "examples:" in p.stdout and f"planardyn {command}" in p.stdout.split("examples:")[1]
    assert "Exit status" in p.stdout


def test_check_describes_the_five_bar():
    p = run("check", FIVE_BAR)
    assert p.returncode == 0, p.stderr
    out = p.stdout
    assert "model: five-bar 5R robot, driven" in out
    assert "bodies: 4" in out and "pairs: 5  (5 revolute)" in out
    assert "mobility (Grubler): 3n - 2p = 3*4 - 2*5 = 2; coordinates: 2" in out
    assert "theta1: drawn 2.00713 rad" in out and "theta2: drawn 1.0472 rad" in out
    # The drawing is away from singularities (model file comment): sigma_min well above 0.
    sigma = float(re.search(r"type II sigma_min ([\d.e-]+)", out).group(1))
    assert 0.1 < sigma < 1.0
    assert re.search(r"passive [\d.]+", out)


def test_check_slider_crank_units_and_kinds():
    p = run("check", MODELS / "slider-crank.yaml")
    assert p.returncode == 0, p.stderr
    assert "(3 revolute, 1 prismatic)" in p.stdout and "3*3 - 2*4 = 1" in p.stdout


def test_check_bad_model_exit_2(tmp_path):
    d = four_bar_dict()
    d["bodies"]["crank"]["mass"] = -1.0
    p = run("check", write_model(tmp_path, d, "bad.json"))
    assert p.returncode == 2 and "bodies.crank.mass" in p.stderr and "Traceback" not in p.stderr


def test_inverse_gives_the_torques_of_a_simulated_motion(tmp_path):
    # Simulate the five-bar, keep only t and q as the prescribed motion: the inverse
    # dynamics (spline derivatives) gives back the motor torques that drove it.
    sim = tmp_path / "sim.npz"
    assert run("simulate", FIVE_BAR, "--t-end", "0.5", "-o", sim).returncode == 0
    res = read_results(sim)
    motion = tmp_path / "motion.csv"
    with motion.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t", "theta1", "theta2"])
        for t, q in zip(res.t.tolist(), res.q.tolist()):
            w.writerow([repr(t), *map(repr, q)])
    out = tmp_path / "torques.csv"
    p = run("inverse", FIVE_BAR, "--motion", motion, "-o", out)
    assert p.returncode == 0, p.stderr
    assert p.stdout.startswith("inverse dynamics: 101 rows") and "|tau_theta1| <= 2.41 N m" in p.stdout
    inv = read_results(out)
    assert inv.metadata["kind"] == "inverse"
    np.testing.assert_allclose(inv.tau, res.tau, rtol=0, atol=3e-3)  # see test_results_io


def test_inverse_bad_motion_exit_2(tmp_path):
    motion = tmp_path / "motion.csv"
    motion.write_text("t,theta1\n0,2\n1,2\n")
    p = run("inverse", FIVE_BAR, "--motion", motion)
    assert p.returncode == 2 and "no column 'theta2'" in p.stderr and "Traceback" not in p.stderr
    p = run("inverse", FIVE_BAR)
    assert p.returncode == 2 and "--motion" in p.stderr


def test_plot_and_animate(tmp_path):
    sim = tmp_path / "run.csv"
    assert run("simulate", FIVE_BAR, "--t-end", "0.3", "-o", sim).returncode == 0
    p = run("plot", sim)
    assert p.returncode == 0, p.stderr
    with Image.open(tmp_path / "run.png") as im:
        assert im.size == (1320, 840)  # 11 x 7 in at 120 dpi
        assert np.asarray(im.convert("L")).std() > 10
    p = run("plot", sim, "--torque-speed", "-o", tmp_path / "ts.png")
    assert p.returncode == 0 and (tmp_path / "ts.png").stat().st_size > 5000
    p = run("animate", FIVE_BAR, sim, "-o", tmp_path / "a.gif", "--fps", "10", "--speed", "0.1")
    assert p.returncode == 0, p.stderr
    with Image.open(tmp_path / "a.gif") as im:
        assert im.n_frames == 31
    p = run("animate", FIVE_BAR, sim, "-o", tmp_path / "a.html", "--channel", "tau_theta2")
    assert p.returncode == 0, p.stderr
    assert '"key":"tau_theta2"' in (tmp_path / "a.html").read_text()
    # The model is in the results file: it is enough alone, and gives the same frames.
    p = run("animate", sim, "-o", tmp_path / "b.gif", "--fps", "10", "--speed", "0.1")
    assert p.returncode == 0, p.stderr
    with Image.open(tmp_path / "a.gif") as a, Image.open(tmp_path / "b.gif") as b:
        assert a.n_frames == b.n_frames and np.array_equal(np.asarray(a.convert("L")), np.asarray(b.convert("L")))


def test_animate_without_a_model_in_the_file_asks_for_it(tmp_path):
    res = pd.load_example("five-bar").simulate(t_end=0.05)
    bare = dataclasses.replace(res, metadata={}).save(tmp_path / "bare.npz")
    p = run("animate", bare, "-o", tmp_path / "a.gif")
    assert p.returncode == 2 and "does not hold its model" in p.stderr and "planardyn animate MODEL" in p.stderr


def test_plot_and_animate_errors(tmp_path):
    p = run("plot", tmp_path / "none.csv")
    assert p.returncode == 2 and "none.csv" in p.stderr and "Traceback" not in p.stderr
    sim = tmp_path / "four.npz"
    assert run("simulate", write_model(tmp_path, four_bar_dict()), "--t-end", "0.05", "-o", sim).returncode == 0
    p = run("animate", FIVE_BAR, sim, "-o", tmp_path / "a.gif")
    assert p.returncode == 2 and "was not computed with" in p.stderr
    p = run("animate", FIVE_BAR, sim, "-o", tmp_path / "a.avi")
    assert p.returncode == 2 and ".gif, .mp4 or .html" in p.stderr and "Traceback" not in p.stderr


# ---------------------------------------------------------------- issue 23 finding 9: output errors in words

@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    """A short five-bar run written as a results file (the input of plot, animate, inverse)
    and a four-bar as MJCF (the input of import)."""
    path = tmp_path_factory.mktemp("run") / "run.csv"
    pd.load(MODELS / "five-bar.yaml").simulate(0.05, output_dt=0.01).save(path)
    # An MJCF file beside it, the input of planardyn import.
    assert run("export", "four-bar-gravity", "-o", path.with_name("four-bar.xml")).returncode == 0
    return path


def writing_commands(run_file, out):
    """Every command that writes, with ``out`` as its output (demo: its folder)."""
    five = MODELS / "five-bar.yaml"
    return {
        "simulate": ["simulate", five, "--t-end", "0.01", "-o", out.with_suffix(".csv")],
        "inverse": ["inverse", five, "--motion", run_file, "-o", out.with_suffix(".npz")],
        "identify": ["identify", five, run_file, "-o", out.with_suffix(".json")],
        "plot": ["plot", run_file, "-o", out.with_suffix(".png")],
        "animate": ["animate", run_file, "-o", out.with_suffix(".html")],
        "demo": ["demo", "--out", out],
        "export": ["export", five, "-o", out.with_suffix(".urdf")],
        "import": ["import", run_file.with_name("four-bar.xml"), "-o", out.with_suffix(".yaml")],
        "size": ["size", "five-bar", "--circle", "0.014", "0.5097", "0.06", "--json", out.with_suffix(".json")],
        "plan": ["plan", "library/five-bar-5r", "--line", "-0.08", "0.28", "0.08", "0.36", "--effort", "5", "5",
                 "-o", out.with_suffix(".csv")],
    }


def prefix(command):
    """How a command's errors start (size and plan name themselves)."""
    return f"planardyn {command}: " if command in ("size", "plan") else "planardyn: "


@pytest.mark.parametrize("command", ["simulate", "inverse", "identify", "plot", "animate", "demo", "export",
                                     "import", "size", "plan"])
def test_an_output_under_a_file_is_named_with_its_cause(short_run, tmp_path, command):
    """Before: 'planardyn: [Errno 17] File exists: ...' (simulate after the whole run)."""
    from conftest import cli_run

    blocker = tmp_path / "file.csv"
    blocker.write_text("x")
    argv = writing_commands(short_run, blocker / "x")[command]
    code, err = cli_run(*argv)
    out = argv[-1]
    assert (code, err) == (2, f"{prefix(command)}cannot write {out}: {blocker} is a file, not a directory\n")


def test_an_output_where_no_file_can_be_made_names_the_path_asked_for(short_run):
    """Before: 'planardyn: [Errno 2] No such file or directory: '/proc/.o.csv.123.part'."""
    from conftest import cli_run

    for command, argv in writing_commands(short_run, __import__("pathlib").Path("/proc/o")).items():
        code, err = cli_run(*argv)
        assert (code, err) == (2, f"{prefix(command)}cannot write {argv[-1]}: /proc does not take new files\n"), command


@pytest.mark.parametrize("errno_, cause", [
    (13, "permission denied"), (30, "the file system is read-only"), (28, "the disk is full")])
def test_a_failed_write_says_why_in_words(short_run, tmp_path, monkeypatch, errno_, cause):
    """The causes root cannot meet in a test (it may write anywhere, the disk is not full):
    the results writer raises them, as the file system would, after the whole run."""
    from conftest import cli_run
    from planardyn import results_format

    def refused(*args, **kwargs):
        raise OSError(errno_, "from the OS")

    monkeypatch.setattr(results_format.np, "savez_compressed", refused)
    out = tmp_path / "run.npz"
    code, err = cli_run("simulate", MODELS / "five-bar.yaml", "--t-end", "0.01", "-o", out)
    assert (code, err) == (2, f"planardyn: cannot write {out}: {cause}\n")
    assert list(tmp_path.iterdir()) == []  # no temporary file left


# ---------------------------------------------------------------- issue 26, the first hour


def test_every_command_is_in_the_help_with_shipped_model_names():
    # Issue 26: plan was missing from --help, size only in the epilog (both dispatched outside
    # argparse); the examples named examples/models/five-bar.yaml, which a wheel user lacks.
    p = run("--help")
    listed = re.findall(r"^    (\w+)(?: |$)", p.stdout, re.M)  # a long name has its help on the next line
    assert listed == ["check", "draw", "simulate", "inverse", "identify", "plot", "animate", "demo", "app", "size",
                      "stiffness", "modes", "flexible", "plan",
                      "export", "import", "docs"]
    for command in listed:
        help_text = run(command, "--help").stdout
        assert help_text.startswith(f"usage: planardyn {command} "), command
        assert "examples/models" not in help_text, command
    assert "examples/models" not in p.stdout
    for name in re.findall(r"planardyn \w+ ([\w/-]+)(?= )", p.stdout):
        assert name in pd.models.names() or name.endswith((".csv", ".npz")) or name == "model-format", name


def test_size_and_plan_as_subcommands_keep_their_exit_codes():
    code, err = cli_run("size", FIVE_BAR, "--circle", "0.014", "0.5097", "0")  # R > 0
    assert code == 2 and "argument --circle: the radius R must be > 0 m, got 0" in err
    code, err = cli_run("plan", "library/five-bar-5r", "--line", "-0.08", "0.28", "0.08", "0.36")
    assert code == 2 and "one of the arguments --effort --actuators is required" in err
    # Limits no timing keeps: exit 1 (InfeasiblePlan), as before.
    code, err = cli_run("plan", "library/five-bar-5r", "--line", "-0.08", "0.28", "0.08", "0.36", "--effort",
                        "1e-6", "1e-6")
    assert code == 1 and err.startswith("planardyn plan: "), err


def test_docs_lists_and_prints_the_installed_pages():
    p = run("docs")
    assert p.returncode == 0 and "model-format     The planardyn model file" in p.stdout
    page = run("docs", "model-format")
    assert page.stdout == (ROOT / "docs" / "model-format.md").read_text()
    assert run("docs", "docs/cli.md", "--path").stdout.strip().endswith("docs/cli.md")
    bad = run("docs", "tutorial")
    assert bad.returncode == 2 and bad.stderr.startswith("planardyn: no page of the guide is named 'tutorial'; the pages are: index, ")


def test_model_errors_point_at_the_installed_page(tmp_path):
    # Issue 26: "see docs/model-format.md" (not in the wheel) is now the command that prints it.
    path = tmp_path / "m.yaml"
    path.write_text("points: {}\n")
    p = run("check", str(path))
    assert p.returncode == 2 and "(see `planardyn docs model-format`)" in p.stderr
    assert run("docs", "model-format").returncode == 0


def test_plot_points_draws_and_prints_a_points_motion(tmp_path):
    # The crank pin A of the slider-crank turns on a circle of radius 0.08 m (the model file's
    # crank): its x and y each travel 0.16 m over a turn, and its speed is 0.08 |theta'|.
    out = tmp_path / "run.csv"
    assert run("simulate", "slider-crank", "--t-end", "1", "--output-dt", "0.001", "-o", str(out)).returncode == 0
    p = run("plot", str(out), "--points", "A", "-o", str(tmp_path / "a.png"))
    assert p.returncode == 0, p.stderr
    res = read_results(out)
    lines = p.stdout.splitlines()
    numbers = [float(v) for v in re.findall(r"-?\d+\.?\d*(?:e[-+]\d+)?", lines[0])]
    assert re.fullmatch(r"A: x \S+ \.\. \S+ m \(travel \S+ m\), y \S+ \.\. \S+ m \(travel \S+ m\); "
                        r"peak speed \S+ m/s, peak acceleration \S+ m/s\^2", lines[0]), lines[0]
    # Sampled every 1 ms at up to 65 rad/s: the extremes are within 0.08 (1 - cos(0.0325)) = 4e-5 m.
    np.testing.assert_allclose(numbers[:6], [-0.08, 0.08, 0.16, -0.08, 0.08, 0.16], atol=1e-4)
    assert numbers[6] == pytest.approx(0.08 * np.abs(res.qd[:, 0]).max(), rel=1e-3)  # 4 digits printed
    assert lines[-1] == f"wrote {tmp_path / 'a.png'}" and Image.open(tmp_path / "a.png").size == (1080, 960)
    # B is the slider's point and the ground's (its guide): refused with the fix.
    p = run("plot", str(out), "--points", "B")
    assert p.returncode == 2 and "the ground carries B as well as rod and slider" in p.stderr
    p = run("plot", str(out), "--points", "Z")
    assert p.returncode == 2 and "--points: the model has no point Z; its points are O, A, B, W" in p.stderr


# ---------------------------------------------------------------- the command line's manners: warnings as one line, a closed pipe ends quietly, messages name
# options, `size` documented, progress for GIF writing, a missing optional package refused
# before the computation, the inverse plot's energy panel says what it shows.
#
# Expected values: the dissipation of the five-bar's two motor dampers (c = 1 N m s/rad each,
# examples/models/five-bar.yaml) along q_k(t) = q_k0 +- 0.2 sin^2(pi t), t in [0, 1] s, is
# c * sum_k int qd_k^2 dt = 2 * c * (0.2 pi)^2 / 2 = 0.394784 J (closed form); the drives' work
# is integrated by the trapezoidal rule on 201 rows, an O(h^2) error of about 1e-5 J.


def test_a_warning_is_one_clean_line():
    p = run("check", models.path("library/double-parallelogram"))
    assert p.returncode == 0, p.stderr
    lines = p.stderr.splitlines()
    assert len(lines) == 1
    assert lines[0].startswith("planardyn: warning: ") and "redundant constraints" in lines[0]
    assert "PlanardynWarning" not in p.stderr and ".py:" not in p.stderr


def test_main_restores_the_warning_display():
    before = __import__("warnings").showwarning
    assert cli.main(["check", str(FIVE_BAR)]) == 0
    assert __import__("warnings").showwarning is before


@pytest.mark.parametrize("args", [("check", FIVE_BAR), ("demo", "--out", "{tmp}"), ("--help",)])
def test_a_closed_pipe_ends_quietly(args, tmp_path):
    args = [str(a).format(tmp=tmp_path / "demo") for a in args]
    proc = subprocess.Popen([sys.executable, "-m", "planardyn", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    proc.stdout.readline()  # the reader takes one line and goes (... | head -1)
    proc.stdout.close()
    err = proc.stderr.read()
    assert proc.wait(timeout=120) == 0
    assert err == ""


def test_rk4_without_step_names_the_option():
    p = run("simulate", FIVE_BAR, "--method", "rk4", "--t-end", "0.1")
    assert p.returncode == 2
    assert "--dt" in p.stderr and "--method rk4" in p.stderr and "Options::" not in p.stderr
    assert run("simulate", FIVE_BAR, "--method", "rk4", "--dt", "1e-3", "--t-end", "0.01").returncode == 0


@pytest.mark.parametrize("page", ["README.md", "docs/cli.md"])
def test_size_is_documented_with_a_command_that_runs(page):
    commands = [line for lang, body in BLOCK.findall((ROOT / page).read_text()) if lang == "bash"
                for line in body.splitlines() if line.startswith("planardyn size ")]
    assert commands  # tests/test_docs.py runs each one
    assert "planardyn size" in cli._parser().format_help()


class Terminal(io.StringIO):
    """A stderr that says it is a terminal, as an interactive shell's is."""

    def isatty(self):
        return True


def test_a_simulation_in_a_terminal_shows_progress(tmp_path, monkeypatch):
    stderr = Terminal()
    monkeypatch.setattr(sys, "stderr", stderr)
    assert cli.main(["simulate", str(FIVE_BAR), "--t-end", "0.5", "-o", str(tmp_path / "run.npz")]) == 0
    updates = [u for u in stderr.getvalue().split("\r") if u]
    # tqdm redraws at most every 0.1 s: at least the start and the end, the end once, full,
    # with the elapsed time and the time left.
    assert len(updates) >= 2 and "|" in updates[0]
    assert [u for u in updates if "100%" in u] == [updates[-1]]
    assert re.search(r"100%\|[#█]+\| 0\.5/0\.5 s \[\d\d:\d\d<00:00\]\n$", updates[-1]), updates[-1]


def test_gif_writing_shows_progress(tmp_path, monkeypatch):
    res = pd.load(FIVE_BAR).simulate(t_end=0.3, output_dt=0.01)
    write_results(res, tmp_path / "run.npz")

    stderr = Terminal()
    monkeypatch.setattr(sys, "stderr", stderr)
    assert cli.main(["animate", str(FIVE_BAR), str(tmp_path / "run.npz"), "-o", str(tmp_path / "run.gif")]) == 0
    updates = [u for u in stderr.getvalue().split("\r") if u]
    # 0.3 s at 20 frames/s in 3 s of playback: 61 frames, the bar full once at the end.
    assert len(updates) >= 2 and [u for u in updates if "100%" in u] == [updates[-1]]
    assert re.search(r"100%\|[#█]+\| 61/61 frames \[\d\d:\d\d<00:00\]\n$", updates[-1]), updates[-1]


@pytest.mark.parametrize(("module", "args", "stopped"), [
    ("pyarrow", ["simulate", str(FIVE_BAR), "-o", "run.parquet"], (Mechanism, "simulate")),
    ("pyarrow", ["inverse", str(FIVE_BAR), "--motion", "motion.csv", "-o", "tau.parquet"], (cli, "load")),
    ("imageio_ffmpeg", ["animate", str(FIVE_BAR), "run.npz", "-o", "run.mp4"], (cli, "load")),
])
def test_missing_optional_package_is_reported_before_the_computation(module, args, stopped, monkeypatch, capsys,
                                                                      tmp_path):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setitem(sys.modules, module, None)  # as if not installed

    def never(*_a, **_k):
        raise AssertionError("the computation started")

    monkeypatch.setattr(*stopped, never)  # what would start the work: the simulation, or reading the inputs
    assert cli.main(args) == 2
    err = capsys.readouterr().err
    package, extra = {"pyarrow": ("pyarrow", "parquet"), "imageio_ffmpeg": ("imageio-ffmpeg", "mp4")}[module]
    assert f"needs the '{extra}' extra: pip install {package} (or the wheel with it" in err and "computation" not in err


def test_inverse_plot_energy_panel_shows_what_the_dampers_take():
    from matplotlib.figure import Figure
    from planardyn.plot import plot_results

    mech = pd.load(FIVE_BAR)
    t = np.linspace(0.0, 1.0, 201)
    swing = 0.2 * np.sin(np.pi * t) ** 2
    rate = 0.2 * np.pi * np.sin(2 * np.pi * t)
    accel = 0.4 * np.pi**2 * np.cos(2 * np.pi * t)
    q0 = mech.q0
    res = inverse_result(mech, t, np.column_stack([q0[0] + swing, q0[1] - swing]),
                         np.column_stack([rate, -rate]), np.column_stack([accel, -accel]))
    fig = Figure()
    plot_results(res, fig=fig)
    energy_ax = [ax for ax in fig.axes if ax.get_ylabel() == "energy dissipated (J)"]
    assert len(energy_ax) == 1
    (line,) = energy_ax[0].get_lines()
    assert line.get_label() == "taken by dampers, friction, loads: W - (T + V - E0)"
    dissipated = line.get_ydata()
    assert dissipated[-1] == pytest.approx(2 * 1.0 * (0.2 * np.pi) ** 2 / 2, abs=1e-4)
    assert np.all(np.diff(dissipated) > -1e-9)  # dampers only take energy
    titles = [ax.get_title() for ax in fig.axes]
    assert "energy: the drives' work W, and what the loads dissipate" in titles


# ---------------------------------------------------------------- no traceback from a damaged file or a bad option


@pytest.fixture(scope="module")
def run_5bar():
    mech = pd.load(FIVE_BAR)
    return mech, mech.simulate(0.2, output_dt=0.01)  # 21 rows


def _meta_edit(path, edit):
    with np.load(path) as z:
        arrays = {k: z[k] for k in z.files}
    meta = json.loads(str(arrays["metadata"]))
    edit(meta, arrays)
    arrays["metadata"] = np.array(json.dumps(meta))
    np.savez(path, **arrays)


@pytest.mark.parametrize("damage, expect", [
    ("empty", r"not an \.npz archive"),
    ("truncated", r"not an \.npz archive|damaged"),
    ("no_array", r"no array 'tau'"),
    ("no_key", r"metadata has no field 'coordinate_names'"),
    ("retyped", r"metadata field 'body_names' is 5, not a list of names"),
    ("pickle", r"array 'metadata' holds Python objects"),
])
def test_damaged_npz_gives_exit_2_naming_file_and_field(run_5bar, tmp_path, damage, expect):
    """Before: BadZipFile, EOFError, KeyError, TypeError tracebacks; an object array was
    refused with numpy's advice to load it with allow_pickle."""
    mech, res = run_5bar
    path = write_results(res, tmp_path / "r.npz", mechanism=mech)
    if damage == "empty":
        path.write_bytes(b"")
    elif damage == "truncated":
        path.write_bytes(path.read_bytes()[:300])
    elif damage == "no_array":
        _meta_edit(path, lambda meta, arrays: arrays.pop("tau"))
    elif damage == "no_key":
        _meta_edit(path, lambda meta, arrays: meta.pop("coordinate_names"))
    elif damage == "retyped":
        _meta_edit(path, lambda meta, arrays: meta.update(body_names=5))
    else:
        np.savez(path, metadata=np.array([{"format": "planardyn-results"}], dtype=object))
    for argv in (["plot", path], ["animate", FIVE_BAR, path, "-o", tmp_path / "v.html"],
                 ["inverse", FIVE_BAR, "--motion", path]):
        code, err = cli_run(*argv)
        assert code == 2 and str(path) in err and "Traceback" not in err, err
        assert len(err.strip().splitlines()) == 1 and "allow_pickle" not in err
        assert __import__("re").search(expect, err), err
    assert zipfile.is_zipfile(path) or damage in ("empty", "truncated")


@pytest.mark.parametrize("argv, option", [
    (["simulate", FIVE_BAR, "--max-steps", "-1"], "--max-steps"),  # was OverflowError
    (["simulate", FIVE_BAR, "--max-steps", "1e3"], "--max-steps"),
    (["simulate", FIVE_BAR, "--t-end", "nan"], "--t-end"),
    (["simulate", FIVE_BAR, "--output-dt", "-0.1"], "--output-dt"),
    (["simulate", FIVE_BAR, "--rtol", "1e-300"], "--rtol"),
    (["plot", "r.csv", "--dpi", "100000"], "--dpi"),  # was MemoryError
    (["animate", FIVE_BAR, "r.csv", "-o", "v.gif", "--fps", "inf"], "--fps"),
])
def test_out_of_range_options_exit_2_naming_the_option(argv, option):
    code, err = cli_run(*argv)
    assert code == 2 and f"argument {option}" in err and "Traceback" not in err, err


def test_unexpected_error_is_one_line_exit_1(monkeypatch):
    def broken(args):
        raise RuntimeError("boom")

    monkeypatch.setitem(cli.COMMANDS, "check", broken)
    code, err = cli_run("check", FIVE_BAR)
    assert (code, err) == (1, "planardyn: unexpected RuntimeError: boom (please report this)\n")


def test_the_summary_of_a_run_without_outputs_says_so():
    # It read "non_finite: 0 outputs to t = - s, 0 steps (...), energy drift 0 J, min sigma -".
    res = pd.load_example("four-bar-gravity").simulate(0.1, qd0=[1e300])
    assert len(res.t) == 0 and res.status == "non_finite"
    assert cli.summary(res) == "non_finite: no outputs, the run stopped at its start before its first row"
