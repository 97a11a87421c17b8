//! Time `planardyn::simulate::simulate_prepared` from Rust (the model prepared once, as the
//! Python binding does), for the Python-overhead comparison.
//!
//! Usage: `planardyn-rust-sim MODEL METHOD RTOL ATOL DT T_END OUTPUT_DT REPEATS`
//! (`DT` and `OUTPUT_DT` may be `-` for none: adaptive steps, output every accepted step).
//! Prints one JSON line: best and median wall time of REPEATS runs (s), status, steps,
//! nfev, the final coordinates and the energy drift (J) at the outputs.

use planardyn::dynamics::{ModelDrives, Prescribed};
use planardyn::simulate::{grid, simulate_prepared, Observe, Prepared, Settings};
use std::time::Instant;

fn opt(s: &str) -> Option<f64> {
    if s == "-" {
        None
    } else {
        Some(s.parse().unwrap_or_else(|e| panic!("not a number: {s:?} ({e})")))
    }
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.len() != 9 {
        eprintln!("usage: {} MODEL METHOD RTOL ATOL DT T_END OUTPUT_DT REPEATS", a[0]);
        std::process::exit(2);
    }
    let mech = planardyn::load(&a[1]).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2)
    });
    let mut s = Settings::for_model(&mech).expect("model settings");
    s.method = a[2].parse().expect("method");
    s.options.rtol = a[3].parse().expect("rtol");
    s.options.atol = a[4].parse().expect("atol");
    s.options.dt = opt(&a[5]);
    s.t_end = a[6].parse().expect("t_end");
    s.t_eval = opt(&a[7]).map(|h| {
        let mut t = grid(s.t0, s.t_end, h);
        // As the Python binding does: never past t_end, no duplicate end point.
        t.iter_mut().for_each(|v| *v = v.min(s.t_end));
        t.dedup();
        t
    });
    let repeats: usize = a[8].parse().expect("repeats");
    let mut times = Vec::with_capacity(repeats);
    let mut last = None;
    // The set-up from the model alone, made once as a Python `Mechanism` makes it at its first run.
    let prepared = Prepared::new(&mech);
    for _ in 0..repeats.max(1) {
        let mut drives = ModelDrives(&mech);
        let start = Instant::now();
        // A progress callback as the Python binding passes one, so that both do the same work.
        let mut on_step = |_t: f64| true;
        let (motion, observe) = (&mut Prescribed::from_model(&mech), Observe::default());
        let traj =
            simulate_prepared(&mech, &prepared, &s, &mut drives, motion, observe, Some(&mut on_step)).expect("simulate");
        times.push(start.elapsed().as_secs_f64());
        last = Some(traj);
    }
    let traj = last.unwrap();
    times.sort_by(f64::total_cmp);
    let n = traj.t.len();
    let q_end: Vec<String> = traj.q[(n - 1) * traj.m..].iter().map(|v| format!("{v:e}")).collect();
    println!(
        "{{\"best_s\": {:e}, \"median_s\": {:e}, \"repeats\": {}, \"status\": \"{}\", \"outputs\": {}, \"naccept\": {}, \"nfev\": {}, \"q_end\": [{}], \"energy_drift\": {:e}}}",
        times[0],
        times[times.len() / 2],
        times.len(),
        traj.status.name(),
        n,
        traj.stats.integrator.naccept,
        traj.stats.integrator.nfev,
        q_end.join(", "),
        traj.stats.energy_drift
    );
}
