"""planardyn.stiffness against independent computations (docs/stiffness.md); the closed-form
cases (Gosselin's 3-RPR, the cantilever, the two-mass drive, the parallelogram pendulum, the
geometric term against finite differences) are in crates/planardyn/tests/elastic.rs."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import planardyn as pd
import pytest
import scipy.linalg
from conftest import cli_run
from planardyn import stiffness as st
from scipy.interpolate import CubicSpline

ROOT = Path(__file__).resolve().parents[1]
FIVE_BAR = (ROOT / "examples/models/five-bar.yaml").read_text().split("\ndrives:")[0]
K1, K2, KP = 2.0e3, 3.0e3, 5.0e5  # N m/rad, N m/rad, N/m
COMPLIANT_FIVE_BAR = FIVE_BAR + f"""
compliance:
  drives:
    - {{actuator: theta1, stiffness: {K1}}}
    - {{actuator: theta2, stiffness: {K2}}}
  pairs:
    - {{pair: effector, stiffness: {KP}}}
"""

# Two exact computations of the same eigenvalues (ours: SVD null space, eigen-whitened mass;
# scipy: its own null space and QZ): they agree to rounding amplified by the conditioning of
# the mass and stiffness (~1e3 here), ~1e-12 relative; the bound is 1e-9.
EIG_TOL = 1e-9


def _rot(phi: float) -> np.ndarray:
    c, s = np.cos(phi), np.sin(phi)
    return np.array([[c, -s], [s, c]])


def _redundant_five_bar(mech: pd.Mechanism) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """M, K and the rigid rows' gradient R of the 5R in body coordinates x (12), assembled by
    hand: revolute rows r_a + R_a s_a - r_b - R_b s_b, drive springs on the proximal links'
    absolute angles (their pairs are with the ground), the effector pair's rows as a spring."""
    x = mech.kinematics(mech.q0)["x"]
    names = mech.body_names
    bodies = {"proximal_left": ["A1", "C1"], "proximal_right": ["A2", "C2"], "distal_left": ["C1", "P"],
              "distal_right": ["C2", "P"]}

    def local(body: str, point: str) -> np.ndarray:
        return np.asarray(dict(mech.body_points[names.index(body)])[point])

    def rows(a: str | None, b: str, point: str) -> np.ndarray:
        g = np.zeros((2, 12))
        for body, sign in ((a, 1.0), (b, -1.0)):
            if body is None:
                continue
            i = names.index(body)
            s = local(body, point)
            assert point in bodies[body]
            g[:, 3 * i:3 * i + 2] = sign * np.eye(2)
            g[:, 3 * i + 2] = sign * (_rot(x[3 * i + 2]) @ np.array([[0.0, -1.0], [1.0, 0.0]]) @ s)
        return g

    rigid = np.vstack([rows(None, "proximal_left", "A1"), rows("proximal_left", "distal_left", "C1"),
                       rows("proximal_right", "distal_right", "C2"), rows(None, "proximal_right", "A2")])
    effector = rows("distal_left", "distal_right", "P")
    K = KP * effector.T @ effector
    for body, k in (("proximal_left", K1), ("proximal_right", K2)):
        e = np.zeros(12)
        e[3 * names.index(body) + 2] = 1.0
        K += k * np.outer(e, e)
    M = np.diag(np.concatenate([[m, m, i] for m, i in zip(mech.masses, mech.inertias)]))
    return M, K, rigid


def test_eigenvalues_match_an_independent_redundant_coordinate_model():
    mech = pd.loads(COMPLIANT_FIVE_BAR)
    M, K, R = _redundant_five_bar(mech)
    N = scipy.linalg.null_space(R)
    assert N.shape[1] == 4  # two drives, the effector pair's two directions
    expected = np.sort(scipy.linalg.eig(N.T @ K @ N, N.T @ M @ N, right=False).real)
    ours = st.modes(mech).omega2
    np.testing.assert_allclose(ours, expected, rtol=EIG_TOL)


