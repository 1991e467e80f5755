//! Four-axis machines (`xyza`, `xyzb`, `xyzc`): programs in machine coordinates, X Y Z and the
//! angle the axes' own positions, each block a straight move of all four.

mod common;

use std::path::Path;

use feedopt::machine::{Machine, references_from_json};
use feedopt::optimize::{Options, Solution, optimize};
use feedopt::toolpath::gcode::{Dialect, parse_for};
use feedopt::toolpath::{MachineContext, Toolpath};

/// A VMC with a rotary table on `letter` ([`common::four_axis_json`]).
fn machine_json(letter: char) -> String {
    common::four_axis_json(letter)
}

fn setup(letter: char) -> (Machine, MachineContext) {
    let text = machine_json(letter);
    let m = Machine::from_json(Path::new("m.json"), &text).unwrap();
    let refs = references_from_json(Path::new("m.json"), &text, &m).unwrap();
    let ctx = MachineContext::new(&m, &refs);
    (m, ctx)
}

fn read(ctx: &MachineContext, dialect: Dialect, program: &str) -> feedopt::error::Result<Toolpath> {
    parse_for(Path::new("p.nc"), program, dialect.spec(), Some(ctx))
}

fn solve(m: &Machine, tp: &Toolpath) -> Solution {
    let s = optimize(m, tp, &Options::default()).unwrap();
    assert!(s.verification.verified, "{:?}", s.verification);
    s
}

/// A rapid turn of the table alone, rest to rest: the axis's trapezoidal profile in closed
/// form, v/a + d/v = 0.2 + 0.9 s for 90° at 100 °/s and 500 °/s²; on every letter.
#[test]
fn a_table_turn_alone_takes_the_axis_own_closed_form_time() {
    for (letter, k) in [('A', 3), ('B', 3), ('C', 3)] {
        let (m, ctx) = setup(letter);
        let tp = read(
            &ctx,
            Dialect::LinuxCnc,
            &format!("G21 G90 G94\nG0 X0 Y0 Z0 {letter}0\nG0 {letter}90\nM2\n"),
        )
        .unwrap();
        let s = solve(&m, &tp);
        let want = 100.0 / 500.0 + 90.0 / 100.0;
        assert!(
            (s.schedule.cycle_time - want).abs() < 1e-6 * want,
            "{letter}: {} s, want {want} s",
            s.schedule.cycle_time
        );
        let last = s.schedule.stations.len() - 1;
        assert!((s.schedule.q(last)[k] - 90.0).abs() < 1e-9);
        assert!(
            tp.warnings.iter().all(|w| !w.message.contains("tool tip")),
            "{:?}",
            tp.warnings
        );
    }
}

/// X and A in one block move together, linearly in each other (the control interpolates the
/// axes, not a tool tip on the turning part), while Y and Z stay where the program left them;
/// F (LinuxCNC: along X Y Z) holds the block to at least 50 mm / 10 mm/s.
#[test]
fn a_block_moves_the_axes_straight_and_leaves_the_others() {
    let (m, ctx) = setup('A');
    let tp = read(
        &ctx,
        Dialect::LinuxCnc,
        "G21 G90 G94\nG0 X0 Y5 Z10 A0\nG1 X50 A180 F600\nM2\n",
    )
    .unwrap();
    let s = solve(&m, &tp);
    assert!(s.schedule.cycle_time > 5.0, "{}", s.schedule.cycle_time);
    let mut moved = 0;
    for i in 0..s.schedule.stations.len() {
        let q = s.schedule.q(i);
        assert!(
            (q[1] - 5.0).abs() < 1e-6 && (q[2] - 10.0).abs() < 1e-6,
            "station {i}: {q:?}"
        );
        if q[0] > 1e-9 {
            moved += 1;
            assert!(
                (q[3] / 180.0 - q[0] / 50.0).abs() < 1e-6,
                "station {i}: {q:?}"
            );
        }
    }
    assert!(moved > 10);
}

