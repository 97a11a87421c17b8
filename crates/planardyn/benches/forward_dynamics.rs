//! One forward-dynamics evaluation as the integrator makes it. Two cases per model:
//! - `NAME`: evaluated again and again at one stage point (1 mrad from the accepted point
//!   the first time): the position is then already converged, so this is the cost of the
//!   stages after it (J factorised, analogues U, convective term, A, b, solve) plus one
//!   residual check. The figure the performance targets (docs/benchmarks.md) are read against.
//! - `NAME+1mrad`: alternating between two stage points 1 mrad apart in every coordinate,
//!   so that each evaluation also runs Newton from the second-order prediction, as between
//!   the stages of an integration step.
//!
//! Run: `cargo bench -p planardyn --bench forward_dynamics`.

use criterion::{criterion_group, criterion_main, Criterion};
use planardyn::dynamics::ModelDrives;
use planardyn::integrate::OdeSystem;
use std::hint::black_box;

#[path = "../tests/common/ode.rs"]
mod ode;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("forward_dynamics");
    for file in ["four-bar-gravity.yaml", "five-bar.yaml", "3-rrr.yaml", "andrews-squeezer.yaml"] {
        let path = format!("{}/../../examples/models/{file}", env!("CARGO_MANIFEST_DIR"));
        let mech = planardyn::load(&path).unwrap();
        let m = mech.dof();
        let mut drives = ModelDrives(&mech);
        let (mut ode, y0) = ode::at_drawing(&mech, &mut drives);
        // A stage point 1 mrad away, as within an integration step.
        let mut y = y0.clone();
        y[..m].iter_mut().for_each(|v| *v += 1e-3);
        let mut dy = vec![0.0; 2 * m + 1];
        let name = file.trim_end_matches(".yaml");
        group.bench_function(name, |b| {
            b.iter(|| ode.rhs(0.0, black_box(&y), &mut dy).unwrap());
        });
        let mut y2 = y.clone();
        y2[..m].iter_mut().for_each(|v| *v += 1e-3);
        let mut second = false;
        group.bench_function(format!("{name}+1mrad"), |b| {
            b.iter(|| {
                second = !second;
                ode.rhs(0.0, black_box(if second { &y2 } else { &y }), &mut dy).unwrap()
            });
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
