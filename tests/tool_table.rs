//! Several tools in one program and the tool table (issue 13 item 1): each move is cut with
//! the tool the program has in the spindle there, against closed forms (A = D_i·a_p in each
//! tool's slot, the chip-load cap f_z·z_i·n/60 with each tool's flutes); the table's errors
//! name the program line and the tool; a single tool's results do not change.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use feedopt::material::program::ProgramProcess;
use feedopt::material::tooltable::{self, ToolTable};
use feedopt::material::{
    self, CutOptions, FeedLimits, Material, MaterialSpec, Overrides, ProcessLimit, Sample, Tool,
    ToolSpec, ToolUse,
};
use feedopt::toolpath::{ToolChange, ToolSelect, Toolpath};
use nalgebra::Vector3;

mod common;
use common::{UP, toolpath};

const MACHINE: &str = r#"{"stock": {"box": {"min": [0, 0, -20], "max": [100, 40, 0]}},
    "process": {"chip_load": 0.05, "spindle_speed": 10000}}"#;

/// Two slots: at y = 10 down to 3 mm, then at y = 30 down to 2 mm (CL points 0–4 and 5–9;
/// the horizontal cuts end at points 3 and 8).
fn two_slots() -> Toolpath {
    let mut pts = Vec::new();
    for (y, ap) in [(10.0, 3.0), (30.0, 2.0)] {
        for p in [
            [20.0, y, 10.0],
            [20.0, y, 1.0],
            [20.0, y, -ap],
            [80.0, y, -ap],
            [80.0, y, 10.0],
        ] {
            pts.push((Vector3::new(p[0], p[1], p[2]), UP));
        }
    }
    let mut tp = toolpath(&pts, Some(20.0));
    tp.source = PathBuf::from("prog.ngc");
    tp
}

fn table() -> ToolTable {
    let v: serde_json::Value = serde_json::from_str(
        r#"{"1": {"diameter": 10, "flutes": 3, "flute_length": 30},
            "2": {"diameter": 6, "flutes": 2, "flute_length": 20}}"#,
    )
    .unwrap();
    tooltable::from_json(Path::new("tools.json"), "", &v).unwrap()
}

/// The program: T1 at line 1 (before any move), T2 at line 6 (from CL point 5 on).
fn program(tp: &Toolpath, second: u32) -> ProgramProcess {
    let mut tp = tp.clone();
    tp.tool_changes = vec![
        ToolChange {
            point: 0,
            line: 1,
            tool: ToolSelect::Number(1),
        },
        ToolChange {
            point: 5,
            line: 6,
            tool: ToolSelect::Number(second),
        },
    ];
    ProgramProcess::from_toolpath(&tp)
}

fn overrides(table: Option<ToolTable>) -> Overrides {
    Overrides {
        tool_table: table,
        options: CutOptions {
            cell: Some(0.1),
            step: None,
        },
        ..Overrides::default()
    }
}

fn resolve(p: &ProgramProcess, o: &Overrides) -> feedopt::error::Result<Option<Material>> {
    let f = Path::new("m.json");
    Material::resolve(f, MaterialSpec::from_json(f, MACHINE).unwrap(), p, o)
}

/// The samples of the horizontal cut ending at `point`, at least one diameter (10 mm) from
/// both ends of its 60 mm.
fn steady(samples: &[Sample], point: usize) -> Vec<&Sample> {
    samples
        .iter()
        .filter(|s| s.point == point && s.t[0] * 60.0 >= 10.0 && s.t[1] * 60.0 <= 50.0)
        .collect()
}

