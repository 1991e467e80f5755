//! `feedopt gcode`: the toolpath written back as G-code with the optimised feed per block, read
//! back by the project's own G-code reader. The program's feeds must imply the schedule's
//! cycle time (the reader's block times: G93 60/F, G94 chord/F) and its points must be the
//! input's.

mod common;

use std::path::{Path, PathBuf};

use feedopt::geometry::GeometryOptions;
use feedopt::kinematics::Kinematics;
use feedopt::machine::Machine;
use feedopt::optimize::{Options, Solution, optimize};
use feedopt::solver::SolverKind;
use feedopt::toolpath::{self, ClPoint, Feed, Toolpath, gcode::Dialect};
use feedopt::writers::gcode::{
    BlockFeed, GcodeOptions, Program, program, programmed_time, write_gcode,
};
use nalgebra::Vector3;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn reach() -> Options {
    Options {
        solver_kind: SolverKind::Reach,
        ..Options::default()
    }
}

/// The CL points of `t` with their path angles (degrees) on `kin`.
fn angles_deg(m: &Machine, t: &Toolpath) -> Vec<[f64; 2]> {
    let kin = Kinematics::new(m);
    kin.rotary_angles(&t.points, &m.axes)
        .unwrap()
        .iter()
        .map(|a| a.map(f64::to_degrees))
        .collect()
}

/// Writes, reads back and checks: no reader warning, programmed time = cycle time within
/// 0.5 %, every written point an input point within 1e-4 mm / 1e-4° (in order; the input
/// points skipped are repeats of the point before, which the writer leaves out). Returns the
/// program and its read-back time.
fn round_trip(
    m: &Machine,
    input: &Toolpath,
    sol: &Solution,
    geometry: &GeometryOptions,
    dialect: Dialect,
) -> (Program, f64) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.ngc");
    let options = GcodeOptions {
        dialect,
        max_rotation_deg: None,
        block_feed: BlockFeed::Average,
    };
    let prog = write_gcode(&out, m, input, sol, geometry, &options).unwrap();
    let back = match toolpath::read_as(&out, Some(toolpath::Format::Gcode), dialect).unwrap() {
        toolpath::Input::Cl(t) => t,
        toolpath::Input::Joint(_) => unreachable!(),
    };
    // No warning, but where a rotary axis turns more than 180° (the impeller's rapids
    // between operations): the written block turns it the long way as the input did, which
    // the reader says a modulo axis set to take the shorter way would not.
    let said: Vec<_> = back
        .warnings
        .iter()
        .filter(|w| !w.message.contains("shortest_way"))
        .collect();
    assert!(
        said.is_empty(),
        "{dialect}: reader warnings {:?}",
        &said[..said.len().min(3)]
    );
    // Every block after the first carries a time (no rapid, no missing F); the dwells are
    // written where they were (G4).
    let time = programmed_time(&back).unwrap() + back.dwell_time();
    let cycle = sol.schedule.cycle_time + input.dwell_time();
    assert!(
        (time - cycle).abs() <= 5e-3 * cycle,
        "{dialect}: programmed {time} s vs schedule {cycle} s"
    );
    // The writer's own sum agrees with the reader's to rounding.
    assert!(
        (prog.time - time).abs() <= 1e-6 * cycle,
        "{} vs {time}",
        prog.time
    );
    assert_eq!(back.points.len(), prog.blocks + 1);

    let kin = Kinematics::new(m);
    let want = angles_deg(m, input);
    let rotary = kin.rotary_axes();
    let got_angles: Vec<[f64; 2]> = back
        .points
        .iter()
        .map(|p| {
            let a = p.rotary.map_or([0.0; 2], |r| kin.angles_from_rotary(r));
            a.map(f64::to_degrees)
        })
        .collect();
    let close = |a: &ClPoint, ai: &[f64; 2], b: &ClPoint, bi: &[f64; 2]| {
        (a.p - b.p).amax() <= 1e-4
            && (0..2).all(|j| rotary[j].is_none() || (ai[j] - bi[j]).abs() <= 1e-4)
    };
    let mut c = 0usize;
    for (k, p) in back.points.iter().enumerate() {
        let start = c;
        while c < input.points.len() && !close(p, &got_angles[k], &input.points[c], &want[c]) {
            c += 1;
        }
        assert!(
            c < input.points.len(),
            "{dialect}: written point {k} at line {} ({:?}) is no input point after input {start}",
            p.line,
            p.p
        );
        // Skipped input points repeat the point before them.
        for s in start.max(1)..c {
            assert!(
                (input.points[s].p - input.points[s - 1].p).norm() <= 1e-6,
                "{dialect}: input point {s} (line {}) was left out",
                input.points[s].line
            );
        }
        c += 1;
    }
    assert_eq!(
        c,
        input.points.len(),
        "{dialect}: the last input point is written last"
    );
    (prog, time)
}

fn bundled(dir: &str, file: &str) -> (Machine, Toolpath) {
    let m = Machine::from_file(&root().join(format!("problems/{dir}/machine.json"))).unwrap();
    let t = toolpath::read(&root().join(format!("problems/{dir}/{file}"))).unwrap();
    (m, t)
}

#[test]
fn the_seed_head_head_blade_round_trips_in_every_dialect() {
    // APT CL with tool vectors → tool-tip X Y Z and the head's C and A words under TCP.
    let (m, t) = bundled("seed_head_head", "impeller_blade.cls");
    let options = Options::default();
    let sol = optimize(&m, &t, &options).unwrap();
    for dialect in Dialect::GCODE {
        let (prog, time) = round_trip(&m, &t, &sol, &options.geometry, dialect);
        // The blade's moves turn the head: those blocks are G93; the straight approach and
        // retract move X Y Z only: G94.
        assert!(prog.inverse_time_blocks > 0 && prog.inverse_time_blocks < prog.blocks);
        assert_eq!(prog.merged, 0);
        eprintln!(
            "{dialect}: {} blocks ({} G93), {time:.6} s vs {:.6} s",
            prog.blocks, prog.inverse_time_blocks, sol.schedule.cycle_time
        );
    }
}

#[test]
fn a_three_axis_pocket_is_written_with_g94_feeds_only() {
    let (m, t) = bundled("xyz_pocket", "pocket_contour.cls");
    let options = reach();
    let sol = optimize(&m, &t, &options).unwrap();
    let (prog, _) = round_trip(&m, &t, &sol, &options.geometry, Dialect::LinuxCnc);
    assert_eq!(prog.inverse_time_blocks, 0);
    assert!(
        !prog
            .text
            .lines()
            .any(|l| l.starts_with("G93") || l.starts_with("M428"))
    );
    assert!(!prog.text.contains(" A") && !prog.text.contains(" C"));
    // Each block's G94 F is its chord over the schedule's time between its CL points: the
    // first block from rest cannot run at the full feed of the middle.
    let feeds: Vec<f64> = prog
        .text
        .lines()
        .filter(|l| l.starts_with("G1"))
        .filter_map(|l| l.split(" F").nth(1))
        .map(|f| f.parse().unwrap())
        .collect();
    let fmax = m.feed_max.unwrap() * 60.0;
    assert!(
        feeds.iter().all(|&f| f > 0.0 && f <= fmax * (1.0 + 1e-6)),
        "{fmax}"
    );
    assert!(feeds[0] < 0.5 * feeds.iter().cloned().fold(0.0, f64::max));
}

fn linuxcnc_dir() -> Option<PathBuf> {
    let d = root().join("../shared/realworld/linuxcnc");
    d.join("impeller-7bl-xyzac.ngc").exists().then_some(d)
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn the_linuxcnc_impeller_is_written_back_at_the_schedules_time() {
    let dir = linuxcnc_dir().expect("../shared is present (cfg shared_data)");
    let m = Machine::from_file(&dir.join("impeller-7bl-xyzac.machine.json")).unwrap();
    let t = toolpath::read(&dir.join("impeller-7bl-xyzac.ngc")).unwrap();
    let options = reach();
    let sol = optimize(&m, &t, &options).unwrap();
    let (prog, time) = round_trip(&m, &t, &sol, &options.geometry, Dialect::LinuxCnc);
    eprintln!(
        "impeller: {} blocks ({} G93, {} merged), program {time:.4} s, schedule {:.4} s",
        prog.blocks, prog.inverse_time_blocks, prog.merged, sol.schedule.cycle_time
    );
    // The program's own feeds imply a different time: the written ones are the schedule's.
    let original = programmed_time(&t);
    assert!(original.is_err(), "the original has rapids without a time");
}

/// A dresser dressing a 90° arc of radius 5 (tool on the normal): B turns 90°.
fn dresser_arc() -> (Machine, Toolpath) {
    let m = common::machine(
        r#"{"name": "dresser", "kinematics": {"type": "dresser", "tool_length": 10},
            "axes": {"X": {"velocity": 50, "acceleration": 500},
                     "Z": {"velocity": 50, "acceleration": 500},
                     "B": {"velocity": 60, "acceleration": 300}},
            "feed": {"max": 50}}"#,
    );
    let pts: Vec<ClPoint> = (0..=9)
        .map(|k| {
            let phi = (10.0 * k as f64).to_radians();
            ClPoint {
                p: Vector3::new(5.0 * phi.sin(), 0.0, -5.0 + 5.0 * phi.cos()),
                o: Vector3::new(phi.sin(), 0.0, phi.cos()),
                feed: Feed::Programmed(20.0),
                rotary: None,
                line: k + 1,
            }
        })
        .collect();
    let t = Toolpath {
        source: PathBuf::from("arc.cls"),
        points: pts,
        ..Default::default()
    };
    (m, t)
}

