//! Events and dense output against closed forms: the pendulum released from rest reaches the
//! vertical at a quarter of its exact period (Landau & Lifshitz sec. 11: T = 4 K(k) / omega,
//! k = sin(theta0 / 2)) and moves as sin(phi / 2) = k sn(K - omega t, k) between outputs; a
//! crank at constant speed crosses an angle at a time known exactly.

mod common;
use common::*;
use planardyn::dynamics::{ModelDrives, Prescribed};
use planardyn::simulate::{simulate_observed, Event, EventFn, Observe, Settings, Status, Trajectory};
use planardyn::Mechanism;
use std::f64::consts::{FRAC_PI_2, PI};

/// Release angle from the downward vertical (rad) and the pendulum's constants of
/// `common::PENDULUM`: omega^2 = m g (l / 2) / I_O with I_O = m l^2 / 3.
const THETA0: f64 = 1.0;
fn omega() -> f64 {
    (9.81_f64 * 0.4 / (0.8 * 0.8 / 3.0)).sqrt()
}
fn k() -> f64 {
    (THETA0 / 2.0).sin()
}
/// Complete elliptic integral of the first kind K(k).
fn big_k() -> f64 {
    PI / (2.0 * agm(1.0, (1.0 - k() * k()).sqrt()))
}

/// Jacobi sn(u | k^2) by the descending Landen (AGM) scheme, Abramowitz & Stegun 16.4.
fn sn(u: f64, k: f64) -> f64 {
    let (mut a, mut b, mut c) = (vec![1.0], (1.0 - k * k).sqrt(), vec![k]);
    while c.last().unwrap().abs() > 1e-16 {
        let (an, bn) = (*a.last().unwrap(), b);
        c.push((an - bn) / 2.0);
        a.push((an + bn) / 2.0);
        b = (an * bn).sqrt();
    }
    let n = a.len() - 1;
    let mut phi = 2f64.powi(n as i32) * a[n] * u;
    for i in (1..=n).rev() {
        phi = (phi + (c[i] / a[i] * phi.sin()).asin()) / 2.0;
    }
    phi.sin()
}

/// The exact angle q(t) = phi(t) - pi/2 of the pendulum released from rest at THETA0.
fn q_exact(t: f64) -> f64 {
    2.0 * (k() * sn(big_k() - omega() * t, k())).asin() - FRAC_PI_2
}

fn pendulum() -> Mechanism {
    let q0 = THETA0 - FRAC_PI_2;
    yaml(
        &PENDULUM
            .replace("{name: theta, pair: O, value: 0.0}", &format!("{{name: theta, pair: O, value: 0.0, q0: {q0}}}")),
    )
}

fn settings(mech: &Mechanism, t_end: f64, rtol: f64, t_eval: Option<Vec<f64>>) -> Settings {
    let mut s = Settings::for_model(mech).unwrap();
    s.t_end = t_end;
    s.options.rtol = rtol;
    s.options.atol = rtol * 1e-2;
    s.t_eval = t_eval;
    s
}

fn observed(mech: &Mechanism, s: &Settings, observe: Observe) -> Trajectory {
    simulate_observed(mech, s, &mut ModelDrives(mech), &mut Prescribed::from_model(mech), observe, None).unwrap()
}