#[test]
fn two_tools_cut_two_slots_each_with_its_own_diameter_and_flutes() {
    let tp = two_slots();
    let m = resolve(&program(&tp, 2), &overrides(Some(table())))
        .unwrap()
        .unwrap();
    assert_eq!(m.tools.len(), 2);
    assert_eq!((m.tools[0].first_move, m.tools[0].line), (0, 1));
    assert_eq!((m.tools[1].first_move, m.tools[1].line), (5, 6));
    let sim = material::simulate(&tp, &m).unwrap();
    // Each slot's volume: its length times D·a_p plus the two half-disc ends.
    let exact = (10.0 * 60.0 + PI * 25.0) * 3.0 + (6.0 * 60.0 + PI * 9.0) * 2.0;
    let err = (sim.removed_volume - exact).abs() / exact;
    assert!(err < 0.005, "removed {} vs {exact}", sim.removed_volume);
    for (point, d, ap) in [(3, 10.0, 3.0), (8, 6.0, 2.0)] {
        let st = steady(&sim.samples, point);
        assert!(st.len() >= 10);
        for s in st {
            assert!(
                (s.area - d * ap).abs() < 0.03 * d * ap,
                "move {point}: A {} vs D·a_p = {}",
                s.area,
                d * ap
            );
        }
    }
    // The chip load with each tool's flutes (a full slot: no thinning): f_z·z·n/60.
    let limits = FeedLimits::new(&sim, &m, tp.points.len());
    for (point, z) in [(3, 3.0), (8, 2.0)] {
        let want = 0.05 * z * 10000.0 / 60.0;
        let caps: Vec<f64> = limits.moves[point]
            .iter()
            .filter_map(|p| p.cap)
            .filter(|c| c.1 == ProcessLimit::ChipLoad)
            .map(|c| c.0)
            .collect();
        let low = caps.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(
            (low - want).abs() < 1e-9 * want,
            "move {point}: {low} vs {want}"
        );
    }
    // The overload check too: 20 mm/s is under the first tool's 25 mm/s and over the second's
    // 16.7 mm/s.
    let findings = material::check::overloads(&sim, &m, 1.0);
    let chip: Vec<usize> = findings
        .iter()
        .filter(|f| f.limit == Some(ProcessLimit::ChipLoad))
        .map(|f| f.point)
        .collect();
    assert!(!chip.is_empty() && chip.iter().all(|&p| p > 5), "{chip:?}");
    // The report names both tools with their lines.
    let report = material::MaterialReport::new(&m, &sim, &program(&tp, 2), Vec::new());
    assert_eq!(report.tools.len(), 2);
    assert_eq!(report.tools[1].select.as_deref(), Some("T2"));
    assert_eq!(report.tools[1].line, 6);
    assert!((report.tools[1].tool.diameter - 6.0).abs() < 1e-12);
    let text = report.to_string();
    assert!(
        text.contains("tool 2/2") && text.contains("T2 at line 6"),
        "{text}"
    );
}

#[test]
fn a_tool_missing_from_the_table_names_the_program_line_and_the_tool() {
    let tp = two_slots();
    let e = resolve(&program(&tp, 7), &overrides(Some(table())))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("prog.ngc:6:") && e.contains("tools.json has no tool 7"),
        "{e}"
    );
    // No table and two tool numbers: say where to give one.
    let e = resolve(&program(&tp, 2), &overrides(None))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("prog.ngc:6:") && e.contains("T1 at line 1") && e.contains("--tool-table"),
        "{e}"
    );
    // No table and one tool number all through (`T1 M6` … `T1 M6`): the machine file's or the
    // options' tool, as before tool tables.
    let mut o = overrides(None);
    o.tool = ToolSpec {
        diameter: Some(8.0),
        flutes: Some(2),
        ..ToolSpec::default()
    };
    let m = resolve(&program(&tp, 1), &o).unwrap().unwrap();
    assert_eq!(m.tools.len(), 1);
    assert_eq!(
        (m.tools[0].tool.diameter, m.tools[0].select.clone()),
        (8.0, None)
    );
}

