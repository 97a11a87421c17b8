//! One forward-dynamics evaluation as the integrator makes it: Newton from the first-order
//! prediction of a nearby accepted point, analogues, convective term, A, b, solve.
//! Run: `cargo bench -p planardyn --bench forward_dynamics`.

use criterion::{criterion_group, criterion_main, Criterion};
use planardyn::dynamics::ModelDrives;
use planardyn::integrate::OdeSystem;
use planardyn::kinematics::{assemble_into, velocity_analogues, Chart};
use planardyn::simulate::ode::MechanismOde;
use planardyn::Workspace;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("forward_dynamics");
    for file in ["four-bar-gravity.yaml", "five-bar.yaml", "3-rrr.yaml", "andrews-squeezer.yaml"] {
        let path = format!("{}/../../examples/models/{file}", env!("CARGO_MANIFEST_DIR"));
        let mech = planardyn::load(&path).unwrap();
        let m = mech.dof();
        let (q0, _) = mech.initial_state();
        let mut ws = Workspace::new(&mech);
        assemble_into(&mech, &q0, &mut ws).unwrap();
        velocity_analogues(&mut ws).unwrap();
        let mut drives = ModelDrives(&mech);
        let mut ode = MechanismOde::new(&mech, ws, &mut drives);
        let mut y0 = vec![0.0; 2 * m + 1];
        y0[..m].copy_from_slice(&q0);
        y0[m..2 * m].fill(1.0);
        ode.set_chart(Chart::Inputs, 0.0, &y0).unwrap();
        // A stage point 1 mrad away, as within an integration step.
        let mut y = y0.clone();
        y[..m].iter_mut().for_each(|v| *v += 1e-3);
        let mut dy = vec![0.0; 2 * m + 1];
        group.bench_function(file.trim_end_matches(".yaml"), |b| {
            b.iter(|| ode.rhs(0.0, black_box(&y), &mut dy).unwrap());
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