#[test]
fn pendulum_reaches_the_vertical_at_a_quarter_period() {
    let mech = pendulum();
    let quarter = big_k() / omega();
    for method in ["dop853", "dopri5", "radau5"] {
        let mut s = settings(&mech, 2.0, 1e-12, None);
        s.method = method.parse().unwrap();
        let down = Event::coordinate(0, -FRAC_PI_2, true, -1.0);
        let tr = observed(&mech, &s, Observe { events: vec![down], dense_output: true });
        assert_eq!(tr.status, Status::Event, "{method}: {}", tr.message);
        assert!(tr.success());
        let t_star = tr.events.t[0][0];
        // rtol 1e-12: the time is as accurate as the solution, about 1e-11 s here.
        assert!((t_star - quarter).abs() < 1e-9, "{method}: t* = {t_star}, K / omega = {quarter}");
        // The last row is the state at t*; nothing after it was recorded.
        let n = tr.len() - 1;
        assert_eq!(tr.t[n], t_star);
        assert!(tr.t[..n].iter().all(|&t| t < t_star));
        assert!((tr.q[n] + FRAC_PI_2).abs() < 1e-12, "{method}: q(t*) = {}", tr.q[n]);
        // The row and the record: one interpolant evaluated two ways (round-off).
        assert!((tr.events.q[0][0] - tr.q[n]).abs() < 1e-14, "{:?} vs {}", tr.events.q[0], tr.q[n]);
        // Energy at the bottom: qd^2 = 2 omega^2 (1 - cos theta0).
        let qd = (2.0 * omega().powi(2) * (1.0 - THETA0.cos())).sqrt();
        assert!((tr.events.qd[0][0] + qd).abs() < 1e-9, "{method}: qd(t*) = {:?}, exact -{qd}", tr.events.qd[0]);
        assert_eq!(tr.dense.as_ref().unwrap().span(), Some((0.0, t_star)));
    }
}

#[test]
fn turning_points_are_found_in_both_directions_by_a_closure() {
    let mech = pendulum();
    let period = 4.0 * big_k() / omega();
    let s = settings(&mech, 1.2 * period, 1e-12, Some(vec![0.0, 1.2 * period]));
    let g = EventFn::Function(Box::new(|_t, _q, qd| Ok(qd[0])));
    let tr = observed(
        &mech,
        &s,
        Observe { events: vec![Event { g, terminal: false, direction: 0.0 }], ..Default::default() },
    );
    assert_eq!(tr.status, Status::Success, "{}", tr.message);
    assert!(tr.dense.is_none(), "kept only when asked for");
    // qd = 0 at the start (not an event: a zero at t0 is not a crossing), T/2 and T.
    let t = &tr.events.t[0];
    assert_eq!(t.len(), 2, "{t:?}");
    assert!((t[0] - period / 2.0).abs() < 1e-8 && (t[1] - period).abs() < 1e-8, "{t:?}, T = {period}");
    assert!((tr.events.q[0][0] + FRAC_PI_2 + THETA0).abs() < 1e-8, "{:?}", tr.events.q[0]);
    assert!((tr.events.q[0][1] + FRAC_PI_2 - THETA0).abs() < 1e-8, "{:?}", tr.events.q[0]);
    // Only rising zeros (qd from - to +): the one at T/2.
    let rising = Event { g: EventFn::Function(Box::new(|_t, _q, qd| Ok(qd[0]))), terminal: false, direction: 1.0 };
    let tr = observed(&mech, &s, Observe { events: vec![rising], ..Default::default() });
    assert_eq!(tr.events.t[0].len(), 1);
    assert!((tr.events.t[0][0] - period / 2.0).abs() < 1e-8);
}

