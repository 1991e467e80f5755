//! The real CAM programs of `../shared/realworld/cam` (issue 12) read with default options:
//! format and dialect detected, each with the machine its README names. Third-party data
//! outside the crate: reported as ignored where `../shared` is absent (`build.rs`).

use feedopt::machine::{Machine, references_from_json};
use feedopt::toolpath::{self, Format, Input, MachineContext, ReadOptions};
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/realworld/cam")
}

/// The machine file, with `reference` positions added when `references` (the shared files
/// give none, and the Mori program returns to them with G28/G30).
fn context(machine: &str, references: bool) -> MachineContext {
    let path = dir().join("machines").join(machine);
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).expect("machine file")).unwrap();
    if references {
        for axis in json["axes"].as_object_mut().unwrap().values_mut() {
            axis["reference"] = serde_json::json!([0.0, 0.0]);
        }
    }
    let text = json.to_string();
    let m = Machine::from_json(&path, &text).unwrap();
    MachineContext::new(&m, &references_from_json(&path, &text, &m).unwrap())
}

fn read(
    file: &str,
    machine: &str,
    references: bool,
) -> feedopt::error::Result<(Input, toolpath::Detected)> {
    let options = ReadOptions {
        machine: Some(context(machine, references)),
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
    ];
    for (file, machine, dialect) in cases {
        let (input, detected) = read(file, machine, true).unwrap_or_else(|e| panic!("{e}"));
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
    // The Mori program returns to the reference points: without them in the machine file,
    // an error names the field to add.
    let e = read("nx_mori_nmv5000_mm.nc", "trt_bc_mori_nmv5000.json", false).unwrap_err();
    assert!(e.to_string().contains("axes.Z"), "{e}");
    // The NX DMU 70 program calls CYCLE76, Sinumerik's rectangular spigot milling cycle, with a
    // drilling cycle's arguments: an error naming it, not a guess.
    let e = read("nx_dmu70evo_840d.mpf", "headtable_dmu70.json", false).unwrap_err();
    assert!(e.to_string().contains("CYCLE76"), "{e}");
}
