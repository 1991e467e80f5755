//! Fuzzing on stable (issue 14): inputs from `problems/` and small hand-made ones, mutated
//! deterministically (byte flips, deleted, duplicated and swapped lines, truncation, extreme
//! numbers, control characters, bytes that are not UTF-8), fed to
//!
//! - the machine file parser (`Machine::from_json`, after the bounded UTF-8 read's check),
//! - the joint CSV parser and the APT and G-code readers (`toolpath::read_as`),
//! - `feedopt solve --solver reach --stations 50 --json -o out.csv` as a child process (so
//!   an abort or a hang is caught too),
//!
//! each case under a time bound. Every case must end in time, without a panic or an abort, with
//! either a result free of NaN (and an output file whose every number is finite) or one error
//! line (`feedopt: error: …`, exit code 2) and no output file left behind.
//!
//! `cargo test --test fuzz_cli` runs a short, fixed set of cases (seconds). The long run is
//! ignored by default:
//!
//! ```sh
//! FEEDOPT_FUZZ_MINUTES=10 cargo test --release --test fuzz_cli -- --ignored --nocapture
//! FEEDOPT_FUZZ_CASES=20000 FEEDOPT_FUZZ_SEED=7 cargo test --release --test fuzz_cli -- --ignored
//! ```
//!
//! It prints the figures per target and writes every failing input to
//! `target/fuzz-failures/` (or `FEEDOPT_FUZZ_OUT`). A solve is bounded by 10 s in the long
//! run (`FEEDOPT_FUZZ_BOUND_S`), 60 s in the short one (a hang, not a busy machine, should
//! fail `cargo test`).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use feedopt::machine::Machine;
use feedopt::toolpath::{self, Input};

/// Time bound of one in-process parse.
const PARSE_BOUND: Duration = Duration::from_secs(5);
/// Time bound of one solve in the long run (the issue's acceptance: within 10 s;
/// `FEEDOPT_FUZZ_BOUND_S` changes it).
const SOLVE_BOUND: Duration = Duration::from_secs(10);

/// Time bound of one solve in the short run of every `cargo test`: generous, so that a
/// machine busy with other builds does not fail it; a hang still does.
const SHORT_SOLVE_BOUND: Duration = Duration::from_secs(60);

// ---------------------------------------------------------------------------------------------
// A small deterministic PRNG (SplitMix64): no dependency, the same cases on every machine.
// ---------------------------------------------------------------------------------------------

struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Rng {
        Rng(seed ^ 0x9e37_79b9_7f4a_7c15)
    }

    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in 0..n (n > 0).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

// ---------------------------------------------------------------------------------------------
// Mutations
// ---------------------------------------------------------------------------------------------

/// Numbers that break naive readers: overflow, underflow, signed zero, not-a-number words.
const EXTREMES: &[&str] = &[
    "1e308",
    "-1e308",
    "1e309",
    "1e-308",
    "1e-300",
    "4.9e-324",
    "0",
    "-0",
    "-1",
    "1e12",
    "1e6",
    "999999999999999999999",
    "NaN",
    "inf",
    "-inf",
    "0x10",
    "1e",
    "--1",
    ".",
    "1.2.3",
    "",
];

/// Bytes worth inserting: controls, a NUL, a byte that is not UTF-8, separators.
const ODD_BYTES: &[u8] = &[
    b'\r', b'\n', 0, 0x1b, b'\t', 0xff, 0xc3, b',', b'/', b'$', b'(', b')', b';', b'"', b'{', b'}',
    b'[', b']', b'e', b'-', b'.',
];

/// Byte ranges of the numbers in `text`.
fn numbers(text: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < text.len() {
        let c = text[i];
        let starts = c.is_ascii_digit()
            || ((c == b'-' || c == b'.') && text.get(i + 1).is_some_and(u8::is_ascii_digit));
        if starts && (i == 0 || !text[i - 1].is_ascii_alphanumeric()) {
            let start = i;
            i += 1;
            while i < text.len()
                && (text[i].is_ascii_digit()
                    || text[i] == b'.'
                    || ((text[i] == b'e' || text[i] == b'E')
                        && text
                            .get(i + 1)
                            .is_some_and(|d| d.is_ascii_digit() || *d == b'-')))
            {
                i += if text[i] == b'e' || text[i] == b'E' {
                    2
                } else {
                    1
                };
            }
            out.push((start, i.min(text.len())));
        } else {
            i += 1;
        }
    }
    out
}

