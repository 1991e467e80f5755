//! Tool changes as the readers record them (issue 13 item 1): APT `CUTTER/` and NX
//! `TLDATA/MILL`, G-code `T… M6` (LinuxCNC, Fanuc, Sinumerik, also inside subprograms),
//! LinuxCNC `M61 Q`, Sinumerik `T="name"`, Klartext `TOOL CALL`; each with the CL point the
//! new tool cuts from and the line that selects it.

use feedopt::toolpath::gcode::{Dialect, parse};
use feedopt::toolpath::{ToolChange, ToolSelect, Toolpath, apt};
use std::path::Path;

fn changes(tp: &Toolpath) -> Vec<(usize, usize, ToolSelect)> {
    tp.tool_changes
        .iter()
        .map(|ToolChange { point, line, tool }| (*point, *line, tool.clone()))
        .collect()
}

fn gcode(dialect: Dialect, text: &str) -> Toolpath {
    parse(Path::new("t.nc"), text, dialect).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn cutter(diameter: f64, corner_radius: f64) -> ToolSelect {
    ToolSelect::Cutter {
        diameter,
        corner_radius,
    }
}

#[test]
fn apt_cutters_in_order_with_their_first_point() {
    let t = "CUTTER/10,2\nGOTO/0,0,5\nGOTO/0,0,0\nCUTTER/6.0,3.0\nGOTO/1,0,0\n\
             TLDATA/MILL,4.0000,0.5000,50.0000,2.0000,0.0000\nGOTO/2,0,0\n\
             TLDATA/TURN,0.4\n";
    let tp = apt::parse(Path::new("a.cls"), t).unwrap();
    assert_eq!(
        changes(&tp),
        vec![
            (0, 1, cutter(10.0, 2.0)),
            (2, 4, cutter(6.0, 3.0)),
            (3, 6, cutter(4.0, 0.5)),
        ]
    );
    // Inch programs: the cutter in mm.
    let inch = "UNITS/INCH\nCUTTER/0.5\nGOTO/0,0,0\n";
    let tp = apt::parse(Path::new("a.cls"), inch).unwrap();
    assert_eq!(changes(&tp), vec![(0, 2, cutter(12.7, 0.0))]);
    let e = apt::parse(Path::new("a.cls"), "GOTO/0,0,0\nCUTTER/\n")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("a.cls:2:") && e.contains("without a diameter"),
        "{e}"
    );
}

#[test]
fn linuxcnc_t_m6_and_m61() {
    // T prepares, M6 changes (also `M6 T3` in one block), M61 Q sets without a change.
    let t = "G21 G90\nT1 M6\nG0 X0 Y0 Z5\nG1 Z0 F100\nT2\nG1 X10\nM6\nG1 X20\nM6 T3\nG1 X30\n\
             M61 Q4\nG1 X40\nM2\n";
    let tp = gcode(Dialect::LinuxCnc, t);
    assert_eq!(
        changes(&tp),
        vec![
            (0, 2, ToolSelect::Number(1)),
            (3, 7, ToolSelect::Number(2)),
            (4, 9, ToolSelect::Number(3)),
            (5, 11, ToolSelect::Number(4)),
        ]
    );
    // M6 without any T before it: a warning, never a silent change.
    let tp = gcode(Dialect::LinuxCnc, "G21\nM6\nG0 X1 Y0 Z0\n");
    assert!(tp.tool_changes.is_empty());
    assert!(
        tp.warnings
            .iter()
            .any(|w| w.line == 2 && w.message.contains("without a T"))
    );
    let e = parse(
        Path::new("t.ngc"),
        "G21\nT1.5 M6\nG0 X1\n",
        Dialect::LinuxCnc,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("t.ngc:2:") && e.contains("whole number"),
        "{e}"
    );
}

#[test]
fn a_tool_change_inside_a_subroutine_counts_where_it_runs() {
    // The subroutine is written before the calls: the changes follow the execution, not the
    // text.
    let t = "o100 sub\nG1 X10 F100\nG0 X0\no100 endsub\nG21 G90 G0 X0 Y0 Z0\nT1 M6\n\
             o100 call\nT2 M6\no100 call\nM2\n";
    let tp = gcode(Dialect::LinuxCnc, t);
    assert_eq!(
        changes(&tp),
        vec![(1, 6, ToolSelect::Number(1)), (3, 8, ToolSelect::Number(2))]
    );
}

