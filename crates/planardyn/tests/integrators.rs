//! Tests of `planardyn::integrate`: measured orders of convergence, dense
//! output, adaptive accuracy, a stiff reference problem, right-hand-side
//! failures, restarts, and allocation-free stepping.
//!
//! Run with `--nocapture` to see the measured numbers.

mod common;
use common::Oscillator;
use planardyn::integrate::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::convert::Infallible;
use std::f64::consts::PI;

// ---------------------------------------------------------------------------
// A counting allocator: counts allocations made by the current thread, so the
// test harness's other threads do not disturb the count.

struct Counting;

thread_local! {
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> usize {
    ALLOCS.with(|c| c.get())
}

// ---------------------------------------------------------------------------
// Test problems with closed-form solutions.

/// Harmonic oscillator y1' = y2, y2' = -y1; y(0) = (1, 0): y = (cos t, -sin t).
fn oscillator_exact(t: f64) -> [f64; 2] {
    [t.cos(), -t.sin()]
}

/// Kepler problem q'' = -q/|q|^3 with eccentricity 0.3 and semi-major axis 1,
/// started at perihelion: q = (1 - e, 0), q' = (0, sqrt((1 + e)/(1 - e))).
/// Period 2π; the exact solution comes from Kepler's equation (`kepler_exact`).
struct Kepler;

const KEPLER_E: f64 = 0.3;

/// Exact Kepler orbit at time t: eccentric anomaly E from E - e sin E = t
/// (mean motion 1), q = (cos E - e, b sin E), q' = (-sin E, b cos E)/(1 - e cos E),
/// b = sqrt(1 - e^2).
fn kepler_exact(t: f64) -> [f64; 4] {
    let e = KEPLER_E;
    let mut ea = t;
    for _ in 0..30 {
        ea -= (ea - e * ea.sin() - t) / (1.0 - e * ea.cos());
    }
    let (s, c) = ea.sin_cos();
    let b = (1.0 - e * e).sqrt();
    let de = 1.0 / (1.0 - e * c);
    [c - e, b * s, -s * de, b * c * de]
}

impl OdeSystem for Kepler {
    type Error = Infallible;
    fn dim(&self) -> usize {
        4
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Infallible> {
        let r3 = (y[0] * y[0] + y[1] * y[1]).powf(1.5);
        dy[0] = y[2];
        dy[1] = y[3];
        dy[2] = -y[0] / r3;
        dy[3] = -y[1] / r3;
        Ok(())
    }
}

/// Van der Pol in Hairer's stiff scaling: y1' = y2, y2' = ((1 - y1^2) y2 - y1)/ε.
struct VanDerPol {
    eps: f64,
}

impl OdeSystem for VanDerPol {
    type Error = Infallible;
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Infallible> {
        dy[0] = y[1];
        dy[1] = ((1.0 - y[0] * y[0]) * y[1] - y[0]) / self.eps;
        Ok(())
    }
}

// ---------------------------------------------------------------------------
// Helpers.

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// Integrate from (t0, y0) to t_end, one `step` at a time.
#[allow(clippy::result_large_err)]
fn solve<S: OdeSystem>(
    method: Method,
    opts: &Options,
    sys: &mut S,
    t0: f64,
    y0: &[f64],
    t_end: f64,
) -> Result<Stepper, (Stepper, StepError<S::Error>)> {
    let mut st = Stepper::new(method, opts, sys.dim()).expect("valid options");
    st.reset(sys, t0, y0).expect("reset");
    while st.t() < t_end {
        if let Err(e) = st.step(sys, t_end) {
            return Err((st, e));
        }
    }
    Ok(st)
}

/// Numbers in scientific notation, for the printed reports.
fn sci(v: &[f64]) -> String {
    let parts: Vec<String> = v.iter().map(|x| format!("{x:.2e}")).collect();
    parts.join(", ")
}

/// Least-squares slope of log(err) against log(h).
fn loglog_slope(h: &[f64], err: &[f64]) -> f64 {
    let x: Vec<f64> = h.iter().map(|v| v.ln()).collect();
    let y: Vec<f64> = err.iter().map(|v| v.ln()).collect();
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
    sxy / sxx
}

/// Fixed-step options; the tight rtol only matters for Radau5's Newton
/// tolerance (max(10 eps/rtol, min(0.03, sqrt(rtol))) in units of rtol |y|),
/// which must be far below the discretisation error being measured.
fn fixed(dt: f64) -> Options {
    Options { rtol: 1e-13, atol: 1e-13, ..Options::fixed(dt) }
}

// ---------------------------------------------------------------------------
// Order of convergence.

/// Allowed deviation of a measured log-log slope from the declared order. The
/// step counts below lie in the asymptotic range (measured slopes within ~0.2
/// of the order); 0.3 leaves room for the higher-order error terms.
const SLOPE_TOL: f64 = 0.3;

/// Fixed-step run of `method` on `sys` from (0, y0) to t_end with `n` steps;
/// returns the max-norm error at t_end.
fn fixed_run<S: OdeSystem>(method: Method, sys: &mut S, y0: &[f64], t_end: f64, n: usize, exact: &[f64]) -> f64 {
    let h = t_end / n as f64;
    let st = solve(method, &fixed(h), sys, 0.0, y0, t_end).unwrap();
    assert_eq!(st.t(), t_end, "{method}: the last step ends on t_stop");
    assert_eq!(st.stats().naccept, n, "{method}: fixed steps");
    max_abs_diff(st.y(), exact)
}

fn assert_order(label: &str, method: Method, ns: &[usize], errs: &[f64], expected: f64) {
    let hs: Vec<f64> = ns.iter().map(|&n| 1.0 / n as f64).collect();
    let slope = loglog_slope(&hs, errs);
    eprintln!("{label} {method}: n = {ns:?}, errors {}, slope {slope:.2} (expected {expected})", sci(errs));
    assert!((slope - expected).abs() < SLOPE_TOL, "{label} {method}: slope {slope:.3}, expected {expected}");
}

/// Kepler, one period, fixed steps: the slope of the end-point error against h
/// is each method's classical order (4, 5, 8, 5). The step counts keep the
/// errors between ~1e-4 and ~1e-12 (asymptotic range, above round-off).
#[test]
fn measured_order_kepler() {
    for method in Method::ALL {
        let ns: &[usize] = match method {
            Method::Rk4 => &[100, 141, 200, 283],
            Method::Dopri5 => &[104, 148, 211, 300],
            // Order 8 leaves a narrow asymptotic window above round-off: errors 6e-11..9e-13.
            Method::Dop853 => &[73, 87, 104, 124],
            Method::Radau5 => &[104, 148, 211, 300],
        };
        let y0 = kepler_exact(0.0);
        let errs: Vec<f64> = ns.iter().map(|&n| fixed_run(method, &mut Kepler, &y0, 2.0 * PI, n, &y0)).collect();
        assert_order("kepler", method, ns, &errs, method.order() as f64);
    }
}

/// Harmonic oscillator over [0, 10], fixed steps: the classical order again.
#[test]
fn measured_order_oscillator() {
    for method in Method::ALL {
        let ns: &[usize] = match method {
            Method::Dop853 => &[20, 24, 29, 35],
            _ => &[40, 57, 80, 113],
        };
        let errs: Vec<f64> = ns
            .iter()
            .map(|&n| fixed_run(method, &mut Oscillator, &[1.0, 0.0], 10.0, n, &oscillator_exact(10.0)))
            .collect();
        assert_order("oscillator", method, ns, &errs, method.order() as f64);
    }
}

/// Dense output: the largest error of `interpolate` at the step midpoints over
/// one Kepler period. It is the global error at the step start, O(h^order), plus
/// the interpolant's local error, O(h^(dense_order + 1)), so its slope is
/// min(order, dense_order + 1): RK4 4, Dopri5 5, Dop853 8, Radau5 4. Only a
/// lower bound is asserted: at these steps Radau5's slope is still ~4.5 (both
/// terms matter), which is more accurate than claimed, not less.
#[test]
fn dense_output_order_kepler() {
    for method in Method::ALL {
        let ns: &[usize] = match method {
            Method::Rk4 | Method::Radau5 => &[148, 211, 300, 424],
            Method::Dopri5 => &[104, 148, 211, 300],
            Method::Dop853 => &[87, 104, 124, 148],
        };
        let mut errs = vec![];
        for &n in ns {
            let h = 2.0 * PI / n as f64;
            let mut st = Stepper::new(method, &fixed(h), 4).unwrap();
            st.reset(&mut Kepler, 0.0, &kepler_exact(0.0)).unwrap();
            let (mut err, mut out) = (0.0f64, [0.0; 4]);
            while st.t() < 2.0 * PI {
                st.step(&mut Kepler, 2.0 * PI).unwrap();
                // The ends of the step are reproduced exactly.
                st.interpolate(&mut Kepler, st.t(), &mut out);
                assert!(max_abs_diff(&out, st.y()) < 1e-13, "{method}: interpolate(t) = y");
                let tm = 0.5 * (st.t_prev() + st.t());
                st.interpolate(&mut Kepler, tm, &mut out);
                err = err.max(max_abs_diff(&out, &kepler_exact(tm)));
            }
            errs.push(err);
        }
        let expected = method.order().min(method.dense_order() + 1) as f64;
        let hs: Vec<f64> = ns.iter().map(|&n| 1.0 / n as f64).collect();
        let slope = loglog_slope(&hs, &errs);
        eprintln!(
            "dense {method}: n = {ns:?}, midpoint errors {}, slope {slope:.2} (expected >= {expected})",
            sci(&errs)
        );
        assert!(slope > expected - SLOPE_TOL, "{method}: dense slope {slope:.3} < {expected}");
    }
}

/// The interpolant at the start of the step reproduces y_prev.
#[test]
fn dense_output_matches_step_start() {
    for method in Method::ALL {
        let opts = Options { dt: Some(0.1), ..Options::default() };
        let mut st = Stepper::new(method, &opts, 2).unwrap();
        st.reset(&mut Oscillator, 0.0, &[1.0, 0.0]).unwrap();
        let mut out = [0.0; 2];
        st.interpolate(&mut Oscillator, 0.0, &mut out);
        assert_eq!(out, [1.0, 0.0], "{method}: before any step, interpolate gives y");
        st.step(&mut Oscillator, 1.0).unwrap();
        let y1 = st.y().to_vec();
        st.step(&mut Oscillator, 1.0).unwrap();
        st.interpolate(&mut Oscillator, st.t_prev(), &mut out);
        assert!(max_abs_diff(&out, &y1) < 1e-14, "{method}");
    }
}

// ---------------------------------------------------------------------------
// Adaptive accuracy.

/// Harmonic oscillator over 10 periods with rtol = 1e-10, atol = 1e-12: the
/// controller keeps each local error below ~1e-10 (|y| <= 1) and on this
/// stable, non-contracting problem the global error grows at most linearly
/// with the number of steps, with partial cancellation; 1e-8 is a bound that
/// holds for all three adaptive methods with a margin of ~10x (the measured
/// errors are printed).
const ADAPTIVE_GLOBAL_TOL: f64 = 1e-8;

#[test]
fn adaptive_accuracy_oscillator() {
    let t_end = 20.0 * PI;
    for method in [Method::Dopri5, Method::Dop853, Method::Radau5] {
        let opts = Options::tol(1e-10, 1e-12);
        let st = solve(method, &opts, &mut Oscillator, 0.0, &[1.0, 0.0], t_end).unwrap();
        assert_eq!(st.t(), t_end);
        let err = max_abs_diff(st.y(), &oscillator_exact(t_end));
        eprintln!("adaptive {method}: global error {err:.2e}, {:?}", st.stats());
        assert!(err < ADAPTIVE_GLOBAL_TOL, "{method}: error {err:e}");
    }
}

/// Kepler (e = 0.3) over one period, dense output compared with the exact orbit
/// at 100 output times: tolerance-proportional accuracy at rtol = 1e-9.
#[test]
fn adaptive_accuracy_kepler_dense() {
    let t_end = 2.0 * PI;
    for method in [Method::Dopri5, Method::Dop853, Method::Radau5] {
        let opts = Options::tol(1e-9, 1e-12);
        let mut st = Stepper::new(method, &opts, 4).unwrap();
        st.reset(&mut Kepler, 0.0, &kepler_exact(0.0)).unwrap();
        let (mut k, mut err, mut out) = (0usize, 0.0f64, [0.0; 4]);
        while st.t() < t_end {
            st.step(&mut Kepler, t_end).unwrap();
            while k <= 100 && k as f64 * t_end / 100.0 <= st.t() {
                let tk = k as f64 * t_end / 100.0;
                st.interpolate(&mut Kepler, tk, &mut out);
                err = err.max(max_abs_diff(&out, &kepler_exact(tk)));
                k += 1;
            }
        }
        assert_eq!(k, 101);
        eprintln!("kepler dense {method}: max error {err:.2e}, {:?}", st.stats());
        // 1e-6: a thousand times rtol, the usual global/local ratio on one orbit.
        assert!(err < 1e-6, "{method}: error {err:e}");
    }
}

// ---------------------------------------------------------------------------
// Stiff problem.

/// Van der Pol, ε = 1e-6, y(0) = (2, 0), t_end = 2: reference solution of the
/// IVP test set of Mazzia and Magherini (problem VDPOL, after Hairer & Wanner,
/// *Solving ODE II*, IV.10), y(2) = (1.706167732170483, -0.8928097010248125).
/// A radau5 run at rtol = atol = 1e-10 here agrees with it to 2e-13.
const VDPOL_REF: [f64; 2] = [1.706167732170483, -0.8928097010248125];

#[test]
fn stiff_van_der_pol_radau5() {
    let mut sys = VanDerPol { eps: 1e-6 };
    // Loose tolerance: few steps, error well within the tolerance scale.
    let opts = Options::tol(1e-6, 1e-6);
    let st = solve(Method::Radau5, &opts, &mut sys, 0.0, &[2.0, 0.0], 2.0).unwrap();
    let s = st.stats();
    let err = max_abs_diff(st.y(), &VDPOL_REF);
    eprintln!("vdpol radau5 rtol 1e-6: y = {:?}, error {err:.2e}, {s:?}", st.y());
    // Measured: ~900 accepted steps (the solution has two fast transients on [0, 2]).
    assert!(s.naccept < 1500, "{s:?}");
    assert!(err < 1e-6, "error {err:e}");
    assert!(s.njev < s.naccept, "the Jacobian is reused across steps: {s:?}");

    // Tight tolerance: agreement with the published reference to ~1e-10.
    let opts = Options::tol(1e-10, 1e-10);
    let st = solve(Method::Radau5, &opts, &mut sys, 0.0, &[2.0, 0.0], 2.0).unwrap();
    let err = max_abs_diff(st.y(), &VDPOL_REF);
    eprintln!("vdpol radau5 rtol 1e-10: error {err:.2e}, {:?}", st.stats());
    assert!(err < 1e-10, "error {err:e}");
}

#[test]
fn stiff_van_der_pol_explicit_runs_out_of_steps() {
    // Dopri5's stability limits its step to ~3.3 ε (ε = 1e-6): ~6e5 steps to
    // reach t = 2. With a budget of 1e5 attempts it stops early, keeping the
    // state of its last accepted step.
    let mut sys = VanDerPol { eps: 1e-6 };
    let opts = Options { max_steps: 100_000, ..Options::tol(1e-6, 1e-6) };
    let (st, e) = solve(Method::Dopri5, &opts, &mut sys, 0.0, &[2.0, 0.0], 2.0).unwrap_err();
    match e {
        StepError::TooManySteps { t, steps } => {
            assert_eq!(steps, 100_000);
            assert_eq!(t, st.t());
            assert!(t < 0.5, "t = {t}");
        }
        other => panic!("expected TooManySteps, got {other:?}"),
    }
}

// ---------------------------------------------------------------------------
// Right-hand-side failures.

/// The failure of a mechanism's position analysis, as a test stand-in.
#[derive(Clone, Debug, PartialEq)]
struct NoAssembly {
    t: f64,
}

/// The oscillator, evaluated like a closed chain whose position analysis is
/// warm-started from the last accepted state (`anchor`, updated by the driving
/// loop after each step): the evaluation fails when `y` is more than
/// `max_jump` away from it, as a Newton solve diverges from a poor initial
/// guess. Large trial steps fail, small ones pass.
struct WarmStarted {
    anchor: [f64; 2],
    max_jump: f64,
    failures: usize,
}

impl OdeSystem for WarmStarted {
    type Error = NoAssembly;
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), NoAssembly> {
        if max_abs_diff(y, &self.anchor) > self.max_jump {
            self.failures += 1;
            return Err(NoAssembly { t });
        }
        Oscillator.rhs(t, y, dy).map_err(|e| match e {})
    }
}

#[test]
fn rhs_failure_rejects_and_recovers() {
    for method in Method::ALL {
        let opts = match method {
            Method::Rk4 => Options::fixed(0.2),
            _ => Options::tol(1e-8, 1e-10),
        };
        let mut sys = WarmStarted { anchor: [1.0, 0.0], max_jump: 0.02, failures: 0 };
        let mut st = Stepper::new(method, &opts, 2).unwrap();
        st.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
        while st.t() < 10.0 {
            st.step(&mut sys, 10.0).unwrap();
            sys.anchor = [st.y()[0], st.y()[1]];
        }
        let err = max_abs_diff(st.y(), &oscillator_exact(10.0));
        let s = st.stats();
        eprintln!("warm-started {method}: {} rhs failures, error {err:.2e}, {s:?}", sys.failures);
        assert!(sys.failures > 0 && s.nreject > 0, "{method}: the test must exercise failures");
        // RK4 runs with the failure-shortened steps (h <= 0.2 / 4): error ~1e-6.
        let tol = if method == Method::Rk4 { 1e-5 } else { 1e-6 };
        assert!(err < tol, "{method}: error {err:e}");
    }
}

/// Fails for every evaluation beyond `t_wall` (a configuration where the
/// mechanism cannot be assembled), or returns NaN there when `nan`.
struct Wall {
    t_wall: f64,
    nan: bool,
}

impl OdeSystem for Wall {
    type Error = NoAssembly;
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), NoAssembly> {
        if t > self.t_wall {
            if !self.nan {
                return Err(NoAssembly { t });
            }
            dy.fill(f64::NAN);
            return Ok(());
        }
        Oscillator.rhs(t, y, dy).map_err(|e| match e {})
    }
}

