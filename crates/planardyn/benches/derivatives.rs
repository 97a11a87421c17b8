//! The exact Jacobian of forward dynamics (dqdd/dq, dqdd/dqd, dqdd/dtau) against one
//! forward-dynamics evaluation, both from a converged point 1 mrad away (Newton runs in
//! each, as between the stages of a step). A one-sided difference Jacobian costs 2m + 1
//! evaluations; the ratio of the two times is what docs/formulation.md (*Derivatives*) quotes
//! (measured on a shared 2-core machine: four-bar 1.8 evaluations for a budget of 3, five-bar
//! 2.5 of 5, 3-RRR 3.0 of 7, Andrews' squeezer 1.9 of 3).
//!
//! Run: `cargo bench -p planardyn --bench derivatives`.

use criterion::{criterion_group, criterion_main, Criterion};
use planardyn::dynamics::{forward, forward_derivatives, FixedDrives};
use planardyn::kinematics::{assemble_into, Chart};
use planardyn::Workspace;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("derivatives");
    for file in ["four-bar-gravity.yaml", "five-bar.yaml", "3-rrr.yaml", "andrews-squeezer.yaml"] {
        let path = format!("{}/../../examples/models/{file}", env!("CARGO_MANIFEST_DIR"));
        let mech = planardyn::load(&path).unwrap();
        let m = mech.dof();
        let (q0, _) = mech.initial_state();
        let mut ws0 = Workspace::new(&mech);
        assemble_into(&mech, &q0, &mut ws0).unwrap();
        let q: Vec<f64> = q0.iter().map(|v| v + 1e-3).collect();
        let (qd, tau) = (vec![1.0; m], vec![0.5; m]);
        let name = file.trim_end_matches(".yaml");
        let mut ws = ws0.clone();
        group.bench_function(format!("{name}/forward"), |b| {
            b.iter(|| {
                ws.x.copy_from_slice(&ws0.x);
                ws.chart = Chart::Inputs;
                forward(&mech, 0.0, black_box(&q), &qd, &mut FixedDrives(&tau), &mut ws).unwrap()
            });
        });
        group.bench_function(format!("{name}/jacobian (m = {m}, 2m + 1 = {})", 2 * m + 1), |b| {
            b.iter(|| {
                ws.x.copy_from_slice(&ws0.x);
                forward_derivatives(&mech, black_box(&q), &qd, &tau, &mut ws).unwrap()
            });
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