#[test]
fn fanuc_and_sinumerik() {
    let t = "O1\nG21 G90 G0 X0 Y0 Z5\nT05 M06\nG1 Z0 F100\nT6 M6\nG1 X5\nM30\n";
    let tp = gcode(Dialect::Fanuc, t);
    assert_eq!(
        changes(&tp),
        vec![(1, 3, ToolSelect::Number(5)), (2, 5, ToolSelect::Number(6))]
    );
    let t = "G71 G90\nT=\"Mill_D10\"\nM6\nG0 X0 Y0 Z5\nT7 M6\nG1 Z0 F100\nM30\n";
    let tp = gcode(Dialect::Sinumerik, t);
    assert_eq!(
        changes(&tp),
        vec![
            (0, 3, ToolSelect::Name("MILL_D10".into())),
            (1, 5, ToolSelect::Number(7)),
        ]
    );
}

#[test]
fn klartext_tool_call() {
    let t = "0 BEGIN PGM T MM\n1 TOOL CALL 5 Z S3000\n2 L X+0 Y+0 Z+5 FMAX\n\
             3 TOOL CALL \"MILL_D6\" Z S5000\n4 L Z+0 F100\n5 TOOL CALL Z S4000\n\
             6 L X+5\n7 END PGM T MM\n";
    let tp = parse(Path::new("t.h"), t, Dialect::Heidenhain).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        changes(&tp),
        vec![
            (0, 2, ToolSelect::Number(5)),
            (1, 4, ToolSelect::Name("MILL_D6".into())),
        ]
    );
}

/// The spindle speeds each reader records, in the order the program runs, with the CL point
/// from which each runs: G-code `S` (not `G4 S`, a dwell in revolutions on Sinumerik; the same
/// speed again is no change; a subprogram's where it is called), Klartext `TOOL CALL … S`,
/// APT `SPINDL/`.
#[test]
fn spindle_speeds_in_program_order() {
    let speeds = |tp: &Toolpath| -> Vec<(usize, usize, f64)> {
        tp.spindle_changes
            .iter()
            .map(|c| (c.point, c.line, c.rpm))
            .collect()
    };
    // LinuxCNC: a speed in a subroutine counts where it is called, after the move before it.
    let t = "G21 G90\nM3 S8000\nG0 X0 Y0 Z5\nG1 Z0 F100\no100 sub\nS12000\no100 endsub\n\
             G1 X10\no100 call\nG1 X20 S12000\nG1 X30 S9000\nM2\n";
    let tp = gcode(Dialect::LinuxCnc, t);
    assert_eq!(
        speeds(&tp),
        vec![(0, 2, 8000.0), (3, 6, 12000.0), (4, 11, 9000.0)]
    );
    // Fanuc: `M03 S…` and a speed on a move's own block (it runs that move).
    let t = "%\nO1000\nG21 G90\nT1 M6\nS6000 M3\nG0 X0 Y0 Z5\nG1 Z0 F100\nG1 X10 S7000\nM30\n%\n";
    let tp = gcode(Dialect::Fanuc, t);
    assert_eq!(speeds(&tp), vec![(0, 5, 6000.0), (2, 8, 7000.0)]);
    // Klartext: the TOOL CALL's S, also without a tool (a speed change only).
    let t = "0 BEGIN PGM T MM\n1 TOOL CALL 5 Z S3000\n2 L X+0 Y+0 Z+5 FMAX\n\
             3 TOOL CALL Z S4500\n4 L Z+0 F100\n5 END PGM T MM\n";
    let tp = parse(Path::new("t.h"), t, Dialect::Heidenhain).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(speeds(&tp), vec![(0, 2, 3000.0), (1, 4, 4500.0)]);
    // APT: `SPINDL/RPM,n,CLW`; `SPINDL/OFF` changes nothing.
    let t =
        "SPINDL/RPM,8000,CLW\nGOTO/0,0,5\nGOTO/0,0,0\nSPINDL/OFF\nSPINDL/RPM,6000\nGOTO/1,0,0\n";
    let tp = apt::parse(Path::new("a.cls"), t).unwrap();
    assert_eq!(speeds(&tp), vec![(0, 1, 8000.0), (2, 5, 6000.0)]);
    // Sinumerik `G4 S2` dwells two revolutions: not a speed (feedopt refuses it, as before).
    let e = parse(
        Path::new("t.mpf"),
        "G71 G90\nS5000 M3\nG1 X1 F100\nG4 S2\nM30\n",
        Dialect::Sinumerik,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("t.mpf:4:") && e.contains("G4 S"), "{e}");
}

