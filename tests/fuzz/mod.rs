//! The fuzzing harness behind `tests/fuzz_cli.rs`: targets, running and judging one case,
//! budgets (cases, CPU time, wall time) and the figures of a campaign.
//!
//! **The time bound of a case is CPU time**, never wall time: campaigns run under `nice 19`
//! on a shared machine, where a case may wait for a core far longer than it runs (a read that
//! takes 2 ms of CPU can take seconds of wall time), so a wall-clock bound would report
//! "timeouts" that are the machine's, not the reader's. An in-process case runs on the
//! [`Worker`] thread, whose CPU clock (`pthread_getcpuclockid`, `clock_gettime`) the harness
//! reads while it waits; a `solve` case runs as a child, whose CPU time (all its threads,
//! `utime + stime` of `/proc/<pid>/stat`) is read the same way, and after it ends its exact
//! total (`getrusage(RUSAGE_CHILDREN)`). Past the bound the case is a hang. A wall-clock
//! backstop of [`WALL_BACKSTOP`] × the bound catches a case that waits without using CPU
//! (a deadlock, a sleep); under `nice 19` beside busy processes a CPU-bound case gets as
//! little as a few percent of a core, hence the generous factor.

pub mod corpus;
pub mod mutate;

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use feedopt::error::Error;
use feedopt::machine::Machine;
use feedopt::toolpath::gcode::Dialect;
use feedopt::toolpath::{self, Format, Input, MachineContext, ReadOptions};

use corpus::Seed;
use mutate::{Rng, Vocabulary, hash, mutate};

// ---------------------------------------------------------------------------------------------
// Targets
// ---------------------------------------------------------------------------------------------

/// What a target feeds mutated inputs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// The APT reader, in-process (`toolpath::read_with`, format APT).
    Apt,
    /// The G-code reader in one dialect, in-process.
    Gcode(Dialect),
    /// The machine file parser with its reference positions, in-process.
    Machine,
    /// The joint CSV reader, in-process.
    JointCsv,
    /// `feedopt solve` as a child process, on mutated toolpaths and machine files.
    Solve,
}

/// A fuzz target: its name (`apt`, `gcode-fanuc`, …) and what it runs.
#[derive(Debug, Clone)]
pub struct Target {
    pub name: String,
    pub kind: Kind,
}

/// Every target: `apt`, `gcode-<dialect>` for every dialect of [`Dialect::ALL`], `machine`,
/// `joint_csv`, `solve`.
pub fn targets() -> Vec<Target> {
    let mut out = vec![Target {
        name: "apt".into(),
        kind: Kind::Apt,
    }];
    for d in Dialect::ALL {
        out.push(Target {
            name: format!("gcode-{}", d.name()),
            kind: Kind::Gcode(d),
        });
    }
    out.push(Target {
        name: "machine".into(),
        kind: Kind::Machine,
    });
    out.push(Target {
        name: "joint_csv".into(),
        kind: Kind::JointCsv,
    });
    out.push(Target {
        name: "solve".into(),
        kind: Kind::Solve,
    });
    out
}

/// The targets a comma list names (`all`: every one), in the list's order.
pub fn select(list: &str) -> Result<Vec<Target>, String> {
    let all = targets();
    if list.trim().eq_ignore_ascii_case("all") {
        return Ok(all);
    }
    list.split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|name| {
            all.iter().find(|t| t.name == name).cloned().ok_or_else(|| {
                let names: Vec<&str> = all.iter().map(|t| t.name.as_str()).collect();
                format!(
                    "FEEDOPT_FUZZ_TARGET: no target `{name}` (the targets: {}, or all)",
                    names.join(", ")
                )
            })
        })
        .collect()
}

/// A scratch folder for the cases' files: on tmpfs (`/dev/shm`) where there is one. Every case
/// writes its input over the last one's, and on ext4 that replacement (a truncation: a
/// write-back and a discard of the old blocks on close) took about 40 % of a small case's CPU
/// time.
pub fn scratch_dir() -> tempfile::TempDir {
    let shm = Path::new("/dev/shm");
    let b = tempfile::Builder::new()
        .prefix("feedopt-fuzz-")
        .tempdir_in(shm);
    b.or_else(|_| tempfile::tempdir())
        .expect("a scratch folder")
}

// ---------------------------------------------------------------------------------------------
// CPU time
// ---------------------------------------------------------------------------------------------

/// Clock ticks per second of `/proc/self/stat` (`getconf CLK_TCK`; 100 on Linux).
fn clock_ticks() -> f64 {
    static TICKS: std::sync::OnceLock<f64> = std::sync::OnceLock::new();
    *TICKS.get_or_init(|| {
        Command::new("getconf")
            .arg("CLK_TCK")
            .output()
            .ok()
            .and_then(|o| String::from_utf8(o.stdout).ok())
            .and_then(|s| s.trim().parse::<f64>().ok())
            .filter(|t| *t > 0.0)
            .unwrap_or(100.0)
    })
}

