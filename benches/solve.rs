//! Solve time of the whole pipeline at a fixed station count on a 5-axis path (seed 000's
//! double swivel head): 1,000 / 10,000 / 100,000 stations.
//!
//! `cargo bench --bench solve` (add `-- 1000` to run one size); `verify/seed_head_head_1ms`
//! times the re-simulation alone on the bundled blade. Reports medians; the target is
//! 1,000 stations in ≤ 45 ms with cost linear in stations.

use std::hint::black_box;
use std::path::PathBuf;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use feedopt::machine::Machine;
use feedopt::optimize::{Options, optimize};
use feedopt::toolpath::{ClPoint, Feed, Toolpath};
use nalgebra::Vector3;

fn machine() -> Machine {
    Machine::from_json(
        "bench.json".as_ref(),
        r#"{"name": "seed double swivel head", "kinematics": {"type": "head_head", "tool_length": 200},
            "axes": {"X": {"velocity": 400, "acceleration": 2000},
                     "Y": {"velocity": 400, "acceleration": 2000},
                     "Z": {"velocity": 300, "acceleration": 1500},
                     "C": {"velocity": 120, "acceleration": 600},
                     "A": {"velocity": 60, "acceleration": 400}},
            "feed": {"max": 150}}"#,
    )
    .expect("bench machine")
}

/// A smooth 5-axis path: a 3D Lissajous-like curve with the tool tilting 15–35° and swinging.
fn toolpath() -> Toolpath {
    let n = 200;
    let points = (0..=n)
        .map(|k| {
            let s = k as f64 / n as f64;
            let a = std::f64::consts::TAU * s;
            let p = Vector3::new(
                60.0 * a.cos(),
                35.0 * (2.0 * a).sin(),
                10.0 * (3.0 * a).sin(),
            );
            let t2 = (25.0 + 10.0 * (2.0 * a).sin()).to_radians();
            let t1 = 0.8 * a + 0.3 * a.sin();
            let o = Vector3::new(t2.sin() * t1.sin(), -t2.sin() * t1.cos(), t2.cos());
            ClPoint {
                p,
                o,
                feed: Feed::Programmed(100.0),
                rotary: None,
                line: k + 1,
            }
        })
        .collect();
    Toolpath {
        source: PathBuf::from("bench.cls"),
        points,
        ..Default::default()
    }
}

fn bench_solve(c: &mut Criterion) {
    let m = machine();
    let t = toolpath();
    let mut group = c.benchmark_group("solve_5axis");
    for n in [1_000usize, 10_000, 100_000] {
        let options = Options {
            stations: Some(n),
            ..Options::default()
        };
        if n >= 10_000 {
            group.sample_size(10);
            group.measurement_time(Duration::from_secs(if n >= 100_000 { 60 } else { 20 }));
        }
        group.bench_with_input(BenchmarkId::from_parameter(n), &options, |b, o| {
            b.iter(|| black_box(optimize(&m, &t, o).expect("solves").schedule.cycle_time))
        });
    }
    group.finish();
}

/// The re-simulation alone (`verify`, 1 ms) of the bundled seed blade's default schedule: what
/// every solve pays after the solver.
fn bench_verify(c: &mut Criterion) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("problems/seed_head_head");
    let m = Machine::from_file(&root.join("machine.json")).expect("machine");
    let t = feedopt::toolpath::read(&root.join("impeller_blade.cls")).expect("toolpath");
    let sol = optimize(&m, &t, &Options::default()).expect("solves");
    let mut group = c.benchmark_group("verify");
    group.bench_function("seed_head_head_1ms", |b| {
        b.iter(|| {
            let v = feedopt::verify::verify(
                &m,
                &sol.kinematics,
                &sol.path.spans,
                &sol.problems,
                &sol.solutions,
                &Default::default(),
            )
            .expect("re-simulates");
            black_box(v.samples)
        })
    });
    group.finish();
}

criterion_group!(benches, bench_solve, bench_verify);
criterion_main!(benches);
