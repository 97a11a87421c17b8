//! Times the passive four-bar of the benchmarks over 10 s at several tolerances and prints
//! wall time, steps and energy drift: `cargo run --release --example four_bar_10s`.

use planardyn::dynamics::ModelDrives;
use planardyn::simulate::{simulate, Settings};
use std::time::Instant;

fn main() {
    let path = format!("{}/../../examples/models/four-bar-gravity.yaml", env!("CARGO_MANIFEST_DIR"));
    let mech = planardyn::load(&path).expect("model");
    for method in ["dop853", "dopri5"] {
        for rtol in [1e-5, 1e-6, 1e-8, 1e-10, 1e-12] {
            let mut s = Settings::for_model(&mech).expect("settings");
            s.t_end = 10.0;
            s.method = method.parse().expect("method");
            s.options.rtol = rtol;
            s.options.atol = rtol * 1e-2;
            let reps = 20;
            let start = Instant::now();
            let mut tr = None;
            for _ in 0..reps {
                tr = Some(simulate(&mech, &s, &mut ModelDrives(&mech), None).expect("simulate"));
            }
            let wall = start.elapsed().as_secs_f64() / reps as f64;
            let tr = tr.expect("ran");
            println!(
                "{method:7} rtol {rtol:.0e}: {:8.3} ms  steps {:5} (rejected {:4}, failed evaluations {:3})  nfev {:6}  energy drift {:.2e} J  loop gap {:.1e}",
                wall * 1e3,
                tr.stats.integrator.naccept,
                tr.stats.integrator.nreject,
                tr.stats.failed_evaluations,
                tr.stats.integrator.nfev,
                tr.stats.energy_drift,
                tr.stats.max_residual
            );
        }
    }
}