#[test]
fn the_rotary_step_rule_splits_dresser_blocks_and_keeps_the_time() {
    let (m, t) = dresser_arc();
    let mut options = reach();
    // The arc turns 10° per CL move: one span, not a corner at every point.
    options.geometry.corner_angle_deg = 30.0;
    let sol = optimize(&m, &t, &options).unwrap();
    // Without Δθ: the programmed points, 10° of B per block.
    let (plain, _) = round_trip(&m, &t, &sol, &options.geometry, Dialect::LinuxCnc);
    assert_eq!((plain.blocks, plain.split), (9, 0));
    // Δθ = 3°: each 10° block is bisected twice (2.5° pieces).
    let o = GcodeOptions {
        dialect: Dialect::LinuxCnc,
        max_rotation_deg: Some(3.0),
        block_feed: BlockFeed::Average,
    };
    let prog = program(&m, &t, &sol, &options.geometry, &o).unwrap();
    assert_eq!((prog.blocks, prog.split), (36, 27));
    let back =
        toolpath::gcode::parse(Path::new("split.ngc"), &prog.text, Dialect::LinuxCnc).unwrap();
    assert!(back.warnings.is_empty(), "{:?}", back.warnings);
    let b: Vec<f64> = back.points.iter().map(|p| p.rotary.unwrap()[1]).collect();
    assert!(b.windows(2).all(|w| (w[1] - w[0]).abs() <= 3.0 + 1e-9));
    assert!((b[36] - 90.0).abs() < 1e-6, "B ends at {}", b[36]);
    // The added points lie on the path (the circle of radius 5) and the time is kept.
    for p in &back.points {
        let r = (p.p.x.powi(2) + (p.p.z + 5.0).powi(2)).sqrt();
        assert!((r - 5.0).abs() < 1e-3, "r = {r}");
    }
    let time = programmed_time(&back).unwrap();
    let cycle = sol.schedule.cycle_time;
    assert!((time - cycle).abs() <= 1e-5 * cycle, "{time} vs {cycle}");
    // A bad Δθ is an error, not a panic.
    let bad = GcodeOptions {
        max_rotation_deg: Some(0.0),
        ..o
    };
    assert!(program(&m, &t, &sol, &options.geometry, &bad).is_err());
}

#[test]
fn repeated_points_and_pure_reorientations_are_blocks_of_their_own_time() {
    // A head-head path: move, turn the tool on the spot, repeat a point, move on.
    let m = Machine::from_file(&root().join("problems/seed_head_head/machine.json")).unwrap();
    let up = common::UP;
    let tilted = Vector3::new(0.0, -0.2, 1.0).normalize();
    let pts = [
        (Vector3::new(0.0, 0.0, 50.0), up),
        (Vector3::new(10.0, 0.0, 50.0), up),
        (Vector3::new(10.0, 0.0, 50.0), tilted),
        (Vector3::new(10.0, 0.0, 50.0), tilted),
        (Vector3::new(20.0, 0.0, 50.0), tilted),
    ];
    let t = common::toolpath(&pts, Some(20.0));
    let options = reach();
    let sol = optimize(&m, &t, &options).unwrap();
    assert_eq!(sol.path.spans.len(), 3, "move, reorientation, move");
    let (prog, _) = round_trip(&m, &t, &sol, &options.geometry, Dialect::Sinumerik);
    assert_eq!(prog.blocks, 3, "the repeated point is not written");
    // The reorientation block is G93: its time is the schedule's time of the turn.
    assert!(prog.text.contains("G93"));
}

#[test]
fn the_cli_writes_a_program_and_rejects_joint_space_input() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pocket.ngc");
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_feedopt"))
            .args(args)
            .current_dir(root())
            .output()
            .unwrap()
    };
    let o = run(&[
        "gcode",
        "--solver",
        "reach",
        "--dialect",
        "fanuc",
        "--machine",
        "problems/xyz_pocket/machine.json",
        "problems/xyz_pocket/pocket_contour.cls",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("%\nO1000\n") && text.trim_end().ends_with('%'));
    assert!(String::from_utf8_lossy(&o.stdout).contains("peak feed"));
    // The written program says it is a Fanuc program (its O number): solve reads it so.
    let o = run(&[
        "solve",
        "--json",
        "--solver",
        "reach",
        "--machine",
        "problems/xyz_pocket/machine.json",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        (j["dialect"].as_str(), j["dialect_by"].as_str()),
        (Some("fanuc"), Some("content"))
    );
    // Joint-space input: a clear error, nothing written.
    let csv = dir.path().join("joint.csv");
    std::fs::write(&csv, "s,q_0\n0,0\n1,1\n2,3\n").unwrap();
    let mj = dir.path().join("joint.json");
    std::fs::write(
        &mj,
        r#"{"name": "j", "kinematics": {"type": "joint"},
            "axes": {"0": {"velocity": 10, "acceleration": 100}}}"#,
    )
    .unwrap();
    let out2 = dir.path().join("joint.ngc");
    let o = run(&[
        "gcode",
        "--solver",
        "reach",
        "--machine",
        mj.to_str().unwrap(),
        csv.to_str().unwrap(),
        "-o",
        out2.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("joint-space"));
    assert!(!out2.exists());
}

/// With a corner tolerance the program is written as the schedule runs it: the blends as G1
/// blocks through their points, the feeds still implying the schedule's cycle time. (It was
/// an error: the writer planned the spans of the unblended toolpath.)
#[test]
fn blended_corners_are_written_as_the_blends_the_schedule_runs() {
    let (m, t) = bundled("xyz_pocket", "pocket_contour.cls");
    let mut options = reach();
    options.geometry.corner_tolerance_mm = 0.05;
    let sol = optimize(&m, &t, &options).unwrap();
    assert!(sol.corners_blended > 0);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.ngc");
    let o = GcodeOptions {
        dialect: Dialect::LinuxCnc,
        max_rotation_deg: None,
        block_feed: BlockFeed::Average,
    };
    let prog = write_gcode(&out, &m, &t, &sol, &options.geometry, &o).unwrap();
    let back =
        match toolpath::read_as(&out, Some(toolpath::Format::Gcode), Dialect::LinuxCnc).unwrap() {
            toolpath::Input::Cl(t) => t,
            toolpath::Input::Joint(_) => unreachable!(),
        };
    let time = programmed_time(&back).unwrap();
    let cycle = sol.schedule.cycle_time;
    assert!((time - cycle).abs() <= 5e-3 * cycle, "{time} vs {cycle}");
    assert!(
        back.points.len() > t.points.len() + 2 * sol.corners_blended,
        "{} points written for {} input points and {} blends",
        back.points.len(),
        t.points.len(),
        sol.corners_blended
    );
    assert_eq!(back.points.len(), prog.blocks + 1);
}

/// A head–table machine with table A (a blade mill) writes its A and B words as the axes
/// stand: its tilt path angle is B − 90° ([`feedopt::kinematics::head_table`]), and a writer
/// that wrote path angles as they are would put every B 90° off. The seed's blade, given by
/// tool vectors, goes through the tool-vector inverse, out as G-code and back.
#[test]
fn a_head_table_with_table_a_writes_its_b_words_as_the_axis_stands() {
    let (_, t) = bundled("seed_head_head", "impeller_blade.cls");
    let m = common::machine(
        r#"{"kinematics": {"type": "head_table", "pivot_length": 250, "table": "A"},
            "feed": {"max": 500},
            "axes": {"X": {"velocity": 500, "acceleration": 3000},
                     "Y": {"velocity": 500, "acceleration": 3000},
                     "Z": {"velocity": 500, "acceleration": 3000},
                     "A": {"velocity": 90, "acceleration": 600},
                     "B": {"velocity": 60, "acceleration": 600}}}"#,
    );
    let options = reach();
    let sol = optimize(&m, &t, &options).unwrap();
    let (prog, _) = round_trip(&m, &t, &sol, &options.geometry, Dialect::LinuxCnc);
    assert!(prog.inverse_time_blocks > 0);
}

