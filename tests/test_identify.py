"""The regressor form of the dynamics and the base parameters (planardyn.identify)."""

from __future__ import annotations

import dataclasses
from functools import partial

import numpy as np
import planardyn as pd
import pytest
from planardyn.identify import base_parameters, sample_states


def two_tones(q0, k, a, w, b, v):
    """Coordinate k moved about q0[k] by two tones (amplitudes a, b; rad/s w, v): t -> (q, qd, qdd)."""
    return lambda t: (q0[k] + a * np.sin(w * t) + b * np.sin(v * t),
                      a * w * np.cos(w * t) + b * v * np.cos(v * t),
                      -a * w * w * np.sin(w * t) - b * v * v * np.sin(v * t))


def excitation(q0):
    """The five-bar's identification motion: both cranks moved by two tones each."""
    return {"theta1": two_tones(q0, 0, 0.25, 2 * np.pi, 0.15, 6 * np.pi),
            "theta2": two_tones(q0, 1, 0.2, 4 * np.pi, 0.15, 2 * np.pi)}


@pytest.mark.parametrize("name", ["five-bar", "3-rrr", "slider-crank", "hydraulic-boom", "andrews-squeezer"])
def test_y_pi_plus_tau_o_is_the_inverse_dynamics_of_a_run(name):
    # Along a run, on its branch: exact in exact arithmetic, so round-off of the sums
    # (1e-12 of the largest effort) bounds the difference.
    mech = pd.load_example(name)
    res = mech.simulate(t_end=0.05, output_dt=0.005)
    Y, tau_o = mech.regressor(res.q, res.qd, res.qdd, x=res.x)
    pi = np.array(list(mech.regressor_parameters.values()))
    # The bodies' 4 each, and the slider-crank's and the boom's viscous friction.
    assert Y.shape == (len(res.t), mech.dof, len(pi)) and tau_o.shape == res.q.shape
    assert len(pi) == 4 * mech.n_bodies + {"slider-crank": 1, "hydraulic-boom": 1}.get(name, 0)
    tau = mech.inverse_dynamics(res.q, res.qd, res.qdd, x=res.x)
    np.testing.assert_allclose(Y @ pi + tau_o, tau, rtol=0, atol=1e-12 * max(1.0, np.abs(tau).max()))


def test_pendulum_has_three_base_parameters(pendulum):
    # A body on a ground pivot s (in the body frame, from the drawn centre of mass) moves by
    # one angle: tau = J qdd + g x (first moment about the pivot), with J = I_O + m |s|^2
    # - 2 s.(m c) and the first moment (m cx - m sx, m cy - m sy): 3 of the 4 parameters.
    pend = pendulum
    base = base_parameters(pend, samples=50)
    assert base.rank == 3 and base.parameters == ["m_bob", "mcx_bob", "mcy_bob", "I_bob"]
    # The three scaled base columns are well apart: a bound far from round-off (1e16)
    # and from the dependent case (infinite).
    assert base.condition < 1e3


@pytest.mark.parametrize("name", ["library/four-bar", "five-bar", "3-rrr"])
def test_base_parameters_give_the_same_efforts_for_any_parameters(name):
    # beta = pi_ind + K pi_dep must reproduce Y pi for every pi, at states the rank was not
    # found from (another seed): 1e-9 of the efforts' size (K comes from a least-squares fit
    # of exactly dependent columns, exact to round-off of its conditioning).
    mech = pd.load_example(name)
    base = base_parameters(mech, samples=150, seed=1)
    p = len(base.parameters)
    # Measured ranks 8, 11, 16 of 12, 16, 28 and conditions 143, 24, 4.6e3: well
    # conditioned, far from the 1e9 of RANK_RTOL that would mean a missed dependence.
    assert 0 < base.rank < p and base.condition < 1e6
    q, qd, qdd, x = sample_states(mech, 40, seed=2)
    Y, _ = mech.regressor(q, qd, qdd, x=x)
    rng = np.random.default_rng(3)
    for _ in range(3):
        pi = rng.uniform(0.1, 2.0, p)
        full = Y @ pi
        np.testing.assert_allclose(Y[..., base.independent] @ base.of(pi), full, rtol=0,
                                   atol=1e-9 * np.abs(full).max())
    assert len(base.expressions) == base.rank and all(e.split()[0] in base.parameters for e in base.expressions)


