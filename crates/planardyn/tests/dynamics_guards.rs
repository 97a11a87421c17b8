//! The dynamics entry points refuse, with the quantity or the singularity named, what they
//! cannot compute: overflowing results and configurations within
//! `dynamics::SINGULAR_SIGMA` of a type II singularity.

mod common;
use common::*;
use planardyn::batch::{inverse_rows_checked, inverse_rows_on, Branch};
use planardyn::dynamics::{self, Drives, SINGULAR_SIGMA};
use planardyn::kinematics::{assemble_into, sigma_min, Chart};
use planardyn::{Error, KinematicsError, Mechanism, SingularityKind, Workspace};

struct Fixed(Vec<f64>);
impl Drives for Fixed {
    fn efforts(&mut self, _t: f64, _q: &[f64], _qd: &[f64], tau: &mut [f64]) -> Result<(), String> {
        tau.copy_from_slice(&self.0);
        Ok(())
    }
}

/// The offset slider-crank driven by its slider: a type II singularity at the dead centre,
/// slider x = sqrt((r + l)^2 - e^2) with r = 0.1, l = 0.35, e = 0.02 m.
fn slider_driven() -> Mechanism {
    let text = SLIDER_CRANK
        .replace(
            "- {name: phi, pair: O, value: 0.5235987755982988, qd0: 3.0}",
            "- {name: s, pair: guide, value: 0.43531445586169776}",
        )
        .replace("- {coordinate: phi, effort: 0.4}", "- {coordinate: s, effort: 0.4}");
    yaml(&text)
}

fn dead_centre() -> f64 {
    (0.45f64.powi(2) - 0.02f64.powi(2)).sqrt()
}

/// Efforts at slider position s (qd = 0.1 m/s, qdd = 1 m/s^2), the check allowed.
fn efforts(mech: &Mechanism, s: f64) -> f64 {
    inverse_rows_checked(mech, Branch::Drawing, &[s], &[0.1], &[1.0], true).unwrap()[0]
}

/// Scaled type II measure at s, and how many digits the efforts keep there: the relative
/// spread of the efforts over the next 4 representable slider positions (a position is only
/// known to an ulp, so no double-precision result is better; near the dead centre the
/// efforts grow as 1/sigma^3 and so does this spread).
fn measure_at(mech: &Mechanism, s: f64) -> (f64, f64) {
    let mut ws = Workspace::new(mech);
    assemble_into(mech, &[s], &mut ws).unwrap();
    let sigma = sigma_min(mech, &Chart::Inputs, &ws.x);
    let tau = efforts(mech, s);
    let spread =
        (1..=4).map(|k| (efforts(mech, f64::from_bits(s.to_bits() - k)) - tau).abs() / tau.abs()).fold(0.0, f64::max);
    (sigma, spread)
}

/// The relative forward/inverse round-trip error |FD(ID(qdd)) - qdd| / |qdd| at s.
fn round_trip(mech: &Mechanism, s: f64) -> f64 {
    let (q, qd, qdd) = ([s], [0.1], [1.0]);
    let mut ws = Workspace::new(mech);
    assemble_into(mech, &q, &mut ws).unwrap();
    dynamics::forward(mech, 0.0, &q, &qd, &mut Fixed(vec![efforts(mech, s)]), &mut ws).unwrap();
    (ws.qdd[0] - qdd[0]).abs() / qdd[0].abs()
}

#[test]
fn threshold_is_where_the_efforts_keep_three_digits() {
    // Prints the measurements: above SINGULAR_SIGMA the efforts keep 3 digits, at a tenth of
    // it they no longer do.
    let mech = slider_driven();
    let mut worst_above: f64 = 0.0;
    let mut worst_below: f64 = 0.0;
    for k in 2..=16 {
        let s = dead_centre() - 10f64.powi(-k);
        let (sigma, spread) = measure_at(&mech, s);
        let tau = efforts(&mech, s);
        println!(
            "d = 1e-{k:02}: sigma {sigma:.3e}, tau {tau:.3e} N, ulp spread {spread:.3e}, round trip {:.3e}",
            round_trip(&mech, s)
        );
        if sigma >= SINGULAR_SIGMA {
            worst_above = worst_above.max(spread);
        } else if sigma < 0.1 * SINGULAR_SIGMA {
            worst_below = worst_below.max(spread);
        }
    }
    assert!(worst_above < 1e-3, "{worst_above:e}");
    assert!(worst_below > 1e-3, "{worst_below:e}");
}

