//! Jerk-limited schedules (issue 6).

use std::path::{Path, PathBuf};
use std::time::Instant;

use feedopt::machine::Machine;
use feedopt::optimize::{Options, optimize_joint};
use feedopt::toolpath::joint_csv;
use serde_json::Value;

#[path = "common/copp.rs"]
mod copp_data;

fn copp_dir() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/bench/copp_random7");
    if dir.join("path_000.json").is_file() {
        Some(dir)
    } else {
        eprintln!("skipping: {} is absent", dir.display());
        None
    }
}

#[test]
#[ignore]
fn explore_copp_jerk() {
    let Some(dir) = copp_dir() else { return };
    let which = std::env::var("COPP_PATH").unwrap_or_default();
    let list: Vec<usize> = if which == "all" {
        (0..20).collect()
    } else {
        vec![which.parse().unwrap_or(0)]
    };
    let (mut sum_t, mut sum_ref, mut sum_solve) = (0.0, 0.0, 0.0);
    for &idx in &list {
        let v: Value = serde_json::from_str(
            &std::fs::read_to_string(dir.join(format!("path_{idx:03}.json"))).unwrap(),
        )
        .unwrap();
        let m = Machine::from_json(
            Path::new("m.json"),
            &copp_data::machine_json_jerk(&v["limits"]),
        )
        .unwrap();
        let path = joint_csv::read(&dir.join(format!("path_{idx:03}.csv"))).unwrap();
        let refine = std::env::var("REFINE").is_ok();
        let options = Options {
            stations: Some(1000),
            refine_until_verified: refine,
            ..Options::default()
        };
        let t0 = Instant::now();
        let sol = optimize_joint(&m, &path, &options).unwrap();
        let topp3 = v["results"]["TOPP3-SOCP"]["traversal_time_s"]
            .as_f64()
            .unwrap();
        eprintln!(
            "path {idx}: T = {:.6} s vs TOPP3-SOCP {topp3:.6} ({:+.4} %), iterations {}, solve {:.1} ms, wall {:.1} ms, stations {}, verified {}, worst {:.5}, violating {}",
            sol.schedule.cycle_time,
            100.0 * (sol.schedule.cycle_time / topp3 - 1.0),
            sol.iterations,
            sol.solve_time * 1e3,
            t0.elapsed().as_secs_f64() * 1e3,
            sol.stations(),
            sol.verification.verified,
            sol.verification.worst_ratio(),
            sol.verification.violating_intervals
        );
        if list.len() == 1 {
            for w in &sol.verification.worst {
                eprintln!(
                    "  {}: v {:.4} a {:.4} j {:.4}",
                    w.name, w.velocity, w.acceleration, w.jerk
                );
            }
        }
        for v in sol.verification.violations.iter().take(5) {
            eprintln!("  {v:?}");
        }
        sum_t += sol.schedule.cycle_time;
        sum_ref += topp3;
        sum_solve += t0.elapsed().as_secs_f64();
    }
    let k = list.len() as f64;
    eprintln!(
        "mean T {:.6} vs TOPP3-SOCP {:.6} ({:+.4} %), mean wall {:.1} ms",
        sum_t / k,
        sum_ref / k,
        100.0 * (sum_t / sum_ref - 1.0),
        sum_solve / k * 1e3
    );
}

#[test]
#[ignore]
fn debug_knot() {
    use feedopt::geometry::{GeometryOptions, Path as GPath};
    use feedopt::kinematics::Kinematics;
    let m = Machine::from_file(Path::new("problems/seed_head_head/machine_jerk.json")).unwrap();
    let tp =
        feedopt::toolpath::read(Path::new("problems/seed_head_head/impeller_blade.cls")).unwrap();
    let kin = Kinematics::new(&m);
    let angles = kin.rotary_angles(&tp.points, &m.axes).unwrap();
    let path = GPath::build(
        &tp,
        &angles,
        m.feed_max,
        kin.uses_orientation(),
        false,
        &GeometryOptions::default(),
    )
    .unwrap();
    let span = &path.spans[1];
    let knots = span.spline.knots();
    let k = knots
        .iter()
        .position(|&x| (x - 87.24001595270282).abs() < 1e-6)
        .unwrap();
    eprintln!("knot {k} of {}", knots.len());
    for seg in [k - 1, k] {
        let w = span.spline.eval_in(seg, knots[k]);
        let j = kin.axis_jets(&w);
        let d3 = kin.axis_third_derivatives(&w, &span.spline.d3_in(seg, knots[k]));
        eprintln!(
            "seg {seg}: d1 {:?}\n d2 {:?}\n ddq {:?}\n dddq {:?}",
            w.d1, w.d2, j.ddq, d3
        );
    }
}

#[test]
#[ignore]
fn debug_knot2() {
    use feedopt::motion::Interval;
    let m = Machine::from_file(Path::new("problems/seed_head_head/machine_jerk.json")).unwrap();
    let tp =
        feedopt::toolpath::read(Path::new("problems/seed_head_head/impeller_blade.cls")).unwrap();
    let o = Options {
        refine_until_verified: false,
        stations: Some(2000),
        ..Options::default()
    };
    let sol = feedopt::optimize::optimize(&m, &tp, &o).unwrap();
    let v = &sol.verification;
    eprintln!(
        "violations {}: {:?}",
        v.violating_intervals,
        v.violations.first()
    );
    let viol = v.violations.first().unwrap();
    let (p, s) = (&sol.problems[viol.span], &sol.solutions[viol.span]);
    let span = &sol.path.spans[viol.span];
    let k = viol.interval;
    eprintln!(
        "interval {k}: u {} .. {}, viol u {}",
        p.u[k],
        p.u[k + 1],
        viol.u
    );
    let a = s.a.as_ref().unwrap();
    for kk in [k - 1, k, k + 1] {
        let iv = Interval::of(&p.u, &s.b, Some(a), kk);
        let (s0, s1) = iv.ends();
        for (e, st) in [(kk, s0), (kk + 1, s1)] {
            for seg in [
                span.spline.segment(p.u[e]).saturating_sub(1),
                span.spline.segment(p.u[e]),
            ] {
                let w = span.spline.eval_in(seg, p.u[e]);
                let j = sol.kinematics.axis_jets(&w);
                let d3 = sol
                    .kinematics
                    .axis_third_derivatives(&w, &span.spline.d3_in(seg, p.u[e]));
                let q3 = d3[4] * st.ud * st.b + 3.0 * j.ddq[4] * st.ud * st.udd + j.dq[4] * st.uddd;
                eprintln!(
                    "iv {kk} e {e} u {} seg {seg}: law {:?} b {} a {} uddd {} jerkA {q3}",
                    p.u[e], iv.law, st.b, st.udd, st.uddd
                );
            }
        }
    }
}