@pytest.fixture(scope="module")
def experiment():
    # The "real" robot: the five-bar with its links 15-20 % heavier or lighter (centres of
    # mass where the model has them, so its parameters in the model's frames are its own),
    # driven through a two-tone motion of both motors (no singularity on the way).
    from planardyn.identify import base_parameters

    prior = pd.load_example("five-bar")
    d = prior.to_dict()
    for b, s in {"proximal_left": 1.2, "proximal_right": 0.85, "distal_left": 1.15, "distal_right": 0.9}.items():
        for part in d["bodies"][b].get("parts", [d["bodies"][b]]):
            part["mass"] *= s
    real = pd.from_dict(d)
    q0 = prior.q0

    law = partial(two_tones, q0)
    motion = excitation(q0)
    runs = {T: real.simulate(t_end=T, output_dt=0.005, motion=motion) for T in (2.0, 8.0)}
    # Another motion, for validation: other tones, other amplitudes.
    other = {"theta1": law(0, 0.2, 3 * np.pi, 0.1, 8 * np.pi), "theta2": law(1, 0.25, 5 * np.pi, 0.1, 3 * np.pi)}
    runs["validation"] = real.simulate(t_end=2.0, output_dt=0.005, motion=other)
    base = base_parameters(prior)
    return prior, runs, base, base.of(real.inertial_parameters)


def noisy(res, seed):
    # 1 % of each motor's RMS effort, Gaussian.
    rng = np.random.default_rng(seed)
    return res.tau + 0.01 * np.sqrt(np.mean(res.tau**2, axis=0)) * rng.standard_normal(res.tau.shape)


def test_identified_base_parameters_are_within_their_standard_errors(experiment):
    from planardyn.identify import identify

    prior, runs, base, truth = experiment
    res = runs[2.0]
    assert res.success and len(res.t) == 401
    # Over 20 noise draws, z = (estimate - truth) / standard error is standard normal when
    # the standard errors are right: |z| <= 3 for 99.7 % (measured 98.6 % over 40 draws,
    # the errors ~10 % low), mean |z| = 0.80.
    z = np.array([(identify(prior, res.q, res.qd, res.qdd, noisy(res, s), x=res.x, base=base).beta - truth)
                  for s in range(20)])
    std = identify(prior, res.q, res.qd, res.qdd, noisy(res, 0), x=res.x, base=base).std_error
    z /= std
    assert np.mean(np.abs(z) <= 3) >= 0.97 and 0.6 < np.mean(np.abs(z)) < 1.0
    # Four times the samples: every base parameter within 3 standard errors, which halve.
    long = runs[8.0]
    ident = identify(prior, long.q, long.qd, long.qdd, noisy(long, 7), x=long.x, base=base)
    assert np.all(np.abs(ident.beta - truth) <= 3 * ident.std_error)
    np.testing.assert_allclose(std / ident.std_error, 2.0, rtol=0.15)
    # A consistent full parameter set with those base parameters.
    pi = ident.pi
    for b in prior.body_names:
        assert pi[f"m_{b}"] > 0 and pi[f"m_{b}"] * pi[f"I_{b}"] > pi[f"mcx_{b}"] ** 2 + pi[f"mcy_{b}"] ** 2
    np.testing.assert_allclose(base.of(pi), ident.beta, rtol=1e-6, atol=1e-9)
    assert "samples" in ident.report() and len(ident.report().splitlines()) == base.rank + 2


