"""One rule per simulation setting, the same for the model loader, the API, the batch runner
and the CLI (planardyn.settings); batch threads bounded; a batch keeps what it has done."""

from __future__ import annotations

import math

import numpy as np
import planardyn as pd
import pytest
import yaml
from conftest import MODELS, cli_run
from planardyn import batch
from planardyn import settings as settings_module
from planardyn._core import check_setting
from planardyn.settings import MAX_STEPS, MAX_THREADS, MIN_RTOL

FIVE_BAR = MODELS / "five-bar.yaml"



def model_with(**simulate) -> str:
    d = yaml.safe_load(FIVE_BAR.read_text())
    d["simulate"] = {**(d.get("simulate") or {}), **simulate}
    return yaml.safe_dump(d)


@pytest.mark.parametrize("name", ["atol", "rtol", "dt", "output_dt", "t_end"])
@pytest.mark.parametrize("value", [0.0, -1e-9, math.nan, math.inf])
def test_loader_api_and_cli_refuse_the_same_values(name, value):
    """Before: atol = 0 was refused by the loader but taken by the API and the CLI, where
    the run then failed as "NaN or infinity in the solution"."""
    with pytest.raises(pd.ModelError, match=f"simulate.{name}"):
        pd.loads(model_with(**{name: value}))
    mech = pd.load(FIVE_BAR)
    error = ValueError if name == "t_end" else pd.SimulationError
    with pytest.raises(error, match=f"{name} = .* must be a finite number > 0"):
        mech.simulate(**{name: value})
    code, err = cli_run("simulate", FIVE_BAR, f"--{name.replace('_', '-')}={value!r}")
    assert code == 2 and f"argument --{name.replace('_', '-')}: {name} = " in err, err


@pytest.mark.parametrize("simulate", [{"t_end": 1e31, "output_dt": 0.01}, {"t_end": 1e7, "output_dt": 1e-3},
                                      {"output_dt": 1e-12}])
def test_a_model_whose_output_grid_cannot_fit_is_refused_at_load(simulate):
    """Before (s15-sweep): such a model loaded, and every simulate() of it, whatever t_end it
    was given, aborted the process ("memory allocation of 4294967296 bytes failed" in
    simulate::grid, building the file's grid of 1e33 times). The rule is the run's own output_dt
    rule (planardyn::error::MAX_OUTPUTS, 1e8 outputs); without t_end the run lasts 1 s."""
    with pytest.raises(pd.ModelError, match=r"<string>: simulate.output_dt: output_dt = .* output times, "
                                            r"more than 1e8: use a larger output_dt or a shorter t_end"):
        pd.loads(model_with(**simulate))
    # At the limit the model loads (t_end 1e6 s, output_dt 0.01 s: 1e8 outputs).
    assert pd.loads(model_with(t_end=1e6, output_dt=0.01)).name


def test_positive_tolerances_are_taken():
    # The smallest values the rules allow run: atol just above 0, rtol at 100 epsilons.
    res = pd.load(FIVE_BAR).simulate(0.01, atol=1e-300, rtol=MIN_RTOL, max_steps=50)
    assert res.status in ("success", "too_many_steps")
    assert MIN_RTOL == pytest.approx(2.22e-14, rel=1e-3)  # 100 * 2.220446e-16
    with pytest.raises(pd.SimulationError, match="below 100 machine epsilons"):
        pd.load(FIVE_BAR).simulate(0.01, rtol=MIN_RTOL / 2)


# One bad value of each rule (planardyn::error::Setting::check): t_end an argument, the
# others solver options.
BAD_SETTINGS = [
    ("t_end", 0.0, pd.ArgumentError),
    ("t_end", math.nan, pd.ArgumentError),
    ("rtol", -1e-9, pd.SimulationError),
    ("rtol", MIN_RTOL / 2, pd.SimulationError),
    # At 5816799 rtol = 2 (or 1e308) ran: an error test that lets a step's error exceed the
    # state itself (s22-check).
    ("rtol", 2.0, pd.SimulationError),
    ("atol", 0.0, pd.SimulationError),
    ("dt", math.inf, pd.SimulationError),
    ("output_dt", -1.0, pd.SimulationError),
    ("max_steps", 0, pd.SimulationError),
    ("max_steps", MAX_STEPS + 1, pd.SimulationError),
]