/// Byte ranges of the lines of `text`, each with its newline.
fn lines(text: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, &b) in text.iter().enumerate() {
        if b == b'\n' {
            out.push((start, i + 1));
            start = i + 1;
        }
    }
    if start < text.len() {
        out.push((start, text.len()));
    }
    out
}

/// Applies one random mutation to `text`; returns its name.
fn mutate_once(rng: &mut Rng, text: &mut Vec<u8>) -> &'static str {
    if text.is_empty() {
        text.extend_from_slice(rng.pick(EXTREMES).as_bytes());
        return "fill";
    }
    match rng.below(9) {
        0 => {
            let i = rng.below(text.len());
            text[i] ^= 1 << rng.below(8);
            "bit flip"
        }
        1 => {
            let i = rng.below(text.len());
            text[i] = *rng.pick(ODD_BYTES);
            "byte set"
        }
        2 => {
            let i = rng.below(text.len() + 1);
            text.insert(i, *rng.pick(ODD_BYTES));
            "byte insert"
        }
        3 => {
            let ls = lines(text);
            let (a, b) = *rng.pick(&ls);
            text.drain(a..b);
            "line delete"
        }
        4 => {
            let ls = lines(text);
            let (a, b) = *rng.pick(&ls);
            let copy = text[a..b].to_vec();
            let times = if rng.below(4) == 0 {
                1 + rng.below(50)
            } else {
                1
            };
            for _ in 0..times {
                text.splice(a..a, copy.iter().copied());
            }
            "line duplicate"
        }
        5 => {
            let ls = lines(text);
            if ls.len() >= 2 {
                let (i, j) = (rng.below(ls.len()), rng.below(ls.len()));
                let (i, j) = (i.min(j), i.max(j));
                if i != j {
                    let (a, b) = (ls[i], ls[j]);
                    let mut out = text[..a.0].to_vec();
                    out.extend_from_slice(&text[b.0..b.1]);
                    out.extend_from_slice(&text[a.1..b.0]);
                    out.extend_from_slice(&text[a.0..a.1]);
                    out.extend_from_slice(&text[b.1..]);
                    *text = out;
                }
            }
            "line swap"
        }
        6 => {
            let n = rng.below(text.len() + 1);
            text.truncate(n);
            "truncate"
        }
        _ => {
            let nums = numbers(text);
            if nums.is_empty() {
                text.extend_from_slice(rng.pick(EXTREMES).as_bytes());
                return "append extreme";
            }
            // Several at once now and then: a whole record of extremes.
            let count = if rng.below(5) == 0 {
                1 + rng.below(6)
            } else {
                1
            };
            let mut picks: Vec<(usize, usize)> = (0..count).map(|_| *rng.pick(&nums)).collect();
            picks.sort();
            picks.dedup();
            for (a, b) in picks.into_iter().rev() {
                let by = rng.pick(EXTREMES).as_bytes().to_vec();
                text.splice(a..b, by);
            }
            "extreme number"
        }
    }
}

/// 1 to 3 mutations of `seed_text`; the mutated bytes and what was done.
fn mutate(rng: &mut Rng, seed_text: &[u8]) -> (Vec<u8>, String) {
    let mut text = seed_text.to_vec();
    let n = 1 + rng.below(3);
    let names: Vec<&str> = (0..n).map(|_| mutate_once(rng, &mut text)).collect();
    (text, names.join(" + "))
}

// ---------------------------------------------------------------------------------------------
// Corpus
// ---------------------------------------------------------------------------------------------

fn repo(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

fn file(p: &str) -> Vec<u8> {
    std::fs::read(repo(p)).unwrap_or_else(|e| panic!("{p}: {e}"))
}

/// The first `n` lines of a file (a small toolpath keeps every solve fast).
fn head(bytes: &[u8], n: usize) -> Vec<u8> {
    let ls = lines(bytes);
    bytes[..ls.get(n.min(ls.len()) - 1).map_or(0, |l| l.1)].to_vec()
}

const JOINT_MACHINE: &str = r#"{"name": "two joints", "kinematics": {"type": "joint"},
 "axes": {"a": {"velocity": [-1, 1.2], "acceleration": 2, "jerk": 20},
          "b": {"velocity": 0.8, "acceleration": [-3, 2.5]}}}
