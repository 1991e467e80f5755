//! The public reference cases in ../shared/cases (machine + APT CL file + a cycle time computed
//! independently with TOPP-RA): each must come within 0.5 %. Skipped when ../shared is absent.

use std::path::{Path, PathBuf};

use feedopt::machine::Machine;
use feedopt::optimize::{Options, optimize};
use feedopt::solver::{SolverKind, Status};
use feedopt::toolpath;

fn cases_dir() -> Option<PathBuf> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/cases");
    d.join("references.json").exists().then_some(d)
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn public_cases_match_the_independent_reference_within_half_a_percent() {
    let dir = cases_dir().expect("../shared is present (cfg shared_data)");
    let refs: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("references.json")).unwrap())
            .unwrap();
    let refs = refs.as_array().expect("a list of cases");
    assert!(!refs.is_empty());
    for r in refs {
        let name = r["case"].as_str().unwrap();
        let expect = r["cycle_time_s"].as_f64().unwrap();
        let m = Machine::from_file(&dir.join(format!("{name}.machine.json"))).unwrap();
        let t = toolpath::read(&dir.join(format!("{name}.cls"))).unwrap();
        // The references interpolate the CL points exactly: compare like with like.
        let mut exact = Options::default();
        exact.geometry.tolerance_mm = 0.0;
        exact.geometry.tolerance_deg = 0.0;
        let sol = optimize(&m, &t, &exact).unwrap();
        let got = sol.schedule.cycle_time;
        let err = (got - expect) / expect;
        eprintln!(
            "{name}: {got:.6} s vs reference {expect:.6} s ({:+.3} %), {} stations, {:?}",
            100.0 * err,
            sol.stations(),
            sol.status
        );
        assert!(err.abs() < 5e-3, "{name}: {got} vs {expect}");
        assert_eq!(sol.status, Status::Optimal, "{name}");
        assert_eq!(
            sol.problems.len() as u64,
            r["spans"].as_u64().unwrap(),
            "{name}: spans"
        );
    }
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn both_solvers_agree_on_the_public_cases_and_every_schedule_verifies() {
    let dir = cases_dir().expect("../shared is present (cfg shared_data)");
    for name in ["p1_spiral_tilt", "p2_xyz_rounded_square", "p3_s_curve_lean"] {
        let m = Machine::from_file(&dir.join(format!("{name}.machine.json"))).unwrap();
        let t = toolpath::read(&dir.join(format!("{name}.cls"))).unwrap();
        let solve = |solver_kind| {
            optimize(
                &m,
                &t,
                &Options {
                    solver_kind,
                    ..Options::default()
                },
            )
            .unwrap()
        };
        let (c, r) = (solve(SolverKind::Clarabel), solve(SolverKind::Reach));
        let (tc, tr) = (c.schedule.cycle_time, r.schedule.cycle_time);
        eprintln!(
            "{name}: clarabel {tc:.7} s ({} st), reach {tr:.7} s ({} st), {:+.2e}",
            c.stations(),
            r.stations(),
            (tr - tc) / tc
        );
        assert!(((tr - tc) / tc).abs() < 1e-4, "{name}: {tc} vs {tr}");
        for s in [&c, &r] {
            assert!(
                s.verification.verified,
                "{name}: {:?}",
                s.verification.violations.first()
            );
            assert!(s.verification.worst_ratio() <= 1.001);
        }
    }
}
