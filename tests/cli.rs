//! End-to-end tests of the `feedopt` binary: `feedopt solve` on tiny machine and APT CL files
//! written into a temporary directory.
//!
//! Every solve passes `--stations` so that a debug build finishes well under a second (the
//! automatic refinement starts at 1000 stations).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;
use tempfile::TempDir;

/// X velocity 400 mm/s, acceleration 2000 mm/s²: a 100 mm/s feed binds, not the X velocity.
const XYZ_MACHINE: &str = r#"{
  "name": "test router",
  "kinematics": {"type": "xyz"},
  "axes": {
    "X": {"velocity": 400, "acceleration": 2000},
    "Y": {"velocity": 400, "acceleration": 2000},
    "Z": {"velocity": 300, "acceleration": 1500}
  },
  "feed": {"max": 150}
}
"#;

const HEAD_HEAD_MACHINE: &str = r#"{
  "name": "test double swivel head",
  "kinematics": {"type": "head_head", "tool_length": 200.0},
  "axes": {
    "X": {"velocity": 400, "acceleration": 2000},
    "Y": {"velocity": 400, "acceleration": 2000},
    "Z": {"velocity": 300, "acceleration": 1500},
    "C": {"velocity": 120, "acceleration": 600},
    "A": {"velocity": 60, "acceleration": 400}
  },
  "feed": {"max": 150}
}
"#;

/// 6000 mm/min = 100 mm/s along a 100 mm straight line in X.
const LINE: &str = "FEDRAT/MMPM,6000\nGOTO/0,0,0\nGOTO/100,0,0\n";
const LENGTH_MM: f64 = 100.0;
const FEED_MM_S: f64 = 100.0;
const X_ACCELERATION: f64 = 2000.0;

/// Station intervals for every solve (keeps debug builds fast; the acceleration ramps of
/// F²/(2a) = 2.5 mm fall on stations, so the discrete optimum is the exact one).
const STATIONS: &str = "200";

/// A temporary working directory; the binary runs inside it and files are named relative to it.
struct Work {
    dir: TempDir,
}

impl Work {
    fn new() -> Work {
        Work {
            dir: tempfile::tempdir().expect("create temp dir"),
        }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn write(&self, name: &str, text: &str) {
        std::fs::write(self.path(name), text).expect("write input file");
    }

    fn read(&self, name: &str) -> String {
        std::fs::read_to_string(self.path(name))
            .unwrap_or_else(|e| panic!("cannot read {name}: {e}"))
    }

    /// `feedopt solve -m machine.json line.cls --stations STATIONS` plus `extra`.
    fn solve_line(&self, extra: &[&str]) -> Output {
        let mut args = vec![
            "solve",
            "-m",
            "machine.json",
            "line.cls",
            "--stations",
            STATIONS,
        ];
        args.extend_from_slice(extra);
        self.run(&args)
    }

    /// Runs `feedopt` with `args` in the directory.
    fn run(&self, args: &[&str]) -> Output {
        Command::new(env!("CARGO_BIN_EXE_feedopt"))
            .args(args)
            .current_dir(self.dir.path())
            .output()
            .expect("run feedopt")
    }

    /// Every entry of the directory, hidden ones included.
    fn listing(&self) -> BTreeSet<String> {
        std::fs::read_dir(self.dir.path())
            .expect("list temp dir")
            .map(|e| {
                e.expect("dir entry")
                    .file_name()
                    .to_string_lossy()
                    .into_owned()
            })
            .collect()
    }

    fn assert_listing(&self, expected: &[&str]) {
        let expected: BTreeSet<String> = expected.iter().map(|s| s.to_string()).collect();
        assert_eq!(
            self.listing(),
            expected,
            "unexpected files in {}",
            self.dir.path().display()
        );
    }
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn assert_success(out: &Output) {
    assert!(
        out.status.success(),
        "feedopt failed with {:?}\nstderr: {}",
        out.status,
        stderr(out)
    );
}

/// Asserts exit code 2, nothing on stdout and exactly one line on stderr containing every one
/// of `needles`; returns that line.
fn assert_error(out: &Output, needles: &[&str]) -> String {
    let err = stderr(out);
    assert_eq!(
        out.status.code(),
        Some(2),
        "expected exit code 2\nstdout: {}\nstderr: {err}",
        stdout(out)
    );
    assert!(
        out.stdout.is_empty(),
        "stdout not empty on error: {}",
        stdout(out)
    );
    assert!(
        err.ends_with('\n'),
        "stderr not newline-terminated: {err:?}"
    );
    assert_eq!(err.lines().count(), 1, "stderr is not one line: {err:?}");
    for needle in needles {
        assert!(
            err.contains(needle),
            "stderr does not mention `{needle}`: {err}"
        );
    }
    err
}

fn num(v: &Value, what: &str) -> f64 {
    v.as_f64()
        .unwrap_or_else(|| panic!("`{what}` is not a number: {v}"))
}

fn parse_json(text: &str, what: &str) -> Value {
    serde_json::from_str(text)
        .unwrap_or_else(|e| panic!("{what} is not one JSON value: {e}\n{text}"))
}

fn assert_rel(got: f64, want: f64, rel: f64, what: &str) {
    assert!(
        (got - want).abs() <= rel * want.abs(),
        "{what}: got {got}, want {want} (within {rel})"
    );
}

/// Rest-to-rest straight line with the feed binding: accelerate at `a` to `f`, cruise, brake.
fn closed_form_cycle_time() -> f64 {
    const { assert!(LENGTH_MM >= FEED_MM_S * FEED_MM_S / X_ACCELERATION) };
    LENGTH_MM / FEED_MM_S + FEED_MM_S / X_ACCELERATION
}

// ---------------------------------------------------------------------------------------------
// Success
// ---------------------------------------------------------------------------------------------

#[test]
fn json_summary_of_a_straight_line() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write("line.cls", LINE);
    let out = w.run(&[
        "solve",
        "--machine",
        "machine.json",
        "line.cls",
        "--json",
        "--stations",
        STATIONS,
    ]);
    assert_success(&out);
    let text = stdout(&out);
    // Exactly one JSON object on stdout (from_str rejects trailing values).
    let v = parse_json(&text, "stdout");
    assert!(v.is_object(), "stdout is not a JSON object: {text}");

    let t = num(&v["cycle_time_s"], "cycle_time_s");
    let expected = closed_form_cycle_time();
    assert!((expected - 1.05).abs() < 1e-12);
    assert_rel(t, expected, 1e-3, "cycle_time_s");

    let stations = v["stations"]
        .as_u64()
        .unwrap_or_else(|| panic!("`stations` is not an integer: {}", v["stations"]));
    assert!(stations >= 200, "stations = {stations}");
    assert_eq!(v["status"], "optimal");
    let solve_time = num(&v["solve_time_s"], "solve_time_s");
    assert!((0.0..60.0).contains(&solve_time), "{solve_time}");
    assert_rel(
        num(&v["path_length_mm"], "path_length_mm"),
        LENGTH_MM,
        1e-9,
        "path_length_mm",
    );

    // X does all the moving: it reaches F/v = 0.25 of its velocity limit and all of its
    // acceleration; Y and Z stand still.
    let x = &v["axes"]["X"];
    assert_rel(
        num(&x["peak_velocity_ratio"], "axes.X.peak_velocity_ratio"),
        FEED_MM_S / 400.0,
        1e-3,
        "axes.X.peak_velocity_ratio",
    );
    assert_rel(
        num(
            &x["peak_acceleration_ratio"],
            "axes.X.peak_acceleration_ratio",
        ),
        1.0,
        1e-3,
        "axes.X.peak_acceleration_ratio",
    );
    for axis in ["Y", "Z"] {
        let a = &v["axes"][axis];
        assert!(num(&a["peak_velocity_ratio"], "peak_velocity_ratio").abs() < 1e-6);
        assert!(num(&a["peak_acceleration_ratio"], "peak_acceleration_ratio").abs() < 1e-6);
    }
    w.assert_listing(&["machine.json", "line.cls"]);
}

#[test]
fn readable_report_mentions_cycle_time() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write("line.apt", LINE);
    let out = w.run(&[
        "solve",
        "-m",
        "machine.json",
        "line.apt",
        "--stations",
        STATIONS,
    ]);
    assert_success(&out);
    let text = stdout(&out);
    assert!(text.contains("cycle time"), "report: {text}");
    assert!(
        text.contains("1.05"),
        "report lacks the cycle time 1.05: {text}"
    );
    assert!(
        text.contains("line.apt"),
        "report lacks the toolpath: {text}"
    );
    assert!(
        serde_json::from_str::<Value>(&text).is_err(),
        "readable report is JSON"
    );
}