#[test]
fn rhs_always_failing_returns_error_at_last_accepted_point() {
    for nan in [false, true] {
        for method in Method::ALL {
            let opts = match method {
                Method::Rk4 => Options::fixed(0.1),
                _ => Options::tol(1e-9, 1e-12),
            };
            let mut sys = Wall { t_wall: 1.0, nan };
            let (mut st, e) = solve(method, &opts, &mut sys, 0.0, &[1.0, 0.0], 2.0).unwrap_err();
            let t = st.t();
            match (&e, nan) {
                (StepError::Rhs { t: te, error }, false) => {
                    assert_eq!(*te, t);
                    assert!(error.t > 1.0, "{method}: carries the last failure {error:?}");
                }
                (StepError::NonFinite { t: te }, true) => assert_eq!(*te, t),
                _ => panic!("{method}: unexpected error {e:?}"),
            }
            // The state is the last accepted one, right below the wall, and still correct.
            assert!(t <= 1.0 && t > 1.0 - 1e-6, "{method}: t = {t}");
            let err = max_abs_diff(st.y(), &oscillator_exact(t));
            assert!(err < 1e-6, "{method}: error {err:e}");
            let mut out = [0.0; 2];
            st.interpolate(&mut sys, t, &mut out);
            assert!(max_abs_diff(&out, st.y()) < 1e-12, "{method}: dense output intact");
            eprintln!("wall (nan = {nan}) {method}: {e} ; {:?}", st.stats());
        }
    }
}

