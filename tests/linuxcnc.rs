//! Real programs on real machines: the three LinuxCNC 5-axis demos (GPL-2.0 test data in
//! ../shared/realworld/linuxcnc, read when present, never copied), and G93 timing.

use std::path::{Path, PathBuf};

use feedopt::machine::Machine;
use feedopt::optimize::{Options, optimize};
use feedopt::solver::SolverKind;
use feedopt::toolpath::{self, gcode};

fn dir() -> Option<PathBuf> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/realworld/linuxcnc");
    d.join("impeller-7bl-xyzac.ngc").exists().then_some(d)
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn the_linuxcnc_programs_parse_map_within_travel_and_solve() {
    let dir = dir().expect("../shared is present (cfg shared_data)");
    for name in ["boat-xyzbc", "boat-xyzac", "impeller-7bl-xyzac"] {
        let m = Machine::from_file(&dir.join(format!("{name}.machine.json"))).unwrap();
        let t = toolpath::read(&dir.join(format!("{name}.ngc"))).unwrap();
        // The reach pass keeps this test fast; Clarabel gives the same times (see the README).
        let options = Options {
            solver_kind: SolverKind::Reach,
            ..Options::default()
        };
        let sol = optimize(&m, &t, &options).unwrap();
        assert!(sol.verification.verified, "{name}");
        // Every axis position at every station is within the machine's travel.
        for k in 0..sol.schedule.stations.len() {
            for (j, axis) in m.axes.iter().enumerate() {
                if let Some((lo, hi)) = axis.travel {
                    let q = sol.schedule.q(k)[j];
                    assert!(
                        q >= lo - 1e-6 && q <= hi + 1e-6,
                        "{name}: {} = {q}",
                        axis.name
                    );
                }
            }
        }
        eprintln!(
            "{name}: {:.3} s, {} stations, {} spans",
            sol.schedule.cycle_time,
            sol.stations(),
            sol.problems.len()
        );
        assert!(sol.schedule.cycle_time.is_finite() && sol.schedule.cycle_time > 0.0);
    }
}

#[test]
fn a_g93_programs_time_is_the_sum_of_its_block_times_when_the_machine_is_fast() {
    // Collinear blocks (no corner stops) with inverse-time feeds; with enormous axis limits
    // the only bound is each block's programmed time, so T = Σ 60/F.
    // A rapid to X0 first: the start position must be known (it takes ~1e-5 s here).
    let program =
        "G21 G90 G0 X0\nG93\nG1 X10 F60\nG1 X12 F120\nG1 X30 F30\nG1 X31 F600\nG1 X40 F45\n";
    let t = gcode::parse(Path::new("g93.ngc"), program, gcode::Dialect::LinuxCnc).unwrap();
    let m = Machine::from_json(
        Path::new("fast.json"),
        r#"{"name": "fast", "kinematics": {"type": "xyz"},
            "axes": {"X": {"velocity": 1e6, "acceleration": 1e9},
                     "Y": {"velocity": 1e6, "acceleration": 1e9},
                     "Z": {"velocity": 1e6, "acceleration": 1e9}}}"#,
    )
    .unwrap();
    let mut options = Options::default();
    options.geometry.tolerance_mm = 0.0;
    let sol = optimize(&m, &t, &options).unwrap();
    let expect: f64 = [60.0, 120.0, 30.0, 600.0, 45.0]
        .iter()
        .map(|f| 60.0 / f)
        .sum();
    let got = sol.schedule.cycle_time;
    assert!(
        (got - expect).abs() < 1e-3 * expect,
        "T {got} vs Σ 1/F {expect}"
    );
}