#[test]
fn csv_schedule() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write("line.cls", LINE);
    let out = w.solve_line(&["--json", "-o", "out.csv"]);
    assert_success(&out);
    let summary = parse_json(&stdout(&out), "stdout");
    let cycle_time = num(&summary["cycle_time_s"], "cycle_time_s");
    let stations = summary["stations"].as_u64().expect("stations") as usize;

    let csv = w.read("out.csv");
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("CSV header").split(',').collect();
    assert_eq!(header[..6], ["span", "u", "s", "t", "v", "a"]);
    for col in [
        "q_X", "q_Y", "q_Z", "qd_X", "qd_Y", "qd_Z", "qdd_X", "qdd_Y", "qdd_Z",
    ] {
        assert!(header.contains(&col), "CSV header lacks {col}: {header:?}");
    }
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| {
            let row: Vec<f64> = l
                .split(',')
                .map(|x| x.parse().unwrap_or_else(|_| panic!("bad CSV value `{x}`")))
                .collect();
            assert_eq!(row.len(), header.len(), "CSV row width: {l}");
            row
        })
        .collect();
    assert_eq!(rows.len(), stations, "one CSV row per station");
    let (first, last) = (&rows[0], &rows[rows.len() - 1]);
    assert_eq!(first[col("t")], 0.0);
    assert_rel(last[col("t")], cycle_time, 1e-9, "last t vs cycle_time_s");
    assert_rel(last[col("s")], LENGTH_MM, 1e-9, "last s");
    assert_rel(last[col("q_X")], LENGTH_MM, 1e-9, "last q_X");
    // Rest to rest; cruising at the programmed feed in the middle.
    assert!(first[col("v")].abs() < 1e-6 && last[col("v")].abs() < 1e-6);
    assert_rel(
        rows[rows.len() / 2][col("v")],
        FEED_MM_S,
        1e-3,
        "mid-path feed",
    );
    w.assert_listing(&["machine.json", "line.cls", "out.csv"]);
}

/// The schedule file's times count the program's dwells as `cycle_time_s` does: a dwell is
/// the gap between the last station of the span before it and the first of the next, where
/// the tool stands (they were left out: the last t fell short of the cycle time by them).
#[test]
fn the_schedule_file_counts_the_dwells() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write(
        "dwell.ngc",
        "G21 G90 G94\nG0 X0 Y0 Z0\nG1 X10 F600\nG4 P1.5\nG1 X20\nG4 P0.5\nM2\n",
    );
    let out = w.run(&[
        "solve",
        "-m",
        "machine.json",
        "dwell.ngc",
        "--json",
        "-o",
        "out.csv",
    ]);
    assert_success(&out);
    let summary = parse_json(&stdout(&out), "stdout");
    let cycle_time = num(&summary["cycle_time_s"], "cycle_time_s");
    assert_rel(
        num(&summary["dwell_time_s"], "dwell_time_s"),
        2.0,
        1e-12,
        "dwells",
    );
    let csv = w.read("out.csv");
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("CSV header").split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_rel(
        rows[rows.len() - 1][col("t")],
        cycle_time - 0.5,
        1e-9,
        "last t",
    );
    // The two spans meet at X10, where the tool stands 1.5 s.
    let k = rows.iter().position(|r| r[col("span")] == 1.0).unwrap();
    let (end, start) = (&rows[k - 1], &rows[k]);
    assert_eq!((end[col("q_X")], start[col("q_X")]), (10.0, 10.0));
    assert_eq!((end[col("v")], start[col("v")]), (0.0, 0.0));
    assert_rel(start[col("t")] - end[col("t")], 1.5, 1e-9, "dwell gap");
}

