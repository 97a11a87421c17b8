"""Sizing on samples that resolve the motion, one answer by both routes (issue 23, findings 5
and 11, and the sizing part of 1).

Expected values: a circle sampled at its start and end only looks like a point at rest (zero
speed and power, issue 23), so such samplings must be refused; the spacing the refusal offers
must pass; the report of `planardyn size` is the one `robot.size` gives for the same task; the
peaks and margins between samples do not depend on the sampling (to the printed digits).
"""

from __future__ import annotations

import json

import numpy as np
import planardyn as pd
import pytest
import scipy.linalg
from conftest import MODELS
from planardyn import robot

MODEL = MODELS / "five-bar.yaml"
CENTER, RADIUS = [0.014, 0.5097], 0.06  # m: the circle of docs/robot.md and docs/cli.md
CIRCLE = ["--circle", "0.014", "0.5097", "0.06"]


@pytest.fixture(scope="module")
def ee() -> robot.EndEffector:
    return robot.EndEffector(pd.load(MODEL), "P")


@pytest.mark.parametrize("options", [["--dt", "5"], ["--dt", "1"], ["--duration", "1e-9"]])
def test_a_sampling_that_misses_the_circle_is_refused(options, capsys) -> None:
    # Issue 23: each gave a full circle at zero speed and power (its two samples at the start
    # point), exit 0. Now exit 2, naming --dt and a spacing that resolves the path.
    assert robot.size_cli([str(MODEL), *CIRCLE, *options]) == 2
    err = capsys.readouterr().err
    assert "--dt" in err and "do not resolve the path" in err and "or closer" in err


@pytest.mark.parametrize("dt", ["0", "-1e-3", "nan", "inf"])
def test_a_spacing_that_is_not_positive_is_refused(dt, capsys) -> None:
    # Issue 23: --dt 0 was read as "the default".
    assert robot.size_cli([str(MODEL), *CIRCLE, f"--dt={dt}"]) == 2
    assert "argument --dt" in capsys.readouterr().err


def test_the_refusal_offers_a_spacing_that_passes(ee) -> None:
    path = robot.circle(CENTER, RADIUS, duration=1.0)
    with pytest.raises(robot.SamplingError) as info:
        robot.size(ee, path, dt=1.0)
    assert info.value.argument == "dt" and 0 < info.value.dt < 0.1
    report = robot.size(ee, path, dt=info.value.dt)
    # The circle at its sampled speed: P's speed peaks at 1.875 * 2 pi r / T (the quintic
    # law's peak rate), so the inputs move; the coarse sampling had them at rest.
    assert min(d.peak_speed for d in report.drives) > 1.0
    for bad in (0.0, -1.0, np.nan, np.inf):
        with pytest.raises(robot.SizingError, match="dt") as err:
            robot.size(ee, path, dt=bad)
        assert err.value.argument == "dt"


def test_a_solved_motion_too_coarse_for_its_shape_is_refused(ee) -> None:
    # 21 samples the core can follow, but every other one lies 3e-3 of the circle's extent
    # off its neighbours' interpolant (at most 1e-4).
    coarse = robot.solve_motion(ee, robot.circle(CENTER, RADIUS, duration=1.0), n=21)
    with pytest.raises(robot.SamplingError, match="do not resolve"):
        robot.size(coarse)
    two = robot.solve_motion(ee, robot.circle(CENTER, RADIUS, duration=1.0), n=2)
    with pytest.raises(robot.SamplingError, match="2 samples"):
        robot.size(two)


def test_cli_and_python_give_one_report(ee, tmp_path, capsys) -> None:
    # The same task by both routes: the same text and the same numbers, exactly (the CLI
    # calls robot.size with its defaults). Issue 23: RMS 6.248 against 6.249 N m, the type I
    # minimum at t = 0.475 against 0.476 s. Sampled at the docs' 2 ms the printed report is
    # the same too: the peaks and margins are resampled between the samples (at 2ac385e the
    # minimum moved with the sampling).
    out = tmp_path / "size.json"
    assert robot.size_cli([str(MODEL), *CIRCLE, "--payload", "0.5", "--json", str(out)]) == 0
    printed = capsys.readouterr().out.strip()
    path = robot.circle(CENTER, RADIUS, duration=1.0)
    report = robot.size(ee, path, payload=0.5)
    assert printed == str(report)
    assert json.loads(out.read_text()) == json.loads(json.dumps(report.to_dict()))
    assert str(robot.size(ee, path, payload=0.5, dt=2e-3)) == printed


def test_bad_arguments_name_themselves(ee) -> None:
    path = robot.circle(CENTER, RADIUS, duration=1.0)
    for kwargs, argument in (({"payload": np.nan}, "payload"), ({"payload": -1.0}, "payload"),
                             ({"payload": np.inf}, "payload"), ({"distribution": "fair"}, "distribution"),
                             ({"preload": [np.nan]}, "preload"), ({"n": 1}, "n"), ({"n": 2.5}, "n"),
                             ({"singular_tol": 0.0}, "singular_tol"), ({"speed": 1.0}, "speed")):
        with pytest.raises(robot.SizingError) as err:
            robot.size(ee, path, **kwargs)
        assert err.value.argument == argument, kwargs
        assert str(err.value).startswith(argument)
    with pytest.raises(robot.SizingError, match="path"):
        robot.size(ee, None)
    with pytest.raises(robot.SizingError, match="mass"):
        robot.with_payload(ee.mech, "P", np.nan)
    with pytest.raises(robot.SizingError, match="inertia"):
        robot.with_payload(ee.mech, "P", 0.5, inertia=-1.0)


def test_the_report_states_the_first_natural_frequency_of_a_compliant_model() -> None:
    # Issue 27 item 3. Drive springs only, rotors held, no load: the elastic potential is
    # sum k_i (q_i - theta_i)^2 / 2 with theta held, so omega^2 = eig(diag(k), M(q)) at each
    # sample exactly (M the rigid mass matrix in the coordinates); the lowest over the samples
    # is the report's. Two exact computations (ours: the redundant-coordinate eigenproblem,
    # condensed), rounding amplified by M's conditioning: 1e-9 relative.
    k = np.array([2.0e3, 3.0e3])  # N m/rad
    text = MODEL.read_text().split("\ndrives:")[0] + (
        f"\ncompliance:\n  drives:\n    - {{actuator: theta1, stiffness: {k[0]}}}\n"
        f"    - {{actuator: theta2, stiffness: {k[1]}}}\n")
    mech = pd.loads(text)
    report = robot.size(robot.EndEffector(mech, "P"), robot.circle(CENTER, RADIUS, duration=1.0))
    m = report.motion
    f = [np.sqrt(scipy.linalg.eigh(np.diag(k), mech.mass_matrix(q), eigvals_only=True)[0]) / (2 * np.pi) for q in m.q]
    i = int(np.argmin(f))
    assert report.first_frequency is not None
    np.testing.assert_allclose(report.first_frequency[0], f[i], rtol=1e-9)
    assert report.first_frequency[1] == m.t[i]
    assert f"lowest first natural frequency: {f[i]:.4g} Hz" in str(report)
    assert report.to_dict()["first_frequency_hz"]["value"] == report.first_frequency[0]
    # A rigid model's report has none (and its text and JSON are as before).
    rigid = robot.size(robot.EndEffector(pd.load(MODEL), "P"), robot.circle(CENTER, RADIUS, duration=1.0))
    assert rigid.first_frequency is None and "natural frequency" not in str(rigid)
    assert "first_frequency_hz" not in rigid.to_dict()