"#;

/// Two joints along s ∈ [0, 1], with first and second derivatives.
fn joint_csv() -> Vec<u8> {
    let mut t = String::from("s,q_a,q_b,dq_a,dq_b,ddq_a,ddq_b\n");
    for i in 0..=20 {
        let s = i as f64 / 20.0;
        let (a, b) = ((3.0 * s).sin(), s * s);
        let (da, db) = (3.0 * (3.0 * s).cos(), 2.0 * s);
        let (dda, ddb) = (-9.0 * (3.0 * s).sin(), 2.0);
        t.push_str(&format!("{s},{a},{b},{da},{db},{dda},{ddb}\n"));
    }
    t.into_bytes()
}

const GCODE: &str = "(a small 5-axis program)\nG21 G90 G94\nM428\nG0 X0 Y0 Z5 A0 C0\n\
G1 Z0 F3000\nG1 X10 Y2 A5 C10\nG1 X20 Y0 A10 C25 F2400\nG2 X30 Y0 I5 J0 F1500\n\
G3 X40 Y0 R5\nG93 G1 X45 A0 C0 F120\nG94 G0 Z5\nM429\nM2\n";

const GCODE_MACHINE: &str = r#"{"name": "trunnion", "kinematics": {"type": "table_table_ac",
 "x-rot-point": 0, "y-rot-point": 0, "z-rot-point": 0, "y-offset": 0, "z-offset": 20},
 "axes": {"X": {"velocity": 200, "acceleration": 1000, "min": -500, "max": 500},
          "Y": {"velocity": 200, "acceleration": 1000},
          "Z": {"velocity": 150, "acceleration": 800},
          "A": {"velocity": 60, "acceleration": 300, "min": -120, "max": 120},
          "C": {"velocity": 90, "acceleration": 400}},
 "feed": {"max": 120}}
"#;

/// A toolpath and the machine it runs on, by name.
struct Problem {
    name: &'static str,
    ext: &'static str,
    machine: Vec<u8>,
    toolpath: Vec<u8>,
}

fn problems() -> Vec<Problem> {
    let blade = file("problems/seed_head_head/impeller_blade.cls");
    let pocket = file("problems/xyz_pocket/pocket_contour.cls");
    vec![
        Problem {
            name: "blade",
            ext: "cls",
            machine: file("problems/seed_head_head/machine.json"),
            toolpath: head(&blade, 60),
        },
        Problem {
            name: "blade_jerk",
            ext: "cls",
            machine: file("problems/seed_head_head/machine_jerk.json"),
            toolpath: head(&blade, 30),
        },
        Problem {
            name: "pocket",
            ext: "cls",
            machine: file("problems/xyz_pocket/machine.json"),
            toolpath: head(&pocket, 80),
        },
        Problem {
            name: "joint",
            ext: "csv",
            machine: JOINT_MACHINE.as_bytes().to_vec(),
            toolpath: joint_csv(),
        },
        Problem {
            name: "trunnion",
            ext: "ngc",
            machine: GCODE_MACHINE.as_bytes().to_vec(),
            toolpath: GCODE.as_bytes().to_vec(),
        },
    ]
}

// ---------------------------------------------------------------------------------------------
// Running one case
// ---------------------------------------------------------------------------------------------

/// How a case ended, when it did not end well.
#[derive(Debug)]
struct Failure {
    target: &'static str,
    case: u64,
    what: String,
    mutation: String,
    files: Vec<(String, Vec<u8>)>,
}

/// Runs `f` on its own thread under `bound`: `Err` with what went wrong on a panic or a hang
/// (the hung thread is left behind; the test fails anyway).
fn bounded<T: Send + 'static>(
    bound: Duration,
    f: impl FnOnce() -> T + Send + 'static,
) -> Result<T, String> {
    let (tx, rx) = mpsc::channel();
    let handle = std::thread::spawn(move || {
        let r = f();
        let _ = tx.send(());
        r
    });
    match rx.recv_timeout(bound) {
        Ok(()) | Err(mpsc::RecvTimeoutError::Disconnected) => handle.join().map_err(|p| {
            let msg = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            format!("panic: {msg}")
        }),
        Err(mpsc::RecvTimeoutError::Timeout) => Err(format!("still running after {bound:?}")),
    }
}