#[test]
fn json_schedule() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write("line.cls", LINE);
    let out = w.solve_line(&["--json", "--output", "out.json"]);
    assert_success(&out);
    let summary = parse_json(&stdout(&out), "stdout");
    let cycle_time = num(&summary["cycle_time_s"], "cycle_time_s");
    assert_rel(cycle_time, closed_form_cycle_time(), 1e-3, "cycle_time_s");

    let doc = parse_json(&w.read("out.json"), "out.json");
    assert_rel(
        num(&doc["cycle_time_s"], "out.json cycle_time_s"),
        cycle_time,
        1e-12,
        "out.json cycle_time_s",
    );
    assert_eq!(doc["axes"], serde_json::json!(["X", "Y", "Z"]));
    let stations = doc["stations"].as_array().expect("`stations` array");
    assert_eq!(
        stations.len() as u64,
        summary["stations"].as_u64().unwrap(),
        "station count"
    );
    let first = &stations[0];
    let last = stations.last().unwrap();
    assert_eq!(num(&first["t"], "t"), 0.0);
    assert_rel(num(&last["t"], "t"), cycle_time, 1e-9, "last t");
    assert_rel(num(&last["s"], "s"), LENGTH_MM, 1e-9, "last s");
    assert_rel(num(&last["q"]["X"], "q.X"), LENGTH_MM, 1e-9, "last q.X");
    for key in ["span", "u", "v", "a"] {
        num(&last[key], key);
    }
    for key in ["qd", "qdd"] {
        num(&last[key]["X"], key);
    }
    // Time increases along the schedule.
    let times: Vec<f64> = stations.iter().map(|s| num(&s["t"], "t")).collect();
    assert!(times.windows(2).all(|p| p[1] > p[0]), "t not increasing");
    w.assert_listing(&["machine.json", "line.cls", "out.json"]);
}

// ---------------------------------------------------------------------------------------------
// Errors: exit code 2, one line on stderr, no output file and no temp file left behind
// ---------------------------------------------------------------------------------------------

/// Runs a solve that must fail with `-o out.json`; checks stderr and that the directory holds
/// exactly the input files afterwards.
fn solve_fails(
    w: &Work,
    machine: &str,
    toolpath: &str,
    inputs: &[&str],
    needles: &[&str],
) -> String {
    let out = w.run(&[
        "solve",
        "-m",
        machine,
        toolpath,
        "--stations",
        STATIONS,
        "-o",
        "out.json",
    ]);
    let line = assert_error(&out, needles);
    assert!(!w.path("out.json").exists(), "out.json written on error");
    w.assert_listing(inputs);
    line
}

#[test]
fn bad_number_in_toolpath_names_file_and_line() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write(
        "bad.cls",
        "FEDRAT/MMPM,6000\nGOTO/0,0,0\nGOTO/1.0,abc,3\nGOTO/5,0,0\n",
    );
    let line = solve_fails(
        &w,
        "machine.json",
        "bad.cls",
        &["machine.json", "bad.cls"],
        &["bad.cls:3:", "abc"],
    );
    assert!(line.contains("GOTO"), "stderr: {line}");
}

#[test]
fn machine_missing_limit_names_file_and_field() {
    let w = Work::new();
    let machine = XYZ_MACHINE.replace(
        r#""Y": {"velocity": 400, "acceleration": 2000}"#,
        r#""Y": {"velocity": 400}"#,
    );
    assert_ne!(machine, XYZ_MACHINE);
    w.write("machine.json", &machine);
    w.write("line.cls", LINE);
    solve_fails(
        &w,
        "machine.json",
        "line.cls",
        &["machine.json", "line.cls"],
        &["machine.json", "axes.Y.acceleration", "missing"],
    );
}

#[test]
fn machine_negative_limit_names_file_and_field() {
    let w = Work::new();
    let machine = XYZ_MACHINE.replace(r#""Y": {"velocity": 400,"#, r#""Y": {"velocity": -5,"#);
    assert_ne!(machine, XYZ_MACHINE);
    w.write("machine.json", &machine);
    w.write("line.cls", LINE);
    solve_fails(
        &w,
        "machine.json",
        "line.cls",
        &["machine.json", "line.cls"],
        &["machine.json", "axes.Y.velocity", "-5"],
    );
}

#[test]
fn machine_invalid_json_names_file_and_line() {
    let w = Work::new();
    // Line 5 (axis X) lacks its trailing comma; the parser notices on line 6.
    let machine = XYZ_MACHINE.replace(
        r#""X": {"velocity": 400, "acceleration": 2000},"#,
        r#""X": {"velocity": 400, "acceleration": 2000}"#,
    );
    assert_ne!(machine, XYZ_MACHINE);
    w.write("machine.json", &machine);
    w.write("line.cls", LINE);
    solve_fails(
        &w,
        "machine.json",
        "line.cls",
        &["machine.json", "line.cls"],
        &["machine.json:6:"],
    );
}

#[test]
fn zero_tool_vector_on_five_axis_machine() {
    let w = Work::new();
    w.write("machine.json", HEAD_HEAD_MACHINE);
    w.write(
        "five.cls",
        "MULTAX/ON\nFEDRAT/MMPM,3000\nGOTO/0,0,0,0,0,1\nGOTO/10,0,0,0,0,0\nGOTO/20,0,0,0,0,1\n",
    );
    let line = solve_fails(
        &w,
        "machine.json",
        "five.cls",
        &["machine.json", "five.cls"],
        &["five.cls:4:"],
    );
    assert!(line.contains("tool vector"), "stderr: {line}");
}

#[test]
fn missing_toolpath_file() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    solve_fails(
        &w,
        "machine.json",
        "nowhere.cls",
        &["machine.json"],
        &["nowhere.cls", "no such file: check the path"],
    );
}

#[test]
fn missing_machine_file() {
    let w = Work::new();
    w.write("line.cls", LINE);
    solve_fails(
        &w,
        "nomachine.json",
        "line.cls",
        &["line.cls"],
        &["nomachine.json"],
    );
}