/// The program's dwells are written where they stand (G4 after the block that reaches the
/// point, in each dialect's word: LinuxCNC P s, Fanuc X s, Sinumerik F s) and the program's
/// time includes them, as the cycle time does. The writer left them out: the NX DMU 70 eVo
/// program's 75.0 s of drilling dwells (CYCLE83 at the holes' bottoms) were missing from the
/// program it wrote, which ran 75 s short of the schedule it reported, and drilled without
/// them.
#[test]
fn dwells_are_written_where_they_stand() {
    let text = std::fs::read_to_string(root().join("problems/xyz_pocket/machine.json")).unwrap();
    let m = Machine::from_json(Path::new("machine.json"), &text).unwrap();
    let input = toolpath::gcode::parse(
        Path::new("drill.ngc"),
        "G21 G90 G94\nG0 X0 Y0 Z5\nG4 P0.5\nG1 Z-3 F300\nG4 P1.25\nG1 Z-3\nG4 P0.75\n\
         G0 Z5\nG0 X20\nG1 Z-3 F300\nG4 P2\nG0 Z5\nM2\n",
        Dialect::LinuxCnc,
    )
    .unwrap();
    assert_eq!(input.dwell_time(), 4.5);
    let options = reach();
    let sol = optimize(&m, &input, &options).unwrap();
    for dialect in [Dialect::LinuxCnc, Dialect::Fanuc, Dialect::Sinumerik] {
        let (prog, _) = round_trip(&m, &input, &sol, &options.geometry, dialect);
        assert_eq!(prog.dwell_time, 4.5, "{dialect}");
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.ngc");
        std::fs::write(&out, &prog.text).unwrap();
        let back = match toolpath::read_as(&out, Some(toolpath::Format::Gcode), dialect).unwrap() {
            toolpath::Input::Cl(t) => t,
            toolpath::Input::Joint(_) => unreachable!(),
        };
        // Where: the start (0.5 s), the first hole's bottom (1.25 + 0.75 s: the second move
        // there repeats the point), the second hole's bottom (2 s).
        let at: Vec<([f64; 3], f64)> = back
            .dwells
            .iter()
            .map(|d| {
                let p = back.points[d.point].p;
                ([p.x, p.y, p.z], d.seconds)
            })
            .collect();
        let want = [
            ([0.0, 0.0, 5.0], 0.5),
            ([0.0, 0.0, -3.0], 2.0),
            ([20.0, 0.0, -3.0], 2.0),
        ];
        assert_eq!(at.len(), want.len(), "{dialect}: {at:?}\n{}", prog.text);
        for ((p, s), (wp, ws)) in at.iter().zip(&want) {
            assert!(
                p.iter().zip(wp).all(|(a, b)| (a - b).abs() < 1e-9) && (s - ws).abs() < 1e-9,
                "{dialect}: {at:?}"
            );
        }
    }
}

/// The schedule's cycle time of `t` and that of the program written from it with
/// `block_feed`, read back and solved again on the same machine (a control that plans its
/// acceleration within the machine's limits).
fn written_and_solved_again(
    m: &Machine,
    t: &Toolpath,
    block_feed: BlockFeed,
    dialect: Dialect,
) -> (f64, f64, Program) {
    let options = Options::default();
    let sol = optimize(m, t, &options).unwrap();
    let o = GcodeOptions {
        dialect,
        max_rotation_deg: None,
        block_feed,
    };
    let prog = program(m, t, &sol, &options.geometry, &o).unwrap();
    let back = toolpath::gcode::parse(Path::new("back.ngc"), &prog.text, dialect).unwrap();
    assert!(back.warnings.is_empty(), "{:?}", back.warnings);
    let again = optimize(m, &back, &options).unwrap();
    (sol.schedule.cycle_time, again.schedule.cycle_time, prog)
}

#[test]
fn peak_feeds_let_a_control_that_accelerates_run_the_schedules_time() {
    // One 400 mm move at F30000 (500 mm/s) on a mill that accelerates at 1000 mm/s²: the
    // schedule ramps up over 125 mm and down over 125 mm, 400/500 + 500/1000 = 1.3 s.
    let m = common::machine(
        r#"{"name": "mill", "kinematics": {"type": "xyz"},
            "axes": {"X": {"velocity": 500, "acceleration": 1000},
                     "Y": {"velocity": 500, "acceleration": 1000},
                     "Z": {"velocity": 500, "acceleration": 1000}},
            "feed": {"max": 500}}"#,
    );
    let t = toolpath::gcode::parse(
        Path::new("line.ngc"),
        "G21 G90 G94\nG1 X0 Y0 Z0 F30000\nG1 X400\n",
        Dialect::LinuxCnc,
    )
    .unwrap();
    // Average: F is 400 mm / 1.3 s = 307.7 mm/s, which a control reaches only after
    // accelerating: solved again, 400/307.7 + 0.3077 = 1.608 s.
    let (cycle, again, prog) =
        written_and_solved_again(&m, &t, BlockFeed::Average, Dialect::LinuxCnc);
    assert!((cycle - 1.3).abs() < 1e-3, "{cycle}");
    assert!((prog.time - cycle).abs() < 1e-6, "{}", prog.time);
    assert!((again - 1.6077).abs() < 2e-3, "average: {again} s");
    // Peak: F is the schedule's top feed, 500 mm/s (F30000.00): the control's ramps are the
    // schedule's and so is its time; at F without accelerating the block would take 0.8 s.
    let (cycle, again, prog) = written_and_solved_again(&m, &t, BlockFeed::Peak, Dialect::LinuxCnc);
    assert!(
        prog.text
            .contains("G1 X400.000000 Y0.000000 Z0.000000 F30000.00"),
        "{}",
        prog.text
    );
    assert!((prog.time - 0.8).abs() < 1e-6, "{}", prog.time);
    assert!(
        (again - cycle).abs() <= 1e-4 * cycle,
        "peak: {again} s against {cycle} s"
    );
}

#[test]
fn peak_feeds_hold_for_g93_blocks_and_turns_on_the_spot() {
    // The head-head path: a move, a turn of the tool on the spot (a G93 block of its own), a
    // move while turning back (G93), each starting and ending at rest.
    let m = Machine::from_file(&root().join("problems/seed_head_head/machine.json")).unwrap();
    let up = common::UP;
    let tilted = Vector3::new(0.0, -0.3, 1.0).normalize();
    let pts = [
        (Vector3::new(0.0, 0.0, 50.0), up),
        (Vector3::new(40.0, 0.0, 50.0), up),
        (Vector3::new(40.0, 0.0, 50.0), tilted),
        (Vector3::new(80.0, 10.0, 50.0), up),
    ];
    let t = common::toolpath(&pts, Some(50.0));
    for dialect in Dialect::GCODE {
        let (cycle, average, _) = written_and_solved_again(&m, &t, BlockFeed::Average, dialect);
        let (_, peak, prog) = written_and_solved_again(&m, &t, BlockFeed::Peak, dialect);
        assert!(prog.inverse_time_blocks == 2, "{}", prog.text);
        assert!(prog.time < cycle, "{} vs {cycle}", prog.time);
        assert!(
            average > cycle * 1.01,
            "{dialect}: average {average} vs {cycle}"
        );
        assert!(
            (peak - cycle).abs() <= 1e-3 * cycle,
            "{dialect}: peak {peak} vs {cycle}"
        );
    }
}

/// The command line's default: each block's F at its peak, no Δθ rule.
fn peak(dialect: Dialect) -> GcodeOptions {
    GcodeOptions {
        dialect,
        max_rotation_deg: None,
        block_feed: BlockFeed::Peak,
    }
}

/// The program's tool changes, spindle speeds and switches in program order, each with where
/// the tool stands when it comes (the CL point before it; `None`: before the first).
fn machine_words(t: &Toolpath) -> Vec<(String, Option<[f64; 3]>)> {
    let mut v: Vec<(usize, usize, u8, String)> = Vec::new();
    v.extend(
        t.tool_changes
            .iter()
            .map(|c| (c.point, c.line, 0, format!("{:?}", c.tool))),
    );
    v.extend(
        t.spindle_changes
            .iter()
            .map(|c| (c.point, c.line, 1, format!("S{}", c.rpm))),
    );
    v.extend(
        t.switches
            .iter()
            .map(|c| (c.point, c.line, 2, format!("{:?}", c.switch))),
    );
    v.sort_by_key(|e| (e.0, e.1, e.2));
    v.into_iter()
        .map(|(point, _, _, what)| (what, stands_at(t, point)))
        .collect()
}

/// Where the tool stands before the move ending at CL point `point` (`None`: before the
/// first).
fn stands_at(t: &Toolpath, point: usize) -> Option<[f64; 3]> {
    point
        .checked_sub(1)
        .map(|k| t.points[k.min(t.points.len() - 1)].p)
        .map(|p| [p.x, p.y, p.z])
}