/// CPU seconds used by this process (all its threads: `utime + stime` of `/proc/self/stat`)
/// and, with `children`, by the child processes it has waited for (`cutime + cstime`);
/// `None` where `/proc` is not there.
pub fn cpu_seconds(children: bool) -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) in parentheses: state is field 3,
    // utime 14, stime 15, cutime 16, cstime 17.
    let rest = &stat[stat.rfind(')')? + 1..];
    let f: Vec<f64> = rest
        .split_whitespace()
        .skip(11)
        .take(4)
        .map(|x| x.parse().unwrap_or(0.0))
        .collect();
    if f.len() < 4 {
        return None;
    }
    let ticks = f[0] + f[1] + if children { f[2] + f[3] } else { 0.0 };
    Some(ticks / clock_ticks())
}

// ---------------------------------------------------------------------------------------------
// Running one case
// ---------------------------------------------------------------------------------------------

/// The wall-clock backstop of a case, as a multiple of its CPU-time bound (see the module
/// documentation): 5 s of CPU for a read, 5 minutes of wall time.
pub const WALL_BACKSTOP: u32 = 60;

/// Marks an error of the harness itself (writing a case's file, starting a child): not the
/// target's failure. The campaign stops and reports it apart.
const HARNESS: &str = "harness error";

/// The calling thread's CPU time so far.
pub fn thread_cpu() -> Duration {
    clock_time(libc::CLOCK_THREAD_CPUTIME_ID).unwrap_or_default()
}

/// CPU time of the clock `clock` (a thread's: `pthread_getcpuclockid`).
fn clock_time(clock: libc::clockid_t) -> Option<Duration> {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid timespec to write into; a bad clock id only returns an error.
    let rc = unsafe { libc::clock_gettime(clock, &mut t) };
    (rc == 0).then(|| Duration::new(t.tv_sec as u64, t.tv_nsec as u32))
}

/// CPU time of this process's waited-for children (`getrusage(RUSAGE_CHILDREN)`).
fn children_cpu() -> Duration {
    // SAFETY: an all-zero rusage is a valid value for getrusage to overwrite.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `u` is a valid rusage to write into.
    if unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut u) } != 0 {
        return Duration::ZERO;
    }
    let tv = |t: libc::timeval| Duration::new(t.tv_sec as u64, t.tv_usec as u32 * 1000);
    tv(u.ru_utime) + tv(u.ru_stime)
}

/// CPU time of process `pid` so far (all its threads: `utime + stime` of `/proc/<pid>/stat`;
/// clock ticks, 10 ms), or `None` when it has ended.
fn process_cpu(pid: u32) -> Option<Duration> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let rest = &stat[stat.rfind(')')? + 1..];
    let f: Vec<f64> = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .map(|x| x.parse().unwrap_or(0.0))
        .collect();
    (f.len() == 2).then(|| Duration::from_secs_f64((f[0] + f[1]) / clock_ticks()))
}

/// How a case ended.
#[derive(Debug)]
pub enum Outcome {
    /// A result, and every check of it passed.
    Accepted,
    /// One clean error line: its kind (what it says, without the file, numbers and quoted
    /// text) and the message.
    Error { kind: String, message: String },
    /// A panic, an abort, a bad result or message.
    Failed(String),
    /// Still running past the time bound.
    Hung(String),
    /// The harness itself failed (a case's file could not be written, a child not started):
    /// the campaign stops; the target is not blamed.
    Harness(String),
}

/// A job for the [`Worker`]: one case, read and judged.
pub type Job = Box<dyn FnOnce() -> Outcome + Send>;

/// One thread that runs the in-process cases of a target one after another, each under a
/// bound on the thread's CPU time. (A thread per case would cost a thread's creation and
/// teardown each time: about as much system time as a small case.)
pub struct Worker {
    jobs: mpsc::Sender<Job>,
    done: mpsc::Receiver<std::thread::Result<Outcome>>,
    /// The worker thread's CPU clock.
    clock: libc::clockid_t,
    /// Keeps the thread's id valid for its clock.
    _thread: std::thread::JoinHandle<()>,
}

/// How often the harness looks at a running case's clocks.
const POLL: Duration = Duration::from_millis(20);

impl Worker {
    pub fn new() -> Worker {
        use std::os::unix::thread::JoinHandleExt;
        let (jobs, inbox) = mpsc::channel::<Job>();
        let (outbox, done) = mpsc::channel();
        let thread = std::thread::spawn(move || {
            for job in inbox {
                let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(job));
                if outbox.send(r).is_err() {
                    break;
                }
            }
        });
        let mut clock: libc::clockid_t = 0;
        // SAFETY: the thread is alive (it waits on `inbox`, which we hold) and `clock` is a
        // valid place to write its clock id.
        let rc = unsafe { libc::pthread_getcpuclockid(thread.as_pthread_t(), &mut clock) };
        assert_eq!(rc, 0, "pthread_getcpuclockid: error {rc}");
        Worker {
            jobs,
            done,
            clock,
            _thread: thread,
        }
    }

    /// The worker thread's CPU time so far.
    fn cpu(&self) -> Duration {
        clock_time(self.clock).unwrap_or_default()
    }

    /// Runs `job` under `bound` of the worker thread's CPU time (and a wall-clock backstop of
    /// [`WALL_BACKSTOP`] × `bound`): its outcome and the CPU time it took; `Failed` on a
    /// panic, `Hung` past the bound (the worker is then busy for good: the caller stops the
    /// target).
    pub fn run(&self, bound: Duration, job: Job) -> (Outcome, Duration) {
        let (t0, cpu0) = (Instant::now(), self.cpu());
        if self.jobs.send(job).is_err() {
            return (
                Outcome::Failed("the worker thread is gone".into()),
                Duration::ZERO,
            );
        }
        let backstop = bound * WALL_BACKSTOP;
        let outcome = loop {
            match self.done.recv_timeout(POLL) {
                Ok(Ok(outcome)) => break outcome,
                Ok(Err(p)) => {
                    let msg = p
                        .downcast_ref::<String>()
                        .cloned()
                        .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                        .unwrap_or_default();
                    break Outcome::Failed(format!("panic: {msg}"));
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    let (cpu, wall) = (self.cpu() - cpu0, t0.elapsed());
                    if cpu > bound {
                        break Outcome::Hung(format!(
                            "still running after {:.2} s of CPU time (bound {bound:?}; {:.1} s \
                             wall)",
                            cpu.as_secs_f64(),
                            wall.as_secs_f64()
                        ));
                    }
                    if wall > backstop {
                        break Outcome::Hung(format!(
                            "still running after {:.0} s of wall time (the backstop; {:.2} s of \
                             CPU time)",
                            wall.as_secs_f64(),
                            cpu.as_secs_f64()
                        ));
                    }
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    break Outcome::Failed("the worker thread is gone".into());
                }
            }
        };
        (outcome, self.cpu() - cpu0)
    }
}