@pytest.mark.parametrize("name, value, error", BAD_SETTINGS)
def test_each_bad_setting_is_refused_alike_naming_it(name, value, error):
    """The API, the batch runner (its common settings and a variant's own) and the CLI refuse
    a bad setting with one rule, the core's: the same class and message, which starts with
    the setting's name and value."""
    mech = pd.load(FIVE_BAR)
    settings = {"t_end": 0.01, name: value}
    with pytest.raises(error) as api:
        mech.simulate(**settings)
    message = str(api.value).removeprefix("invalid option: ")
    assert message.startswith(f"{name} = "), message
    assert error is not pd.ArgumentError or api.value.argument == name
    with pytest.raises(error) as common:
        batch.simulate([mech], **settings)
    assert str(common.value) == str(api.value)
    (own,) = batch.simulate([(mech, {name: value})], 0.01)
    assert isinstance(own, batch.BatchError) and (own.type, own.message) == (error.__name__, str(api.value))
    option = "--" + name.replace("_", "-")
    code, err = cli_run("simulate", FIVE_BAR, "--t-end=0.01", f"{option}={value!r}")
    assert code == 2 and f"argument {option}: {message}" in err, err


def test_simulate_checks_the_rules_once_in_the_run(monkeypatch):
    """Mechanism.simulate leaves the rules of its numbers to the run (the core's one check, the
    same errors as above: issue 25 item 4), but checks them before counting the rows of an
    output grid too large to always fit, so that a bad setting is refused as such."""
    mech = pd.load(FIVE_BAR)
    calls = []
    monkeypatch.setattr(settings_module, "check_setting", lambda *a: calls.append(a) or a[1])
    assert mech.simulate(0.01, rtol=1e-9, atol=1e-9, output_dt=1e-3).success
    assert calls == [], "no rule checked in Python on the way to the run"
    monkeypatch.undo()
    with pytest.raises(pd.SimulationError, match=r"rtol = -1 must be a finite number > 0"):
        mech.simulate(0.01, rtol=-1.0)
    # 1e9 rows of output would be refused for memory, but an infinite t_end is refused first.
    with pytest.raises(pd.ArgumentError, match=r"t_end = inf must be a finite number > 0") as err:
        mech.simulate(math.inf, output_dt=1e-9)
    assert err.value.argument == "t_end"


def test_the_rules_are_the_cores():
    """settings.py keeps no rule of its own: its bounds are the core's, and what it refuses
    the core's check refuses with the same message."""
    assert MAX_STEPS == 10**12 and MIN_RTOL == 100 * np.finfo(float).eps
    for name, value, error in BAD_SETTINGS:
        with pytest.raises(error) as core:
            check_setting(name, float(value))
        assert str(core.value).removeprefix("invalid option: ").startswith(f"{name} = ")
    assert check_setting("rtol", MIN_RTOL) == MIN_RTOL
    with pytest.raises(pd.ArgumentError, match='no setting "tend": use one of t_end, rtol'):
        check_setting("tend", 1.0)


@pytest.mark.parametrize("value, error", [(-1, pd.SimulationError), (0, pd.SimulationError),
                                          (10**13, pd.SimulationError), (True, TypeError), (2.5, TypeError)])
def test_max_steps_rule(value, error):
    """Before: max_steps = -1 was an OverflowError from the conversion to an unsigned integer."""
    with pytest.raises(error, match="max_steps"):
        pd.load(FIVE_BAR).simulate(0.01, max_steps=value)


@pytest.mark.parametrize("threads, error", [(-1, ValueError), (0, ValueError), (MAX_THREADS + 1, ValueError),
                                            (20000, ValueError), ("x", TypeError), (2.0, TypeError)])