#[test]
fn dense_output_matches_the_outputs_and_the_closed_form() {
    let mech = pendulum();
    let period = 4.0 * big_k() / omega();
    let t_eval: Vec<f64> = (0..=40).map(|i| period * i as f64 / 40.0).collect();
    let (mut q, mut qd) = ([0.0], [0.0]);
    for method in ["dop853", "dopri5", "radau5"] {
        let mut s = settings(&mech, period, 1e-12, Some(t_eval.clone()));
        s.method = method.parse().unwrap();
        let tr = observed(&mech, &s, Observe { dense_output: true, ..Default::default() });
        assert!(tr.success(), "{}", tr.message);
        let sol = tr.dense.as_ref().unwrap();
        // At the output times: the same interpolant, evaluated another way (round-off).
        for (k, &t) in tr.t.iter().enumerate() {
            sol.eval(t, &mut q, &mut qd).unwrap();
            assert!((q[0] - tr.q[k]).abs() < 1e-13, "{method} t = {t}: {} vs {}", q[0], tr.q[k]);
            assert!((qd[0] - tr.qd[k]).abs() < 1e-12, "{method} t = {t}: {} vs {}", qd[0], tr.qd[k]);
        }
        // Between them: the closed form to the integrator's accuracy at rtol 1e-12 (its
        // global error over a period, measured at the outputs, is a few 1e-13 rad; the
        // interpolants of order 3-7 add no more than that between the steps).
        let bound = 1e-11;
        let mut worst: f64 = 0.0;
        for i in 0..400 {
            let t = period * (i as f64 + 0.37) / 400.0;
            sol.eval(t, &mut q, &mut qd).unwrap();
            worst = worst.max((q[0] - q_exact(t)).abs());
            let speed = (2.0 * omega().powi(2) * ((q[0] + FRAC_PI_2).cos() - THETA0.cos())).max(0.0).sqrt();
            assert!((qd[0].abs() - speed).abs() < 1e-5 * omega(), "{method} t = {t}: |qd| {} vs {speed}", qd[0]);
        }
        assert!(worst < bound, "{method}: largest |q - q_exact| between outputs {worst:e}");
        let outside = sol.eval(1.01 * period, &mut q, &mut qd).unwrap_err();
        assert!(outside.contains("outside the run"), "{outside}");
    }
}

/// The crank of the slider-crank driven at 2 pi rad/s from pi/6 passes pi at 5/12 s exactly.
#[test]
fn events_on_a_coordinate_driven_by_motion() {
    let mech = yaml(SLIDER_CRANK);
    let mut s = settings(&mech, 1.0, 1e-10, Some(vec![0.0, 0.25, 0.5, 0.75, 1.0]));
    s.q0 = Some(vec![PI / 6.0]);
    let mut motion = Prescribed::from_model(&mech);
    motion.set(0, planardyn::dynamics::Motion::Law(planardyn::model::MotionLaw::Speed(2.0 * PI))).unwrap();
    let observe = Observe { events: vec![Event::coordinate(0, PI, true, 1.0)], dense_output: true };
    let tr = simulate_observed(&mech, &s, &mut ModelDrives(&mech), &mut motion, observe, None).unwrap();
    assert_eq!(tr.status, Status::Event, "{}", tr.message);
    let t_star = tr.events.t[0][0];
    assert!((t_star - 5.0 / 12.0).abs() < 1e-12, "t* = {t_star}");
    // The outputs before t*, then t* itself.
    assert_eq!(tr.t, vec![0.0, 0.25, t_star]);
    assert!((tr.q[2] - PI).abs() < 1e-12, "q(t*) = {}", tr.q[2]);
    assert!((tr.qd[2] - 2.0 * PI).abs() < 1e-12);
}

#[test]
fn bad_events_are_refused_or_stop_the_run_with_a_reason() {
    let mech = pendulum();
    let s = settings(&mech, 0.5, 1e-10, None);
    let bad = Observe { events: vec![Event::coordinate(3, 0.0, true, 0.0)], ..Default::default() };
    let e = simulate_observed(&mech, &s, &mut ModelDrives(&mech), &mut Prescribed::from_model(&mech), bad, None);
    assert!(e.unwrap_err().to_string().contains("theta"));
    let nan = Event {
        g: EventFn::Function(Box::new(|t, _q, _qd| Ok(if t > 0.1 { f64::NAN } else { 1.0 }))),
        terminal: false,
        direction: 0.0,
    };
    let tr = observed(&mech, &s, Observe { events: vec![nan], ..Default::default() });
    assert_eq!(tr.status, Status::EventFailed);
    assert!(tr.message.contains("finite"), "{}", tr.message);
    assert!(!tr.is_empty() && *tr.t.last().unwrap() > 0.1);
}