/// The kind of an error message: what follows the file's name, without numbers and quoted
/// text, so that the number of kinds seen says how many different checks the mutations
/// reached.
fn kind_of(msg: &str, file: &str) -> String {
    let msg = msg.rfind(file).map_or(msg, |i| &msg[i + file.len()..]);
    let mut out = String::new();
    let mut quoted = false;
    let mut last_digit = false;
    for c in msg.chars() {
        if c == '`' {
            quoted = !quoted;
            out.push(c);
            continue;
        }
        if quoted {
            continue;
        }
        let digit = c.is_ascii_digit() || (last_digit && matches!(c, '.' | 'e' | '-' | '+'));
        if digit && !last_digit {
            out.push('#');
        } else if !digit {
            out.push(c);
        }
        last_digit = digit;
    }
    out
}

/// The number of lines of `text` (a last line without a newline counts).
fn line_count(text: &[u8]) -> usize {
    text.iter().filter(|&&b| b == b'\n').count() + 1
}

/// Text that may be shown on one line: no newline, carriage return or escape.
fn one_line_safe(text: &str) -> bool {
    !text.chars().any(|c| matches!(c, '\n' | '\r' | '\u{1b}'))
}

/// Judges a reader's error as the CLI shows it (text quoted from the input with its control
/// characters escaped: `files::escape_control`, the CLI's boundary): one non-empty line that
/// names the file, and a line within the file.
fn judge_error(e: &Error, file: &str, lines: usize) -> Outcome {
    let msg = feedopt::files::escape_control(&e.to_string());
    if msg.is_empty() || !one_line_safe(&msg) {
        return Outcome::Failed(format!("error is not one clean line: {msg:?}"));
    }
    if !msg.contains(file) {
        return Outcome::Failed(format!("error does not name the file {file}: {msg}"));
    }
    if let Error::Parse { line, .. } = e
        && !(1..=lines).contains(line)
    {
        return Outcome::Failed(format!("error names line {line} of {lines}: {msg}"));
    }
    Outcome::Error {
        kind: kind_of(&msg, file),
        message: msg,
    }
}

/// Checks a CL toolpath as read: finite positions within the coordinate bound, unit tool
/// vectors, feeds and dwells that are numbers of the right sign, every line within the file.
fn judge_toolpath(t: &toolpath::Toolpath, lines: usize) -> Result<(), String> {
    use toolpath::Feed;
    for (k, p) in t.points.iter().enumerate() {
        let at = format!("point from line {}", p.line);
        if !(1..=lines).contains(&p.line) {
            return Err(format!("{at}: the line is not in the file ({lines} lines)"));
        }
        if !p
            .p
            .iter()
            .all(|x| x.is_finite() && x.abs() <= toolpath::MAX_COORDINATE_MM)
        {
            return Err(format!(
                "{at}: position {:?} not finite or out of bounds",
                p.p
            ));
        }
        if (p.o.norm() - 1.0).abs() >= 1e-9 || !p.o.norm().is_finite() {
            return Err(format!("{at}: tool vector {:?} is not a unit vector", p.o));
        }
        if p.rotary.is_some_and(|r| !r.iter().all(|x| x.is_finite())) {
            return Err(format!("{at}: rotary positions {:?}", p.rotary));
        }
        match p.feed {
            // The first point's feed moves nothing (no move ends there): unused, and not
            // checked by `toolpath::plausible` either.
            Feed::Programmed(f) if k > 0 && !(f.is_finite() && f >= toolpath::MIN_FEED_MM_S) => {
                return Err(format!("{at}: feed {f} mm/s"));
            }
            Feed::BlockTime(s) if !(s.is_finite() && s > 0.0) => {
                return Err(format!("{at}: block time {s} s"));
            }
            _ => {}
        }
    }
    for d in &t.dwells {
        if d.point >= t.points.len() || !(d.seconds.is_finite() && d.seconds >= 0.0) {
            return Err(format!(
                "dwell from line {}: point {} of {}, {} s",
                d.line,
                d.point,
                t.points.len(),
                d.seconds
            ));
        }
    }
    for w in &t.warnings {
        let shown = feedopt::files::escape_control(&w.message);
        if !(1..=lines).contains(&w.line) || !one_line_safe(&shown) || shown.is_empty() {
            return Err(format!(
                "warning on line {} of {lines}: {:?}",
                w.line, w.message
            ));
        }
    }
    Ok(())
}

