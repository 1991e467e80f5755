//! Solve times on COPP's benchmark paths (`../shared/bench/copp_random7`, the first 20 of COPP's
//! 100 random 7-axis spline paths; skipped when the folder is absent).
//!
//! `cargo bench --bench copp` measures, on COPP's own grid (every one of the 1,001 CSV rows a
//! station):
//!
//! - `copp20_solver/{reach,clarabel,optimal}`: the solver alone, all 20 paths per iteration
//!   (the span problems are built outside the timed loop); divide by 20 for the time per path
//!   (the throughput line says paths/s). `clarabel` is one cone program per path; `optimal` is
//!   what the default solve runs: the reach pass, then the lattice relaxation where it is the
//!   exact optimum and Clarabel only on the windows where it is not;
//! - `copp20_optimize_joint/{reach,clarabel}`: the whole `optimize_joint` with default options
//!   (path, problem, the reachability pass that always runs first, the solver, the schedule,
//!   the re-simulation at the servo period and the stations it adds), all 20 paths per
//!   iteration; `copp20_optimize_joint_fixed_grid/…` the same on COPP's grid as it is
//!   (`refine_until_verified: false`);
//! - `reach_scaling/solver/N` and `reach_scaling/optimize_joint/N`: path 000 at N = 10⁴, 10⁵,
//!   10⁶ stations (each CSV interval divided into N/1000).
//!
//! COPP's own figures on the same machine type (its README): TOPP2-RA 1.9 ms and COPP2-SOCP
//! 448 ms per path including problem build; TOPP2-RA 1.2 / 9 / 88 ms at 10³ / 10⁴ / 10⁵.

use std::hint::black_box;
use std::path::Path as FsPath;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use feedopt::constraints::{Grid, SpanProblem};
use feedopt::geometry::Path;
use feedopt::kinematics::Kinematics;
use feedopt::machine::Machine;
use feedopt::optimize::{Options, optimize_joint};
use feedopt::solver::{self, SolverKind};
use feedopt::toolpath::joint_csv::{self, JointPath};
use serde_json::Value;

#[path = "../tests/common/copp.rs"]
mod copp_data;

/// The joint-space machine of a COPP path's `limits`.
fn machine(limits: &Value) -> Machine {
    let text = copp_data::machine_json(limits);
    Machine::from_json(FsPath::new("copp_machine.json"), &text).expect("valid machine")
}

const PATHS: usize = 20;

struct Case {
    machine: Machine,
    /// The same machine with the path's jerk limits (issue 6).
    machine_jerk: Machine,
    path: JointPath,
}

fn load(dir: &FsPath) -> Vec<Case> {
    (0..PATHS)
        .map(|i| {
            let text = std::fs::read_to_string(dir.join(format!("path_{i:03}.json")))
                .expect("read COPP json");
            let v: Value = serde_json::from_str(&text).expect("COPP json");
            Case {
                machine: machine(&v["limits"]),
                machine_jerk: Machine::from_json(
                    FsPath::new("copp_jerk.json"),
                    &copp_data::machine_json_jerk(&v["limits"]),
                )
                .expect("valid machine"),
                path: joint_csv::read(&dir.join(format!("path_{i:03}.csv"))).expect("COPP csv"),
            }
        })
        .collect()
}

/// The span problem of a case with every CSV interval divided into `parts`.
fn problem(case: &Case, parts: usize) -> SpanProblem {
    let path = Path::from_joint(&case.path, &case.machine).expect("joint path");
    let span = &path.spans[0];
    let rows = case.path.s.len() - 1;
    let n = rows * parts;
    let grid = Grid {
        spacing: span.length() / n as f64,
        min_parts: parts,
    };
    let mut p = SpanProblem::build(span, &Kinematics::new(&case.machine), &case.machine, grid);
    // COPP's discretisation (ü constant per interval), as its TOPP2-RA and COPP2-SOCP state it.
    p.ramp = feedopt::constraints::Ramp::Constant;
    assert_eq!(p.intervals(), n, "the grid is the CSV's, divided {parts}×");
    p
}