#[test]
fn reset_at_failing_point_reports_rhs_error() {
    let mut st = Stepper::new(Method::Dopri5, &Options::default(), 2).unwrap();
    let e = st.reset(&mut Wall { t_wall: 1.0, nan: false }, 1.5, &[1.0, 0.0]).unwrap_err();
    assert!(matches!(e, StepError::Rhs { t, .. } if t == 1.5));
    let e = st.reset(&mut Oscillator, 0.0, &[f64::NAN, 0.0]).unwrap_err();
    assert!(matches!(e, StepError::NonFinite { .. }));
}

// ---------------------------------------------------------------------------
// Restart.

/// Stopping at t = 2.5, then `reset` from the same state (as the driver does
/// after a change of coordinates), gives the continuous run's result to within
/// the integration error (rtol 1e-10 -> ~1e-9 on one Kepler period).
#[test]
fn restart_matches_continuous_run() {
    let t_end = 2.0 * PI;
    for method in Method::ALL {
        let opts = match method {
            Method::Rk4 => Options::fixed(t_end / 2000.0),
            _ => Options::tol(1e-10, 1e-12),
        };
        let y0 = kepler_exact(0.0);
        let cont = solve(method, &opts, &mut Kepler, 0.0, &y0, t_end).unwrap();

        let mut st = Stepper::new(method, &opts, 4).unwrap();
        st.reset(&mut Kepler, 0.0, &y0).unwrap();
        while st.t() < 2.5 {
            st.step(&mut Kepler, 2.5).unwrap();
            assert!(st.t() <= 2.5, "{method}: never past t_stop");
        }
        assert_eq!(st.t(), 2.5, "{method}: lands exactly on t_stop");
        let y_mid = st.y().to_vec();
        st.reset(&mut Kepler, 2.5, &y_mid).unwrap();
        assert_eq!(st.h_next(), 0.0);
        while st.t() < t_end {
            st.step(&mut Kepler, t_end).unwrap();
        }
        let diff = max_abs_diff(st.y(), cont.y());
        let err = max_abs_diff(st.y(), &kepler_exact(t_end));
        eprintln!("restart {method}: |restarted - continuous| = {diff:.2e}, error {err:.2e}");
        assert!(diff < 1e-7, "{method}: {diff:e}");
        assert!(st.stats().naccept > cont.stats().naccept / 2);
    }
}