/// Checks a joint path as read: s strictly increasing, every value finite.
fn judge_joint(j: &toolpath::joint_csv::JointPath) -> Result<(), String> {
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
    Ok(())
}

/// Reads a mutated toolpath in-process, as the CLI does (`read_with`), and judges it.
fn toolpath_case(
    path: PathBuf,
    bytes: Vec<u8>,
    format: Format,
    dialect: Option<Dialect>,
    machine: Option<MachineContext>,
) -> Outcome {
    if let Err(e) = std::fs::write(&path, &bytes) {
        return Outcome::Harness(format!("{HARNESS}: writing {}: {e}", path.display()));
    }
    let lines = line_count(&bytes);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let options = ReadOptions {
        format: Some(format),
        dialect,
        machine,
        // The block-skip switch both ways (`/` blocks run or skipped), case by case.
        block_delete: bytes.len() % 2 == 1,
        ..Default::default()
    };
    match toolpath::read_with(&path, &options) {
        Err(e) => judge_error(&e, &name, lines),
        Ok((input, _)) => {
            let r = match &input {
                Input::Cl(t) => judge_toolpath(t, lines),
                Input::Joint(j) => judge_joint(j),
            };
            r.map_or_else(Outcome::Failed, |()| Outcome::Accepted)
        }
    }
}

/// Reads a mutated machine file in-process, as the CLI does (with its reference positions),
/// and judges it.
fn machine_case(path: PathBuf, bytes: Vec<u8>) -> Outcome {
    if let Err(e) = std::fs::write(&path, &bytes) {
        return Outcome::Harness(format!("{HARNESS}: writing {}: {e}", path.display()));
    }
    let lines = line_count(&bytes);
    match Machine::references_from_file(&path) {
        Err(e) => judge_error(&e, "machine.json", lines),
        Ok((m, references)) => {
            for a in &m.axes {
                let limits = [Some(a.velocity), Some(a.acceleration), a.jerk];
                for l in limits.into_iter().flatten() {
                    if !(l.min.is_finite() && l.max.is_finite() && l.min < 0.0 && l.max > 0.0) {
                        return Outcome::Failed(format!("accepted limit {l:?} on axis {}", a.name));
                    }
                }
            }
            if references
                .axes
                .iter()
                .any(|(_, r)| r.iter().any(|x| !x.is_finite()))
            {
                return Outcome::Failed(format!(
                    "accepted a reference that is not finite: {references:?}"
                ));
            }
            Outcome::Accepted
        }
    }
}