def test_modes_under_gravity_are_the_small_oscillations_of_the_rigid_model_on_springs():
    # Independent computation: the rigid 5R with torsional springs K1, K2 at its motors (model
    # `loads`), their rest angles set so that the drawing is their equilibrium under gravity
    # (k rest = the holding torque), swings about it with K = d tau/dq from the dynamics'
    # exact derivatives and A = U^T M U (`small_oscillations`). The compliant model with the
    # same drive springs under its gravity (`modes(gravity=True)`: balance, multipliers and
    # the rows' second derivatives) must give the same omega^2; both exact, so EIG_TOL. And
    # gravity's geometric term moves them far more than that.
    rigid = pd.loads(FIVE_BAR)
    hold = rigid.inverse_dynamics(rigid.q0, [0.0, 0.0], [0.0, 0.0])
    springs = "".join(f"\n  - {{type: torsional_spring, pair: {pair}, stiffness: {k}, rest: {float(h / k)!r}}}"
                      for pair, k, h in (("motor1", K1, hold[0]), ("motor2", K2, hold[1])))
    sprung = pd.loads(FIVE_BAR + "\nloads:" + springs + "\n")
    np.testing.assert_allclose(sprung.inverse_dynamics(sprung.q0, [0.0, 0.0], [0.0, 0.0]), 0.0, atol=1e-12)
    expected = st.small_oscillations(sprung, equilibrium=False).omega2
    compliant = pd.loads(FIVE_BAR + f"\ncompliance:\n  drives:\n    - {{actuator: theta1, stiffness: {K1}}}\n"
                         f"    - {{actuator: theta2, stiffness: {K2}}}\n")
    ours = st.modes(compliant, gravity=True).omega2
    np.testing.assert_allclose(ours, expected, rtol=EIG_TOL)
    without = st.modes(compliant).omega2
    assert np.abs(without / expected - 1).max() > 1e3 * EIG_TOL, (without, expected)


def _first_frequency_at(mech: pd.Mechanism, q: np.ndarray) -> float:
    """Drive springs only, rotors held: omega^2 = eig(diag(k), M(q)) exactly (M the rigid mass
    matrix in the coordinates), by scipy."""
    w2 = scipy.linalg.eigh(np.diag([K1, K2]), mech.mass_matrix(q), eigvals_only=True)[0]
    return float(np.sqrt(w2) / (2 * np.pi))


def test_topp_and_collocation_reports_state_the_first_natural_frequency():
    # Issue 27 item 3: the planned motion's report gives the lowest first natural frequency
    # over its grid and the time; at that time it equals scipy's eigenvalue of the pose
    # there (two exact computations: 1e-9 relative, as the sizing report's test), and no grid
    # point is lower. A rigid model's report has no such line.
    from planardyn.plan import collocate, time_optimal

    mech = pd.loads(FIVE_BAR + f"\ncompliance:\n  drives:\n    - {{actuator: theta1, stiffness: {K1}}}\n"
                    f"    - {{actuator: theta2, stiffness: {K2}}}\n")
    q0 = np.asarray(mech.q0)
    plans = [time_optimal(mech, [q0, q0 + [0.3, 0.2]], effort=[10.0, 10.0], n_grid=40, rtol=None),
             collocate(mech, q0, q0 + [0.3, 0.2], effort=[10.0, 10.0], n_intervals=12)]
    for plan in plans:
        assert plan.first_frequency is not None
        f, t = plan.first_frequency
        q_at = plan.state([t])[0][0]
        np.testing.assert_allclose(f, _first_frequency_at(mech, q_at), rtol=1e-9)
        assert min(_first_frequency_at(mech, q) for q in plan.q) >= f * (1 - 1e-9)
        assert dict(plan._summary_rows())["lowest first natural frequency"] == f"{f:.4g} Hz at t = {t:.4g} s"
    rigid = time_optimal(pd.loads(FIVE_BAR), [q0, q0 + [0.3, 0.2]], effort=[10.0, 10.0], n_grid=40, rtol=None)
    assert rigid.first_frequency is None and not rigid.frequency_rows()


