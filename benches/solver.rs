//! Criterion benchmarks of the solver: `cargo bench` (add `-- --quick` for a short run).
//!
//! The same workloads as `slidebase bench`, at sizes criterion can repeat many times:
//! a slice of the two-block run, steps of the three-storey frame and of a 10-course wall,
//! and the exact mass-spring model. `slidebase bench` gives the full-length numbers.

use std::hint::black_box;
use std::sync::Arc;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use slidebase::dda::{Dda, SolverParams};
use slidebase::ground_motion::{GroundMotion, resolve_record};
use slidebase::headless::run::run;
use slidebase::model::presets::resolve_scene;
use slidebase::setup::{ModelKind, RunSpec};

fn two_block(c: &mut Criterion) {
    let mut group = c.benchmark_group("two-block");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(8));
    for (name, model) in [
        ("dda 10 s", ModelKind::Dda),
        ("exact 10 s", ModelKind::MassSpring),
    ] {
        let req = RunSpec {
            duration: Some(10.0),
            model,
            ..RunSpec::default()
        };
        group.bench_function(name, |b| {
            b.iter(|| black_box(run(&req).map(|o| o.summary.us_max_over_d)))
        });
    }
    group.finish();
}

/// A model of `scene` under El Centro, ready to step (set-up and settling not timed).
fn model(scene: &str) -> Option<Dda> {
    let scene = resolve_scene(scene).ok()?;
    let record = resolve_record("el-centro").ok()?;
    let motion = GroundMotion::Record(Arc::new(record));
    let params = SolverParams {
        duration: 1e9,
        ..SolverParams::for_scene(&scene)
    };
    Dda::new(&scene, Some(motion), params).ok()
}

fn steps(c: &mut Criterion) {
    let mut group = c.benchmark_group("100 steps");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(8));
    for scene in ["three-storey", "frame:20", "wall:10"] {
        let Some(start) = model(scene) else {
            eprintln!("cannot build {scene}");
            continue;
        };
        group.bench_function(scene, |b| {
            b.iter_batched(
                || start.clone(),
                |mut dda| {
                    for _ in 0..100 {
                        if dda.step(1e-3).is_err() {
                            break;
                        }
                    }
                    black_box(dda.time())
                },
                criterion::BatchSize::LargeInput,
            )
        });
    }
    group.finish();
}

criterion_group!(benches, two_block, steps);
criterion_main!(benches);
