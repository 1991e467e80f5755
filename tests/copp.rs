//! COPP's public benchmark (TOPP-THU/copp, `tests/test_random_spline.rs`): the first 20 of its
//! 100 random 7-axis spline paths, with the traversal times COPP's own methods gave.
//!
//! The data lives in `../shared/bench/copp_random7` (not in the crate); the tests skip when it
//! is absent. Each path's machine is converted here from its JSON's `limits` (axis j is named
//! `j`, matching the CSV's `q_j` columns). With `stations: Some(1000)` on the 1,001-row CSV every
//! row is a station, and with `refine_until_verified: false` no station is added, so feedopt
//! solves exactly COPP's second-order discretisation:
//!
//! - Clarabel must match `COPP2-SOCP` (the same SOCP, also solved by Clarabel) to 0.3 %, and to
//!   1e-4 relative as a regression guard (measured: about +2e-6);
//! - the reachability pass must match `TOPP2-RA` (the same algorithm) to 1e-6 and `COPP2-SOCP`
//!   to 0.3 %, and can never beat the convex optimum of the same discretisation.

use std::path::{Path, PathBuf};
use std::process::Command;

use feedopt::machine::Machine;
use feedopt::optimize::{Options, Solution, optimize_joint};
use feedopt::solver::{SolverKind, Status};
use feedopt::toolpath::joint_csv::{self, JointPath};
use serde_json::Value;

/// Number of COPP paths in the shared folder.
#[path = "common/copp.rs"]
mod copp_data;
use copp_data::machine_json;

const PATHS: usize = 20;

/// One benchmark path: its machine (converted), joint path and COPP's reference times.
struct Case {
    index: usize,
    csv: PathBuf,
    machine_json: String,
    machine: Machine,
    path: JointPath,
    /// `results."COPP2-SOCP".traversal_time_s`
    copp2_socp: f64,
    /// `results."TOPP2-RA".traversal_time_s`
    topp2_ra: f64,
}

fn load(dir: &Path, index: usize) -> Case {
    let json_path = dir.join(format!("path_{index:03}.json"));
    let csv = dir.join(format!("path_{index:03}.csv"));
    let text = std::fs::read_to_string(&json_path).expect("read the COPP json");
    let v: Value = serde_json::from_str(&text).expect("valid COPP json");
    let machine_json = machine_json(&v["limits"]);
    let machine =
        Machine::from_json(Path::new("copp_machine.json"), &machine_json).expect("valid machine");
    let time = |method: &str| {
        v["results"][method]["traversal_time_s"]
            .as_f64()
            .unwrap_or_else(|| panic!("results.{method}.traversal_time_s"))
    };
    Case {
        index,
        path: joint_csv::read(&csv).expect("valid COPP csv"),
        csv,
        machine_json,
        machine,
        copp2_socp: time("COPP2-SOCP"),
        topp2_ra: time("TOPP2-RA"),
    }
}