#[test]
fn options_override_every_tool_and_the_machine_file_fills_what_a_tbl_lacks() {
    let tp = two_slots();
    // A LinuxCNC table gives D only; the machine file's tool gives the flutes.
    let tbl = tooltable::parse_tbl(Path::new("t.tbl"), "T1 P1 D10\nT2 P2 D6 ;six\n").unwrap();
    let f = Path::new("m.json");
    let with_tool = MACHINE.replace(r#""process""#, r#""tool": {"flutes": 4}, "process""#);
    let spec = MaterialSpec::from_json(f, &with_tool).unwrap();
    let m = Material::resolve(
        f,
        spec.clone(),
        &program(&tp, 2),
        &overrides(Some(tbl.clone())),
    )
    .unwrap()
    .unwrap();
    let got: Vec<(f64, u32)> = m
        .tools
        .iter()
        .map(|t| (t.tool.diameter, t.tool.flutes))
        .collect();
    assert_eq!(got, vec![(10.0, 4), (6.0, 4)]);
    // The options win over the table for every tool.
    let mut o = overrides(Some(tbl));
    o.tool = ToolSpec {
        flutes: Some(5),
        ..ToolSpec::default()
    };
    let m = Material::resolve(f, spec, &program(&tp, 2), &o)
        .unwrap()
        .unwrap();
    assert!(m.tools.iter().all(|t| t.tool.flutes == 5));
}

/// A change to an identical tool (another selection, the same geometry) restarts the shared
/// poses of a tilted cut; the samples stay bit for bit those of one tool.
#[test]
fn one_tool_is_cut_bit_for_bit_the_same_across_a_change() {
    let o = Vector3::new(0.3, 0.1, 1.0);
    let pts: Vec<(Vector3<f64>, Vector3<f64>)> = [
        [10.0, 20.0, 5.0],
        [10.0, 20.0, -2.0],
        [50.0, 22.0, -2.0],
        [90.0, 20.0, -1.0],
    ]
    .iter()
    .map(|p| (Vector3::new(p[0], p[1], p[2]), o))
    .collect();
    let tp = toolpath(&pts, Some(20.0));
    let stock = MaterialSpec::from_json(Path::new("m.json"), MACHINE)
        .unwrap()
        .unwrap()
        .stock
        .unwrap();
    let tool = Tool::new(6.0, 3.0, 20.0, 2).unwrap();
    let opts = CutOptions {
        cell: Some(0.2),
        step: None,
    };
    let one = Material::single(stock, tool, Default::default(), opts);
    let mut two = one.clone();
    two.tools.push(ToolUse {
        first_move: 3,
        line: 3,
        select: Some(ToolSelect::Number(2)),
        tool,
    });
    let a = material::simulate(&tp, &one).unwrap();
    let b = material::simulate(&tp, &two).unwrap();
    assert!(a.samples.len() > 20);
    assert_eq!(a.samples, b.samples);
    assert_eq!(a.final_volume.to_bits(), b.final_volume.to_bits());
}

/// End to end: a LinuxCNC program with `T1 M6` and `T2 M6`, the machine file's `tools` naming
/// a `.tbl` beside it, and `--tool-table` instead; the report lists both tools.
#[test]
fn feedopt_check_reads_the_tool_table_of_the_machine_file_or_the_option() {
    use std::process::Command;
    let dir = std::env::temp_dir().join(format!("feedopt-tool-table-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let machine = r#"{"name": "xyz", "kinematics": {"type": "xyz"},
        "axes": {"X": {"velocity": 500, "acceleration": 3000},
                 "Y": {"velocity": 500, "acceleration": 3000},
                 "Z": {"velocity": 250, "acceleration": 1500}},
        "feed": {"max": 250},
        "stock": {"box": {"min": [0, 0, -10], "max": [100, 40, 0]}},
        "tool": {"flutes": 3},
        "tools": "mill.tbl",
        "process": {"chip_load": 0.05, "spindle_speed": 10000}}"#;
    std::fs::write(dir.join("m.json"), machine).unwrap();
    std::fs::write(
        dir.join("mill.tbl"),
        "T1 P1 D10 Z0 ;10 mm\nT2 P2 D6 Z0 ;6 mm\n",
    )
    .unwrap();
    std::fs::write(dir.join("other.tbl"), "T1 P1 D8\n").unwrap();
    let program = "G21 G90 G94\nT1 M6\nG0 X20 Y10 Z5\nG1 Z-3 F1200\nG1 X80\nG0 Z5\n\
                   T2 M6\nG0 X20 Y30\nG1 Z-2 F1200\nG1 X80\nG0 Z5\nM2\n";
    std::fs::write(dir.join("p.ngc"), program).unwrap();
    let run = |extra: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_feedopt"))
            .args(["check", "--json", "--machine"])
            .arg(dir.join("m.json"))
            .arg(dir.join("p.ngc"))
            .args(extra)
            .output()
            .unwrap();
        (
            String::from_utf8_lossy(&out.stdout).to_string(),
            String::from_utf8_lossy(&out.stderr).to_string(),
        )
    };
    let (out, err) = run(&[]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {err}"));
    let tools = v["tools"].as_array().unwrap();
    let got: Vec<(String, u64, f64, u64)> = tools
        .iter()
        .map(|t| {
            (
                t["select"].as_str().unwrap().to_string(),
                t["line"].as_u64().unwrap(),
                t["tool"]["diameter"].as_f64().unwrap(),
                t["tool"]["flutes"].as_u64().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        got,
        vec![("T1".into(), 2, 10.0, 3), ("T2".into(), 7, 6.0, 3)]
    );
    // --tool-table wins over the machine file's; a tool it lacks is one line naming both files.
    let (out, err) = run(&["--tool-table", dir.join("other.tbl").to_str().unwrap()]);
    assert!(out.is_empty());
    assert!(
        err.contains("p.ngc:7:")
            && err.contains("other.tbl has no tool 2")
            && err.lines().count() == 1,
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Each move's chip load uses the spindle speed the program has set there (its `S` words as
/// the reader recorded them): the first slot at 6,000 rpm, the second at 12,000 — caps
/// f_z·z·n/60 of each; before the program's first speed the machine file's 10,000 applies; an
/// option `--spindle-speed` applies to every move.
#[test]
fn each_move_has_the_spindle_speed_the_program_set_there() {
    use feedopt::toolpath::SpindleChange;
    let tp = two_slots();
    let mut p = program(&tp, 2);
    p.spindle_changes = vec![
        SpindleChange {
            point: 1,
            line: 2,
            rpm: 6000.0,
        },
        SpindleChange {
            point: 5,
            line: 6,
            rpm: 12000.0,
        },
    ];
    let m = resolve(&p, &overrides(Some(table()))).unwrap().unwrap();
    let at: Vec<Option<f64>> = (0..10).map(|k| m.spindle_at(k)).collect();
    assert_eq!(
        at[0],
        Some(10000.0),
        "the machine file's before the first S"
    );
    assert!(at[1..5].iter().all(|n| *n == Some(6000.0)), "{at:?}");
    assert!(at[5..].iter().all(|n| *n == Some(12000.0)), "{at:?}");
    let sim = material::simulate(&tp, &m).unwrap();
    let limits = FeedLimits::new(&sim, &m, tp.points.len());
    let chip_cap = |point: usize| -> f64 {
        limits.moves[point]
            .iter()
            .filter_map(|p| p.cap)
            .filter(|c| c.1 == ProcessLimit::ChipLoad)
            .map(|c| c.0)
            .fold(f64::INFINITY, f64::min)
    };
    for (point, z, n) in [(3, 3.0, 6000.0), (8, 2.0, 12000.0)] {
        let want = 0.05 * z * n / 60.0;
        let got = chip_cap(point);
        assert!(
            (got - want).abs() < 1e-9 * want,
            "move {point}: {got} vs {want}"
        );
    }
    let report = material::MaterialReport::new(&m, &sim, &p, Vec::new());
    assert_eq!(report.program_spindle_speeds, 2);
    assert!(report.to_string().contains("6000–12000 rpm"), "{report}");
    // The option wins everywhere.
    let o = Overrides {
        spindle_speed: Some(9000.0),
        ..overrides(Some(table()))
    };
    let m = resolve(&p, &o).unwrap().unwrap();
    assert!((0..10).all(|k| m.spindle_at(k) == Some(9000.0)));
}