#[test]
fn unknown_toolpath_extension() {
    // Issue 12: an extension feedopt does not know is read by content (a GOTO/ record is
    // APT), and the summary says so; content that is neither APT nor G-code is an error that
    // says what to give.
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write("line.txt", LINE);
    let out = w.run(&["solve", "--machine", "machine.json", "line.txt"]);
    assert_success(&out);
    assert!(
        stdout(&out).contains("read as       apt (content)"),
        "{}",
        stdout(&out)
    );
    w.write("notes.xyz", "hello\n");
    let line = solve_fails(
        &w,
        "machine.json",
        "notes.xyz",
        &["machine.json", "line.txt", "notes.xyz"],
        &["notes.xyz", ".xyz"],
    );
    assert!(
        line.contains("--format"),
        "message does not say what is wrong and what is expected: {line}"
    );
}

#[test]
fn unknown_output_extension() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write("line.cls", LINE);
    let out = w.solve_line(&["-o", "out.txt"]);
    assert_error(&out, &["out.txt", ".json", ".csv"]);
    w.assert_listing(&["machine.json", "line.cls"]);
}

#[test]
fn bad_station_count_is_a_usage_error() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write("line.cls", LINE);
    let out = w.run(&[
        "solve",
        "-m",
        "machine.json",
        "line.cls",
        "--stations",
        "1",
        "-o",
        "out.json",
    ]);
    assert_error(&out, &["--stations"]);
    w.assert_listing(&["machine.json", "line.cls"]);
}

/// Absolute paths work as well as names relative to the current directory.
#[test]
fn absolute_paths() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write("line.cls", LINE);
    let abs_out = w.path("abs.json");
    let out = w.run(&[
        "solve",
        "-m",
        w.path("machine.json").to_str().unwrap(),
        w.path("line.cls").to_str().unwrap(),
        "--stations",
        "20",
        "-o",
        abs_out.to_str().unwrap(),
    ]);
    assert_success(&out);
    assert!(Path::new(&abs_out).is_file());
    w.assert_listing(&["machine.json", "line.cls", "abs.json"]);
}

/// Every subcommand's arguments are well formed (clap's own consistency check: unique names,
/// valid defaults), so no flattened option set can clash with another at run time.
#[test]
fn command_line_definition_is_consistent() {
    use clap::CommandFactory;
    feedopt::cli::Cli::command().debug_assert();
}

// ---------------------------------------------------------------------------------------------
// Issue 14: outputs never overwrite inputs, fail before the solve, work bounded up front
// ---------------------------------------------------------------------------------------------

/// Two 1 m/s² joint axes along s ∈ [0, 1] (for `interpolate` onto a CSV input).
const JOINT_MACHINE: &str = r#"{"kinematics": {"type": "joint"},
  "axes": {"a": {"velocity": 1, "acceleration": 1}, "b": {"velocity": 1, "acceleration": 1}}}"#;
const JOINT_PATH: &str = "s,q_a,q_b\n0,0,0\n0.5,0.5,0.25\n1,1,0.5\n";

/// Asserts that `name` still holds `text`.
fn assert_unchanged(w: &Work, name: &str, text: &str) {
    assert_eq!(w.read(name), text, "{name} was changed");
}

#[test]
fn output_onto_an_input_is_refused_and_the_input_unchanged() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write("line.cls", LINE);
    w.write("line.ngc", "G21 G90 G94\nF6000\nG0 X0 Y0 Z0\nG1 X100\nM2\n");
    w.write("jm.json", JOINT_MACHINE);
    w.write("joint.csv", JOINT_PATH);
    // solve -o onto the machine file, by its name and by another spelling.
    for out in ["machine.json", "./machine.json"] {
        let line = assert_error(
            &w.solve_line(&["-o", out]),
            &["-o", "machine file", "overwrite"],
        );
        assert!(line.contains(out), "{line}");
    }
    // A symbolic link and a hard link to an input are the input.
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink("machine.json", w.path("link.json")).unwrap();
        assert_error(
            &w.solve_line(&["-o", "link.json"]),
            &["link.json", "overwrite"],
        );
        std::fs::hard_link(w.path("machine.json"), w.path("hard.json")).unwrap();
        assert_error(
            &w.solve_line(&["-o", "hard.json"]),
            &["hard.json", "overwrite"],
        );
    }
    // solve -o onto a CSV toolpath; --plot onto a toolpath read with --format.
    let joint = |cmd: &str, extra: &[&str]| {
        let mut args = vec![cmd, "-m", "jm.json", "joint.csv", "--stations", "20"];
        args.extend_from_slice(extra);
        w.run(&args)
    };
    assert_error(
        &joint("solve", &["-o", "joint.csv"]),
        &["toolpath", "joint.csv"],
    );
    // interpolate -o onto the CSV toolpath.
    assert_error(
        &joint("interpolate", &["-o", "joint.csv"]),
        &["toolpath", "joint.csv"],
    );
    // sweep -o onto the machine file.
    assert_error(
        &joint(
            "sweep",
            &[
                "--axis", "a", "--limit", "velocity", "--from", "0.5", "--to", "1", "--steps", "2",
                "-o", "jm.json",
            ],
        ),
        &["machine file", "jm.json"],
    );
    // gcode -o onto its .ngc input.
    assert_error(
        &w.run(&[
            "gcode",
            "-m",
            "machine.json",
            "line.ngc",
            "--stations",
            "20",
            "-o",
            "line.ngc",
        ]),
        &["toolpath", "line.ngc", "overwrite"],
    );
    // --plot onto the toolpath (read as APT whatever its name).
    w.write("path.svg", LINE);
    assert_error(
        &w.run(&[
            "solve",
            "-m",
            "machine.json",
            "path.svg",
            "--format",
            "apt",
            "--stations",
            "20",
            "--plot",
            "path.svg",
        ]),
        &["--plot", "toolpath", "path.svg"],
    );
    assert_unchanged(&w, "machine.json", XYZ_MACHINE);
    assert_unchanged(&w, "jm.json", JOINT_MACHINE);
    assert_unchanged(&w, "joint.csv", JOINT_PATH);
    assert_unchanged(&w, "line.cls", LINE);
    assert_unchanged(&w, "path.svg", LINE);
    assert!(w.read("line.ngc").starts_with("G21 G90 G94\n"));
}