/// Solves on COPP's grid exactly: 1,000 intervals, every CSV row a station, ü constant on
/// each (`Ramp::Constant`, the discretisation COPP's solvers state), and no stations added
/// where the re-simulation between stations finds a limit exceeded
/// (`refine_until_verified: false`), so both sides solve the same discretisation.
fn solve(case: &Case, kind: SolverKind) -> Solution {
    let options = Options {
        stations: Some(1000),
        solver_kind: kind,
        refine_until_verified: false,
        ramp: feedopt::constraints::Ramp::Constant,
        ..Options::default()
    };
    optimize_joint(&case.machine, &case.path, &options)
        .unwrap_or_else(|e| panic!("path {:03} ({kind:?}): {e}", case.index))
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b) / b
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn both_solvers_match_copp_on_its_own_grid() {
    let dir = copp_data::data_dir().expect("../shared is present (cfg shared_data)");
    let mut failures = Vec::new();
    eprintln!(
        "path  T_clarabel      vs COPP2-SOCP   T_reach         vs TOPP2-RA    vs COPP2-SOCP  \
         reach−clarabel"
    );
    for index in 0..PATHS {
        let case = load(&dir, index);
        let c = solve(&case, SolverKind::Clarabel);
        let r = solve(&case, SolverKind::Reach);
        assert_eq!(
            c.stations(),
            1001,
            "path {index:03}: every CSV row is a station"
        );
        assert_eq!(r.stations(), 1001);
        let (tc, tr) = (c.schedule.cycle_time, r.schedule.cycle_time);
        let (ec, er_ra, er_socp) = (
            rel(tc, case.copp2_socp),
            rel(tr, case.topp2_ra),
            rel(tr, case.copp2_socp),
        );
        eprintln!(
            "{index:03}   {tc:.9}  {ec:+.3e}     {tr:.9}  {er_ra:+.3e}     {er_socp:+.3e}     \
             {:+.3e}",
            rel(tr, tc)
        );
        let mut check = |ok: bool, what: String| {
            if !ok {
                failures.push(format!("path {index:03}: {what}"));
            }
        };
        check(
            c.status == Status::Optimal,
            format!("Clarabel status {:?}", c.status),
        );
        check(
            r.status == Status::Greedy,
            format!("reach status {:?}", r.status),
        );
        check(
            ec.abs() < 3e-3,
            format!("Clarabel {tc} vs COPP2-SOCP {}: {ec:+e}", case.copp2_socp),
        );
        check(
            ec.abs() < 1e-4,
            format!(
                "Clarabel {tc} vs COPP2-SOCP {}: {ec:+e} (regression guard 1e-4)",
                case.copp2_socp
            ),
        );
        check(
            er_socp.abs() < 3e-3,
            format!("reach {tr} vs COPP2-SOCP {}: {er_socp:+e}", case.copp2_socp),
        );
        check(
            er_ra.abs() < 1e-6,
            format!("reach {tr} vs TOPP2-RA {}: {er_ra:+e}", case.topp2_ra),
        );
        check(
            tr >= tc - 1e-9 * tc,
            format!("reach {tr} beats the convex optimum {tc}"),
        );
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The CLI always refines until the re-simulation at the servo period verifies: on path 000
/// COPP's grid is exceeded between its points, so stations are added where it fails (1,001 →
/// 1,886 when written) and the cycle time rises a little above COPP2-SOCP's (+0.1 %), which
/// solves the coarser grid.
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn cli_solves_a_copp_path() {
    let dir = copp_data::data_dir().expect("../shared is present (cfg shared_data)");
    let case = load(&dir, 0);
    let tmp = tempfile::tempdir().expect("temp dir");
    let machine = tmp.path().join("M.json");
    std::fs::write(&machine, &case.machine_json).expect("write machine");
    let csv = case.csv.canonicalize().expect("absolute csv path");
    let out = Command::new(env!("CARGO_BIN_EXE_feedopt"))
        .current_dir(tmp.path())
        .arg("solve")
        .arg("--machine")
        .arg(&machine)
        .arg(&csv)
        .args(["--json", "--stations", "1000"])
        .output()
        .expect("run feedopt");
    assert!(
        out.status.success(),
        "feedopt failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let t = v["cycle_time_s"].as_f64().expect("cycle_time_s");
    let stations = v["stations"].as_u64().expect("stations");
    assert!(stations >= 1001, "at least COPP's grid: {stations}");
    assert_eq!(v["status"].as_str(), Some("optimal"));
    assert_eq!(v["verified"].as_bool(), Some(true), "{v}");
    let e = rel(t, case.copp2_socp);
    eprintln!(
        "CLI path 000: {t:.9} s at {stations} stations vs COPP2-SOCP {}: {e:+.3e}",
        case.copp2_socp
    );
    assert!(e.abs() < 3e-3, "CLI {t} vs COPP2-SOCP {}", case.copp2_socp);
    // The library with the CLI's defaults gives the same answer.
    let options = Options {
        stations: Some(1000),
        ..Options::default()
    };
    let lib = optimize_joint(&case.machine, &case.path, &options).expect("solves");
    assert_eq!(lib.stations() as u64, stations);
    let tl = lib.schedule.cycle_time;
    assert!(rel(t, tl).abs() < 1e-9, "CLI {t} vs library {tl}");
}