#[test]
fn tools_spindle_and_coolant_are_written_where_the_program_has_them() {
    // A written program runs on the machine: its tools, spindle and coolant as the input's,
    // at the same places (the spindle stops after the retract that carries M5, not in the cut).
    let text = std::fs::read_to_string(root().join("problems/xyz_pocket/machine.json")).unwrap();
    let m = Machine::from_json(Path::new("machine.json"), &text).unwrap();
    let input = toolpath::gcode::parse(
        Path::new("two_tools.ngc"),
        "G21 G90 G94\nT1 M6\nG43 H1\nG0 X0 Y0 Z5 S2000 M3\nM8\nG1 Z-2 F300\nG1 X20\n\
         G0 Z5 M5 M9\nT2 M6\nG43 H2\nS3000 M4\nM7\nG0 X40\nG1 Z-2 F300\nG1 X60\nG0 Z5 M5\nM9\nM2\n",
        Dialect::LinuxCnc,
    )
    .unwrap();
    let want = machine_words(&input);
    assert_eq!(want.len(), 12, "{want:?}");
    let options = reach();
    let sol = optimize(&m, &input, &options).unwrap();
    for dialect in [Dialect::LinuxCnc, Dialect::Fanuc, Dialect::Sinumerik] {
        let (prog, _) = round_trip(&m, &input, &sol, &options.geometry, dialect);
        let back = toolpath::gcode::parse(Path::new("back.nc"), &prog.text, dialect).unwrap();
        assert_eq!(machine_words(&back), want, "{dialect}\n{}", prog.text);
        // A three-axis program's Z is the tool tip: the tool's length offset with each tool
        // (LinuxCNC, Fanuc; a Sinumerik applies the tool's own with T … M6).
        let g43 = prog.text.lines().filter(|l| l.starts_with("G43 H")).count();
        assert_eq!(g43, if dialect == Dialect::Sinumerik { 0 } else { 2 });
    }
}

/// The program's length offsets in program order, each with where the tool stands when it
/// comes (as [`machine_words`]).
fn length_words(t: &Toolpath) -> Vec<(String, Option<[f64; 3]>)> {
    t.length_offsets
        .iter()
        .flatten()
        .map(|c| (format!("{:?}", c.offset), stands_at(t, c.point)))
        .collect()
}

#[test]
fn the_programs_own_length_offsets_are_written_rather_than_one_with_each_tool() {
    // A LinuxCNC program without G43 (CAMotics writes `T1M6` and no G43: the operator's touch
    // off holds the tool's length) runs with its Z at the spindle's gauge line. Written with
    // `G43 H1`, a control whose table gives T1 a length would run it that much higher.
    let text = std::fs::read_to_string(root().join("problems/xyz_pocket/machine.json")).unwrap();
    let m = Machine::from_json(Path::new("machine.json"), &text).unwrap();
    let options = reach();
    let lines = |prog: &str| prog.lines().map(str::to_string).collect::<Vec<_>>();
    let plain = toolpath::gcode::parse(
        Path::new("plain.ngc"),
        "G21 G90 G94\nT1 M6\nG0 X0 Y0 Z5 S2000 M3\nG1 Z-2 F300\nG1 X20\nG0 Z5 M5\nM2\n",
        Dialect::LinuxCnc,
    )
    .unwrap();
    assert_eq!(plain.length_offsets, Some(vec![]));
    let sol = optimize(&m, &plain, &options).unwrap();
    for dialect in Dialect::GCODE {
        let (prog, _) = round_trip(&m, &plain, &sol, &options.geometry, dialect);
        let l = lines(&prog.text);
        assert!(
            !l.iter().any(|l| l.starts_with("G43")),
            "{dialect}\n{}",
            prog.text
        );
        // A Sinumerik applies the tool's length with `T… M6`: off again, as in the program.
        if dialect == Dialect::Sinumerik {
            let t = l.iter().position(|l| l == "T1 M6").unwrap();
            assert_eq!(l[t + 1], "D0", "{}", prog.text);
        }
    }
    // Its own offsets, where it switches them: a bare G43 (LinuxCNC: the tool in the
    // spindle's), G49, and an H of another number than the tool's.
    let own = toolpath::gcode::parse(
        Path::new("own.ngc"),
        "G21 G90 G94\nT1 M6\nG43\nG0 X0 Y0 Z5 S2000 M3\nG1 Z-2 F300\nG1 X20\nG0 Z5 M5\n\
         G49\nG0 X30\nT2 M6 G43 H12\nG0 X40\nG1 Z-2 F300\nG1 X60\nG0 Z5\nM2\n",
        Dialect::LinuxCnc,
    )
    .unwrap();
    let want = length_words(&own);
    assert_eq!(
        want.iter().map(|w| w.0.as_str()).collect::<Vec<_>>(),
        ["Plus(Some(1))", "Cancel", "Plus(Some(12))"]
    );
    let sol = optimize(&m, &own, &options).unwrap();
    for dialect in Dialect::GCODE {
        let (prog, _) = round_trip(&m, &own, &sol, &options.geometry, dialect);
        let l = lines(&prog.text);
        let at = |s: &str| l.iter().position(|l| l == s).unwrap_or(usize::MAX);
        if dialect == Dialect::Sinumerik {
            // D1 for the offset on, D0 for G49, D1 for G43 H12 (T2's change applies T2's
            // length, as the program's G43 H12 in its block does).
            let d: Vec<&String> = l.iter().filter(|l| l.starts_with('D')).collect();
            assert_eq!(d, ["D1", "D0", "D1"], "{}", prog.text);
            continue;
        }
        assert!(
            at("T1 M6") < at("G43 H1") && at("G43 H1") < at("G49"),
            "{}",
            prog.text
        );
        assert_eq!(l[at("T2 M6") + 1], "G43 H12", "{}", prog.text);
        assert_eq!(l.iter().filter(|l| l.starts_with("G43")).count(), 2);
        let back = toolpath::gcode::parse(Path::new("back.nc"), &prog.text, dialect).unwrap();
        assert_eq!(length_words(&back), want, "{dialect}\n{}", prog.text);
    }
    // A program whose language has no length offsets (Sinumerik: `T… M6` applies the
    // tool's): written for a LinuxCNC or Fanuc control, each numbered tool comes with its own.
    let sinumerik = toolpath::gcode::parse(
        Path::new("s.mpf"),
        "G71 G90\nT1 M6\nG0 X0 Y0 Z5 S2000 M3\nG1 Z-2 F300\nG1 X20\nG0 Z5 M5\nM30\n",
        Dialect::Sinumerik,
    )
    .unwrap();
    assert_eq!(sinumerik.length_offsets, None);
    let sol = optimize(&m, &sinumerik, &options).unwrap();
    for dialect in [Dialect::LinuxCnc, Dialect::Fanuc] {
        let (prog, _) = round_trip(&m, &sinumerik, &sol, &options.geometry, dialect);
        let l = lines(&prog.text);
        let t = l.iter().position(|l| l == "T1 M6").unwrap();
        assert_eq!(l[t + 1], "G43 H1", "{dialect}\n{}", prog.text);
    }
}

#[test]
fn tool_tip_mode_takes_the_programs_length_offset_number() {
    // NX's Fanuc posts give the length offset in the G43.4 block; it need not be the tool's
    // number.
    let (m, _) = bundled("seed_head_head", "impeller_blade.cls");
    let input = toolpath::gcode::parse(
        Path::new("tcp.nc"),
        "%\nO1\nG21 G90 G94\nT5 M6\nG43.4 H25\nG0 X0 Y0 Z50 A0 C0 S10000 M3\nG1 Z10 F1000\n\
         G1 X10 A5\nG0 Z50 M5\nG49\nM30\n%\n",
        Dialect::Fanuc,
    )
    .unwrap();
    let options = reach();
    let sol = optimize(&m, &input, &options).unwrap();
    let (prog, _) = round_trip(&m, &input, &sol, &options.geometry, Dialect::Fanuc);
    assert!(prog.text.lines().any(|l| l == "G43.4 H25"), "{}", prog.text);
    assert!(!prog.text.lines().any(|l| l == "G43.4 H5"), "{}", prog.text);
}