def test_identified_model_predicts_a_validation_motion_better_than_the_prior(experiment):
    from planardyn.identify import identify

    prior, runs, base, _ = experiment
    fit, check = runs[2.0], runs["validation"]
    assert check.success
    ident = identify(prior, fit.q, fit.qd, fit.qdd, noisy(fit, 1), x=fit.x, base=base)
    Y, tau_o = prior.regressor(check.q, check.qd, check.qdd, x=check.x)
    predicted = Y[..., base.independent] @ ident.beta + tau_o
    rms = lambda e: float(np.sqrt(np.mean(e**2)))  # noqa: E731
    err_identified, err_prior = rms(predicted - check.tau), rms(prior.inverse_dynamics(check.q, check.qd, check.qdd,
                                                                                       x=check.x) - check.tau)
    # The prior is 15-20 % off in mass; the identified model only by the noise's effect on
    # its estimates (measured: RMS 0.0072 against 0.39 N m, efforts of 4.7 N m RMS).
    assert err_identified < 0.05 * err_prior


def test_differentiate_a_quantised_encoder_signal():
    # q = 0.3 sin(2 pi t) sampled at 200 Hz by a 16-bit encoder (quantum 2 pi / 65536 rad).
    # Filtered at 10 Hz (the 1 Hz motion passes whole: gain 1 - 1e-8), the derivatives of
    # what is left of the quantisation noise: measured 1.3e-3 rad/s and 0.16 rad/s^2 against
    # 1.9 rad/s and 11.8 rad/s^2 inside; the filter's edge transients spoil the first and
    # last 0.2 s (a lower cutoff, longer).
    from planardyn.identify import differentiate

    t = np.arange(0.0, 2.0, 0.005)
    w = 2 * np.pi
    quantum = 2 * np.pi / 65536
    q = np.round(0.3 * np.sin(w * t) / quantum) * quantum
    qf, qd, qdd = differentiate(t, q[:, None], cutoff=10.0)
    inside = (t > 0.2) & (t < 1.8)
    assert np.abs(qd[inside, 0] - 0.3 * w * np.cos(w * t[inside])).max() < 2e-3
    assert np.abs(qdd[inside, 0] + 0.3 * w * w * np.sin(w * t[inside])).max() < 0.25
    with pytest.raises(ValueError, match="half the sampling rate"):
        differentiate(t, q[:, None], cutoff=150.0)


def test_optimised_excitation_is_better_conditioned_than_a_sine(experiment):
    # From a sine on both motors (condition 7.7e6: every coordinate in phase) to a three-
    # harmonic motion (measured 24), within 0.3 rad of the start; identification along it has
    # standard errors 5e4 to 3e5 times smaller (median 1.6e5) for the same 1 % effort noise.
    from planardyn.identify import excitation, identify

    prior, _, base, truth = experiment
    exc = excitation(prior, period=1.0, harmonics=3, amplitude=0.3, base=base)
    assert exc.start_condition > 1e6 and exc.condition < 50
    q, _, _ = exc.sample(np.linspace(0.0, 1.0, 100_001))
    assert np.all(np.abs(q - prior.q0) <= 0.3 * (1 + 1e-5))
    runs = {}
    for name, e in (("optimised", exc), ("sine", dataclasses.replace(exc, a=exc.a * 0, b=exc.b * 0))):
        if name == "sine":
            e.a[:, 0] = 0.15
        runs[name] = prior.simulate(t_end=2.0, output_dt=0.005, motion=e.motion(prior.coordinate_names))
        assert runs[name].success, runs[name].message
    std = {k: identify(prior, r.q, r.qd, r.qdd, noisy(r, 5), x=r.x, base=base).std_error for k, r in runs.items()}
    assert np.median(std["sine"] / std["optimised"]) > 1e3