fn bench_copp(c: &mut Criterion) {
    let Some(dir) = copp_data::data_dir() else {
        return;
    };
    let cases = load(&dir);
    let problems: Vec<SpanProblem> = cases.iter().map(|k| problem(k, 1)).collect();

    let mut g = c.benchmark_group("copp20_solver");
    g.throughput(Throughput::Elements(PATHS as u64));
    g.sample_size(20);
    g.measurement_time(Duration::from_secs(5));
    g.bench_function("reach", |b| {
        b.iter(|| {
            for p in &problems {
                black_box(solver::reach::solve(p).expect("feasible"));
            }
        })
    });
    g.sample_size(10);
    g.measurement_time(Duration::from_secs(15));
    g.bench_function("clarabel", |b| {
        let settings = Default::default();
        b.iter(|| {
            for p in &problems {
                black_box(solver::clarabel::solve(p, &settings).expect("solves"));
            }
        })
    });
    // What the default solve runs on a span: the reach pass (always first), then the optimum
    // of the discretisation — the lattice relaxation where it is exact, Clarabel on the windows
    // where it is not (`solver::optimal`).
    g.bench_function("optimal", |b| {
        let settings = Default::default();
        b.iter(|| {
            for p in &problems {
                let greedy = solver::reach::solve(p).expect("feasible");
                black_box(solver::optimal(p, &greedy, &settings).expect("solves"));
            }
        })
    });
    g.finish();

    // The default pipeline adds stations where the re-simulation at the servo period finds a
    // limit exceeded (path 000: 1,001 → 1,886) and solves again; `fixed_grid` keeps COPP's grid
    // (`refine_until_verified: false`; the re-simulation still runs once), like COPP's timing.
    for (group, refine) in [
        ("copp20_optimize_joint", true),
        ("copp20_optimize_joint_fixed_grid", false),
    ] {
        let mut g = c.benchmark_group(group);
        g.throughput(Throughput::Elements(PATHS as u64));
        for (name, kind, secs) in [
            ("reach", SolverKind::Reach, 5),
            ("clarabel", SolverKind::Clarabel, 15),
        ] {
            let options = Options {
                stations: Some(1000),
                solver_kind: kind,
                refine_until_verified: refine,
                ..Options::default()
            };
            g.sample_size(10);
            g.measurement_time(Duration::from_secs(secs));
            g.bench_function(name, |b| {
                b.iter(|| {
                    for k in &cases {
                        let sol = optimize_joint(&k.machine, &k.path, &options).expect("solves");
                        black_box(sol.schedule.cycle_time);
                    }
                })
            });
        }
        g.finish();
    }
}

/// Issue 6: the jerk-limited pipeline per COPP path as the acceptance test runs it — COPP's
/// 1,000 intervals to start, the SCP with Clarabel, stations added until the 1 kHz
/// re-simulation (jerk included) verifies. Compare with COPP's TOPP3-SOCP, 834 ms per path on
/// this kind of machine (its time includes its TOPP2-RA start, as ours includes the reach pass
/// and the verification). `optimize_joint` uses every core the machine has (windows of the
/// SCP, chunks of the re-simulation); `optimize_joint_one_thread` the same on one.
fn bench_copp_jerk(c: &mut Criterion) {
    let Some(dir) = copp_data::data_dir() else {
        return;
    };
    let cases = load(&dir);
    let mut g = c.benchmark_group("copp20_jerk");
    g.throughput(Throughput::Elements(PATHS as u64));
    g.sample_size(10);
    for (name, threads, secs) in [
        ("optimize_joint", 0, 40),
        ("optimize_joint_one_thread", 1, 60),
    ] {
        let mut options = Options {
            stations: Some(1000),
            ..Options::default()
        };
        options.solver.threads = threads;
        options.verify.threads = threads;
        g.measurement_time(Duration::from_secs(secs));
        g.bench_function(name, |b| {
            b.iter(|| {
                for k in &cases {
                    let sol = optimize_joint(&k.machine_jerk, &k.path, &options).expect("solves");
                    assert!(sol.verification.verified);
                    black_box(sol.schedule.cycle_time);
                }
            })
        });
    }
    g.finish();
}

fn bench_reach_scaling(c: &mut Criterion) {
    let Some(dir) = copp_data::data_dir() else {
        return;
    };
    let cases = load(&dir);
    let case = &cases[0];
    let mut g = c.benchmark_group("reach_scaling");
    g.sample_size(10);
    for n in [10_000usize, 100_000, 1_000_000] {
        let p = problem(case, n / 1000);
        g.measurement_time(Duration::from_secs(if n >= 1_000_000 { 20 } else { 5 }));
        g.bench_with_input(BenchmarkId::new("solver", n), &p, |b, p| {
            b.iter(|| black_box(solver::reach::solve(p).expect("feasible")))
        });
        drop(p);
        let options = Options {
            stations: Some(n),
            solver_kind: SolverKind::Reach,
            ..Options::default()
        };
        g.measurement_time(Duration::from_secs(if n >= 1_000_000 { 40 } else { 5 }));
        g.bench_with_input(BenchmarkId::new("optimize_joint", n), &options, |b, o| {
            b.iter(|| {
                let sol = optimize_joint(&case.machine, &case.path, o).expect("solves");
                black_box(sol.schedule.cycle_time)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench_copp, bench_copp_jerk, bench_reach_scaling);
criterion_main!(benches);