// ---------------------------------------------------------------------------
// No allocation per step.

#[test]
fn steps_do_not_allocate() {
    for method in Method::ALL {
        let opts = match method {
            Method::Rk4 => Options::fixed(0.01),
            _ => Options::tol(1e-8, 1e-10),
        };
        let mut st = Stepper::new(method, &opts, 2).unwrap();
        // The oscillator until the wall at t = 3π + 0.1, where every evaluation fails.
        let mut sys = Wall { t_wall: 3.0 * PI + 0.1, nan: false };
        let mut out = [0.0; 2];
        let before = allocations();
        st.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
        while st.t() < 2.0 * PI {
            st.step(&mut sys, 2.0 * PI).unwrap();
            st.interpolate(&mut sys, 0.5 * (st.t() + st.t_prev()), &mut out);
        }
        // A restart and the rhs-failure path do not allocate either.
        let y = [st.y()[0], st.y()[1]];
        st.reset(&mut sys, st.t(), &y).unwrap();
        let r = loop {
            if let Err(e) = st.step(&mut sys, 4.0 * PI) {
                break e;
            }
        };
        let n_alloc = allocations() - before;
        assert!(matches!(r, StepError::Rhs { .. }), "{method}: {r:?}");
        assert_eq!(n_alloc, 0, "{method}: {n_alloc} allocations in reset/step/interpolate");
    }
}