def test_excitation_keeps_actuator_limits_and_a_singularity_margin(experiment):
    # Unconstrained, the optimised motion of the test above peaks at 7.6 and 8.0 N m, 3.7 rad/s,
    # and comes to a type II measure of 0.206; the plain sine at 4.8 and 5.0 N m, 0.94 rad/s,
    # 0.244. Limits below the former: 6 N m, 2.5 rad/s, a margin of 0.22. Measured: condition
    # 61 (the sine's 7.7e6), peaks 6.0003 N m and 0.21999 between the 100 points the
    # optimiser checks (a 3-harmonic motion varies little between them: 1e-3 allowed here).
    from planardyn.identify import excitation

    prior, _, base, _ = experiment
    exc = excitation(prior, period=1.0, harmonics=3, amplitude=0.3, base=base, tau_max=6.0, qd_max=2.5,
                     sigma_margin=0.22)
    assert exc.start_condition > 1e6 and exc.condition < 100
    for t, slack in ((np.linspace(0.0, 1.0, 100, endpoint=False), 1e-12), (np.linspace(0.0, 1.0, 1001), 1e-3)):
        q, qd, qdd = exc.sample(t)
        tau = prior.inverse_dynamics(q, qd, qdd)  # the model's inverse dynamics, not the regressor
        assert np.abs(tau).max() <= 6.0 * (1 + slack), np.abs(tau).max()
        assert np.abs(qd).max() <= 2.5
        x, least = None, np.inf
        for row in q:
            k = prior.kinematics(row, x_start=x)
            x, least = k["x"], min(least, k["sigma_min"])
        assert least >= 0.22 * (1 - slack), least
    with pytest.raises(ValueError, match="tau_max"):
        excitation(prior, base=base, tau_max=[1.0, -1.0])