#[test]
fn a_tool_change_under_tool_tip_mode_leaves_it_and_comes_back_with_the_new_tool() {
    let (m, _) = bundled("seed_head_head", "impeller_blade.cls");
    let input = toolpath::gcode::parse(
        Path::new("tcp.ngc"),
        "G21 G90 G94\nT1 M6\nM428\nG0 X0 Y0 Z50 A0 C0 S10000 M3\nG1 Z10 F1000\nG1 X10 A5\n\
         G0 Z50 M5\nT2 M6\nS12000 M3\nG1 X20 F1000\nG0 Z60 M5\nM429\nM2\n",
        Dialect::LinuxCnc,
    )
    .unwrap();
    let options = reach();
    let sol = optimize(&m, &input, &options).unwrap();
    let (prog, _) = round_trip(&m, &input, &sol, &options.geometry, Dialect::Fanuc);
    let lines: Vec<&str> = prog.text.lines().collect();
    let at = |s: &str| lines.iter().position(|l| *l == s).unwrap_or(usize::MAX);
    // The first tool before tool-tip mode, with its length; the second out of it and back
    // before the next move (after the spindle's words).
    assert!(at("T1 M6") < at("G43.4 H1"), "{}", prog.text);
    let t2 = at("T2 M6");
    assert_eq!(
        &lines[t2 - 1..=t2 + 2],
        ["G49", "T2 M6", "S12000 M3", "G43.4 H2"]
    );
    assert!(lines[t2 + 3].starts_with("G1 "));
    let back = toolpath::gcode::parse(Path::new("back.nc"), &prog.text, Dialect::Fanuc).unwrap();
    assert_eq!(machine_words(&back), machine_words(&input), "{}", prog.text);
}

#[test]
fn the_written_program_selects_the_work_offset_the_program_is_in() {
    let text = std::fs::read_to_string(root().join("problems/xyz_pocket/machine.json")).unwrap();
    let m = Machine::from_json(Path::new("machine.json"), &text).unwrap();
    let options = reach();
    let read = |name: &str, text: &str| {
        toolpath::gcode::parse(Path::new(name), text, Dialect::Fanuc).unwrap()
    };
    let body = "G0 X0 Y0 Z5\nG1 Z-1 F300\nG1 X10\nG0 Z5\nM30\n%\n";
    // What the reader takes as the program's offset: the last one it selects before its first
    // move; none where it selects none before it (the control's default).
    for (head, want) in [
        ("G55\n", Some("G55")),
        ("G54.1 P3\n", Some("G54.1 P3")),
        ("G54\nG56\n", Some("G56")),
        ("", None),
    ] {
        let t = read("o.nc", &format!("%\nO1\nG21 G90\n{head}{body}"));
        assert_eq!(t.work_offset.as_deref(), want, "{head}");
    }
    let t = read("o.nc", &format!("%\nO1\nG21 G90\nG55\n{body}"));
    let sol = optimize(&m, &t, &options).unwrap();
    for dialect in [Dialect::LinuxCnc, Dialect::Fanuc, Dialect::Sinumerik] {
        let (prog, _) = round_trip(&m, &t, &sol, &options.geometry, dialect);
        let back = toolpath::gcode::parse(Path::new("b.nc"), &prog.text, dialect).unwrap();
        assert_eq!(back.work_offset.as_deref(), Some("G55"), "{dialect}");
    }
    // Fanuc's extended offset: written for a Fanuc, named in a comment for a LinuxCNC.
    let t = read("o.nc", &format!("%\nO1\nG21 G90\nG54.1 P3\n{body}"));
    let sol = optimize(&m, &t, &options).unwrap();
    let (prog, _) = round_trip(&m, &t, &sol, &options.geometry, Dialect::Fanuc);
    assert!(prog.text.lines().any(|l| l == "G54.1 P3"), "{}", prog.text);
    let (prog, _) = round_trip(&m, &t, &sol, &options.geometry, Dialect::LinuxCnc);
    assert!(
        prog.text
            .lines()
            .any(|l| l.starts_with('(') && l.contains("G54.1 P3")),
        "{}",
        prog.text
    );
    let back = toolpath::gcode::parse(Path::new("b.ngc"), &prog.text, Dialect::LinuxCnc).unwrap();
    assert_eq!(back.work_offset, None);
}

#[test]
fn work_offsets_selected_after_the_first_move_are_written_with_the_programs_coordinates() {
    // Three setups: G54, then G55 (never set: the reader takes it as equal to G54), then G56
    // set by the program at the current position (LinuxCNC G10 L20: its origin lies at X10 of
    // G55). G55 is selected where the program selects it and its coordinates are the
    // program's own: the machine places them by its offsets, as it places the program's. G56
    // is not: the program gave its values itself, and the written program, which writes no
    // G10, would run in whatever the control holds for G56 (until round 17 it did, the third
    // setup written at X0..X10 of that G56). It is written on in G55 at X10..X20, the G10's
    // shift in its coordinates, with a comment where the program selects G56.
    let text = std::fs::read_to_string(root().join("problems/xyz_pocket/machine.json")).unwrap();
    let m = Machine::from_json(Path::new("machine.json"), &text).unwrap();
    let body = "G0 X0 Y0\nG1 Z-1 F300\nG1 X10\nG0 Z5\n";
    let input = toolpath::gcode::parse(
        Path::new("setups.ngc"),
        &format!("G21 G90\nG54\nG0 Z5\n{body}G55\n{body}G10 L20 P3 X0 Y0 Z5\nG56\n{body}M2\n"),
        Dialect::LinuxCnc,
    )
    .unwrap();
    let offsets: Vec<(&str, [f64; 3], bool)> = input
        .offset_changes
        .iter()
        .map(|c| (c.name.as_str(), c.origin, c.given))
        .collect();
    assert_eq!(
        offsets,
        [
            ("G55", [0.0, 0.0, 0.0], false),
            ("G56", [10.0, 0.0, 0.0], true)
        ]
    );
    // The reader's points of the third setup lie 10 mm further in X.
    assert_eq!(input.points.last().unwrap().p.x, 20.0);
    let options = reach();
    let sol = optimize(&m, &input, &options).unwrap();
    for dialect in [Dialect::LinuxCnc, Dialect::Fanuc, Dialect::Sinumerik] {
        let prog = program(&m, &input, &sol, &options.geometry, &peak(dialect)).unwrap();
        let lines: Vec<&str> = prog.text.lines().collect();
        let at = |s: &str| lines.iter().position(|l| *l == s);
        let (g54, g55) = (at("G54"), at("G55"));
        assert!(g54 < g55 && g54.is_some(), "{dialect}\n{}", prog.text);
        assert_eq!(at("G56"), None, "{dialect}\n{}", prog.text);
        let g56 = lines
            .iter()
            .position(|l| l.contains("selects work offset G56 here with the values it gives"))
            .unwrap_or_else(|| panic!("{dialect}\n{}", prog.text));
        // The first two setups cut from X0 to X10 at Z−1, the third from X10 to X20.
        let cuts = |x: &str| -> Vec<usize> {
            let cut = format!("G1 X{x} Y0.000000 Z-1.000000");
            (lines.iter().enumerate())
                .filter(|(_, l)| l.starts_with(&cut))
                .map(|(i, _)| i)
                .collect()
        };
        let (tens, twenties) = (cuts("10.000000"), cuts("20.000000"));
        assert_eq!(tens.len(), 3, "{dialect}\n{}", prog.text);
        assert_eq!(twenties.len(), 1, "{dialect}\n{}", prog.text);
        assert!(tens[0] < g55.unwrap() && tens[1] < g56 && tens[2] > g56 && twenties[0] > g56);
        // Read back, the points are the input's: the third setup 10 mm further in X.
        let back = toolpath::gcode::parse(Path::new("b.nc"), &prog.text, dialect).unwrap();
        assert_eq!(back.points.last().unwrap().p.x, 20.0, "{dialect}");
    }
}

/// A program that gives the offset it works in new values (`G10 L2 P2 Y-101.6`) and selects
/// it again, to cut a second part 101.6 mm over (a CAMotics example, round 17): the written
/// program, which writes no G10, selected G55 again with the second part's own coordinates,
/// so the control cut it on the first. The second part is now written on in the offset in
/// force, 101.6 mm over.
#[test]
fn an_offset_the_program_sets_again_is_written_as_its_shift() {
    let text = std::fs::read_to_string(root().join("problems/xyz_pocket/machine.json")).unwrap();
    let m = Machine::from_json(Path::new("machine.json"), &text).unwrap();
    let body = "G0 X0 Y0 Z2\nG1 Z-1 F300\nG1 X10\nG0 Z2\n";
    let input = toolpath::gcode::parse(
        Path::new("two.ngc"),
        &format!(
            "G21 G90\nG10 L2 P2 X0 Y0 Z0\nG55\n{body}G10 L2 P2 X0 Y-101.6 Z0\nG55\n{body}M2\n"
        ),
        Dialect::LinuxCnc,
    )
    .unwrap();
    assert_eq!(input.points.last().unwrap().p.y, -101.6);
    let options = reach();
    let sol = optimize(&m, &input, &options).unwrap();
    for dialect in [Dialect::LinuxCnc, Dialect::Fanuc, Dialect::Sinumerik] {
        let prog = program(&m, &input, &sol, &options.geometry, &peak(dialect)).unwrap();
        assert_eq!(
            prog.text.lines().filter(|l| *l == "G55").count(),
            1,
            "{dialect}\n{}",
            prog.text
        );
        assert!(
            prog.text.contains("G1 X10.000000 Y-101.600000 Z-1.000000"),
            "{dialect}\n{}",
            prog.text
        );
        let back = toolpath::gcode::parse(Path::new("b.nc"), &prog.text, dialect).unwrap();
        assert_eq!(back.points.last().unwrap().p.y, -101.6, "{dialect}");
    }
}