#[test]
fn an_unwritable_output_fails_before_the_solve_naming_the_path() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    // The toolpath does not exist: an error about it would mean the output was checked late.
    let out = w.run(&[
        "interpolate",
        "-m",
        "machine.json",
        "nowhere.cls",
        "-o",
        "missing/set.csv",
    ]);
    assert_error(&out, &["missing/set.csv", "does not exist"]);
    w.write("line.cls", LINE);
    for cmd in ["solve", "interpolate"] {
        let out = w.run(&[
            cmd,
            "-m",
            "machine.json",
            "line.cls",
            "--stations",
            "20",
            "-o",
            "missing/x.csv",
        ]);
        assert_error(&out, &["missing/x.csv", "does not exist"]);
    }
    // An existing directory as the output.
    std::fs::create_dir(w.path("dir.csv")).unwrap();
    let out = w.solve_line(&["-o", "dir.csv"]);
    assert_error(&out, &["dir.csv", "not a regular file"]);
    w.assert_listing(&["machine.json", "line.cls", "dir.csv"]);
}

#[cfg(target_os = "linux")]
#[test]
fn an_output_in_a_directory_that_takes_no_files_fails_before_the_solve() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    for cmd in ["solve", "interpolate"] {
        let out = w.run(&[
            cmd,
            "-m",
            "machine.json",
            "nowhere.cls",
            "-o",
            "/proc/version.csv",
        ]);
        assert_error(
            &out,
            &["/proc/version.csv", "cannot create a file in /proc"],
        );
    }
}

/// Runs `feedopt ARGS` on the straight line and asserts a quick one-line error mentioning
/// `needles` and no `inf`/`NaN`.
fn refused_quickly(w: &Work, args: &[&str], needles: &[&str]) {
    let t0 = std::time::Instant::now();
    let out = w.run(args);
    let line = assert_error(&out, needles);
    assert!(
        t0.elapsed().as_secs_f64() < 10.0,
        "{args:?} took {:?}",
        t0.elapsed()
    );
    assert!(
        !line.contains("inf ") && !line.contains("NaN"),
        "not in words: {line}"
    );
}

#[test]
fn work_is_bounded_before_it_starts() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write("line.cls", LINE);
    fn solve<'a>(extra: &[&'a str]) -> Vec<&'a str> {
        let mut a = vec!["solve", "-m", "machine.json", "line.cls"];
        a.extend_from_slice(extra);
        a
    }
    refused_quickly(
        &w,
        &solve(&["--stations", "100000000"]),
        &["--stations", "4000000"],
    );
    refused_quickly(
        &w,
        &solve(&["--period", "1e-12"]),
        &["--period", "1 µs to 1 s"],
    );
    refused_quickly(&w, &solve(&["--period", "10s"]), &["--period"]);
    refused_quickly(
        &w,
        &solve(&["--chord-tolerance", "1e-300"]),
        &["--chord-tolerance", "1e-6 mm"],
    );
    refused_quickly(
        &w,
        &solve(&["--start-feed", "1e300"]),
        &["--start-feed", "1e300"],
    );
    refused_quickly(&w, &solve(&["--end-feed", "inf"]), &["--end-feed"]);
    refused_quickly(
        &w,
        &solve(&["--feed-override", "1e-300"]),
        &["--feed-override", "1e-300", "0.001 to 1000"],
    );
    // Above the machine's feed.max (150 mm/s): no schedule can start there.
    refused_quickly(
        &w,
        &solve(&["--start-feed", "151"]),
        &["--start-feed", "feed.max = 150"],
    );
    fn sweep<'a>(extra: &[&'a str]) -> Vec<&'a str> {
        let mut a = vec![
            "sweep",
            "-m",
            "machine.json",
            "line.cls",
            "--stations",
            "20",
            "--axis",
            "X",
            "--limit",
            "acceleration",
        ];
        a.extend_from_slice(extra);
        a
    }
    refused_quickly(
        &w,
        &sweep(&["--from", "100", "--to", "200", "--steps", "1000000000"]),
        &["--steps", "10000"],
    );
    refused_quickly(
        &w,
        &sweep(&["--from", "1e-300", "--to", "200"]),
        &["--from", "X acceleration", "2000"],
    );
    refused_quickly(
        &w,
        &sweep(&["--from", "100", "--to", "1e12"]),
        &["--to", "1/1000 to 1000 times"],
    );
    w.write("head.json", HEAD_HEAD_MACHINE);
    w.write(
        "turn.cls",
        "MULTAX/ON\nFEDRAT/MMPM,3000\nGOTO/0,0,0,0,0,1\nGOTO/10,0,0,0.5,0,0.866025\n",
    );
    refused_quickly(
        &w,
        &[
            "gcode",
            "-m",
            "head.json",
            "turn.cls",
            "--stations",
            "20",
            "-o",
            "out.ngc",
            "--max-rotation-deg",
            "1e-6",
        ],
        &["--max-rotation-deg", "0.001"],
    );
    w.assert_listing(&["machine.json", "line.cls", "head.json", "turn.cls"]);
}

/// The library checks the options (`feedopt::validate`); the command line names its own flag
/// for the field the library names, in one line.
#[test]
fn an_option_the_library_refuses_is_named_by_its_flag() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write("line.cls", LINE);
    fn solve<'a>(extra: &[&'a str]) -> Vec<&'a str> {
        let mut a = vec!["solve", "-m", "machine.json", "line.cls"];
        a.extend_from_slice(extra);
        a
    }
    for (args, needles) in [
        (
            solve(&["--corner-angle", "200"]),
            &["--corner-angle", "180"][..],
        ),
        (solve(&["--tolerance=-1"]), &["--tolerance ", "≥ 0 mm"]),
        (
            solve(&["--tolerance-deg=-1"]),
            &["--tolerance-deg", "≥ 0 degrees"],
        ),
        (
            vec![
                "compare",
                "-m",
                "machine.json",
                "line.cls",
                "--junction-deviation=-1",
            ],
            &["--junction-deviation", "≥ 0 mm"],
        ),
        (
            vec![
                "sweep",
                "-m",
                "machine.json",
                "line.cls",
                "--axis",
                "Q",
                "--limit",
                "velocity",
                "--from",
                "1",
                "--to",
                "2",
            ],
            &["--axis Q", "no such axis"],
        ),
        (
            vec![
                "sweep",
                "-m",
                "machine.json",
                "line.cls",
                "--axis",
                "X",
                "--limit",
                "velocity",
                "--from",
                "100",
                "--to",
                "200",
                "--fd-step",
                "0.7",
            ],
            &["--fd-step", "(0, 0.5)"],
        ),
    ] {
        refused_quickly(&w, &args, needles);
    }
    w.assert_listing(&["machine.json", "line.cls"]);
}

