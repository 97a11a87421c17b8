//! Times the passive four-bar of the benchmarks over 10 s and prints wall time, steps and
//! energy drift. `cargo run --release --example four_bar_10s` sweeps DOP853 and DOPRI5 over
//! tolerances (atol = rtol, outputs on a 0.1 s grid, as the benchmark suite times them);
//! `... -- METHOD RTOL [REPEATS]` runs one setting REPEATS times (for a profiler).

use planardyn::dynamics::ModelDrives;
use planardyn::simulate::{grid, simulate, Settings};
use std::time::Instant;

fn run(mech: &planardyn::Mechanism, method: &str, rtol: f64, reps: usize) {
    let mut s = Settings::for_model(mech).expect("settings");
    s.t_end = 10.0;
    s.method = method.parse().expect("method");
    s.options.rtol = rtol;
    s.options.atol = rtol;
    s.t_eval = Some(grid(0.0, 10.0, 0.1));
    let mut best = f64::INFINITY;
    let mut tr = None;
    for _ in 0..reps {
        let start = Instant::now();
        tr = Some(simulate(mech, &s, &mut ModelDrives(mech), None).expect("simulate"));
        best = best.min(start.elapsed().as_secs_f64());
    }
    let tr = tr.expect("ran");
    println!(
        "{method:7} rtol {rtol:.0e}: {:8.3} ms  steps {:5} (rejected {:4}, failed evaluations {:3})  nfev {:6}  energy drift {:.2e} J  loop gap {:.1e}",
        best * 1e3,
        tr.stats.integrator.naccept,
        tr.stats.integrator.nreject,
        tr.stats.failed_evaluations,
        tr.stats.integrator.nfev,
        tr.stats.energy_drift,
        tr.stats.max_residual
    );
}

fn main() {
    let path = format!("{}/../../examples/models/four-bar-gravity.yaml", env!("CARGO_MANIFEST_DIR"));
    let mech = planardyn::load(&path).expect("model");
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let [method, rtol, rest @ ..] = args.as_slice() {
        let reps = rest.first().map_or(20, |r| r.parse().expect("REPEATS"));
        run(&mech, method, rtol.parse().expect("RTOL"), reps);
        return;
    }
    for method in ["dop853", "dopri5"] {
        for rtol in [1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-12] {
            run(&mech, method, rtol, 20);
        }
    }
}