/// Tool-tip mode, a tool vector or a stock on a turning part cannot be read in machine
/// coordinates: each is an error naming where.
#[test]
fn tool_tip_mode_tool_vectors_and_a_turning_stock_are_refused() {
    let (m, ctx) = setup('A');
    let e = read(
        &ctx,
        Dialect::Fanuc,
        "G21 G90 G94\nG0 X0. Y0. Z0. A0.\nG43.4 H1\nG1 X10. A20. F600.\nM30\n",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("p.nc:3") && e.contains("tool-tip mode"), "{e}");
    let e = read(
        &ctx,
        Dialect::LinuxCnc,
        "G21 G90 G94\nG0 X0 Y0 Z0 A0\nM428\nG1 X10 A20 F600\nM2\n",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("p.nc:3") && e.contains("tool-tip mode"), "{e}");
    // An APT program's tool vectors: the tool of a four-axis machine stays along +Z.
    let apt = feedopt::toolpath::apt::parse(
        Path::new("p.cls"),
        "MULTAX/ON\nFEDRAT/MMPM,600\nGOTO/0,0,10,0,0,1\nGOTO/10,0,10,0,0.6,0.8\nFINI\n",
    )
    .unwrap();
    let e = optimize(&m, &apt, &Options::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 4") && e.contains("tool vector"), "{e}");
    // The material model: a program that turns A turns the part.
    let tp = read(
        &ctx,
        Dialect::LinuxCnc,
        "G21 G90 G94\nG0 X0 Y0 Z0 A0\nG1 X10 A20 F600\nM2\n",
    )
    .unwrap();
    let e = feedopt::material::tool_axes(&tp, &m)
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 3") && e.contains("A axis"), "{e}");
    // One that never turns it is in the part's coordinates: read as it is.
    let tp = read(
        &ctx,
        Dialect::LinuxCnc,
        "G21 G90 G94\nG0 X0 Y0 Z0\nG1 X10 F600\nM2\n",
    )
    .unwrap();
    assert!(feedopt::material::tool_axes(&tp, &m).is_ok());
}

/// The machine file: `xyza`, `xyzb`, `xyzc` take X Y Z and that axis, no other.
#[test]
fn four_axis_machine_files_name_their_axes() {
    for letter in ['A', 'B', 'C'] {
        let m = Machine::from_json(Path::new("m.json"), &machine_json(letter)).unwrap();
        let names: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
        assert_eq!(names, vec!["X", "Y", "Z", &letter.to_string()[..]]);
    }
    let wrong = machine_json('A').replace(r#""type": "xyza""#, r#""type": "xyzb""#);
    let e = Machine::from_json(Path::new("m.json"), &wrong)
        .unwrap_err()
        .to_string();
    assert!(e.contains("axes"), "{e}");
}

/// `feedopt gcode` writes a four-axis program back in machine coordinates: the optimised feed
/// per block, without a tool-tip mode switch, and it reads back on the same machine.
#[test]
fn the_written_program_stays_in_machine_coordinates() {
    use feedopt::writers::gcode::{BlockFeed, GcodeOptions, program};
    let (m, ctx) = setup('A');
    let tp = read(
        &ctx,
        Dialect::LinuxCnc,
        "G21 G90 G94\nG0 X0 Y0 Z10 A0\nG1 X50 A180 F600\nG1 X0 A0\nM2\n",
    )
    .unwrap();
    let options = Options::default();
    let s = solve(&m, &tp);
    let written = program(
        &m,
        &tp,
        &s,
        &options.geometry,
        &GcodeOptions {
            dialect: Dialect::LinuxCnc,
            max_rotation_deg: None,
            block_feed: BlockFeed::Average,
        },
    )
    .unwrap();
    assert!(
        !written.text.contains("M428") && !written.text.contains("M429"),
        "{}",
        written.text
    );
    let back = read(&ctx, Dialect::LinuxCnc, &written.text).unwrap();
    assert!(
        back.warnings
            .iter()
            .all(|w| !w.message.contains("tool tip"))
    );
    let again = solve(&m, &back);
    // Each block now runs in the block time it was given: no faster than the schedule.
    assert!(again.schedule.cycle_time >= s.schedule.cycle_time * (1.0 - 1e-9));
}

/// Between CL points the control moves the rotary axis straight, as X Y Z: the fitted angle is
/// held to its programmed chords as the tip is. A step in A (three short moves, a long one
/// turning 180°, three short ones) swung a cubic through the angles 16.9° off the programmed
/// chord; held, it stays within the angular tolerance (0.01°) and a hair of slack.
#[test]
fn the_rotary_angle_is_held_to_its_chords() {
    let (m, ctx) = setup('A');
    let tp = read(
        &ctx,
        Dialect::LinuxCnc,
        "G21 G90 G94\nG0 X0 Y0 Z0 A0\nG1 X1 A0 F3000\nX2 A0\nX100 A180\nX101 A180\nX102 A180\nM2\n",
    )
    .unwrap();
    let s = solve(&m, &tp);
    let worst = s.path.deviation().1.to_degrees();
    assert!(worst <= 0.0111, "the angle strays {worst}° from its chords");
}

/// A block that turns only the table at a programmed feed takes the time F gives it (F in
/// °/min: a control times the turn at F, as every dialect reads it). NX's Mazak Nexus 510
/// four-axis sample (round 10: `B274.5` … at F9.8) reported 622.7 s where the control takes
/// about 24,600 s: the block's time reached the schedule only as a cap on the tool tip's
/// speed, which caps nothing while the tip stands, so the turn ran at the axis's limits. Now
/// the cap is on the rate of turn: B 90° out and back at F100 (1.667 °/s, far below B's
/// 100 °/s) takes 2 × 54 s, plus v/a to start and to stop.
#[test]
fn a_turn_alone_at_a_programmed_feed_takes_its_programmed_time() {
    let (m, ctx) = setup('B');
    let v = 100.0 / 60.0;
    let want = 2.0 * 90.0 / v + v / 500.0;
    for dialect in [Dialect::Fanuc, Dialect::LinuxCnc, Dialect::Sinumerik] {
        let tp = read(
            &ctx,
            dialect,
            "G90 G94\nG1 X0. Y0. Z0. B0. F100.\nG1 B90.\nB0.\nM30\n",
        )
        .unwrap();
        let s = solve(&m, &tp);
        let t = s.schedule.cycle_time;
        assert!(
            (t - want).abs() <= 1e-3 * want,
            "{dialect:?}: {t} s, want {want} s"
        );
        // (Within the angular tolerance, 0.01°, the fitted turn may cut its reversal short.)
        // A rapid turn is not held to F.
        let tp = read(
            &ctx,
            dialect,
            "G90 G94\nG1 X0. Y0. Z0. B0. F100.\nG0 B90.\nM30\n",
        )
        .unwrap();
        let t = solve(&m, &tp).schedule.cycle_time;
        assert!((t - 1.1).abs() < 1e-6, "{dialect:?}: rapid {t} s");
    }
}

/// A block that turns the table while X, Y or Z move is fed differently by the controls:
/// LinuxCNC (and Sinumerik) along X Y Z, grbl and the Fanuc family over the combined distance.
/// Where nothing named the dialect (a `.gcode` file of a Vectric rotary post for grbl, read in
/// the default LinuxCNC dialect), the first such block warns, naming `--dialect fanuc`; not
/// where the user, the content or LinuxCNC's own `.ngc` extension named it, and not a turn
/// alone (read alike).
#[test]
fn a_rotary_feed_in_an_unnamed_dialect_warns_once() {
    use feedopt::toolpath::{Input, ReadOptions, read_with};
    let (_, ctx) = setup('A');
    let dir = tempfile::tempdir().unwrap();
    let program = "G21 G90 G94\nG0 X0 Y0 Z10 A0\nG1 A30 F600\nG1 X10 A90 F600\nG1 X20 A180\nM2\n";
    let warnings = |name: &str, dialect: Option<Dialect>| -> Vec<(usize, String)> {
        let path = dir.path().join(name);
        std::fs::write(&path, program).unwrap();
        let options = ReadOptions {
            machine: Some(ctx.clone()),
            dialect,
            ..Default::default()
        };
        let (input, _) = read_with(&path, &options).unwrap();
        let Input::Cl(tp) = input else {
            panic!("a toolpath")
        };
        tp.warnings
            .iter()
            .filter(|w| w.message.contains("--dialect fanuc"))
            .map(|w| (w.line, w.message.to_string()))
            .collect()
    };
    let found = warnings("vectric.gcode", None);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].0, 4, "{found:?}");
    assert!(found[0].1.contains("LinuxCNC"), "{found:?}");
    assert!(warnings("part.ngc", None).is_empty());
    assert!(warnings("vectric.gcode", Some(Dialect::LinuxCnc)).is_empty());
}