#[test]
fn moves_in_machine_coordinates_are_written_in_machine_coordinates() {
    // `G91 G28 Z0` goes to the control's reference point, `G53 Z-10.` to a machine
    // coordinate: the reader places both through the machine file (its reference, else
    // machine zero, and its work offset), which the control does not read. Written as the
    // tip position, the first went to the work origin on NX's Mori program. Written so, the
    // control places them itself; read back with the same machine file, every point is the
    // input's.
    for (dir, file, tcp) in [
        ("xyz_pocket", "machine.json", false),
        ("seed_head_head", "machine.json", true),
    ] {
        let m = Machine::from_file(&root().join(format!("problems/{dir}/{file}"))).unwrap();
        let rotary = if tcp { " A0. C0." } else { "" };
        let on = if tcp { "G43.4 H1\n" } else { "" };
        let text = format!(
            "%\nO1\nG21 G90\nG91 G28 Z0.\nG28 X0. Y0.\nG90\nT1 M6\n{on}G0 X10. Y0. Z5.{rotary}\n\
             G1 Z-1. F300.\nG1 X20.\nG53 G0 Z-10.\nG0 X0. Y0.\nG1 Z-1. F300.\nG91 G28 Z0.\n\
             G90\nM30\n%\n"
        );
        let ctx = toolpath::MachineContext::new(&m, &Default::default());
        let input =
            toolpath::gcode::parse_for(Path::new("m.nc"), &text, Dialect::Fanuc.spec(), Some(&ctx))
                .unwrap();
        // (The second goes where the tool stands, by the machine file: X Y at machine zero
        // from the unknown start taken as 0. No block of the schedule ends there; it is
        // written all the same.)
        assert_eq!(input.machine_points.len(), 4);
        let options = reach();
        let sol = optimize(&m, &input, &options).unwrap();
        for dialect in [Dialect::LinuxCnc, Dialect::Fanuc, Dialect::Sinumerik] {
            let prog = program(&m, &input, &sol, &options.geometry, &peak(dialect)).unwrap();
            let lines: Vec<&str> = prog.text.lines().collect();
            let count = |s: &str| lines.iter().filter(|l| **l == s).count();
            match dialect {
                Dialect::Sinumerik => {
                    assert_eq!(count("G0 SUPA X0.000000 Y0.000000"), 1, "{}", prog.text);
                    assert_eq!(count("G0 SUPA Z0.000000"), 2, "{}", prog.text);
                    assert_eq!(count("G0 SUPA Z-10.000000"), 1, "{}", prog.text);
                }
                _ => {
                    let xy = count("G91 G28 X0.000000 Y0.000000");
                    assert_eq!(xy, 1, "{dialect}\n{}", prog.text);
                    assert_eq!(count("G91 G28 Z0.000000"), 2, "{dialect}\n{}", prog.text);
                    assert_eq!(count("G53 G0 Z-10.000000"), 1, "{dialect}\n{}", prog.text);
                }
            }
            // Out of tool-tip mode for each.
            if tcp {
                for (k, l) in lines.iter().enumerate() {
                    if l.starts_with("G53") || l.contains("G28") || l.contains("SUPA") {
                        let off = lines[..k].iter().rev().find(|l| {
                            ["G49", "M429", "TRAFOOF", "G43.4 H1", "M428", "TRAORI"].contains(l)
                        });
                        assert!(
                            off.is_none_or(|l| ["G49", "M429", "TRAFOOF"].contains(l)),
                            "{dialect}: line {k} under tool-tip mode\n{}",
                            prog.text
                        );
                    }
                }
            }
            let back = toolpath::gcode::parse_for(
                Path::new("b.nc"),
                &prog.text,
                dialect.spec(),
                Some(&ctx),
            )
            .unwrap();
            let pts = |t: &Toolpath| -> Vec<[f64; 3]> {
                let mut v: Vec<[f64; 3]> = t.points.iter().map(|p| [p.p.x, p.p.y, p.p.z]).collect();
                v.dedup();
                v
            };
            let (a, b) = (pts(&input), pts(&back));
            assert_eq!(a.len(), b.len(), "{dialect}: {a:?}\n{b:?}\n{}", prog.text);
            for (x, y) in a.iter().zip(&b) {
                assert!(
                    x.iter().zip(y).all(|(u, v)| (u - v).abs() < 1e-6),
                    "{dialect}: {a:?}\n{b:?}"
                );
            }
        }
    }
}

/// The xyz pocket's machine, and a program read in `dialect`.
fn xyz_and(name: &str, text: &str, dialect: Dialect) -> (Machine, Toolpath) {
    let m = Machine::from_file(&root().join("problems/xyz_pocket/machine.json")).unwrap();
    (
        m,
        toolpath::gcode::parse(Path::new(name), text, dialect).unwrap(),
    )
}

/// Written with peak feeds (the command line's default) in `dialect`.
fn written_in(m: &Machine, t: &Toolpath, dialect: Dialect) -> feedopt::error::Result<Program> {
    let options = reach();
    let sol = optimize(m, t, &options).unwrap();
    program(m, t, &sol, &options.geometry, &peak(dialect))
}

/// The program read back (no warning), with its points equal to the input's, each tap's
/// feeds in and out the input's, and its schedule's cycle time the input's (the same points
/// at the same feeds: the same schedule).
fn tapped_back(m: &Machine, input: &Toolpath, prog: &Program, dialect: Dialect) -> Toolpath {
    let back = toolpath::gcode::parse(Path::new("back.nc"), &prog.text, dialect).unwrap();
    assert!(back.warnings.is_empty(), "{dialect}: {:?}", back.warnings);
    let at = |t: &Toolpath| -> Vec<[f64; 3]> {
        let mut v: Vec<[f64; 3]> = Vec::new();
        for p in &t.points {
            let q = [p.p.x, p.p.y, p.p.z];
            if v.last() != Some(&q) {
                v.push(q);
            }
        }
        v
    };
    let (want, got) = (at(input), at(&back));
    assert_eq!(got.len(), want.len(), "{dialect}:\n{}", prog.text);
    for (a, b) in got.iter().zip(&want) {
        assert!(
            (0..3).all(|i| (a[i] - b[i]).abs() < 1e-6),
            "{dialect}: {a:?} vs {b:?}"
        );
    }
    assert_eq!(back.taps.len(), input.taps.len(), "{dialect}");
    for (a, b) in back.taps.iter().zip(&input.taps) {
        assert!(
            (a.feed_in - b.feed_in).abs() < 1e-6 * b.feed_in
                && (a.feed_out - b.feed_out).abs() < 1e-6 * b.feed_out
                && (a.dwell - b.dwell).abs() < 1e-9
                && a.left_hand == b.left_hand,
            "{dialect}: {a:?} vs {b:?}"
        );
    }
    // The program's own sum is what its blocks and cycles take at their feeds.
    let time = programmed_time(&back).unwrap() + back.dwell_time();
    assert!(
        (prog.time - time).abs() < 1e-6,
        "{dialect}: {} vs {time}",
        prog.time
    );
    let options = reach();
    let (before, after) = (
        optimize(m, input, &options).unwrap().schedule.cycle_time,
        optimize(m, &back, &options).unwrap().schedule.cycle_time,
    );
    assert!(
        (before - after).abs() <= 1e-3 * before,
        "{dialect}: solved again {after} s, the input {before} s"
    );
    back
}

/// A Fanuc program that mills, taps three holes with a modal G84 (M3, S500, F750 = pitch
/// 1.5 × S in G94) and mills on.
const FANUC_TAPS: &str = "%\nO1000\nG21 G90 G94\nG0 X0 Y0 Z10. S500 M3\nG1 Z0 F300.\n\
    G1 X20. F600.\nG0 Z10.\nG98 G84 X5. Y0 Z-10. R2. F750.\nX15.\nY10.\nG80\nG0 X30. Y5.\n\
    G1 Z0 F300.\nG1 X40. F600.\nG0 Z10.\nM30\n%\n";