/// An error's message must be one line; `Ok(true)`: the case ended in an error, as it may.
fn one_line(e: &feedopt::error::Error) -> Result<bool, String> {
    let msg = e.to_string();
    if msg.contains('\n') || msg.is_empty() {
        return Err(format!("error is not one line: {msg:?}"));
    }
    Ok(true)
}

/// Parses a mutated machine file in-process.
fn machine_case(bytes: Vec<u8>) -> Result<bool, String> {
    let path = Path::new("fuzz/machine.json");
    let m = match feedopt::files::utf8(path, bytes) {
        Ok(text) => Machine::from_json(path, &text),
        Err(e) => Err(e),
    };
    match m {
        Err(e) => one_line(&e),
        Ok(m) => {
            for a in &m.axes {
                let limits = [Some(a.velocity), Some(a.acceleration), a.jerk];
                for l in limits.into_iter().flatten() {
                    if !(l.min.is_finite() && l.max.is_finite() && l.min < 0.0 && l.max > 0.0) {
                        return Err(format!("accepted limit {l:?} on axis {}", a.name));
                    }
                }
            }
            Ok(false)
        }
    }
}

/// Reads a mutated toolpath in-process (`ext` chooses the reader).
fn toolpath_case(dir: &Path, ext: &str, bytes: Vec<u8>) -> Result<bool, String> {
    let path = dir.join(format!("path.{ext}"));
    std::fs::write(&path, &bytes).map_err(|e| e.to_string())?;
    match toolpath::read_as(&path, None, toolpath::gcode::Dialect::default()) {
        Err(e) => one_line(&e),
        Ok(Input::Cl(t)) => {
            for p in &t.points {
                if !(p.p.iter().all(|x| x.is_finite()) && p.o.iter().all(|x| x.is_finite())) {
                    return Err(format!(
                        "line {}: accepted a point that is not finite",
                        p.line
                    ));
                }
            }
            Ok(false)
        }
        Ok(Input::Joint(j)) => {
            if j.s
                .windows(2)
                .any(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
            {
                return Err("accepted s that does not increase".into());
            }
            let finite = |rows: &[[f64; feedopt::kinematics::MAX_AXES]]| {
                rows.iter().all(|r| r.iter().all(|x| x.is_finite()))
            };
            let derivs = [&j.dq, &j.ddq, &j.dddq];
            if !finite(&j.q)
                || derivs
                    .iter()
                    .any(|d| d.as_ref().is_some_and(|d| !finite(d)))
            {
                return Err("accepted a value that is not finite".into());
            }
            Ok(false)
        }
    }
}

/// Fields of the summary that are `null` by design: no estimate on a fixed grid, no dialect
/// for an APT or CSV input, no reference note when the reader assumed no G28/G30 reference.
const OPTIONAL: [&str; 4] = [
    "summary.error_estimate",
    "summary.dialect",
    "summary.dialect_by",
    "summary.reference",
];

/// Checks a JSON summary for NaN (serde_json writes NaN and infinities as null).
fn nulls(v: &serde_json::Value, at: &str, out: &mut Vec<String>) {
    match v {
        serde_json::Value::Null if OPTIONAL.contains(&at) => {}
        serde_json::Value::Null => out.push(at.to_string()),
        serde_json::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                nulls(x, &format!("{at}[{i}]"), out);
            }
        }
        serde_json::Value::Object(m) => {
            for (k, x) in m {
                nulls(x, &format!("{at}.{k}"), out);
            }
        }
        _ => {}
    }
}