/// A Vectric-style rotary program (A wraps the part, Z is the radius): some blocks turn A far
/// while the tip moves microns (`A12.4` for 9 µm of Z), the next ones move Z far for a tenth of
/// a degree. With u the tip's chord alone, dA/du jumped a hundredfold from knot to knot: the
/// cubic swung A 1.6° off its chords and bent it within microns, the adaptive refinement
/// spent 19,265 stations on 42 blocks (the 76,693-line Vectric Skull roughing: 3.2 M stations,
/// 5.8 GB, and 12 rounds of local refinement that left 30 intervals over a limit). In the joint chord
/// (a degree as a millimetre) A stays on its chords and the path takes 2,257 stations.
#[test]
fn a_rotary_program_that_turns_far_for_tiny_tip_moves_stays_on_its_chords() {
    let (m, ctx) = setup('A');
    let steps = [
        (0.11, 5.0),
        (12.4, 0.009),
        (0.99, 0.044),
        (3.1, -0.03),
        (0.33, -1.4),
        (8.9, 0.3),
        (0.11, -4.0),
    ];
    let mut program = String::from("G21 G90 G94\nG0 X10 Y0 Z40 A0\nG1 Z35 F2190\n");
    let (mut a, mut z) = (0.0, 35.0);
    for i in 0..42 {
        let (da, dz) = steps[i % steps.len()];
        a += da;
        z += dz;
        program.push_str(&format!("G1 A{a:.3} Z{z:.3}\n"));
    }
    program.push_str("M2\n");
    let tp = read(&ctx, Dialect::LinuxCnc, &program).unwrap();
    let s = solve(&m, &tp);
    let (mm, rad) = s.path.deviation();
    assert!(
        rad.to_degrees() <= 0.0111,
        "A strays {}° from its chords",
        rad.to_degrees()
    );
    assert!(mm <= 0.0061, "the tip strays {mm} mm from its chords");
    assert!(
        s.stations() < 5_000,
        "{} stations for 42 blocks",
        s.stations()
    );
}