/// The spindle and coolant switches each reader records (for `feedopt gcode`, which writes
/// them back): a start before its block's move, a stop after it (`G0 Z50 M5` retracts, then
/// stops the spindle), with the line that makes it.
#[test]
fn spindle_and_coolant_switches_in_program_order() {
    use feedopt::toolpath::Switch::*;
    let switches = |tp: &Toolpath| -> Vec<(usize, usize, feedopt::toolpath::Switch)> {
        tp.switches
            .iter()
            .map(|c| (c.point, c.line, c.switch))
            .collect()
    };
    let t = "G21 G90\nT1 M6\nG0 X0 Y0 Z5 S8000 M3\nM8\nG1 Z0 F100\nG1 X10\nG0 Z5 M5 M9\n\
             S6000 M4 M7\nG1 X20 F100\nM5\nM9\nM2\n";
    for dialect in [Dialect::LinuxCnc, Dialect::Fanuc, Dialect::Sinumerik] {
        let text = match dialect {
            Dialect::Fanuc => format!("%\nO1000\n{t}%\n"),
            Dialect::Sinumerik => t.replace("G21", "G71"),
            _ => t.to_string(),
        };
        let line = |n: usize| if dialect == Dialect::Fanuc { n + 2 } else { n };
        let tp = gcode(dialect, &text);
        assert_eq!(
            switches(&tp),
            vec![
                (0, line(3), SpindleClockwise),
                (1, line(4), CoolantFlood),
                (4, line(7), SpindleStop),
                (4, line(7), CoolantOff),
                (4, line(8), SpindleCounterClockwise),
                (4, line(8), CoolantMist),
                (5, line(10), SpindleStop),
                (5, line(11), CoolantOff),
            ],
            "{dialect}"
        );
    }
    // Klartext (lines count from `0 BEGIN PGM`, the file's first): M13 is the spindle
    // clockwise and the coolant, M14 counter-clockwise and it.
    let t = "0 BEGIN PGM T MM\n1 TOOL CALL 5 Z S3000\n2 L X+0 Y+0 Z+5 FMAX M13\n\
             3 L Z+0 F100\n4 L Z+5 FMAX M5 M9\n5 L X+5 M14\n6 END PGM T MM\n";
    let tp = parse(Path::new("t.h"), t, Dialect::Heidenhain).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        switches(&tp),
        vec![
            (0, 3, SpindleClockwise),
            (0, 3, CoolantFlood),
            (3, 5, SpindleStop),
            (3, 5, CoolantOff),
            (3, 6, SpindleCounterClockwise),
            (3, 6, CoolantFlood),
        ]
    );
    // APT: `SPINDL/…,CLW|CCLW`, `SPINDL/OFF`, `COOLNT/ON|FLOOD|MIST|OFF`.
    let t = "SPINDL/RPM,8000,CLW\nCOOLNT/MIST\nGOTO/0,0,5\nGOTO/0,0,0\nCOOLNT/OFF\n\
             SPINDL/OFF\nSPINDL/RPM,6000,CCLW\nCOOLNT/FLOOD\nGOTO/1,0,0\n";
    let tp = apt::parse(Path::new("a.cls"), t).unwrap();
    assert_eq!(
        switches(&tp),
        vec![
            (0, 1, SpindleClockwise),
            (0, 2, CoolantMist),
            (2, 5, CoolantOff),
            (2, 6, SpindleStop),
            (2, 7, SpindleCounterClockwise),
            (2, 8, CoolantFlood),
        ]
    );
}