/// Runs `feedopt solve` on a mutated problem as a child process, killed after the bound.
fn solve_case(
    dir: &Path,
    ext: &str,
    machine: &[u8],
    toolpath: &[u8],
    bound: Duration,
) -> Result<(), String> {
    std::fs::write(dir.join("machine.json"), machine).map_err(|e| e.to_string())?;
    let tp = format!("path.{ext}");
    std::fs::write(dir.join(&tp), toolpath).map_err(|e| e.to_string())?;
    let out_csv = dir.join("out.csv");
    let _ = std::fs::remove_file(&out_csv);
    let mut child = Command::new(env!("CARGO_BIN_EXE_feedopt"))
        .args(["solve", "--solver", "reach", "--stations", "50", "--json"])
        .args(["-m", "machine.json", &tp, "-o", "out.csv"])
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("spawn: {e}"))?;
    let t0 = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().map_err(|e| e.to_string())? {
            break s;
        }
        if t0.elapsed() > bound {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("still running after {bound:?} (killed)"));
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    let output = child.wait_with_output().map_err(|e| e.to_string())?;
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    match status.code() {
        Some(0) => {
            let v: serde_json::Value = serde_json::from_str(&stdout)
                .map_err(|e| format!("stdout is not JSON ({e}): {stdout}"))?;
            let mut bad = Vec::new();
            nulls(&v, "summary", &mut bad);
            if !bad.is_empty() {
                return Err(format!("NaN (null) in the summary at {}", bad.join(", ")));
            }
            let csv = std::fs::read_to_string(&out_csv).map_err(|e| format!("out.csv: {e}"))?;
            for (i, line) in csv.lines().enumerate().skip(1) {
                if let Some(x) = line
                    .split(',')
                    .find(|x| !x.parse::<f64>().is_ok_and(f64::is_finite))
                {
                    return Err(format!(
                        "out.csv line {}: `{x}` is not a finite number",
                        i + 1
                    ));
                }
            }
            if stderr.lines().any(|l| !l.starts_with("feedopt: warning: ")) {
                return Err(format!("stderr on success is not warnings: {stderr:?}"));
            }
            Ok(())
        }
        Some(2) => {
            let ls: Vec<&str> = stderr.lines().collect();
            let last = ls.last().copied().unwrap_or("");
            if !last.starts_with("feedopt: error: ")
                || ls[..ls.len().saturating_sub(1)]
                    .iter()
                    .any(|l| !l.starts_with("feedopt: warning: "))
            {
                return Err(format!("the error is not one line: {stderr:?}"));
            }
            if stderr.contains('\r') || stderr.contains('\u{1b}') {
                return Err(format!("raw control characters on stderr: {stderr:?}"));
            }
            if !stdout.is_empty() {
                return Err(format!("stdout on error: {stdout}"));
            }
            if out_csv.exists() {
                return Err("out.csv left behind on error".into());
            }
            Ok(())
        }
        other => Err(format!(
            "exit {other:?} (panic or abort): {}",
            stderr.lines().take(3).collect::<Vec<_>>().join(" | ")
        )),
    }
}

// ---------------------------------------------------------------------------------------------
// Campaigns
// ---------------------------------------------------------------------------------------------

/// What one target did.
#[derive(Default)]
struct Figures {
    cases: u64,
    errors: u64,
    slowest: Duration,
    total: Duration,
}

struct Campaign {
    seed: u64,
    solve_bound: Duration,
    deadline: Option<Instant>,
    failures: Vec<Failure>,
    figures: Vec<(&'static str, Figures)>,
}

impl Campaign {
    fn figures(&mut self, target: &'static str) -> &mut Figures {
        if let Some(i) = self.figures.iter().position(|(t, _)| *t == target) {
            return &mut self.figures[i].1;
        }
        self.figures.push((target, Figures::default()));
        &mut self.figures.last_mut().expect("just pushed").1
    }

    fn record(
        &mut self,
        target: &'static str,
        case: u64,
        elapsed: Duration,
        result: Result<bool, Failure>,
    ) {
        let f = self.figures(target);
        f.cases += 1;
        f.total += elapsed;
        f.slowest = f.slowest.max(elapsed);
        match result {
            Ok(true) => f.errors += 1,
            Ok(false) => {}
            Err(failure) => {
                eprintln!(
                    "FAIL {target} case {case}: {} ({})",
                    failure.what, failure.mutation
                );
                self.failures.push(failure);
            }
        }
    }

    fn over(&self) -> bool {
        self.deadline.is_some_and(|d| Instant::now() > d)
    }