#[cfg(unix)]
#[test]
fn an_endless_input_is_refused() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write("line.cls", LINE);
    refused_quickly(
        &w,
        &[
            "solve",
            "-m",
            "machine.json",
            "/dev/zero",
            "--format",
            "apt",
        ],
        &["/dev/zero", "larger than 64 MiB", "toolpath"],
    );
    refused_quickly(
        &w,
        &["solve", "-m", "/dev/zero", "line.cls"],
        &["/dev/zero", "larger than 1 MiB", "machine file"],
    );
}

#[test]
fn input_text_is_escaped_in_messages() {
    let w = Work::new();
    // An escape sequence in a key (valid JSON) and a carriage return in a toolpath value.
    w.write(
        "machine.json",
        &XYZ_MACHINE.replace(
            r#""Z": {"#,
            r#""Z\u001b[2J": {"velocity": 1, "acceleration": 1}, "Z": {"#,
        ),
    );
    w.write("line.cls", LINE);
    let out = w.solve_line(&[]);
    let line = assert_error(&out, &["machine.json", "axes.Z\\u{1b}[2J"]);
    assert!(!line.contains('\u{1b}'), "raw escape echoed: {line:?}");
    w.write("machine.json", XYZ_MACHINE);
    w.write("bad.cls", "FEDRAT/MMPM,6000\nGOTO/0,0,0\nGOTO/1,2\r3x,0\n");
    let out = w.run(&["solve", "-m", "machine.json", "bad.cls", "--stations", "20"]);
    let line = assert_error(&out, &["bad.cls:3:"]);
    assert!(!line.contains('\r'), "raw carriage return echoed: {line:?}");
}

#[test]
fn a_machine_file_that_is_not_utf8_names_its_line() {
    let w = Work::new();
    let mut bytes = XYZ_MACHINE.replace("test router", "fr@se").into_bytes();
    let at = bytes.iter().position(|&b| b == b'@').unwrap();
    bytes[at] = 0xe4; // ä in Latin-1
    std::fs::write(w.path("machine.json"), bytes).unwrap();
    w.write("line.cls", LINE);
    assert_error(&w.solve_line(&[]), &["machine.json:2:", "UTF-8", "save"]);
}

/// Two turns of the tool about the vertical on a 30° cone: C turns 720°, 45° per block.
fn cone_turns() -> String {
    let mut t = String::from("MULTAX/ON\nFEDRAT/MMPM,3000\n");
    for k in 0..17 {
        let a = (45.0 * k as f64).to_radians();
        let (s, c) = 30f64.to_radians().sin_cos();
        t.push_str(&format!(
            "GOTO/{:.4},{:.4},0,{:.6},{:.6},{c:.6}\n",
            50.0 * a.cos(),
            50.0 * a.sin(),
            s * a.cos(),
            s * a.sin()
        ));
    }
    t
}

#[test]
fn gcode_block_count_is_bounded_before_writing() {
    let w = Work::new();
    w.write("head.json", HEAD_HEAD_MACHINE);
    w.write("cone.cls", &cone_turns());
    let gcode = |deg: &str| {
        w.run(&[
            "gcode",
            "--solver",
            "reach",
            "-m",
            "head.json",
            "cone.cls",
            "--stations",
            "200",
            "-o",
            "cone.ngc",
            "--max-rotation-deg",
            deg,
        ])
    };
    // 720° in steps of 0.001° is 720,000 pieces, 2^16 per 45° block: past 1,000,000 blocks.
    refused_quickly(
        &w,
        &[
            "gcode",
            "--solver",
            "reach",
            "-m",
            "head.json",
            "cone.cls",
            "--stations",
            "200",
            "-o",
            "cone.ngc",
            "--max-rotation-deg",
            "0.001",
        ],
        &["cone.cls:", "1000000 blocks", "larger rotation"],
    );
    w.assert_listing(&["head.json", "cone.cls"]);
    // Control: 1° per block is written.
    let out = gcode("1");
    assert_success(&out);
    assert!(stdout(&out).contains("added by Δθ"), "{}", stdout(&out));
    w.assert_listing(&["head.json", "cone.cls", "cone.ngc"]);
}

/// An output gets the permissions of any new file in its directory, not a temporary file's
/// private 0600.
#[cfg(unix)]
#[test]
fn outputs_have_the_permissions_of_a_new_file() {
    use std::os::unix::fs::PermissionsExt;
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write("line.cls", LINE);
    assert_success(&w.solve_line(&["-o", "out.csv"]));
    let mode = |name: &str| {
        std::fs::metadata(w.path(name))
            .expect("metadata")
            .permissions()
            .mode()
            & 0o777
    };
    assert_eq!(
        mode("out.csv"),
        mode("line.cls"),
        "written by std::fs::write"
    );
}