def test_compliance_quantities_take_units():
    # The same compliances in SI and with units (issue 26's "120 mm" for the compliance
    # section): each conversion is one multiplication by the unit's SI value (one rounding),
    # amplified by the eigenproblem's conditioning (~1e3), so 1e-12 relative.
    def model(k1: str, k2: str, c1: str, kp: str, ea: str, rect: str) -> str:
        return FIVE_BAR + f"""
compliance:
  drives:
    - {{actuator: theta1, stiffness: {k1}, damping: {c1}}}
    - {{actuator: theta2, stiffness: {k2}}}
  pairs:
    - {{pair: effector, stiffness: {kp}}}
  links:
    - {{body: distal_left, EA: {ea}, EI: 20.0}}
    - {{body: distal_right, E: 7.0e10, section: {{rectangle: {rect}}}}}
"""
    si = st.modes(pd.loads(model("2000", str(3 / np.deg2rad(1)), "0.5", "5.0e5", "1.0e6", "[0.01, 0.02]")))
    units = st.modes(pd.loads(model('"2000 N m/rad"', '"3 N m/deg"', '"500 N mm s/rad"', '"500 N/mm"',
                                    '"1000 kN"', '["10 mm", "20 mm"]')))
    np.testing.assert_allclose(units.omega2, si.omega2, rtol=1e-12)
    np.testing.assert_allclose(units.damping_ratio, si.damping_ratio, rtol=1e-12,
                               atol=1e-12 * si.damping_ratio.max())  # modes the damper misses: 0
    with pytest.raises(pd.ModelError, match=r"compliance.pairs\[0\].stiffness.*N/m"):
        pd.loads(FIVE_BAR + '\ncompliance:\n  pairs: [{pair: effector, stiffness: "5 N m/rad"}]\n')


def _period(res: pd.SimulationResult, q_eq: float) -> float:
    """Mean period between the upward zero crossings of q - q_eq (a cubic spline's roots)."""
    spline = CubicSpline(res.t, res.q[:, 0] - q_eq)
    roots = spline.roots(extrapolate=False)
    up = [r for r in roots if spline(r, 1) > 0]
    return float((up[-1] - up[0]) / (len(up) - 1))


def test_small_oscillation_period_is_the_simulated_swings_as_the_amplitude_vanishes():
    # Linearisation error of the period ~ c a^2 with c ~ 0.1 (the pendulum's 1/16); the
    # integrator at rtol 1e-12 and the spline at output_dt 1e-3 (error ~ (omega h)^4 ~ 1e-10)
    # leave the amplitude's term to dominate: below 1e-6 at a = 1e-3, and falling as a^2.
    mech = pd.load(ROOT / "examples/models/four-bar-gravity.yaml")
    report = st.small_oscillations(mech, [-1.0])
    q_eq = float(report.q[0])
    T = float(report.period[0])
    errors = []
    for a in (1e-2, 1e-3):
        res = mech.simulate(12 * T, q0=[q_eq + a], qd0=[0.0], method="dop853", rtol=1e-12, atol=1e-14,
                            output_dt=1e-3)
        errors.append(abs(_period(res, q_eq) - T) / T)
    assert errors[1] < 1e-6, errors
    assert errors[1] < 0.05 * errors[0], errors  # ~ a^2: a hundredth, at most a twentieth


def test_stiffness_report_and_errors_name_the_argument():
    mech = pd.loads(COMPLIANT_FIVE_BAR)
    r = st.stiffness(mech, body="distal_left", point="P")
    # Symmetric compliance, stiffness its inverse, weakest direction a unit vector.
    np.testing.assert_allclose(r.compliance, r.compliance.T, atol=1e-12 * abs(r.compliance).max())
    assert abs(np.linalg.norm(r.weakest_direction) - 1) < 1e-12
    assert "weakest" in str(r) and "<table" in r._repr_html_()
    with pytest.raises(pd.ArgumentError, match="body"):
        st.stiffness(mech, body="nope")
    with pytest.raises(pd.ArgumentError, match="point"):
        st.stiffness(mech, body="distal_right", point="C1")
    with pytest.raises(pd.ArgumentError, match="compliance:"):
        st.modes(pd.load(ROOT / "examples/models/four-bar-gravity.yaml"))


