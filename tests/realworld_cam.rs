//! The real CAM programs of `../shared/realworld/cam` (issue 12) read with default options:
//! format and dialect detected, each with the machine its README names. Third-party data
//! outside the crate: reported as ignored where `../shared` is absent (`build.rs`).

use feedopt::machine::{Machine, references_from_json};
use feedopt::toolpath::{self, Format, Input, MachineContext, ReadOptions};
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/realworld/cam")
}

/// The machine file as the shared folder has it (it gives no `reference` positions).
fn context(machine: &str) -> MachineContext {
    let path = dir().join("machines").join(machine);
    let text = std::fs::read_to_string(&path).expect("machine file");
    let m = Machine::from_json(&path, &text).unwrap();
    MachineContext::new(&m, &references_from_json(&path, &text, &m).unwrap())
}

fn read(file: &str, machine: &str) -> feedopt::error::Result<(Input, toolpath::Detected)> {
    let options = ReadOptions {
        machine: Some(context(machine)),
        ..Default::default()
    };
    toolpath::read_with(&dir().join(file), &options)
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn every_real_program_reads_with_defaults() {
    assert!(dir().is_dir(), "{} is missing", dir().display());
    let cases = [
        (
            "elmoe_keychain.mpf",
            "trt_bc_spinner_u5.json",
            Some("sinumerik"),
        ),
        ("camotics_bear.nc", "xyz_mill.json", Some("linuxcnc")),
        ("camotics_flower_mold.nc", "xyz_mill.json", Some("linuxcnc")),
        ("nx_roeders_rfm600_finish.nc", "xyz_mill.json", None),
        ("aamorim_boss.apt", "xyz_mill.json", None),
        ("aamorim_basemach.apt", "xyz_mill.json", None),
    ];
    for (file, machine, dialect) in cases {
        let (input, detected) = read(file, machine).unwrap_or_else(|e| panic!("{e}"));
        let Input::Cl(tp) = input else {
            panic!("{file}: not a CL path")
        };
        eprintln!(
            "{file}: {} CL points, {:.3} s of dwells, {} warnings, {:?}",
            tp.points.len(),
            tp.dwell_time(),
            tp.warnings.len(),
            detected
        );
        assert!(tp.points.len() > 100);
        if let Some(d) = dialect {
            assert_eq!(detected.dialect.map(|d| d.name()), Some(d), "{file}");
        }
        if file.ends_with(".apt") {
            assert_eq!(detected.format, Format::Apt);
        }
    }
    // Round 21: the two NX five-axis programs call drilling and tapping cycles under tool-tip
    // control with the tool tilted off Z and no tilted working plane (the Mori's G73 at
    // B-37.576, its first; the DMU's MCALL CYCLE84 at B81.101). Each reader fed them along Z
    // and timed them without a word; now an error names the line, the angle and what to do.
    for (file, machine, says) in [
        (
            "nx_mori_nmv5000_mm.nc",
            "trt_bc_mori_nmv5000.json",
            ":548: G73: a drilling or tapping cycle under tool-tip control (G43.4) with the \
             tool axis 37.576° off Z (B-37.576 C315)",
        ),
        (
            "nx_dmu70evo_840d.mpf",
            "headtable_dmu70.json",
            ":903: MCALL CYCLE84: a drilling or tapping cycle under tool-tip control (TRAORI) \
             with the tool axis 81.101° off Z (B81.101 C1903.826)",
        ),
    ] {
        let e = match read(file, machine) {
            Ok(_) => panic!("{file}: read without an error"),
            Err(e) => e.to_string(),
        };
        assert!(
            e.contains(says) && e.contains("post these holes under a tilted working plane"),
            "{file}: {e}"
        );
    }
}

/// The three five-axis programs solve with default options, verified at 1 ms, their fitted
/// rotary angles within 2° of the programmed chords (`geometry::ANGLE_SWING_RAD`): the NX
/// Mori program's swung up to 80° off them (a B/C trunnion near its pole) until that bound.
/// The two NX programs are read up to their drilling operations (line 536 of the Mori's, 828
/// of the DMU's), whose cycles under a tilted tool no longer read (round 21, above).
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn the_five_axis_programs_keep_their_angles_near_the_programmed_ones() {
    use feedopt::optimize::{Options, optimize_input};
    use feedopt::toolpath::gcode::{Dialect, parse_for};
    for (file, machine, before) in [
        ("elmoe_keychain.mpf", "trt_bc_spinner_u5.json", None),
        (
            "nx_mori_nmv5000_mm.nc",
            "trt_bc_mori_nmv5000.json",
            Some((536, Dialect::Fanuc)),
        ),
        (
            "nx_dmu70evo_840d.mpf",
            "headtable_dmu70.json",
            Some((828, Dialect::Sinumerik)),
        ),
    ] {
        let m = Machine::from_file(&dir().join("machines").join(machine)).expect("machine");
        let input = match before {
            None => read(file, machine).unwrap_or_else(|e| panic!("{e}")).0,
            Some((lines, dialect)) => {
                let path = dir().join(file);
                let text = std::fs::read_to_string(&path).expect("program");
                let mut head: String = text.lines().take(lines).map(|l| format!("{l}\n")).collect();
                head.push_str("M30\n");
                let ctx = context(machine);
                let tp = parse_for(&path, &head, dialect.spec(), Some(&ctx))
                    .unwrap_or_else(|e| panic!("{e}"));
                Input::Cl(tp)
            }
        };
        let sol = optimize_input(&m, &input, &Options::default()).expect("solves");
        assert!(sol.verification.verified, "{file}");
        let worst = sol.path.deviation().1.to_degrees();
        eprintln!(
            "{file}: {:.4} s, angles within {worst:.4}°",
            sol.schedule.cycle_time
        );
        assert!(worst <= 2.0 + 1e-9, "{file}: the angles stray {worst}°");
    }
}

/// aamorim's boss (SolidWorks CAM APT) has four side operations: `CSYS/0,0,1.,…` with the
/// tool along +X (from line 5551 on, and at 11188, 12063 and 12362). A three-axis mill cannot
/// tilt its tool, so there the program is refused naming the first such point (it was read
/// with the tool along +Z before, quietly); a machine that tilts it (the shared Spinner U5,
/// a B/C trunnion) solves it, verified.
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn a_program_with_side_operations_needs_a_machine_that_tilts_the_tool() {
    use feedopt::optimize::{Options, optimize_input};
    let solve = |machine: &str| {
        let m = Machine::from_file(&dir().join("machines").join(machine)).expect("machine");
        let (input, _) = read("aamorim_boss.apt", machine).unwrap_or_else(|e| panic!("{e}"));
        optimize_input(&m, &input, &Options::default())
    };
    let e = solve("xyz_mill.json").unwrap_err().to_string();
    assert!(
        e.contains("line 5553") && e.contains("tool vector (1, 0, 0)"),
        "{e}"
    );
    let sol = solve("trt_bc_spinner_u5.json").expect("solves");
    eprintln!("boss on the Spinner U5: {:.4} s", sol.schedule.cycle_time);
    assert!(sol.verification.verified);
}