// ---------------------------------------------------------------------------
// API details.

#[test]
fn method_names_and_properties() {
    for (s, m) in [
        ("rk4", Method::Rk4),
        ("dopri5", Method::Dopri5),
        ("RK45", Method::Dopri5),
        ("dop853", Method::Dop853),
        ("radau5", Method::Radau5),
        ("Radau", Method::Radau5),
    ] {
        assert_eq!(s.parse::<Method>().unwrap(), m);
    }
    for m in Method::ALL {
        assert_eq!(m.to_string().parse::<Method>().unwrap(), m);
    }
    let e = "euler".parse::<Method>().unwrap_err();
    assert!(e.contains("dopri5"), "{e}");
    assert_eq!(Method::ALL.map(Method::order), [4, 5, 8, 5]);
    assert_eq!(Method::ALL.map(Method::is_adaptive), [false, true, true, true]);
}

#[test]
fn invalid_options_are_rejected_with_a_fix() {
    let e = Stepper::new(Method::Rk4, &Options::default(), 2).unwrap_err();
    assert!(e.contains("dt"), "{e}");
    let e = Stepper::new(Method::Dopri5, &Options::tol(0.0, 1e-10), 2).unwrap_err();
    assert!(e.contains("rtol"), "{e}");
    let e = Stepper::new(Method::Dopri5, &Options::tol(1e-8, -1.0), 2).unwrap_err();
    assert!(e.contains("atol"), "{e}");
    let bad_h0 = Options { h0: Some(-1.0), ..Options::default() };
    assert!(Stepper::new(Method::Radau5, &bad_h0, 2).is_err());
    let bad_dt = Options { dt: Some(f64::NAN), ..Options::default() };
    assert!(Stepper::new(Method::Rk4, &bad_dt, 2).is_err());
    assert!(Stepper::new(Method::Dop853, &Options::default(), 2).is_ok());
}

