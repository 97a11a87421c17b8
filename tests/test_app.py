"""`planardyn app`, `planardyn animate -o .html` and planardyn.app without a browser: the page holds
the model as written (or as built) and a run in the replay format (planardyn.replay), its data
element cannot be closed early by the model's text, and the commands refuse what they cannot
write (exit 2). The page in a browser: test_app_browser.py."""

from __future__ import annotations

import json
import re

import numpy as np
import planardyn as pdy
import pytest
from conftest import MODELS
from planardyn.app import DATA_ELEMENT, app_html, write_app
from planardyn.cli import main
from planardyn.replay import DIGITS, run_data
from planardyn.results_io import write_results

#: The five-bar run of its model file: 1.5 s every 5 ms (301 outputs).
FIVE_BAR_OUTPUTS = 301

DATA = re.compile(r'<script type="application/json" id="planardyn-data">(.*?)</script>', re.S)


def page_data(page: str) -> dict:
    found = DATA.findall(page)
    assert len(found) == 1
    return json.loads(found[0])


def test_the_page_holds_the_model_as_written(tmp_path):
    out = write_app(tmp_path / "app.html", pdy.models.path("five-bar"))
    page = out.read_text()
    assert DATA_ELEMENT not in page
    data = page_data(page)
    assert data["model"] == {"text": pdy.models.path("five-bar").read_text(), "format": "yaml", "source": "five-bar.yaml"}
    assert "run" not in data


def test_a_script_end_in_the_model_cannot_close_the_data_element():
    # The data escapes every "<" as "\\u003c" (the same string once parsed), so only the
    # element's own end tag ends it.
    text = "name: x\n# </script><script>alert(1)</script>\n"
    data = page_data(app_html({"text": text, "format": "yaml", "source": "m.yaml"}))
    assert data["model"]["text"] == text


def test_a_run_is_in_the_page_in_the_replay_format(tmp_path):
    mech = pdy.load(pdy.models.path("four-bar-gravity"))
    res = mech.simulate(t_end=0.2, output_dt=0.05)
    out = write_app(tmp_path / "run.html", pdy.models.path("four-bar-gravity"), res, mech)
    run = page_data(out.read_text())["run"]
    assert run["t"] == pytest.approx([0.0, 0.05, 0.1, 0.15, 0.2])
    assert len(run["P"]) == 5 and {c["key"] for c in run["channels"]} >= {"kinetic", "potential"}


def test_a_runs_first_channels_are_the_pages_choice_unless_named(five_bar):
    # Without channels named, run_data marks none: the page opens the run on the channels it
    # opens its own runs on (web/src/channels.js's defaultChannels; tests/test_app_browser.py
    # checks the page's choice). Named channels are marked on, the others off.
    mech = pdy.load(pdy.models.path("four-bar-gravity"))
    res = mech.simulate(t_end=0.2, output_dt=0.05)
    data = run_data(mech, res)
    assert not any("on" in c for c in data["channels"])
    assert "; 1 coordinate (theta1), 3 bodies;" in data["info"]
    driven, res = five_bar
    chans = run_data(driven, res, channels=["theta1", "tau_theta2"])["channels"]
    assert [c["key"] for c in chans if c["on"]] == ["theta1", "tau_theta2"]
    assert all("on" in c for c in chans)


def test_the_page_holds_the_shipped_models_to_start_from(tmp_path):
    out = write_app(tmp_path / "a.html", pdy.models.path("five-bar"))
    shipped = page_data(out.read_text())["shipped"]
    assert set(shipped) == {n for n in pdy.models.names() if "/" not in n} >= {"3-rrr", "four-bar-gravity"}
    assert shipped["3-rrr"] == pdy.models.path("3-rrr").read_text()


def test_the_command_writes_the_page_and_refuses_other_outputs(tmp_path, capsys):
    assert main(["app", "slider-crank", "-o", str(tmp_path / "a.html")]) == 0
    assert page_data((tmp_path / "a.html").read_text())["model"]["source"] == "slider-crank.yaml"
    assert "one offline file" in capsys.readouterr().out
    assert main(["app", "slider-crank", "-o", str(tmp_path / "a.png")]) == 2
    assert "the app is an .html file" in capsys.readouterr().err
    assert main(["app", "no-such-model", "-o", str(tmp_path / "b.html")]) == 2


def broken_four_bar(tmp_path, old: str, new: str) -> tuple[str, int, int]:
    """The four-bar under gravity with `old` written `new` once, as a file: its path, and the
    line and column (1-based) where `new` is written."""
    text = (MODELS / "four-bar-gravity.yaml").read_text()
    assert old in text
    lines = text.replace(old, new, 1).splitlines()
    line = next(i for i, row in enumerate(lines, 1) if new in row)
    path = tmp_path / "broken.yaml"
    path.write_text("\n".join(lines) + "\n")
    return str(path), line, lines[line - 1].index(new) + 1


def refusal(capsys, *argv: str) -> str:
    """The message of a command that refuses (exit 2)."""
    assert main(list(argv)) == 2
    return capsys.readouterr().err