    /// `cases` cases of each target (fewer if the deadline passes first).
    fn run(&mut self, cases: u64, solves: u64) {
        let corpus = problems();
        let dir = tempfile::tempdir().expect("temp dir");
        for case in 0..cases {
            if self.over() {
                break;
            }
            let mut rng = Rng::new(self.seed.wrapping_mul(1_000_003).wrapping_add(case));
            let p = rng.pick(&corpus);
            // Machine files.
            let (m, how) = mutate(&mut rng, &p.machine);
            let t0 = Instant::now();
            let m2 = m.clone();
            let r = bounded(PARSE_BOUND, move || machine_case(m2)).and_then(|r| r);
            let res = r.map_err(|what| Failure {
                target: "machine",
                case,
                what,
                mutation: how.clone(),
                files: vec![("machine.json".into(), m)],
            });
            self.record("machine", case, t0.elapsed(), res);
            // Toolpaths (joint CSV, APT, G-code).
            let (t, how) = mutate(&mut rng, &p.toolpath);
            let target = match p.ext {
                "csv" => "joint_csv",
                "ngc" => "gcode",
                _ => "apt",
            };
            let t0 = Instant::now();
            let (t2, d2, ext) = (t.clone(), dir.path().to_path_buf(), p.ext);
            let r = bounded(PARSE_BOUND, move || toolpath_case(&d2, ext, t2)).and_then(|r| r);
            let res = r.map_err(|what| Failure {
                target,
                case,
                what,
                mutation: how.clone(),
                files: vec![(format!("path.{}", p.ext), t)],
            });
            self.record(target, case, t0.elapsed(), res);
        }
        for case in 0..solves {
            if self.over() {
                break;
            }
            let mut rng = Rng::new(self.seed.wrapping_mul(7_000_003).wrapping_add(case));
            let p = rng.pick(&corpus);
            // Mutate the toolpath, the machine, or both.
            let which = rng.below(3);
            let (m, hm) = if which != 1 {
                mutate(&mut rng, &p.machine)
            } else {
                (p.machine.clone(), String::new())
            };
            let (t, ht) = if which != 0 {
                mutate(&mut rng, &p.toolpath)
            } else {
                (p.toolpath.clone(), String::new())
            };
            let how = format!("{}: machine [{hm}] toolpath [{ht}]", p.name);
            let t0 = Instant::now();
            let r = solve_case(dir.path(), p.ext, &m, &t, self.solve_bound);
            let res = match r {
                Ok(()) => Ok(!dir.path().join("out.csv").exists()),
                Err(what) => Err(Failure {
                    target: "solve",
                    case,
                    what,
                    mutation: how,
                    files: vec![("machine.json".into(), m), (format!("path.{}", p.ext), t)],
                }),
            };
            self.record("solve", case, t0.elapsed(), res);
        }
    }

    fn report(&self, label: &str) {
        eprintln!("fuzz {label} (seed {}):", self.seed);
        eprintln!(
            "  {:<10} {:>8} {:>8} {:>9} {:>10} {:>10}",
            "target", "cases", "errors", "failures", "mean ms", "slowest ms"
        );
        for (t, f) in &self.figures {
            let failures = self.failures.iter().filter(|x| x.target == *t).count();
            eprintln!(
                "  {:<10} {:>8} {:>8} {:>9} {:>10.2} {:>10.1}",
                t,
                f.cases,
                f.errors,
                failures,
                f.total.as_secs_f64() * 1e3 / f.cases.max(1) as f64,
                f.slowest.as_secs_f64() * 1e3
            );
        }
    }

    /// Writes every failing input under `dir/<target>-<case>/`.
    fn save_failures(&self, dir: &Path) {
        for f in &self.failures {
            let d = dir.join(format!("{}-{}", f.target, f.case));
            let _ = std::fs::create_dir_all(&d);
            for (name, bytes) in &f.files {
                let _ = std::fs::write(d.join(name), bytes);
            }
            let _ = std::fs::write(
                d.join("WHAT.txt"),
                format!("{}\nmutation: {}\nseed {}\n", f.what, f.mutation, self.seed),
            );
        }
    }