def test_batch_threads_bounded(threads, error):
    """Before: -1 or "x" became a BatchError in every variant's place, and 20000 spawned
    20000 threads (over 300 s)."""
    mech = pd.load(FIVE_BAR)
    with pytest.raises(error, match="threads"):
        batch.simulate([mech, mech], 0.01, threads=threads)


def test_batch_settings_checked_once_and_per_variant():
    mech = pd.load(FIVE_BAR)
    with pytest.raises(pd.SimulationError, match="atol = 0"):
        batch.simulate([mech], 0.01, atol=0)
    got = batch.simulate([mech, (mech, {"atol": 0.0})], 0.01)
    assert got[0].success and isinstance(got[1], batch.BatchError) and got[1].type == "SimulationError"


def test_batch_progress_raising_keeps_the_variants_done():
    """Before: a progress callback that raised lost every result of the batch."""
    mech = pd.load(FIVE_BAR)
    variants = [(mech, {"t_end": 0.01 * (k + 1)}) for k in range(5)]
    calls = []

    def progress(done, total):
        calls.append(done)
        if done == 2:
            raise RuntimeError("stop here")

    got = batch.simulate(variants, chunk_size=1, progress=progress, threads=1)
    assert calls == [1, 2]
    # The two finished variants are the runs a direct call gives, bit for bit.
    for k in (0, 1):
        direct = mech.simulate(0.01 * (k + 1))
        assert np.array_equal(got[k].q, direct.q) and np.array_equal(got[k].t, direct.t)
    for k in (2, 3, 4):
        assert isinstance(got[k], batch.BatchError) and got[k].type == "Cancelled"
        assert "progress callback raised RuntimeError('stop here') after 2 of 5" in got[k].message
    # Returning False stops it the same way; None goes on.
    got = batch.simulate(variants, chunk_size=2, progress=lambda d, n: d < 2, threads=1)
    assert [getattr(r, "type", "ok") for r in got] == ["ok", "ok", "Cancelled", "Cancelled", "Cancelled"]


def test_a_mechanisms_runs_each_follow_their_own_arguments():
    """A mechanism keeps its last run's settings for a run with the same arguments
    (crates/planardyn-py LastSettings): each run of a sequence that changes one argument at a
    time, and comes back to an earlier one, equals the same run of a fresh mechanism bit for
    bit, so no run took another's settings."""
    model = pd.load_example("five-bar-free-fall").to_dict()
    mech = pd.from_dict(model)
    runs = [dict(t_end=0.1), dict(t_end=0.1), dict(t_end=0.2), dict(t_end=0.1, rtol=1e-7),
            dict(t_end=0.1, rtol=1e-7, atol=1e-10), dict(t_end=0.1, method="dopri5"), dict(t_end=0.1, method="rk4", dt=1e-3),
            dict(t_end=0.1, t_eval=[0.0, 0.05, 0.1]), dict(t_end=0.1, t_eval=[0.0, 0.04, 0.1]),
            dict(t_end=0.1, output_dt=0.02), dict(t_end=0.1, q0=[2.0, 1.0]), dict(t_end=0.1, q0=[2.0, 1.1]),
            dict(t_end=0.1, qd0=[0.5, 0.0]), dict(t_end=0.1, max_steps=5), dict(t_end=0.1)]
    for kw in runs:
        mine, fresh = mech.simulate(**kw), pd.from_dict(model).simulate(**kw)
        assert mine.status == fresh.status, kw
        np.testing.assert_array_equal(mine.t, fresh.t, err_msg=str(kw))
        np.testing.assert_array_equal(mine.q, fresh.q, err_msg=str(kw))
    # Each change of the arguments changed the run (else the comparison above could not fail):
    # 13 different runs, t_end = 0.1 alone three times.
    assert len({(mech.simulate(**kw).t.tobytes(), mech.simulate(**kw).q.tobytes()) for kw in runs}) == 13