/// Found by the fuzzing harness: a coordinate of 1e308 made the spline's knots collapse (a
/// panic), 1e12 ran the re-simulation for minutes. Implausible magnitudes in any CL toolpath
/// are refused at the entry point, naming the line.
#[test]
fn implausible_toolpath_magnitudes_name_the_line() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    let cases = [
        (
            "big.cls",
            "FEDRAT/MMPM,6000\nGOTO/0,0,0\nGOTO/1e308,0,0\n",
            "big.cls:3:",
            "1e308",
        ),
        (
            "far.cls",
            "FEDRAT/MMPM,6000\nGOTO/0,0,0\nGOTO/0,-1e12,0\n",
            "far.cls:3:",
            "Y",
        ),
        (
            "slow.cls",
            "FEDRAT/MMPM,0.000159\nGOTO/0,0,0\nGOTO/10,0,0\n",
            "slow.cls:3:",
            "1e-3 mm/min",
        ),
        (
            "far.ngc",
            "G21 G90 G94\nG1 X0 F100\nG1 X2000000\n",
            "far.ngc:3:",
            "2e6",
        ),
    ];
    for (name, text, at, what) in cases {
        w.write(name, text);
        let out = w.run(&["solve", "-m", "machine.json", name, "--stations", "20"]);
        assert_error(&out, &[at, what]);
    }
    // 1 km is still a toolpath (2,500 s at the X velocity limit: checked every 0.1 s).
    w.write("km.cls", "FEDRAT/MMPM,600000\nGOTO/0,0,0\nGOTO/1e6,0,0\n");
    let out = w.run(&[
        "solve",
        "-m",
        "machine.json",
        "km.cls",
        "--stations",
        "20",
        "--solver",
        "reach",
        "--period",
        "0.1",
    ]);
    assert_success(&out);
}

#[test]
fn g28_reference_default_and_cycle_alias_on_the_command_line() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    // The machine file gives no reference: G28 goes to machine zero, and the summary and
    // --json say so, naming the field to set.
    w.write(
        "g28.nc",
        "G21 G90 G0 X0 Y0 Z5\nG1 X50 F3000\nG91 G28 Z0\nM30\n",
    );
    let args = [
        "solve",
        "-m",
        "machine.json",
        "g28.nc",
        "--stations",
        STATIONS,
    ];
    let out = w.run(&args);
    assert_success(&out);
    assert!(
        stdout(&out).contains("reference     G28/G30 reference of Z: machine zero"),
        "{}",
        stdout(&out)
    );
    let out = w.run(&[&args[..], &["--json"]].concat());
    assert_success(&out);
    let v = parse_json(&stdout(&out), "stdout");
    let r = v["reference"].as_str().unwrap_or_default();
    assert!(r.contains("axes.Z.reference"), "{v}");
    // A program without G28: null.
    w.write("line.cls", LINE);
    let out = w.solve_line(&["--json"]);
    assert!(parse_json(&stdout(&out), "stdout")["reference"].is_null());
    // A post's CYCLE76 with CYCLE86's list: read as CYCLE86 with a warning at its line; the
    // alias says the same without the guess.
    w.write(
        "spigot.mpf",
        "G71 G90 G0 X0 Y0 Z20\nF120\nMCALL CYCLE76(20,0,2,-10,,3,,,,)\nX10\nMCALL\nM30\n",
    );
    let args = [
        "solve",
        "-m",
        "machine.json",
        "spigot.mpf",
        "--stations",
        STATIONS,
    ];
    let out = w.run(&[&args[..], &["--json"]].concat());
    assert_success(&out);
    assert_eq!(parse_json(&stdout(&out), "stdout")["dwell_time_s"], 3.0);
    assert!(
        stderr(&out).contains("spigot.mpf:3:") && stderr(&out).contains("read as CYCLE86"),
        "{}",
        stderr(&out)
    );
    let out = w.run(&[&args[..], &["--cycle-alias", "CYCLE76=CYCLE86", "--json"]].concat());
    assert_success(&out);
    let v = parse_json(&stdout(&out), "stdout");
    assert_eq!(v["dwell_time_s"], 3.0);
    assert!(stderr(&out).contains("CYCLE76 is read as CYCLE86"));
    let out = w.run(&[&args[..], &["--cycle-alias", "CYCLE76=CYCLE7"]].concat());
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("cycle alias `CYCLE76=CYCLE7`"),
        "{}",
        stderr(&out)
    );
}

/// The same warning on many lines (FreeCAD's grbl post writes `K0.000` on every G17 arc: 172
/// lines of it) is printed once, at its first line, with the count of the others; different
/// warnings each keep their line. The `--json` summary lists the same lines.
#[test]
fn a_warning_repeated_on_many_lines_is_printed_once_with_the_count() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write(
        "k.ngc",
        "G21 G90 G17\nG0 X0 Y0 Z0\nG2 X10 Y0 I5 J0 K0 F600\nG2 X0 Y0 I-5 J0 K0\n\
         G2 X10 Y0 I5 J0 K0\nG1 X20 R3\nM2\n",
    );
    let args = [
        "solve",
        "-m",
        "machine.json",
        "k.ngc",
        "--stations",
        STATIONS,
    ];
    let out = w.run(&args);
    assert_success(&out);
    let err = stderr(&out);
    let k: Vec<&str> = err.lines().filter(|l| l.contains("K is not")).collect();
    assert_eq!(k.len(), 1, "{err}");
    assert!(
        k[0].contains("k.ngc:3:") && k[0].contains("(and 2 more like it, the last at line 5)"),
        "{err}"
    );
    assert!(
        err.lines()
            .any(|l| l.contains("k.ngc:6:") && l.contains("R on a straight move")),
        "{err}"
    );
    let out = w.run(&[&args[..], &["--json"]].concat());
    assert_success(&out);
    let v = parse_json(&stdout(&out), "stdout");
    let warnings = v["warnings"].as_array().expect("warnings");
    assert_eq!(warnings.len(), 2, "{v}");
    assert!(
        warnings[0]
            .as_str()
            .unwrap_or_default()
            .contains("2 more like it")
    );
}

/// `--decimal-point-input calculator` reads a Fanuc `X100` as 100 mm (round 3: the default
/// increment reading made a 117.8 mm program 0.118 mm long, silently; it now warns once and
/// says how to choose); a value other than increment or calculator is a usage error.
#[test]
fn decimal_point_input_on_the_command_line() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write(
        "int.nc",
        "O0001\nG21 G90 G94\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X100 Y50 F600\nM30\n",
    );
    let args = [
        "solve",
        "-m",
        "machine.json",
        "int.nc",
        "--stations",
        STATIONS,
        "--json",
    ];
    let length = |extra: &[&str]| {
        let out = w.run(&[&args[..], extra].concat());
        assert_success(&out);
        (
            num(
                &parse_json(&stdout(&out), "stdout")["path_length_mm"],
                "path_length_mm",
            ),
            stderr(&out),
        )
    };
    let (l, err) = length(&[]);
    assert!((l - 0.1178).abs() < 1e-3, "{l}");
    assert_eq!(err.matches("decimal point").count(), 1, "{err}");
    assert!(err.contains("int.nc:3:") && err.contains("--decimal-point-input calculator"));
    let (l, err) = length(&["--decimal-point-input", "calculator"]);
    assert!((l - (6.0 + 100f64.hypot(50.0))).abs() < 1e-6, "{l}");
    assert!(!err.contains("decimal point"), "{err}");
    let out = w.run(&[&args[..], &["--decimal-point-input", "dpi"]].concat());
    assert!(!out.status.success());
    assert!(stderr(&out).contains("calculator"), "{}", stderr(&out));
}