/// The loader's and the Python API's rule: atol > 0, rtol >= 100 eps, dt > 0, all finite,
/// max_steps >= 1; each refusal names its option. The boundary values pass.
#[test]
fn options_follow_the_loaders_rule() {
    let eps = f64::EPSILON;
    let refused = |opts: Options, name: &str| {
        let e = opts.validate(Method::Dopri5).unwrap_err();
        assert_eq!(e.setting.name(), name, "{e}");
        assert!(e.to_string().starts_with(name), "{name}: {e}");
    };
    for atol in [0.0, -0.0, -1e-10, f64::NAN, f64::INFINITY] {
        refused(Options::tol(1e-8, atol), "atol");
    }
    // rtol > 1 (MAX_RTOL) ran at 5816799 (s22-check).
    for rtol in [0.0, 99.0 * eps, 1.0 + eps, 2.0, 1e308, f64::NAN, f64::INFINITY] {
        refused(Options::tol(rtol, 1e-10), "rtol");
    }
    for dt in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
        refused(Options::fixed(dt), "dt");
    }
    refused(Options { max_steps: 0, ..Options::default() }, "max_steps");
    for opts in [
        Options::tol(100.0 * eps, f64::MIN_POSITIVE),
        Options::tol(1.0, 1e-10),
        Options { max_steps: 1, ..Options::fixed(1e-300) },
    ] {
        assert!(opts.validate(Method::Dopri5).is_ok(), "{opts:?}");
    }
}