/// Fields of the summary that are `null` by design: no estimate or target on a fixed grid,
/// no reason when the refinement converged, none when no span was slowed down, no dialect for
/// an APT or CSV input, no reference or units note when the reader assumed no G28/G30
/// reference and no program unit.
const OPTIONAL: [&str; 8] = [
    "summary.error_estimate",
    "summary.error_target",
    "summary.unconverged",
    "summary.slowed_down",
    "summary.dialect",
    "summary.dialect_by",
    "summary.reference",
    "summary.units",
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

/// Runs `feedopt solve --stations 50 --json -o out.csv` with the `extra` arguments (`--solver
/// reach`, `--dialect fanuc`) on a mutated problem as a child process, killed past `bound` of
/// its CPU time (on one thread: `RAYON_NUM_THREADS=1`, so its CPU time is the time it would
/// take on a free core) or [`WALL_BACKSTOP`] × `bound` of wall time; `Ok(Some(line))`: it
/// ended in one clean error line. An error of the harness itself (writing the files, starting
/// the child) starts with `harness error`.
pub fn solve_case(
    dir: &Path,
    ext: &str,
    machine: &[u8],
    toolpath: &[u8],
    extra: &[&str],
    bound: Duration,
) -> Result<Option<String>, String> {
    let write = |name: &str, bytes: &[u8]| {
        std::fs::write(dir.join(name), bytes)
            .map_err(|e| format!("{HARNESS}: writing {}: {e}", dir.join(name).display()))
    };
    write("machine.json", machine)?;
    let tp = format!("path.{ext}");
    write(&tp, toolpath)?;
    let out_csv = dir.join("out.csv");
    let _ = std::fs::remove_file(&out_csv);
    let mut child = Command::new(env!("CARGO_BIN_EXE_feedopt"))
        .args(["solve", "--stations", "50", "--json"])
        .args(extra)
        .args(["-m", "machine.json", &tp, "-o", "out.csv"])
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("{HARNESS}: starting feedopt: {e}"))?;
    // Drain the pipes while waiting, so that a chatty child cannot block on a full pipe.
    let (mut out, mut err) = (child.stdout.take(), child.stderr.take());
    let reader = std::thread::spawn(move || {
        use std::io::Read;
        let (mut o, mut e) = (Vec::new(), Vec::new());
        if let Some(s) = out.as_mut() {
            let _ = s.read_to_end(&mut o);
        }
        if let Some(s) = err.as_mut() {
            let _ = s.read_to_end(&mut e);
        }
        (o, e)
    });
    let t0 = Instant::now();
    let backstop = bound * WALL_BACKSTOP;
    let status = loop {
        if let Some(s) = child
            .try_wait()
            .map_err(|e| format!("{HARNESS}: waiting for feedopt: {e}"))?
        {
            break s;
        }
        let cpu = process_cpu(child.id()).unwrap_or_default();
        let wall = t0.elapsed();
        if cpu > bound || wall > backstop {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!(
                "still running after {:.2} s of CPU time and {:.1} s of wall time (bound \
                 {bound:?} of CPU, backstop {backstop:?} of wall; killed)",
                cpu.as_secs_f64(),
                wall.as_secs_f64()
            ));
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    let (stdout, stderr) = reader.join().map_err(|_| "reading the child's output")?;
    let stdout = String::from_utf8_lossy(&stdout);
    let stderr = String::from_utf8_lossy(&stderr);
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
            Ok(None)
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
            Ok(Some(last.to_string()))
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

/// When a target stops: after so many cases, CPU seconds or wall time, whichever comes first
/// (`None`: no limit of that kind; at least one must be set).
#[derive(Debug, Clone, Copy, Default)]
pub struct Budget {
    pub cases: Option<u64>,
    /// CPU seconds of the process; for `solve`, of the process and its waited-for children.
    pub cpu_s: Option<f64>,
    pub wall: Option<Duration>,
}

/// How a campaign runs.
#[derive(Debug, Clone)]
pub struct Settings {
    /// Selects the stream of cases (the same seed gives the same cases).
    pub seed: u64,
    /// Add the excerpts of `../shared` to the corpora.
    pub shared: bool,
    /// Use the structure-aware mutations (words, constructs, records, keys, columns); without,
    /// only the blind ones (bytes, lines, numbers, splices).
    pub structure_aware: bool,
    /// Time bound of one in-process read.
    pub parse_bound: Duration,
    /// Time bound of one `feedopt solve`.
    pub solve_bound: Duration,
    /// Where each case's input is written, under `<work>/<target>/work/` (best on tmpfs:
    /// [`scratch_dir`]).
    pub work: PathBuf,
    /// The long run's output folder: each failure is saved under `<out>/<target>/failures/`
    /// as it is found and each target's figures go to `<out>/<target>/figures.txt`; with it,
    /// each case is described in `<work>/<target>/work/CASE.txt` before it runs (after an
    /// abort, the last case is there).
    pub out: Option<PathBuf>,
}

/// What one target did.
#[derive(Debug, Default, Clone)]
pub struct Figures {
    pub cases: u64,
    /// Cases that ended in one clean error line.
    pub errors: u64,
    pub failures: u64,
    /// The unmutated seeds run, and how many of them ended in an error.
    pub seeds: usize,
    pub seed_errors: usize,
    /// The seeds that ended in an error, with the message.
    pub seed_messages: Vec<String>,
    /// Distinct kinds of error message (without numbers and quoted text).
    pub kinds: HashSet<String>,
    /// Wall time of the cases, and the longest case's CPU time (what the bound bounds: the
    /// worker thread's, or for `solve` the child's).
    pub total: Duration,
    pub slowest: Duration,
    pub cpu_s: f64,
    pub wall_s: f64,
    /// Why the target stopped before its budget (a hung case, a harness error).
    pub stopped: Option<String>,
    /// An error of the harness itself that stopped the target (not a failure of the target).
    pub harness: Option<String>,
}

/// A case that failed, with its input.
#[derive(Debug)]
pub struct Failure {
    pub target: String,
    pub case: u64,
    pub what: String,
    pub mutation: String,
    pub seed: String,
    pub files: Vec<(String, Vec<u8>)>,
}

/// A fuzzing campaign over some targets.
pub struct Campaign {
    pub settings: Settings,
    pub failures: Vec<Failure>,
    /// Errors of the harness itself (writing files): reported apart from the failures.
    pub harness: Vec<String>,
    pub figures: Vec<(String, Figures)>,
}

/// At most this many failures per target are kept (the first ones).
const KEEP_FAILURES: usize = 50;

/// The context the reader gets from a seed's machine file (which must be valid).
fn context_of(seed: &Seed) -> MachineContext {
    let path = Path::new("seed-machine.json");
    let text = String::from_utf8(seed.machine.clone()).expect("UTF-8 seed machine");
    let m = Machine::from_json(path, &text)
        .unwrap_or_else(|e| panic!("the machine of seed {}: {e}", seed.name));
    let r = feedopt::machine::references_from_json(path, &text, &m)
        .unwrap_or_else(|e| panic!("the machine of seed {}: {e}", seed.name));
    MachineContext::new(&m, &r)
}

impl Campaign {
    /// A campaign with no target run yet.
    pub fn new(settings: Settings) -> Campaign {
        Campaign {
            settings,
            failures: Vec::new(),
            harness: Vec::new(),
            figures: Vec::new(),
        }
    }

    /// The seeds and mutation vocabulary of a target.
    fn corpus(&self, kind: Kind) -> (Vec<Seed>, Vocabulary) {
        let shared = self.settings.shared;
        let (seeds, vocabulary) = match kind {
            Kind::Apt => (corpus::apt(shared), corpus::apt_vocabulary()),
            Kind::Gcode(d) => (corpus::gcode(d, shared), corpus::gcode_vocabulary(d)),
            Kind::Machine => (corpus::machines(shared), corpus::machine_vocabulary()),
            Kind::JointCsv => (corpus::joint_csv_seeds(), corpus::csv_vocabulary()),
            Kind::Solve => (corpus::solves(shared, 120), Vocabulary::default()),
        };
        if self.settings.structure_aware {
            (seeds, vocabulary)
        } else {
            (seeds, Vocabulary::default())
        }
    }

    /// Runs `target` until `budget` is spent: first every seed as it is, then mutated ones.
    pub fn run(&mut self, target: &Target, budget: &Budget) {
        assert!(
            budget.cases.is_some() || budget.cpu_s.is_some() || budget.wall.is_some(),
            "a budget without a limit"
        );
        let (seeds, vocab) = self.corpus(target.kind);
        assert!(
            !seeds.is_empty(),
            "target {} has no seeds: give its dialect a row in DIALECTS (tests/fuzz/corpus.rs)",
            target.name
        );
        let contexts: Vec<MachineContext> = match target.kind {
            Kind::Apt | Kind::Gcode(_) => seeds.iter().map(context_of).collect(),
            _ => Vec::new(),
        };
        let others: Vec<&[u8]> = seeds.iter().map(|s| s.text.as_slice()).collect();
        let work = self.settings.work.join(&target.name).join("work");
        std::fs::create_dir_all(&work)
            .unwrap_or_else(|e| panic!("HARNESS ERROR: {}: {e}", work.display()));
        let children = target.kind == Kind::Solve;
        let (t0, cpu0) = (Instant::now(), cpu_seconds(children).unwrap_or(0.0));
        let mut fig = Figures::default();
        let worker = Worker::new();
        let stream = self.settings.seed.wrapping_mul(1_000_003) ^ hash(&target.name);
        let mut case: u64 = 0;
        loop {
            if budget.cases.is_some_and(|n| case >= n) {
                break;
            }
            // The clocks are read every 16 cases (a read costs about as much as a small case).
            if case % 16 == 0 {
                if budget.wall.is_some_and(|w| t0.elapsed() >= w) {
                    break;
                }
                if let Some(limit) = budget.cpu_s {
                    let used = cpu_seconds(children).unwrap_or(0.0) - cpu0;
                    if used >= limit {
                        break;
                    }
                }
            }
            let mut rng = Rng::new(stream.wrapping_add(case.wrapping_mul(0x9e37_79b9)));
            let (k, text, how) = if (case as usize) < seeds.len() {
                let k = case as usize;
                (
                    k,
                    seeds[k].text.clone(),
                    "none (the seed as it is)".to_string(),
                )
            } else {
                let k = rng.below(seeds.len());
                let (t, how) = mutate(&mut rng, &seeds[k].text, &vocab, &others);
                (k, t, how)
            };
            let seed = &seeds[k];
            if self.settings.out.is_some() {
                let input = match target.kind {
                    Kind::Machine => "machine.json".to_string(),
                    Kind::Solve => format!(
                        "path.{} and machine.json, with the arguments `feedopt solve --stations \
                         50 --json -m machine.json path.{} -o out.csv` and --solver, --dialect \
                         or --no-jerk (either file may be mutated)",
                        seed.ext, seed.ext
                    ),
                    _ => format!(
                        "path.{} (read with the context of the seed's machine file, or none)",
                        seed.ext
                    ),
                };
                let described = std::fs::write(
                    work.join("CASE.txt"),
                    format!(
                        "target {}, case {case}, seed {:?}, mutation: {how}\ninput: {input}\n",
                        target.name, seed.name
                    ),
                );
                if let Err(e) = described {
                    let what = format!(
                        "{HARNESS}: writing {}: {e}",
                        work.join("CASE.txt").display()
                    );
                    eprintln!("HARNESS ERROR {}: {what}", target.name);
                    fig.stopped = Some(what.clone());
                    fig.harness = Some(what);
                    break;
                }
            }
            let started = Instant::now();
            let is_seed = (case as usize) < seeds.len();
            let (outcome, cpu, files) = self.case(
                target.kind,
                &work,
                seed,
                text,
                is_seed,
                &contexts,
                k,
                &mut rng,
                &worker,
            );
            let elapsed = started.elapsed();
            if let Outcome::Harness(what) = outcome {
                // Not the target's failure: no failing input; the campaign reports it apart.
                eprintln!("HARNESS ERROR {} case {case}: {what}", target.name);
                fig.stopped = Some(format!("case {case}: {what}"));
                fig.harness = Some(what);
                break;
            }
            fig.cases += 1;
            fig.seeds += is_seed as usize;
            fig.total += elapsed;
            fig.slowest = fig.slowest.max(cpu);
            let mut failed = None;
            match outcome {
                Outcome::Accepted => {}
                Outcome::Error { kind, message } => {
                    fig.errors += 1;
                    if is_seed {
                        fig.seed_errors += 1;
                        fig.seed_messages.push(format!("{}: {message}", seed.name));
                    }
                    fig.kinds.insert(kind);
                }
                Outcome::Failed(what) => failed = Some((what, false)),
                Outcome::Hung(what) => failed = Some((what, true)),
                Outcome::Harness(_) => unreachable!("handled above"),
            }
            if let Some((what, hung)) = failed {
                fig.failures += 1;
                eprintln!("FAIL {} case {case}: {what} ({how})", target.name);
                if fig.failures as usize <= KEEP_FAILURES {
                    let f = Failure {
                        target: target.name.clone(),
                        case,
                        what: what.clone(),
                        mutation: how,
                        seed: seed.name.clone(),
                        files,
                    };
                    if let Some(out) = &self.settings.out
                        && let Err(e) = self.save_failure(&f, out)
                    {
                        eprintln!("HARNESS ERROR {}: {e}", target.name);
                        fig.stopped = Some(e.clone());
                        fig.harness = Some(e);
                        self.failures.push(f);
                        break;
                    }
                    self.failures.push(f);
                }
                if hung && target.kind != Kind::Solve {
                    // The hung worker keeps a core busy and takes no more cases.
                    fig.stopped = Some(format!("case {case} hung: {what}"));
                    break;
                }
            }
            case += 1;
        }
        fig.wall_s = t0.elapsed().as_secs_f64();
        fig.cpu_s = cpu_seconds(children).unwrap_or(0.0) - cpu0;
        if let Some(e) = &fig.harness {
            self.harness.push(format!("{}: {e}", target.name));
        }
        self.figures.push((target.name.clone(), fig));
        if let Some(out) = &self.settings.out {
            let path = out.join(&target.name).join("figures.txt");
            let table = self.table_of(&self.figures[self.figures.len() - 1..], "long");
            // The target's folder exists only where a failure was saved: make it.
            let written = std::fs::create_dir_all(out.join(&target.name))
                .and_then(|()| std::fs::write(&path, table));
            if let Err(e) = written {
                let e = format!("{HARNESS}: writing {}: {e}", path.display());
                eprintln!("HARNESS ERROR {}: {e}", target.name);
                self.harness.push(e);
            }
        }
    }

    /// Runs one case of `kind` on `text` (a mutation of `seed`, or the seed itself when
    /// `pristine`): the outcome, the CPU time it took (the worker thread's, or the `solve`
    /// child's) and the files to keep when it fails.
    #[allow(clippy::too_many_arguments)]
    fn case(
        &self,
        kind: Kind,
        work: &Path,
        seed: &Seed,
        text: Vec<u8>,
        pristine: bool,
        contexts: &[MachineContext],
        k: usize,
        rng: &mut Rng,
        worker: &Worker,
    ) -> (Outcome, Duration, Vec<(String, Vec<u8>)>) {
        let bound = self.settings.parse_bound;
        match kind {
            Kind::Apt | Kind::Gcode(_) | Kind::JointCsv => {
                let (format, dialect) = match kind {
                    Kind::Apt => (Format::Apt, None),
                    Kind::Gcode(d) => (Format::Gcode, Some(d)),
                    _ => (Format::Csv, None),
                };
                // The reader with the machine's context three times in four.
                let machine = contexts
                    .get(k)
                    .filter(|_| pristine || !rng.one_in(4))
                    .cloned();
                let name = format!("path.{}", seed.ext);
                let files = vec![
                    (name.clone(), text.clone()),
                    ("machine.json".to_string(), seed.machine.clone()),
                ];
                let path = work.join(&name);
                let job = move || toolpath_case(path, text, format, dialect, machine);
                let (outcome, cpu) = worker.run(bound, Box::new(job));
                (outcome, cpu, files)
            }
            Kind::Machine => {
                let files = vec![("machine.json".to_string(), text.clone())];
                let path = work.join("machine.json");
                let job = move || machine_case(path, text);
                let (outcome, cpu) = worker.run(bound, Box::new(job));
                (outcome, cpu, files)
            }
            Kind::Solve => {
                // Mutate the toolpath (three times in five), the machine, or both (`text` is
                // the mutated toolpath). Most mutated machine files are not JSON any more and
                // end the solve at once, so the toolpath gets most of the cases.
                let (machine, toolpath, how) = match rng.below(5) {
                    _ if pristine => (seed.machine.clone(), text, "nothing"),
                    0..=2 => (seed.machine.clone(), text, "toolpath"),
                    3 => {
                        let (m, _) = mutate(rng, &seed.machine, &corpus::machine_vocabulary(), &[]);
                        (m, seed.text.clone(), "machine")
                    }
                    _ => {
                        let (m, _) = mutate(rng, &seed.machine, &corpus::machine_vocabulary(), &[]);
                        (m, text, "both")
                    }
                };
                // The dialect given two times in three, else detected.
                let dialect = seed.dialect.filter(|_| pristine || !rng.one_in(3));
                let mut extra: Vec<&str> = match dialect {
                    Some(d) => vec!["--dialect", d.name()],
                    None => Vec::new(),
                };
                // The reach pass ignores jerk limits and refuses a machine that has them: a
                // seed machine with jerk runs with Clarabel, or without its jerk limits.
                let jerk = std::str::from_utf8(&seed.machine)
                    .ok()
                    .and_then(|t| Machine::from_json(Path::new("m.json"), t).ok())
                    .is_some_and(|m| m.has_jerk());
                if jerk && rng.one_in(2) {
                    extra.extend(["--solver", "clarabel"]);
                } else {
                    extra.extend(["--solver", "reach"]);
                    if jerk {
                        extra.push("--no-jerk");
                    }
                }
                let files = vec![
                    ("machine.json".to_string(), machine.clone()),
                    (format!("path.{}", seed.ext), toolpath.clone()),
                    (
                        "ARGS.txt".to_string(),
                        format!("mutated: {how}; extra arguments: {extra:?}\n").into_bytes(),
                    ),
                ];
                let cpu0 = children_cpu();
                let r = solve_case(
                    work,
                    seed.ext,
                    &machine,
                    &toolpath,
                    &extra,
                    self.settings.solve_bound,
                );
                let o = match r {
                    Ok(None) => Outcome::Accepted,
                    Ok(Some(line)) => Outcome::Error {
                        kind: kind_of(&line, &format!("path.{}", seed.ext)),
                        message: line,
                    },
                    Err(what) if what.starts_with("still running") => Outcome::Hung(what),
                    Err(what) if what.starts_with(HARNESS) => Outcome::Harness(what),
                    Err(what) => Outcome::Failed(what),
                };
                (o, children_cpu().saturating_sub(cpu0), files)
            }
        }
    }

    /// The figures as a table, one row per target run.
    pub fn table(&self, label: &str) -> String {
        self.table_of(&self.figures, label)
    }

    /// The table of some targets' figures.
    fn table_of(&self, figures: &[(String, Figures)], label: &str) -> String {
        let mut out = format!(
            "fuzz {label} (seed {}, corpora {}):\n",
            self.settings.seed,
            if self.settings.shared {
                "problems/, hand-made and ../shared"
            } else {
                "problems/ and hand-made"
            }
        );
        out.push_str(&format!(
            "  {:<16} {:>9} {:>9} {:>8} {:>6} {:>7} {:>8} {:>11} {:>14} {:>8} {:>8}\n",
            "target",
            "cases",
            "errors",
            "failures",
            "kinds",
            "seeds",
            "mean ms",
            "mean CPU ms",
            "slowest CPU ms",
            "CPU s",
            "wall s"
        ));
        for (t, f) in figures {
            out.push_str(&format!(
                "  {:<16} {:>9} {:>9} {:>8} {:>6} {:>7} {:>8.3} {:>11.3} {:>14.1} {:>8.1} {:>8.1}\n",
                t,
                f.cases,
                f.errors,
                f.failures,
                f.kinds.len(),
                format!("{}/{}", f.seeds - f.seed_errors, f.seeds),
                f.total.as_secs_f64() * 1e3 / f.cases.max(1) as f64,
                f.cpu_s * 1e3 / f.cases.max(1) as f64,
                f.slowest.as_secs_f64() * 1e3,
                f.cpu_s,
                f.wall_s
            ));
            if let Some(why) = &f.stopped {
                out.push_str(&format!("    {t} stopped early: {why}\n"));
            }
        }
        out.push_str(
            "  (errors: cases that ended in one clean error line; kinds: distinct error \
             messages without numbers and quoted text; seeds: read cleanly / run; mean ms: \
             wall time of a case; slowest CPU ms: the CPU time of the longest case, what the \
             time bound bounds (the worker thread's, for solve the feedopt child's); mean CPU \
             ms, CPU s: this process, and for solve its feedopt children too)\n",
        );
        out
    }

    /// Writes a failing case's input under `dir/<target>/failures/case-<n>/`, with `WHAT.txt`;
    /// a harness error when it cannot.
    fn save_failure(&self, f: &Failure, dir: &Path) -> Result<(), String> {
        let d = dir
            .join(&f.target)
            .join("failures")
            .join(format!("case-{}", f.case));
        let saved = std::fs::create_dir_all(&d)
            .and_then(|()| {
                f.files
                    .iter()
                    .try_for_each(|(name, bytes)| std::fs::write(d.join(name), bytes))
            })
            .and_then(|()| {
                std::fs::write(
                    d.join("WHAT.txt"),
                    format!(
                        "{}\nseed: {}\nmutation: {}\ncampaign seed {}\n",
                        f.what, f.seed, f.mutation, self.settings.seed
                    ),
                )
            });
        saved.map_err(|e| format!("{HARNESS}: saving a failing input in {}: {e}", d.display()))
    }

    /// Panics with the list of failures (after saving them under `dir`), if there are any,
    /// and with the harness's own errors, apart (`HARNESS ERROR`: not the targets' failures).
    pub fn assert_clean(&self, dir: &Path) {
        let mut harness = self.harness.clone();
        for f in &self.failures {
            if let Err(e) = self.save_failure(f, dir) {
                harness.push(e);
            }
        }
        assert!(
            harness.is_empty(),
            "HARNESS ERROR (the harness failed, not the targets; {} failing cases): {}",
            self.failures.len(),
            harness.join("; ")
        );
        if self.failures.is_empty() {
            return;
        }
        let list: Vec<String> = self
            .failures
            .iter()
            .take(20)
            .map(|f| {
                format!(
                    "{} case {}: {} ({}; {})",
                    f.target, f.case, f.what, f.seed, f.mutation
                )
            })
            .collect();
        panic!(
            "{} failing cases (inputs in {}):\n{}",
            self.figures.iter().map(|(_, f)| f.failures).sum::<u64>(),
            dir.display(),
            list.join("\n")
        );
    }
}