/// Each output dialect writes a modal tap's holes as its own tapping cycle, never as feed
/// moves (round 17: an NX Haas program's G84 holes were written as G1 in and out, which
/// strips the thread or breaks the tap), and the written program reads back to the same CL
/// points, the same taps at the same feeds, and the same schedule.
#[test]
fn taps_are_written_as_each_dialects_tapping_cycle_and_read_back_to_the_same_points() {
    let (m, input) = xyz_and("tap.nc", FANUC_TAPS, Dialect::Fanuc);
    assert_eq!(input.taps.len(), 3);
    for (dialect, cycle) in [
        (Dialect::Fanuc, "G99 G84 X"),
        (Dialect::LinuxCnc, "G33.1 Z"),
        (Dialect::Sinumerik, "CYCLE84("),
    ] {
        let prog = written_in(&m, &input, dialect).unwrap();
        // One cycle per hole, and no feed move of a tap's (Z-10 is only ever a cycle's).
        assert_eq!(
            prog.text.matches(cycle).count(),
            3,
            "{dialect}:\n{}",
            prog.text
        );
        assert!(
            !prog
                .text
                .lines()
                .any(|l| l.starts_with("G1") && l.contains("Z-10.")),
            "{dialect}:\n{}",
            prog.text
        );
        tapped_back(&m, &input, &prog, dialect);
    }
}

/// One hole's block in each dialect, as its manual writes it:
/// * Fanuc (Series 30i/0i operator's manual, "Rigid tapping (G84)"): `M29 S…` before
///   `G84 X Y Z R P F K`, F in mm/min under G94 = pitch × S; G99 returns to R, `G80` cancels.
/// * LinuxCNC (G-code reference, "G33.1 Rigid Tapping"): `G33.1 X- Y- Z- K- I- $-`, K the
///   distance per revolution; "for Z only tapping preposition the XY location prior to
///   calling G33.1 and only use a Z word"; the move ends at the original coordinate.
/// * Sinumerik 840D (cycles manual, CYCLE84 "Tapping without compensating chuck"):
///   `CYCLE84(RTP, RFP, SDIS, DP, DPR, DTB, SDAC, MPIT, PIT, POSS, SST, SST1)`, SDAC 3 for M3
///   after the cycle, PIT in the program's unit, SST the speed in, SST1 out.
#[test]
fn a_holes_tapping_block_is_the_manuals_form_in_each_dialect() {
    let one = FANUC_TAPS.replace("X15.\nY10.\n", "");
    let (m, input) = xyz_and("tap.nc", &one, Dialect::Fanuc);
    let block = |dialect: Dialect| -> Vec<String> {
        let prog = written_in(&m, &input, dialect).unwrap();
        let lines: Vec<String> = prog.text.lines().map(String::from).collect();
        // The block over the hole at R, then the cycle, then on to the initial level.
        let at = lines
            .iter()
            .position(|l| l.starts_with("G1 X5.000000 Y0.000000 Z2.000000 "))
            .unwrap_or_else(|| panic!("{dialect}:\n{}", prog.text));
        let end = (at + 1..lines.len())
            .find(|&k| lines[k].starts_with("G1 "))
            .unwrap();
        assert!(lines[end].starts_with("G1 X5.000000 Y0.000000 Z10.000000 "));
        lines[at + 1..end].to_vec()
    };
    assert_eq!(
        block(Dialect::Fanuc),
        [
            "M29 S500",
            "G99 G84 X5.000000 Y0.000000 Z-10.000000 R2.000000 F750.0000",
            "G80"
        ]
    );
    assert_eq!(block(Dialect::LinuxCnc), ["G33.1 Z-10.000000 K1.5"]);
    assert_eq!(
        block(Dialect::Sinumerik),
        ["CYCLE84(2.000000,2.000000,0,-10.000000,,,3,,1.5,0,500,500)"]
    );
}

/// A tap between milling moves changes nothing around it: the program whose holes are
/// bored with G85 (feed in, feed out at the same F: the same points at the same feeds) is
/// written with the same blocks, the tap's two G1 blocks per hole replaced by its cycle.
#[test]
fn a_tap_between_milling_moves_leaves_the_neighbouring_blocks_as_they_are() {
    let (m, tapped) = xyz_and("tap.nc", FANUC_TAPS, Dialect::Fanuc);
    let (_, bored) = xyz_and("bore.nc", &FANUC_TAPS.replace("G84", "G85"), Dialect::Fanuc);
    for dialect in Dialect::GCODE {
        let a = written_in(&m, &tapped, dialect).unwrap();
        let b = written_in(&m, &bored, dialect).unwrap();
        // (Comments name the file.) The tap's cycle lines; the bore's feeds at F750, the
        // only blocks at that feed.
        let tap_words = ["M29 ", "G99 G84", "G80", "G33.1", "CYCLE84("];
        let rest = |text: &str, drop: &dyn Fn(&str) -> bool| -> Vec<String> {
            text.lines()
                .filter(|l| !l.starts_with('(') && !l.starts_with(';'))
                .filter(|l| !drop(l))
                .map(String::from)
                .collect()
        };
        let around_taps = rest(&a.text, &|l| tap_words.iter().any(|w| l.starts_with(w)));
        let around_bores = rest(&b.text, &|l| {
            l.starts_with("G1 ") && l.ends_with(" F750.0000")
        });
        assert_eq!(b.text.matches(" F750.0000").count(), 6, "{}", b.text);
        assert_eq!(
            around_taps, around_bores,
            "{dialect}:\n{}\n---\n{}",
            a.text, b.text
        );
        assert_eq!(
            a.blocks, b.blocks,
            "{dialect}: a cycle stands for the tap's two blocks"
        );
        // The same schedule: the moves around the tap take the time they took.
        assert!((a.time - b.time).abs() < 1e-6, "{} vs {}", a.time, b.time);
    }
}

/// A left-hand tap (G74, the spindle M4) with a dwell at the bottom: Fanuc writes `G74 … P`
/// (P in ms in a Fanuc cycle), Sinumerik a negative PIT (CYCLE84: "the sign of the pitch
/// gives the direction of rotation") and DTB in s; LinuxCNC's G33.1 has no dwell (it reverses
/// at the bottom) and is refused, naming the line. Without the dwell, G33.1 taps in the
/// spindle's M4.
#[test]
fn a_left_hand_tap_with_a_dwell_is_written_where_the_cycle_can_say_it() {
    let text = "%\nO1000\nG21 G90 G94\nG0 X0 Y0 Z10. S400 M4\n\
                G99 G74 X5. Y0 Z-8. R2. P250 F500.\nG80\nG0 Z10.\nM30\n%\n";
    let (m, input) = xyz_and("left.nc", text, Dialect::Fanuc);
    assert!(input.taps[0].left_hand && input.taps[0].dwell == 0.25);
    assert!(input.warnings.is_empty(), "{:?}", input.warnings);
    // A Q (Fanuc peck tapping, machine data) is read as one pass, and said.
    let (_, pecks) = xyz_and(
        "left.nc",
        &text.replace(" P250", " P250 Q3."),
        Dialect::Fanuc,
    );
    assert!(
        pecks
            .warnings
            .iter()
            .any(|w| w.line == 5 && w.message.contains("PCT")),
        "{:?}",
        pecks.warnings
    );
    let fanuc = written_in(&m, &input, Dialect::Fanuc).unwrap();
    assert!(
        fanuc.text.contains(
            "M29 S400\nG99 G74 X5.000000 Y0.000000 Z-8.000000 R2.000000 P250 F500.0000\nG80\n"
        ),
        "{}",
        fanuc.text
    );
    tapped_back(&m, &input, &fanuc, Dialect::Fanuc);
    let sinumerik = written_in(&m, &input, Dialect::Sinumerik).unwrap();
    assert!(
        sinumerik
            .text
            .contains("CYCLE84(2.000000,2.000000,0,-8.000000,,0.250000,4,,-1.25,0,400,400)"),
        "{}",
        sinumerik.text
    );
    tapped_back(&m, &input, &sinumerik, Dialect::Sinumerik);
    let e = written_in(&m, &input, Dialect::LinuxCnc)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("left.nc:5:") && e.contains("G74") && e.contains("dwells 0.25 s"),
        "{e}"
    );
    let (_, no_dwell) = xyz_and("left.nc", &text.replace(" P250", ""), Dialect::Fanuc);
    let linuxcnc = written_in(&m, &no_dwell, Dialect::LinuxCnc).unwrap();
    assert!(
        linuxcnc.text.contains("\nG33.1 Z-8.000000 K1.25\n"),
        "{}",
        linuxcnc.text
    );
    let back = tapped_back(&m, &no_dwell, &linuxcnc, Dialect::LinuxCnc);
    assert!(back.taps[0].left_hand);
}