def test_state_space_matches_the_forward_dynamics_derivatives():
    # The blocks are the exact derivatives (docs/stiffness.md); checked against their source.
    mech = pd.load(ROOT / "examples/models/four-bar-gravity.yaml")
    q = st.small_oscillations(mech, [-1.0]).q
    A, B, C, D = st.state_space(mech, q, points=[("crank", "A")])
    tau = mech.inverse_dynamics(q, [0.0], [0.0])
    d = mech.forward_dynamics_derivatives(q, [0.0], tau=tau)
    np.testing.assert_array_equal(A[1:, :1], d["dq"])
    np.testing.assert_array_equal(B[1:], d["dtau"])
    assert C.shape == (3, 2) and D.shape == (3, 1)
    # At rest about the stable equilibrium, A's eigenvalues are +-i omega of the swing.
    omega = st.small_oscillations(mech, q).omega[0]
    np.testing.assert_allclose(np.abs(np.linalg.eigvals(A).imag), omega, rtol=1e-9)


def test_compliant_state_space_has_the_modes_and_the_static_gain_of_finite_differences():
    # The 5R with geared motors (n = 10, 20) behind its drive springs, rotors free, under its
    # gravity at the drawing. (1) A's eigenvalues lambda are +-i omega of the modes
    # (lambda^2 = -omega^2; two exact computations: EIG_TOL). (2) The static gain -C A^-1 B:
    # at rest each spring passes its motor's torque to its joint, so tau_hold(q) = n t_m and
    # dq/dt_m = (d tau_hold/dq)^-1 diag(n) whatever k; the point P moves by (dr_P/dq) dq.
    # Both derivatives by central differences of the rigid model (inverse dynamics, point
    # positions), h = 1e-5: truncation ~h^2 = 1e-10, rounding ~1e-16/h = 1e-11 of the
    # entries; 1e-7 relative bounds both.
    FD_TOL = 1e-7
    ratios = (10.0, 20.0)

    def geared(damping: float) -> pd.Mechanism:
        return pd.loads(FIVE_BAR + f"""
actuators:
  - {{coordinate: theta1, gear_ratio: {ratios[0]}, rotor_inertia: 2.0e-5}}
  - {{coordinate: theta2, gear_ratio: {ratios[1]}, rotor_inertia: 1.0e-5}}
compliance:
  drives:
    - {{actuator: theta1, stiffness: {K1}, damping: {damping}}}
    - {{actuator: theta2, stiffness: {K2}}}
""")

    mech = geared(0.2)
    A, B, C, D = st.compliant_state_space(mech, points=[("distal_left", "P")], gravity=True)
    assert A.shape == (8, 8) and B.shape == (8, 2) and C.shape == (4, 8) and D.shape == (4, 2)
    undamped_A = st.compliant_state_space(geared(0.0), gravity=True)[0]
    lam2 = np.sort(-(np.linalg.eigvals(undamped_A) ** 2).real)
    omega2 = st.modes(mech, free_rotors=True, gravity=True).omega2
    np.testing.assert_allclose(lam2[::2], omega2, rtol=EIG_TOL)
    np.testing.assert_allclose(lam2[1::2], omega2, rtol=EIG_TOL)
    rigid = pd.loads(FIVE_BAR)
    q0, h, zero = np.asarray(rigid.q0), 1e-5, np.zeros(2)
    p = rigid.point_names.index("P")

    def diff(f):
        return np.column_stack([(f(q0 + h * e) - f(q0 - h * e)) / (2 * h) for e in np.eye(2)])

    dtau = diff(lambda q: np.asarray(rigid.inverse_dynamics(q, zero, zero)))
    dr = diff(lambda q: rigid.point_positions(rigid.assemble(q))[p])
    dq = np.linalg.solve(dtau, np.diag(ratios))
    expected = np.vstack([dq, dr @ dq])
    static = -C @ np.linalg.solve(A, B) + D
    np.testing.assert_allclose(static, expected, atol=FD_TOL * np.abs(expected).max())