#[test]
fn block_delete_on_the_command_line() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    // A `/` block runs by default (the block-skip switch off) and is skipped with
    // --block-delete: 50 mm more or less of path, and a warning at its line either way.
    w.write(
        "skip.nc",
        "G21 G90 G0 X0 Y0 Z5\nG1 X50 F3000\n/G1 Y50\nM30\n",
    );
    let args = [
        "solve",
        "-m",
        "machine.json",
        "skip.nc",
        "--stations",
        STATIONS,
        "--json",
    ];
    let length = |extra: &[&str]| {
        let out = w.run(&[&args[..], extra].concat());
        assert_success(&out);
        assert!(
            stderr(&out).contains("skip.nc:3: block delete"),
            "{}",
            stderr(&out)
        );
        num(
            &parse_json(&stdout(&out), "stdout")["path_length_mm"],
            "path_length_mm",
        )
    };
    let (run, skipped) = (length(&[]), length(&["--block-delete"]));
    assert!((run - skipped - 50.0).abs() < 1e-6, "{run} {skipped}");
}

#[test]
fn interpolate_and_gcode_detect_the_input_dialect_as_solve_does() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    // Klartext: read as Heidenhain by its first block, with no dialect option.
    w.write(
        "part.h",
        "0 BEGIN PGM P MM\n1 L X+0 Y+0 Z+5 R0 FMAX\n2 L X+50 F3000\n3 L Y+20\n4 END PGM P MM\n",
    );
    let out = w.run(&[
        "interpolate",
        "-m",
        "machine.json",
        "part.h",
        "--stations",
        STATIONS,
        "-o",
        "sp.csv",
    ]);
    assert_success(&out);
    let out = w.run(&[
        "gcode",
        "-m",
        "machine.json",
        "part.h",
        "--stations",
        STATIONS,
        "-o",
        "part.ngc",
    ]);
    assert_success(&out);
    // A program nothing in which names a dialect is read in the output's: Fanuc reads `X10`
    // (no decimal point) as 10 µm, LinuxCNC as 10 mm. Where the two readings differ so, the
    // written program would not be the one `solve` reads (round 20: a Fusion program's `Z3`
    // clearance written as `Z0.003`): an error until `--input-dialect` says which is meant.
    w.write("plain.nc", "G21 G90 G0 X0 Y0 Z5\nG1 X10 F3000\nM30\n");
    for (dialect, input, x) in [
        ("fanuc", Some("fanuc"), "X0.010"),
        ("fanuc", Some("linuxcnc"), "X10.000"),
        ("linuxcnc", None, "X10.000"),
    ] {
        let mut args = vec![
            "gcode",
            "-m",
            "machine.json",
            "plain.nc",
            "--stations",
            STATIONS,
            "--dialect",
            dialect,
            "-o",
            "plain-out.nc",
        ];
        if let Some(input) = input {
            args.extend(["--input-dialect", input]);
        }
        let out = w.run(&args);
        assert_success(&out);
        let text = std::fs::read_to_string(w.path("plain-out.nc")).unwrap();
        assert!(text.contains(x), "{dialect}: {text}");
    }
    assert_error(
        &w.run(&[
            "gcode",
            "-m",
            "machine.json",
            "plain.nc",
            "--stations",
            STATIONS,
            "--dialect",
            "fanuc",
            "-o",
            "plain-out2.nc",
        ]),
        &["plain.nc:1", "`Z5`", "0.005 mm", "--input-dialect"],
    );
}

/// Round 20: a Fusion 360 program for a hobby control (MPCNC post: `G0 Z3 F300`, no `O`
/// number, nothing naming a dialect) written by `feedopt gcode --dialect fanuc` was read as a
/// Fanuc program, whose `Z3` counts increments: the written program's clearance plane was
/// `Z0.003`, every rapid between cuts 0.003 mm over the part, where `feedopt solve` read the
/// same file at Z 3 mm — with one warning among others. The reading now is an error naming
/// the word, both readings and `--input-dialect`; naming the input's dialect writes it.
#[test]
fn gcode_refuses_an_unnamed_dialect_whose_reading_depends_on_the_output() {
    let w = Work::new();
    w.write("machine.json", XYZ_MACHINE);
    w.write(
        "part.gcode",
        "G90 G94\nG17\nG21\nG0 Z3 F300\nX3.412 Y49.305 F7500\nG1 Z0.2 F339\nY94.264 F3048\n\
         G0 Z3 F300\nM5\n",
    );
    let run = |extra: &[&str]| {
        let mut a = vec![
            "gcode",
            "-m",
            "machine.json",
            "part.gcode",
            "--solver",
            "reach",
            "-o",
            "out.nc",
            "--dialect",
            "fanuc",
        ];
        a.extend_from_slice(extra);
        w.run(&a)
    };
    assert_error(
        &run(&[]),
        &[
            "part.gcode:4",
            "`Z3`",
            "0.003 mm",
            "3 mm",
            "--input-dialect linuxcnc",
        ],
    );
    assert!(!w.path("out.nc").exists());
    // Read as `solve` reads it: the clearance plane stays at Z 3 mm.
    let out = run(&["--input-dialect", "linuxcnc"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let written = w.read("out.nc");
    assert!(written.contains("Z3.000"), "{written}");
    assert!(!written.contains("Z0.003"), "{written}");
    // Named Fanuc, the user's reading: increments, as the control reads them by default.
    let out = run(&["--input-dialect", "fanuc"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(w.read("out.nc").contains("Z0.003"));
}