/// A corner of a four-axis program is a corner of the axes' motion, in the chord u measures
/// (a degree as a millimetre): Z going up 0.5 mm and back while A turns 10° and 10° more is a
/// turn of 5.7° there, no exact stop, and the block pair takes A's own trapezoid, v/a + d/v =
/// 0.2 + 0.2 s (the tip's chords alone turned back by 180°: a stop, 0.566 s); X running on
/// straight while A starts to turn (10 mm, then 10 mm with 90°) is a turn of 84°, a stop.
#[test]
fn four_axis_corners_are_corners_of_the_axes_motion() {
    let (m, ctx) = setup('A');
    let up_and_back = "G21 G90 G94\nG0 X0 Y0 Z10 A0\nG1 Z10.5 A10 F600\nG1 Z10 A20\nM2\n";
    let tp = read(&ctx, Dialect::LinuxCnc, up_and_back).unwrap();
    let s = solve(&m, &tp);
    assert_eq!(s.path.spans.len(), 1);
    let t = s.schedule.cycle_time;
    assert!((t - 0.4).abs() < 1e-3, "{t} s, want A's 0.4 s");
    let turn_starts = "G21 G90 G94\nG0 X0 Y0 Z10 A0\nG1 X10 A0 F600\nG1 X20 A90\nM2\n";
    let tp = read(&ctx, Dialect::LinuxCnc, turn_starts).unwrap();
    assert_eq!(solve(&m, &tp).path.spans.len(), 2);
}