SLIDER = """name: slider
points: {K: [0, 0], G: [1, 0], P: [0.4, 0]}
ground: [K, G]
bodies:
  slider: {points: [K, P], mass: 2.0, inertia: 0.03, com: P}
pairs:
  - {type: prismatic, name: guide, at: K, bodies: [ground, slider], along: [K, G]}
coordinates:
  - {name: s, pair: guide, value: 0.0}
compliance:
"""


def test_prismatic_pair_compliance_takes_units():
    # The closed form (lateral and tilt springs) is in crates/planardyn/tests/elastic.rs; here
    # the same springs in SI and with units give the same compliance (one multiplication by
    # the unit's value each: 1e-12); the refusals are in the next test.
    si = pd.loads(SLIDER + "  pairs: [{pair: guide, stiffness: 2.0e5, tilt_stiffness: 3.0e3}]\n")
    units = pd.loads(SLIDER + '  pairs: [{pair: guide, stiffness: "200 N/mm", tilt_stiffness: "3e6 N mm/rad"}]\n')
    c_si = st.stiffness(si, body="slider", point="P").compliance
    np.testing.assert_allclose(st.stiffness(units, body="slider", point="P").compliance, c_si,
                               rtol=1e-12, atol=1e-12 * np.abs(c_si).max())


@pytest.mark.parametrize(("text", "message"), [
    (FIVE_BAR + "\ncompliance:\n  drives: [{actuator: nope, stiffness: 1}]\n",
     r"compliance.drives\[0\].actuator.*theta1, theta2"),
    (FIVE_BAR + "\ncompliance:\n  drives: [{actuator: theta1, stiffness: 1, side: motor}]\n", r"compliance.drives\[0\].side"),
    (FIVE_BAR + "\ncompliance:\n  links: [{body: distal_left, EA: 1.0}]\n", r"compliance.links\[0\]"),
    (FIVE_BAR + "\ncompliance:\n  pairs: [{pair: effector, stiffness: -1}]\n", r"compliance.pairs\[0\].stiffness"),
    (SLIDER + "  pairs: [{pair: guide, stiffness: 2.0e5}]\n", r"compliance.pairs\[0\].tilt_stiffness.*N m/rad"),
    (SLIDER + '  pairs: [{pair: guide, stiffness: 2.0e5, tilt_stiffness: "3 N/m"}]\n', r"compliance.pairs\[0\].tilt_stiffness"),
    (FIVE_BAR + "\ncompliance:\n  pairs: [{pair: effector, stiffness: 1.0e5, tilt_stiffness: 1.0}]\n",
     r"compliance.pairs\[0\].tilt_stiffness.*turns freely"),
])
def test_model_file_compliance_errors_name_the_field(text: str, message: str):
    with pytest.raises(pd.ModelError, match=message):
        pd.loads(text)


def test_cli_stiffness_and_modes(tmp_path):
    model = tmp_path / "five-bar-compliant.yaml"
    model.write_text(COMPLIANT_FIVE_BAR)
    assert cli_run("stiffness", model, "--body", "distal_left", "--point", "P", "--load", 0, -50, 0,
                   "--length", 0.1) == (0, "")
    assert cli_run("modes", model, "--free-rotors") == (0, "")
    assert cli_run("modes", model, "--gravity") == (0, "")
    assert cli_run("stiffness", model, "--body", "distal_left", "--point", "P", "--gravity") == (0, "")
    code, err = cli_run("modes", model, "--passive", "--gravity")
    assert code == 2 and "--gravity" in err, err
    plot = tmp_path / "map.png"
    assert cli_run("stiffness", model, "--body", "distal_left", "--point", "P", "--map", -0.05, 0.05, 0.4, 0.5,
                   "--n", 3, "--plot", plot) == (0, "")
    assert plot.stat().st_size > 0
    code, err = cli_run("stiffness", ROOT / "examples/models/five-bar.yaml", "--body", "distal_left")
    assert code == 2 and "compliance:" in err, err
    code, err = cli_run("modes", model, "--at", 1.0)
    assert code == 2 and "--at: give 2 values" in err, err
    # Refused before any work, naming the option (before: the report printed, then an
    # unnamed "the characteristic length must be > 0"; a grid of 0 points leaked numpy's
    # "attempt to get argmin of an empty sequence").
    for length in ("nan", "0", "-1"):
        code, err = cli_run("stiffness", model, "--body", "distal_left", "--length", length)
        assert code == 2 and "--length" in err, err
    for n in (0, -5):
        code, err = cli_run("stiffness", model, "--body", "distal_left", "--point", "P", "--map", -0.05, 0.05, 0.4,
                            0.5, "--n", n)
        assert code == 2 and f"n = {n} must be an integer from 1" in err, err