def test_identify_command(experiment, tmp_path):
    # Encoder readings (16-bit) and efforts with 1 % noise in a CSV table at 200 Hz: the
    # command filters at 10 Hz (the motion's tones reach 3 Hz), differentiates, drops the
    # filter's edge transients, identifies, and predicts another motion (a results file)
    # far better than the model it started from: measured RMS 0.017 against 0.39 N m (at a
    # 5 Hz cutoff the filter bends the 3 Hz tone and the estimate is no better than the model).
    import contextlib
    import csv
    import io
    import json
    import re

    from conftest import cli_run
    from planardyn import cli

    prior, runs, _, _ = experiment
    res = runs[2.0]
    quantum = 2 * np.pi / 65536
    q = np.round(res.q / quantum) * quantum
    tau = noisy(res, 3)
    table = tmp_path / "measured.csv"
    with open(table, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t", "theta1", "theta2", "tau_theta1", "tau_theta2"])
        w.writerows(np.column_stack([res.t, q, tau]).tolist())
    check = runs["validation"].save(tmp_path / "other.npz")
    out = tmp_path / "found.json"
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert cli.main(["identify", "five-bar", str(table), "--cutoff", "10", "--validate", str(check),
                         "-o", str(out)]) == 0
    errors = re.search(r"RMS effort error (\S+) identified, (\S+) with the model", printed.getvalue())
    assert errors is not None and float(errors[1]) < 0.1 * float(errors[2]), printed.getvalue()
    found = json.loads(out.read_text())
    assert len(found["identified"]) == len(found["base_parameters"]) == len(found["std_error"]) == 11
    # 2 s at 200 Hz less 0.2 s of filter transient at each end (EDGE_PERIODS / cutoff).
    assert found["samples"] == 321 and all(v > 0 for k, v in found["parameters"].items() if k.startswith("m_"))
    # Without rates the positions must be differentiated; without efforts nothing to fit.
    code, err = cli_run("identify", "five-bar", table)
    assert code == 2 and "--cutoff" in err
    bare = tmp_path / "bare.csv"
    bare.write_text("t,theta1,theta2\n0,2.0,1.0\n0.01,2.0,1.0\n")
    code, err = cli_run("identify", "five-bar", bare, "--cutoff", "10")
    assert code == 2 and "tau_theta1, tau_theta2" in err


# ---------------------------------------------------------------- issue 23 finding 7: data that cannot identify

def held_still(mech, n):
    """n rows of the mechanism held still at its start, with the efforts that hold it."""
    q = np.tile(mech.q0, (n, 1))
    z = np.zeros_like(q)
    return q, z, z, mech.inverse_dynamics(q, z, z)


def test_a_robot_held_still_names_the_parameters_it_cannot_identify():
    """Before: numpy's 'LinAlgError: Singular matrix'. Held still at one configuration the
    efforts are the two gravity torques there: 2 of the five-bar's 11 base parameters
    (combinations of the first moments) can be told, the 9 others not."""
    mech = pd.load_example("five-bar")
    base = base_parameters(mech)
    with pytest.raises(pd.DataError) as info:
        pd.identify.identify(mech, *held_still(mech, 50), base=base)
    msg = str(info.value)
    assert msg.startswith("these 50 rows cannot identify 9 of the 11 base parameters")
    # Every inertia about a pivot is among them (no acceleration, no speed: no inertia).
    assert all(e in msg for e in base.expressions if e.startswith("I_"))
    assert "identify.excitation" in msg and info.value.path is None


def test_too_few_rows_give_the_least_number():
    mech = pd.load_example("five-bar")
    q, qd, qdd, tau = (a[:3] for a in held_still(mech, 3))
    # 11 base parameters need more than 11 equations: 6 rows of 2 efforts.
    with pytest.raises(pd.DataError, match=r"^3 rows of 2 efforts cannot determine 11 base parameters .* "
                                           r"give at least 6 rows$"):
        pd.identify.identify(mech, q, qd, qdd, tau)


def test_a_nan_effort_is_named_by_row_and_column_before_lapack_runs(capfd):
    """Before: 'LinAlgError: SVD did not converge', and LAPACK's DLASCL lines on stdout."""
    mech = pd.load_example("five-bar")
    q, qd, qdd, tau = held_still(mech, 50)
    tau[7, 1] = np.nan
    with pytest.raises(pd.ArgumentError, match=r"^tau\[7, 1\] \(row 7, column 'tau_theta2'\) = nan is not a "
                                               r"finite number: remove the row or give its value$") as info:
        pd.identify.identify(mech, q, qd, qdd, tau)
    assert info.value.argument == "tau"
    assert capfd.readouterr().out == ""


def test_the_identify_command_names_the_file_and_the_cause(tmp_path):
    """Before: 'planardyn: Singular matrix', scipy's 'The length of the input vector x must be
    greater than padlen, which is 15.', and a NaN named by its row only."""
    import csv

    from conftest import cli_run

    mech = pd.load_example("five-bar")
    q, _, _, tau = held_still(mech, 50)

    def table(name, rows, nan_at=None):
        path = tmp_path / name
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["t", "theta1", "theta2", "tau_theta1", "tau_theta2"])
            for i in range(rows):
                w.writerow([0.01 * i, *q[i], *(tau[i] if i != nan_at else (1.0, float("nan")))])
        return path

    still, nan, short = table("still.csv", 50), table("nan.csv", 50, nan_at=7), table("short.csv", 10)
    code, err = cli_run("identify", "five-bar", still, "--cutoff", "20")
    assert code == 2 and err.startswith(f"planardyn: {still}: these 30 rows cannot identify 9 of the 11 base "
                                        "parameters"), err
    code, err = cli_run("identify", "five-bar", nan, "--cutoff", "20")
    assert (code, err) == (2, f"planardyn: {nan}: data row 8 has nan in column 'tau_theta2': give finite numbers "
                              "(remove the row, or fill it in)\n")
    code, err = cli_run("identify", "five-bar", short, "--cutoff", "20")
    assert (code, err) == (2, f"planardyn: {short}: t has 10 times: give at least 16 (the zero-phase filter's "
                              "padding at both ends needs them)\n")
    code, err = cli_run("identify", "five-bar", still, "--cutoff", "60")
    assert (code, err) == (2, f"planardyn: {still}: --cutoff = 60 Hz must be below half the sampling rate (50 Hz): "
                              "a lower cutoff, or a record sampled faster\n")
