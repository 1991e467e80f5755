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
        (
            "nx_mori_nmv5000_mm.nc",
            "trt_bc_mori_nmv5000.json",
            Some("fanuc"),
        ),
        ("camotics_bear.nc", "xyz_mill.json", Some("linuxcnc")),
        ("camotics_flower_mold.nc", "xyz_mill.json", Some("linuxcnc")),
        ("nx_roeders_rfm600_finish.nc", "xyz_mill.json", None),
        ("aamorim_boss.apt", "xyz_mill.json", None),
        ("aamorim_basemach.apt", "xyz_mill.json", None),
        (
            "nx_dmu70evo_840d.mpf",
            "headtable_dmu70.json",
            Some("sinumerik"),
        ),
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
    // The Mori program returns to the reference points: the shared machine file gives none,
    // so machine zero (the controls' default) is used, and said.
    let (_, detected) = read("nx_mori_nmv5000_mm.nc", "trt_bc_mori_nmv5000.json").unwrap();
    let note = detected.assumed.reference_note().unwrap_or_default();
    assert!(note.contains("axes.Z.reference"), "{note}");
    // The NX DMU 70 program calls CYCLE76 (Sinumerik's rectangular spigot milling) with
    // CYCLE86's list and no spigot dimensions: read by default as CYCLE86, said at line 1011.
    let (input, _) = read("nx_dmu70evo_840d.mpf", "headtable_dmu70.json").unwrap();
    let Input::Cl(tp) = input else {
        panic!("not a CL path")
    };
    assert!(
        tp.warnings
            .iter()
            .any(|w| w.line == 1011 && w.message.contains("CYCLE86"))
    );
}

/// The three five-axis programs solve with default options, verified at 1 ms, their fitted
/// rotary angles within 2° of the programmed chords (`geometry::ANGLE_SWING_RAD`): the NX
/// Mori program's swung up to 80° off them (a B/C trunnion near its pole) until that bound,
/// and its cycle time with them (`feedopt solve`, dwells included: 1064.95 s; 1061.50 s
/// held).
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn the_five_axis_programs_keep_their_angles_near_the_programmed_ones() {
    use feedopt::optimize::{Options, optimize_input};
    for (file, machine) in [
        ("elmoe_keychain.mpf", "trt_bc_spinner_u5.json"),
        ("nx_mori_nmv5000_mm.nc", "trt_bc_mori_nmv5000.json"),
        ("nx_dmu70evo_840d.mpf", "headtable_dmu70.json"),
    ] {
        let m = Machine::from_file(&dir().join("machines").join(machine)).expect("machine");
        let (input, _) = read(file, machine).unwrap_or_else(|e| panic!("{e}"));
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