    fn assert_clean(&self) {
        if !self.failures.is_empty() {
            let out = std::env::var_os("FEEDOPT_FUZZ_OUT")
                .map(PathBuf::from)
                .unwrap_or_else(|| repo("target/fuzz-failures"));
            self.save_failures(&out);
            let list: Vec<String> = self
                .failures
                .iter()
                .take(20)
                .map(|f| format!("{} case {}: {} ({})", f.target, f.case, f.what, f.mutation))
                .collect();
            panic!(
                "{} failing cases (inputs in {}):\n{}",
                self.failures.len(),
                out.display(),
                list.join("\n")
            );
        }
    }
}

fn env_u64(name: &str) -> Option<u64> {
    std::env::var(name).ok().and_then(|v| v.parse().ok())
}

/// The short run of every `cargo test`: a fixed seed, a few hundred parses, a dozen solves.
#[test]
fn fuzz_short() {
    let mut c = Campaign {
        seed: 1,
        solve_bound: SHORT_SOLVE_BOUND,
        deadline: None,
        failures: Vec::new(),
        figures: Vec::new(),
    };
    c.run(300, 40);
    c.report("short");
    // Every target ran, and the mutations reach both outcomes.
    for t in ["machine", "joint_csv", "apt", "gcode", "solve"] {
        assert!(
            c.figures.iter().any(|(n, f)| *n == t && f.cases > 0),
            "target {t} did not run"
        );
    }
    let errors: u64 = c.figures.iter().map(|(_, f)| f.errors).sum();
    assert!(
        errors > 0,
        "no case ended in an error: the mutations do nothing"
    );
    c.assert_clean();
}

/// The long run, by hand: `FEEDOPT_FUZZ_MINUTES` (default 10) or `FEEDOPT_FUZZ_CASES`.
#[test]
#[ignore = "long fuzzing run: FEEDOPT_FUZZ_MINUTES / FEEDOPT_FUZZ_CASES, --release"]
fn fuzz_long() {
    let cases = env_u64("FEEDOPT_FUZZ_CASES");
    let minutes = env_u64("FEEDOPT_FUZZ_MINUTES").unwrap_or(if cases.is_some() { 0 } else { 10 });
    let mut c = Campaign {
        seed: env_u64("FEEDOPT_FUZZ_SEED").unwrap_or(2),
        solve_bound: env_u64("FEEDOPT_FUZZ_BOUND_S").map_or(SOLVE_BOUND, Duration::from_secs),
        deadline: (minutes > 0).then(|| Instant::now() + Duration::from_secs(60 * minutes)),
        failures: Vec::new(),
        figures: Vec::new(),
    };
    // With a deadline: parses for a third of the time, solves for the rest.
    let (parses, solves) = match cases {
        Some(n) => (n, n / 10),
        None => (u64::MAX, 0),
    };
    if let Some(deadline) = c.deadline {
        let now = Instant::now();
        c.deadline = Some(now + (deadline - now) / 3);
        c.run(parses, 0);
        c.deadline = Some(deadline);
        c.run(0, u64::MAX);
    } else {
        c.run(parses, solves);
    }
    c.report("long");
    c.assert_clean();
}

/// Solve case 20369 of the long run with seed 3 (the only failure of 25,224 solves, after the
/// entry-point bounds): a 2 km excursion in Z (Z = 1e6 mm, the largest coordinate allowed) on
/// the seed blade with two tool-vector components set to 1e-308 and one to 1e21. The cycle
/// time is about 23,000 s, and the solve (reach, 50 stations) ran for minutes while the
/// re-simulation's work grew with cycle time ÷ period; with at most
/// `verify::MAX_INTERVAL_SAMPLES` instants per interval it ends in well under a second.
#[test]
fn fuzz_case_a_2_km_excursion_ends_within_10_s() {
    let blade = String::from_utf8(head(
        &file("problems/seed_head_head/impeller_blade.cls"),
        60,
    ))
    .expect("UTF-8");
    let edits = [
        (
            32,
            "GOTO/0,-11.891693,49.323303,-0.101962182,1e-308,0.978129178",
        ),
        (
            49,
            "GOTO/35.152761,-11.628542,47.422336,-0.096668601,999999999999999999999,0.977877460",
        ),
        (
            51,
            "GOTO/35.351186,-11.593753,47.200314,1e-308,-0.186066750,0.977828453",
        ),
        (
            52,
            "GOTO/35.450490,-11.576055,1e6,-0.095782523,-0.186354897,0.977802414",
        ),
        (
            54,
            "GOTO/35.649280,0,46.867933,-0.095198905,-0.186942397,0.977747262",
        ),
    ];
    let mut lines: Vec<String> = blade.lines().map(str::to_string).collect();
    for (n, text) in edits {
        lines[n - 1] = text.to_string();
    }
    let toolpath = lines.join("\n") + "\n";
    let dir = tempfile::tempdir().expect("temp dir");
    let machine = file("problems/seed_head_head/machine.json");
    let t0 = Instant::now();
    let r = solve_case(
        dir.path(),
        "cls",
        &machine,
        toolpath.as_bytes(),
        SOLVE_BOUND,
    );
    assert!(r.is_ok(), "{r:?} after {:?}", t0.elapsed());
}