/// Sinumerik's CYCLE84 retracts at SST1: Sinumerik writes it back, LinuxCNC as G33.1's
/// speed factor I (SST1 / SST), and Fanuc, whose G84 retracts at F (its retract override is
/// machine data), refuses the tap, naming its line.
#[test]
fn a_tap_that_retracts_faster_is_written_where_the_cycle_says_so() {
    let text = "G71 G90 G17 G94\nS500 M3\nG0 X4 Y3 Z20\nF60\n\
                CYCLE84(20,0,2,-12,,,3,,1.5,0,500,1000)\nG0 X30\nM30\n";
    let (m, input) = xyz_and("fast.mpf", text, Dialect::Sinumerik);
    let tap = &input.taps[0];
    assert!((tap.feed_in - 750.0).abs() < 1e-9 && (tap.feed_out - 1500.0).abs() < 1e-9);
    let sinumerik = written_in(&m, &input, Dialect::Sinumerik).unwrap();
    assert!(
        sinumerik
            .text
            .contains("\nCYCLE84(2.000000,2.000000,0,-12.000000,,,3,,1.5,0,500,1000)\n"),
        "{}",
        sinumerik.text
    );
    tapped_back(&m, &input, &sinumerik, Dialect::Sinumerik);
    let linuxcnc = written_in(&m, &input, Dialect::LinuxCnc).unwrap();
    assert!(
        linuxcnc.text.contains("\nG33.1 Z-12.000000 K1.5 I2\n"),
        "{}",
        linuxcnc.text
    );
    tapped_back(&m, &input, &linuxcnc, Dialect::LinuxCnc);
    let e = written_in(&m, &input, Dialect::Fanuc)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("fast.mpf:5:") && e.contains("feeds out at 1500 mm/min, in at 750"),
        "{e}"
    );
}

/// On a machine with tool-tip mode, a tap with every rotary axis at zero is written out of
/// it (Fanuc `G49`, the tool's `G43 H`, the cycle, `G43.4` again; LinuxCNC `M429`/`M428`;
/// Sinumerik `TRAFOOF`/`TRAORI`) and reads back to the same points. With the head turned
/// (C45: the tool still along Z, but out of tool-tip mode the coordinates turn with it) or
/// tilted (A30, the tap along the tool), it is refused as a tilted tap, naming the line.
#[test]
fn a_tap_under_tool_tip_mode_is_written_out_of_it_and_a_tilted_one_is_refused() {
    let (m, _) = bundled("seed_head_head", "impeller_blade.cls");
    let text = |c: &str| {
        format!(
            "%\nO1\nG21 G90 G94\nT2 M6\nG43.4 H2\nG0 X0 Y0 Z50. A0 C{c} S600 M3\n\
             G1 Z10. F1000.\nG1 X10. F800.\nG0 Z20.\nG98 G84 X20. Y0 Z-6. R2. F900.\nG80\n\
             G0 Z50.\nG1 X40. F800.\nG49\nM30\n%\n"
        )
    };
    let input = toolpath::gcode::parse(Path::new("tcp.nc"), &text("0"), Dialect::Fanuc).unwrap();
    for (dialect, around) in [
        (
            Dialect::Fanuc,
            [
                "G49",
                "G43 H2",
                "M29 S600",
                "G99 G84 X20.000000 Y0.000000 Z-6.000000 R2.000000 F900.0000",
                "G80",
                "G43.4 H2",
            ],
        ),
        (
            Dialect::LinuxCnc,
            ["M429", "G33.1 Z-6.000000 K1.5", "M428", "", "", ""],
        ),
        (
            Dialect::Sinumerik,
            [
                "TRAFOOF",
                "CYCLE84(2.000000,2.000000,0,-6.000000,,,3,,1.5,0,600,600)",
                "TRAORI",
                "",
                "",
                "",
            ],
        ),
    ] {
        let prog = written_in(&m, &input, dialect).unwrap();
        let want: Vec<&str> = around.iter().copied().filter(|l| !l.is_empty()).collect();
        let lines: Vec<&str> = prog.text.lines().collect();
        assert!(
            lines.windows(want.len()).any(|w| w == want.as_slice()),
            "{dialect}:\n{}",
            prog.text
        );
        tapped_back(&m, &input, &prog, dialect);
    }
    let turned = toolpath::gcode::parse(Path::new("tcp.nc"), &text("45"), Dialect::Fanuc).unwrap();
    let e = written_in(&m, &turned, Dialect::Fanuc)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("tcp.nc:10:") && e.contains("rotary axes stand at"),
        "{e}"
    );
    // The head tilted (A30) under tool-tip mode, the cycle along the part's Z (no tilted
    // plane: as NX's Mori NMV5000 and DMU 70 eVo programs tap): the tap would feed 30° off its
    // own axis, which no cycle written reproduces.
    let tilted = text("0").replace("G98 G84", "G0 A30.\nG98 G84");
    let tilted = toolpath::gcode::parse(Path::new("tcp.nc"), &tilted, Dialect::Fanuc).unwrap();
    let e = written_in(&m, &tilted, Dialect::Fanuc)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("tcp.nc:11:")
            && e.contains("30.000° off the direction the cycle feeds")
            && e.contains("A30"),
        "{e}"
    );
    // APT: the tap along a tool tilted 30° about X.
    let (s, c) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
    let apt = toolpath::apt::parse(
        Path::new("tilt.cls"),
        &format!(
            "FEDRAT/MMPM,300\nSPINDL/RPM,500,CLW\nGOTO/0,0,20,0,{},{}\n\
             CYCLE/TAP,FEDTO,10,MMPM,750,RAPTO,2\nGOTO/5,0,0,0,{},{}\nCYCLE/OFF\nGOTO/5,0,20\n",
            -s, c, -s, c
        ),
    )
    .unwrap();
    let e = written_in(&m, &apt, Dialect::Sinumerik)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("tilt.cls:5:") && e.contains("30.000° off Z") && e.contains("not written yet"),
        "{e}"
    );
}

/// Klartext 207 (rigid tapping) is written in each dialect; 209 with chip breaking (Q257: in
/// steps, back Q256 between them) is refused: its steps are no output cycle's. APT's
/// `CYCLE/TAP` is written (the speed is the `SPINDL/`'s).
#[test]
fn klartext_and_apt_taps_are_written_and_chip_breaking_is_refused() {
    let m = Machine::from_file(&root().join("problems/xyz_pocket/machine.json")).unwrap();
    let klartext = |cycle: &str, extra: &str| {
        format!(
            "0 BEGIN PGM T MM\n1 TOOL CALL 3 Z S1000\n2 M3\n3 L X+0 Y+0 Z+10 R0 FMAX\n\
             4 CYCL DEF {cycle}~\n Q200=3 ;SET-UP CLEARANCE~\n Q201=-12 ;DEPTH~\n\
             Q239=+1.5 ;THREAD PITCH~\n Q203=0 ;SURFACE COORDINATE~\n{extra}\
             Q204=5 ;2ND SET-UP CLEARANCE\n5 L X+0 Y+0 R0 F MAX M99\n6 END PGM T MM\n"
        )
    };
    let t207 = toolpath::gcode::parse(
        Path::new("tap.h"),
        &klartext("207 RIGID TAPPING NEW", ""),
        Dialect::Heidenhain,
    )
    .unwrap();
    for dialect in Dialect::GCODE {
        let prog = written_in(&m, &t207, dialect).unwrap();
        tapped_back(&m, &t207, &prog, dialect);
    }
    let t209 = toolpath::gcode::parse(
        Path::new("tap.h"),
        &klartext(
            "209 TAPPING W/ CHIP BRKG",
            " Q257=4 ;DEPTH FOR CHIP BRKG~\n Q256=1 ;DIST FOR CHIP BRKG~\n Q336=0 ;ANGLE OF SPINDLE~\n",
        ),
        Dialect::Heidenhain,
    )
    .unwrap();
    let call = 1 + klartext("209", "")
        .lines()
        .position(|l| l.contains("M99"))
        .unwrap();
    let e = written_in(&m, &t209, Dialect::Fanuc)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!("tap.h:{}:", call + 3)) && e.contains("breaks chips"),
        "{e}"
    );
    let apt = toolpath::apt::parse(
        Path::new("tap.cls"),
        "FEDRAT/MMPM,300\nSPINDL/RPM,500,CLW\nGOTO/0,0,20\nCYCLE/TAP,FEDTO,10,MMPM,750,RAPTO,2\n\
         GOTO/5,0,0\nCYCLE/OFF\nGOTO/5,0,20\n",
    )
    .unwrap();
    let prog = written_in(&m, &apt, Dialect::Fanuc).unwrap();
    assert!(
        prog.text.contains(
            "\nM29 S500\nG99 G84 X5.000000 Y0.000000 Z-10.000000 R2.000000 F750.0000\nG80\n"
        ),
        "{}",
        prog.text
    );
    tapped_back(&m, &apt, &prog, Dialect::Fanuc);
    // Without a spindle speed the cycle has no pitch to tap at: refused, naming the line.
    let no_speed = toolpath::apt::parse(
        Path::new("tap.cls"),
        "FEDRAT/MMPM,300\nGOTO/0,0,20\nCYCLE/TAP,FEDTO,10,MMPM,750,RAPTO,2\nGOTO/5,0,0\n\
         CYCLE/OFF\nGOTO/5,0,20\n",
    )
    .unwrap();
    let e = written_in(&m, &no_speed, Dialect::Sinumerik)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("tap.cls:4:") && e.contains("no spindle speed"),
        "{e}"
    );
}