#[test]
fn fixed_rk4_costs_four_evaluations_per_step() {
    let st = solve(Method::Rk4, &Options::fixed(0.1), &mut Oscillator, 0.0, &[1.0, 0.0], 1.0).unwrap();
    let s = st.stats();
    assert_eq!(s.naccept, 10);
    assert_eq!(s.nfev, 1 + 4 * 10);
    assert_eq!(st.t(), 1.0);
    // dy() is f(t, y) at the current point.
    assert!(max_abs_diff(st.dy(), &[st.y()[1], -st.y()[0]]) < 1e-15);
}

/// The dense output costs 3 evaluations in a step that is interpolated and none in
/// the others, and does not change the solution.
#[test]
fn dop853_dense_output_costs_three_evaluations_where_used() {
    let opts = Options::tol(1e-9, 1e-12);
    let plain = solve(Method::Dop853, &opts, &mut Kepler, 0.0, &kepler_exact(0.0), 2.0 * PI).unwrap();
    let mut st = Stepper::new(Method::Dop853, &opts, 4).unwrap();
    st.reset(&mut Kepler, 0.0, &kepler_exact(0.0)).unwrap();
    let (mut out, mut interpolated) = ([0.0; 4], 0);
    while st.t() < 2.0 * PI {
        st.step(&mut Kepler, 2.0 * PI).unwrap();
        // Every other step, twice (the second call is free).
        if st.stats().naccept.is_multiple_of(2) {
            st.interpolate(&mut Kepler, st.t_prev(), &mut out);
            st.interpolate(&mut Kepler, st.t(), &mut out);
            interpolated += 1;
        }
    }
    assert_eq!(st.y(), plain.y(), "the solution does not depend on the dense output");
    assert_eq!(st.stats().nfev - plain.stats().nfev, 3 * interpolated);
}

#[test]
fn lands_on_close_and_frequent_stops() {
    for method in Method::ALL {
        let opts = match method {
            Method::Rk4 => Options::fixed(0.01),
            _ => Options::tol(1e-9, 1e-12),
        };
        // A t_stop closer than h_min is reached in one step.
        let mut st = Stepper::new(method, &opts, 2).unwrap();
        st.reset(&mut Oscillator, 1.0, &oscillator_exact(1.0)).unwrap();
        st.step(&mut Oscillator, 1.0 + 1e-15).unwrap();
        assert_eq!(st.t(), 1.0 + 1e-15, "{method}");
        // Stopping at 100 output times (as a driver with events would) keeps the accuracy.
        let mut k = 1;
        while k <= 100 {
            let t_out = 1.0 + 0.1 * k as f64;
            st.step(&mut Oscillator, t_out).unwrap();
            if st.t() == t_out {
                k += 1;
            }
        }
        let err = max_abs_diff(st.y(), &oscillator_exact(11.0));
        eprintln!("100 stops {method}: error {err:.2e}, {:?}", st.stats());
        assert!(err < 1e-7, "{method}: {err:e}");
    }
}