def test_flexible_run_from_python_and_its_refusals():
    # The energy balance and the stiff limit are tested in crates/planardyn/tests/elastic.rs;
    # here the binding's shapes, that the spring is felt (the rotors lag), and the refusals.
    text = (ROOT / "examples/models/five-bar.yaml").read_text()
    flex = pd.loads(text + "\nactuators:\n  - {coordinate: theta1, rotor_inertia: 2.0e-3}\n"
                    "  - {coordinate: theta2, rotor_inertia: 2.0e-3}\n"
                    f"compliance:\n  drives:\n    - {{actuator: theta1, stiffness: {K1}}}\n"
                    f"    - {{actuator: theta2, stiffness: {K2}}}\n")
    run = st.simulate_flexible(flex, 0.2, 0.01)
    assert run["q"].shape == (21, 2) and run["theta"].shape == (21, 2) and run["energy"].shape == (21,)
    assert np.abs(run["theta"] - run["q"]).max() > 1e-6
    with pytest.raises(pd.ArgumentError, match="rotor_inertia"):
        st.simulate_flexible(pd.loads(COMPLIANT_FIVE_BAR), 0.2)
    with pytest.raises(pd.ArgumentError, match="method"):
        st.simulate_flexible(flex, 0.2, method="euler")
    # The energy balance E(t) - E(0) = W - D (W the motors' work, D the transmission dampers'
    # loss, both integrated with the run): this model's own servo dampers (its `loads`) also
    # dissipate, so the balance shows what they took; without them it closes to ~1e-11 J
    # (crates/planardyn/tests/elastic.rs).
    assert run["work"].shape == run["dissipated"].shape == (21,)


def test_cli_flexible_prints_the_energy_balance(tmp_path, capsys):
    # A passive, undamped flexible-joint five-bar (no drives, no servos): W = D = 0 and the
    # energy is conserved; dop853 at rtol 1e-12 over 0.1 s keeps it to ~1e-12 J (the usual
    # 1e-9 J bound of the energy checks).
    model = tmp_path / "flexible.yaml"
    model.write_text(FIVE_BAR + "\nactuators:\n  - {coordinate: theta1, rotor_inertia: 2.0e-3}\n"
                     "  - {coordinate: theta2, rotor_inertia: 2.0e-3}\n"
                     f"compliance:\n  drives:\n    - {{actuator: theta1, stiffness: {K1}}}\n"
                     f"    - {{actuator: theta2, stiffness: {K2}}}\n")
    out = tmp_path / "run.csv"
    from planardyn.cli import main

    assert main(["flexible", str(model), "--t-end", "0.1", "--rtol", "1e-12", "--atol", "1e-14", "-o", str(out)]) == 0
    stdout = capsys.readouterr().out
    balance = float(re.search(r"largest \|E\(t\) - E\(0\) - W \+ D\| (\S+) J", stdout).group(1))
    assert balance < 1e-9, stdout
    assert "motors' work W 0 J" in stdout, stdout
    table = np.loadtxt(out, delimiter=",", skiprows=1)
    assert table.shape == (101, 1 + 2 + 2 + 3)
    code, err = cli_run("flexible", pd.models.resolve("five-bar"))
    assert code == 2 and "compliance.drives" in err, err