#[test]
fn inverse_dynamics_at_the_dead_centre_is_refused_with_the_measure() {
    // 1e-13 m short of the dead centre the measure is 1.7e-7 (below the threshold); the
    // efforts there came out as 5.8e21 N, unflagged, with 2 digits at most.
    let mech = slider_driven();
    let s = dead_centre() - 1e-13;
    let err = inverse_rows_on(&mech, Branch::Drawing, &[s], &[0.1], &[1.0]).unwrap_err();
    let Error::Kinematics(KinematicsError::Singular { kind: SingularityKind::TypeII, sigma_min: Some(sigma) }) = err
    else {
        panic!("{err:?}")
    };
    let mut ws = Workspace::new(&mech);
    assemble_into(&mech, &[s], &mut ws).unwrap();
    let svd = sigma_min(&mech, &Chart::Inputs, &ws.x);
    assert!(sigma < SINGULAR_SIGMA && (sigma - svd).abs() <= 2e-3 * svd, "{sigma:e} vs SVD {svd:e}");
    assert!(err.to_string().contains("type II"), "{err}");
    // The same state, asked for with the check allowed, computes (the caller takes the risk).
    assert!(inverse_rows_checked(&mech, Branch::Drawing, &[s], &[0.1], &[1.0], true).is_ok());
}

#[test]
fn forward_dynamics_at_the_dead_centre_is_refused_by_the_entry_check() {
    let mech = slider_driven();
    let s = [dead_centre() - 1e-13];
    let mut ws = Workspace::new(&mech);
    assemble_into(&mech, &s, &mut ws).unwrap();
    dynamics::forward(&mech, 0.0, &s, &[0.0], &mut Fixed(vec![0.0]), &mut ws).unwrap();
    let err = dynamics::type_ii_measure(&mech, &mut ws, false).unwrap_err();
    assert!(
        matches!(err, KinematicsError::Singular { kind: SingularityKind::TypeII, sigma_min: Some(s) } if s < SINGULAR_SIGMA)
    );
}

#[test]
fn just_above_the_threshold_inverse_and_forward_agree() {
    // 1e-11 m short of the dead centre: measure 1.75e-6, above SINGULAR_SIGMA.
    let mech = slider_driven();
    let s = dead_centre() - 1e-11;
    let (sigma, spread) = measure_at(&mech, s);
    assert!(sigma > SINGULAR_SIGMA && sigma < 10.0 * SINGULAR_SIGMA, "{sigma:e}");
    assert!(inverse_rows_on(&mech, Branch::Drawing, &[s], &[0.1], &[1.0]).is_ok());
    assert!(spread < 1e-3, "{spread:e}");
    // Forward dynamics under these efforts gives back qdd = 1 m/s^2 (measured 4e-8).
    let err = round_trip(&mech, s);
    assert!(err < 1e-6, "round trip {err:e}");
}

#[test]
fn overflowing_rates_are_an_overflow_error_naming_the_efforts() {
    // Rates of 1e155 rad/s: the convective term qd^2 w overflows to inf, the efforts to NaN.
    let mech = yaml(FIVE_BAR_FALL);
    let q = mech.drawn_q();
    let err = inverse_rows_on(&mech, Branch::Drawing, &q, &[1e155, 1e155], &[0.0, 0.0]).unwrap_err();
    assert_eq!(err, Error::Kinematics(KinematicsError::Overflow { what: "efforts tau" }));
    assert!(err.to_string().contains("try smaller efforts (tau) or rates (qd)"), "{err}");
}

#[test]
fn overflowing_efforts_are_caught_by_the_finiteness_check() {
    // Efforts of 1e308 N m give infinite accelerations from finite inputs.
    let mech = yaml(FIVE_BAR_FALL);
    let q = mech.drawn_q();
    let mut ws = Workspace::new(&mech);
    assemble_into(&mech, &q, &mut ws).unwrap();
    dynamics::forward(&mech, 0.0, &q, &[0.0, 0.0], &mut Fixed(vec![1e308, 1e308]), &mut ws).unwrap();
    assert!(ws.qdd.iter().any(|v| !v.is_finite()), "{:?}", ws.qdd);
    let err = dynamics::finite("accelerations qdd", &ws.qdd).unwrap_err();
    assert_eq!(err, KinematicsError::Overflow { what: "accelerations qdd" });
}

struct FailsAfterStart;
impl Drives for FailsAfterStart {
    fn efforts(&mut self, t: f64, _q: &[f64], _qd: &[f64], tau: &mut [f64]) -> Result<(), String> {
        tau.fill(0.0);
        if t > 0.0 {
            return Err("no effort after the start".into());
        }
        Ok(())
    }
}

#[test]
fn a_run_of_no_step_reports_its_starts_measure_not_inf() {
    let mech = yaml(FIVE_BAR_FALL);
    let settings = planardyn::simulate::Settings::for_model(&mech).unwrap();
    let tr = planardyn::simulate::simulate(&mech, &settings, &mut FailsAfterStart, None).unwrap();
    assert_eq!(tr.stats.integrator.naccept, 0, "{:?}", tr.status);
    let mut ws = Workspace::new(&mech);
    assemble_into(&mech, &mech.drawn_q(), &mut ws).unwrap();
    let start = sigma_min(&mech, &Chart::Inputs, &ws.x);
    // The integrator's estimate of the measure stops within its SIGMA_RTOL (2e-3) of the SVD.
    assert!((tr.stats.min_sigma - start).abs() <= 2e-3 * start, "{} vs {start}", tr.stats.min_sigma);
}
