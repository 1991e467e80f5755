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
