"""`planardyn app` and planardyn.app without a browser: the page holds the model as written and
a run in the viewer's format, its data element cannot be closed early by the model's text, and
the command refuses what it cannot write (exit 2). The page in a browser: test_app_browser.py."""

from __future__ import annotations

import json
import re

import planardyn as pdy
import pytest
from planardyn.app import DATA_ELEMENT, app_html, write_app
from planardyn.cli import main

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
    # JSON escapes "</" as "<\/" (the same string once parsed), so only the element's own end
    # tag ends it.
    text = "name: x\n# </script><script>alert(1)</script>\n"
    data = page_data(app_html({"text": text, "format": "yaml", "source": "m.yaml"}))
    assert data["model"]["text"] == text


def test_a_run_is_in_the_page_in_the_viewers_format(tmp_path):
    mech = pdy.load(pdy.models.path("four-bar-gravity"))
    res = mech.simulate(t_end=0.2, output_dt=0.05)
    out = write_app(tmp_path / "run.html", pdy.models.path("four-bar-gravity"), res, mech)
    run = page_data(out.read_text())["run"]
    assert run["t"] == pytest.approx([0.0, 0.05, 0.1, 0.15, 0.2])
    assert len(run["P"]) == 5 and {c["key"] for c in run["channels"]} >= {"kinetic", "potential"}


def test_the_command_writes_the_page_and_refuses_other_outputs(tmp_path, capsys):
    assert main(["app", "slider-crank", "-o", str(tmp_path / "a.html")]) == 0
    assert page_data((tmp_path / "a.html").read_text())["model"]["source"] == "slider-crank.yaml"
    assert "one offline file" in capsys.readouterr().out
    assert main(["app", "slider-crank", "-o", str(tmp_path / "a.png")]) == 2
    assert "the app is an .html file" in capsys.readouterr().err
    assert main(["app", "no-such-model", "-o", str(tmp_path / "b.html")]) == 2