@pytest.mark.parametrize("written, message", [
    ("mass: [0.5", "invalid type: list, "),
    # A value that parses but is refused: located as a parse error is (loader/locate.rs).
    ("mass: -0.5", "mass must be > 0 kg, got -0.5"),
])
def test_the_command_refuses_a_broken_model_with_its_file_field_line_and_column(tmp_path, capsys, written, message):
    # The loader's located error, as `planardyn check` gives it (one path: the loader's message).
    path, line, column = broken_four_bar(tmp_path, "mass: 0.5", written)
    err = refusal(capsys, "app", path, "-o", str(tmp_path / "b.html"))
    assert err.startswith(f"planardyn: {path}: bodies.crank.mass: {message}")
    assert f"(line {line} column {column + len('mass: ')})" in err
    assert refusal(capsys, "check", path) == err


@pytest.fixture(scope="module")
def five_bar():
    mech = pdy.load(MODELS / "five-bar.yaml")
    res = mech.simulate()
    assert len(res.t) == FIVE_BAR_OUTPUTS and res.t[-1] == 1.5
    return mech, res


def test_animate_html_writes_the_app_with_the_run(five_bar, tmp_path, capsys):
    # `planardyn animate RESULTS -o F.html` (the model from the results file) writes the app:
    # its model builds the same mechanism, and its run's positions are the Python run's,
    # rounded to DIGITS (6) significant digits of the mechanism's size L.
    mech, res = five_bar
    write_results(res, tmp_path / "run.csv")
    out = tmp_path / "run.html"
    assert main(["animate", str(tmp_path / "run.csv"), "-o", str(out), "--channel", "tau_theta1"]) == 0
    assert "wrote" in capsys.readouterr().out
    data = page_data(out.read_text())
    assert pdy.loads(data["model"]["text"]) == mech
    run = data["run"]
    P = np.array(run["P"]).reshape(FIVE_BAR_OUTPUTS, -1, 2)
    np.testing.assert_allclose(P, mech.point_positions(res.x), rtol=0, atol=1e-6 * mech.scale)
    assert [c["key"] for c in run["channels"] if c["on"]] == ["tau_theta1"]


def test_run_data_is_the_runs_values(five_bar):
    mech, res = five_bar
    data = run_data(mech, res, channels=["theta2", "kinetic"])
    assert data["names"] == mech.point_names and len(data["t"]) == FIVE_BAR_OUTPUTS
    assert [c["key"] for c in data["channels"] if c["on"]] == ["theta2", "kinetic"]
    tau = next(c for c in data["channels"] if c["key"] == "tau_theta2")
    np.testing.assert_allclose(tau["values"], res.tau[:, 1], rtol=1e-5)
    with pytest.raises(ValueError, match="unknown channel"):
        run_data(mech, res, channels=["nope"])


def test_run_data_subsamples_long_results(five_bar):
    # 51 of 301 outputs, the first and last kept; played in 3 s (playback.auto_speed: a 1.5 s
    # run at 0.5x).
    mech, res = five_bar
    data = run_data(mech, res, max_frames=51)
    assert len(data["t"]) == 51 and data["t"][0] == 0.0 and data["t"][-1] == 1.5
    assert data["speed"] == pytest.approx(0.5)


def test_prismatic_guide_in_run_data():
    mech = pdy.load(MODELS / "slider-crank.yaml")
    res = mech.simulate(t_end=0.1, output_dt=0.01)
    data = run_data(mech, res)
    guides = [j for j in data["joints"] if j["kind"] == "prismatic"]
    assert len(guides) == 1 and len(guides[0]["lines"]) == 11
    # The guide is drawn +-0.3 L about the block, along the horizontal axis of the model;
    # positions are rounded to 6 digits of L (1e-6 L).
    lines, blocks = np.array(guides[0]["lines"]), np.array(guides[0]["blocks"])
    L = data["scale"]
    np.testing.assert_allclose(np.hypot(lines[:, 2] - lines[:, 0], lines[:, 3] - lines[:, 1]) / L, 0.6, atol=3e-6)
    np.testing.assert_allclose(lines[:, 1], lines[:, 3], atol=1e-6 * L)
    np.testing.assert_allclose((lines[:, :2] + lines[:, 2:]) / 2, blocks, atol=1e-6 * L)


def test_run_data_has_pair_forces_and_point_motion_channels(five_bar):
    # Each pair's force magnitude and each traced point's speed and acceleration, computed
    # along the frames kept (each on its own branch): the values are those of
    # mech.reactions(res) and mech.point_motion(res), rounded to DIGITS (6) significant digits
    # of each channel's largest value: within half a unit of that digit.
    mech, res = five_bar
    data = run_data(mech, res, channels=["F_elbow1", "v_P"])
    chans = {c["key"]: c for c in data["channels"]}
    assert {g["key"] for g in data["groups"]} >= {"reactions", "speeds", "point_accelerations"}
    assert {f"F_{p}" for p in mech.pair_names} | {"v_P", "a_P"} <= set(chans)
    assert chans["F_elbow1"]["on"] and chans["v_P"]["on"] and not chans["a_P"]["on"]
    f = mech.reactions(res)[:, mech.pair_names.index("elbow1"), :2]

    def half_unit(v):
        return 0.5 * 10.0 ** (np.floor(np.log10(v.max())) - (DIGITS - 1))

    force = np.hypot(*f.T)
    np.testing.assert_allclose(chans["F_elbow1"]["values"], force, rtol=0, atol=half_unit(force))
    v = mech.point_motion(res)["P"][1]
    speed = np.hypot(*v.T)
    np.testing.assert_allclose(chans["v_P"]["values"], speed, rtol=0, atol=half_unit(speed))
