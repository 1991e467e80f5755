//! Writers: everything feedopt writes — the schedule as JSON or CSV (here), G-code
//! ([`gcode`]), plots ([`plot`], cargo feature `plot`), setpoints ([`setpoints`]) and a
//! sweep's table ([`sweep`]); one check of an output's format by its extension
//! ([`output_format`]). Every file is written to a temporary file in the
//! target's directory and renamed into place, so no half-written output is ever left behind.

pub mod gcode;
#[cfg(feature = "plot")]
pub mod plot;
pub mod setpoints;
pub mod sweep;

use std::io::Write;
use std::path::Path;

use crate::error::{Error, Result};
use crate::schedule::Schedule;

/// The formats feedopt writes, told by a file's extension ([`output_format`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// `.json`.
    Json,
    /// `.csv`.
    Csv,
    /// `.bin`: the setpoints' binary layout ([`setpoints`]).
    Bin,
    /// `.svg`: a plot (cargo feature `plot`).
    Svg,
}

impl Format {
    /// The extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Json => "json",
            Format::Csv => "csv",
            Format::Bin => "bin",
            Format::Svg => "svg",
        }
    }
}

/// The formats a schedule (and a sweep's table) is written in: `.json` ([`schedule_json`]) or
/// `.csv` ([`schedule_csv`]).
pub const SCHEDULE: &[Format] = &[Format::Json, Format::Csv];

/// The format of a plot: `.svg`.
pub const PLOT: &[Format] = &[Format::Svg];

/// The one check of an output path's format, made before any work is done: its extension
/// (in any case) names one of the `accepted` formats, and its directory takes a new file
/// ([`check_directory`]). A plot needs the cargo feature `plot`; `.png` is refused with the
/// way to convert an SVG.
pub fn output_format(path: &Path, accepted: &[Format]) -> Result<Format> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let plot = accepted == PLOT;
    if plot && !cfg!(feature = "plot") {
        return Err(Error::Usage(format!(
            "--plot {}: this feedopt was built without plots (cargo feature `plot`): rebuild \
             with it, or leave --plot out",
            path.display()
        )));
    }
    let format = accepted
        .iter()
        .copied()
        .find(|f| ext.as_deref() == Some(f.extension()));
    let Some(format) = format else {
        if plot && ext.as_deref() == Some("png") {
            return Err(Error::Usage(format!(
                "{}: PNG plots are not supported (they need font files feedopt does not \
                 bundle); write .svg (e.g. `rsvg-convert plot.svg -o plot.png` converts it)",
                path.display()
            )));
        }
        let what = if plot {
            "plot"
        } else if accepted == setpoints::SETPOINTS {
            "setpoint"
        } else {
            "output"
        };
        let names: Vec<String> = accepted
            .iter()
            .map(|f| format!(".{}", f.extension()))
            .collect();
        return Err(Error::Usage(format!(
            "{}: unknown {what} format (use {})",
            path.display(),
            names.join(" or ")
        )));
    };
    check_directory(path)?;
    Ok(format)
}

/// An output path must be writable (checked before any work is done, so that a long solve
/// never ends in "cannot write"): its directory exists and a file can be created in it (a
/// temporary file is created and removed at once), and the path is not a directory or a
/// device.
pub fn check_directory(path: &Path) -> Result<()> {
    let dir = parent_dir(path);
    if !dir.is_dir() {
        return Err(Error::Usage(format!(
            "{}: the directory {} does not exist: create it or write elsewhere",
            path.display(),
            dir.display()
        )));
    }
    if let Ok(meta) = std::fs::metadata(path) {
        if !meta.is_file() {
            return Err(Error::Usage(format!(
                "{}: exists and is not a regular file (a directory or a device): name a file",
                path.display()
            )));
        }
    }
    tempfile::NamedTempFile::new_in(dir).map_err(|e| {
        Error::Usage(format!(
            "{}: cannot create a file in {} ({}): write elsewhere",
            path.display(),
            dir.display(),
            std::io::Error::from(e.kind())
        ))
    })?;
    Ok(())
}

/// Checks an output path given by `option` (`-o`, `--plot`) before any work is done: it must
/// not be any of `inputs` (what each is, and its path) — compared as files, so a different
/// spelling, a symbolic link or (on Unix) a hard link to an input counts as the input — and
/// it must be writable ([`check_directory`]).
pub fn check_output(option: &str, path: &Path, inputs: &[(&str, &Path)]) -> Result<()> {
    for (what, input) in inputs {
        if same_file(path, input) {
            return Err(Error::Usage(format!(
                "{option} {}: is the {what} {} itself; writing it would overwrite the input: \
                 name another file",
                path.display(),
                input.display()
            )));
        }
    }
    check_directory(path)
}

/// Whether `a` and `b` name the same existing file: the same canonical path (symbolic links
/// resolved) or, on Unix, the same device and inode (hard links).
pub fn same_file(a: &Path, b: &Path) -> bool {
    if let (Ok(ca), Ok(cb)) = (a.canonicalize(), b.canonicalize()) {
        if ca == cb {
            return true;
        }
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return ma.dev() == mb.dev() && ma.ino() == mb.ino();
        }
    }
    false
}

/// Writes `schedule` to `path`, in the format of its extension (`.json` or `.csv`), streamed
/// to the file: the working set does not grow with the schedule (a 1.08 M-station schedule's
/// JSON document took 7.6 GB built in memory). `holds`: the program's dwells
/// ([`crate::geometry::Path::holds`]), which the stations' times and the cycle time include.
pub fn write_schedule(path: &Path, schedule: &Schedule, holds: &[f64]) -> Result<()> {
    let format = output_format(path, SCHEDULE)?;
    write_atomically_with(path, |w| match format {
        Format::Json => write_schedule_json(schedule, holds, w),
        _ => write_schedule_csv(schedule, holds, w),
    })
}

/// Per span, the dwells before its motion starts ([`crate::geometry::Path::holds`]: the one
/// before the first span and those after each span before it), s; and their total.
fn dwells_before(schedule: &Schedule, holds: &[f64]) -> (Vec<f64>, f64) {
    let spans = schedule.stations.last().map_or(0, |s| s.span + 1);
    let hold = |s: usize| holds.get(s).copied().unwrap_or(0.0);
    let mut before = Vec::with_capacity(spans);
    let mut sum = hold(0);
    for s in 0..spans {
        before.push(sum);
        sum += hold(s + 1);
    }
    (before, holds.iter().sum())
}

fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// The schedule as JSON: `{"units": {…}, "axes": [...], "cycle_time_s": …, "stations":
/// [{span, u, s, t, v, a, q: {X: …}, qd: {…}, qdd: {…}}, …]}`, one station a line; t and
/// `cycle_time_s` count the program's dwells `holds`, as [`schedule_csv`].
pub fn schedule_json(schedule: &Schedule, holds: &[f64]) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    write_schedule_json(schedule, holds, &mut out)
        .map_err(|e| Error::Solver(format!("JSON encoding: {e}")))?;
    Ok(out)
}

/// [`schedule_json`], written to `w` station by station.
pub fn write_schedule_json(
    schedule: &Schedule,
    holds: &[f64],
    w: &mut dyn Write,
) -> std::io::Result<()> {
    let (before, dwells) = dwells_before(schedule, holds);
    let num = |w: &mut dyn Write, x: f64| -> std::io::Result<()> {
        serde_json::to_writer(&mut *w, &x).map_err(std::io::Error::other)
    };
    let names: Vec<String> = schedule
        .axes
        .iter()
        .map(|n| serde_json::to_string(n).map_err(std::io::Error::other))
        .collect::<std::io::Result<_>>()?;
    write!(
        w,
        "{{\n  \"units\": {{\"length\": \"mm\", \"angle\": \"deg\", \"time\": \"s\"}},\n  \"axes\": [{}],\n  \"cycle_time_s\": ",
        names.join(", ")
    )?;
    num(w, schedule.cycle_time + dwells)?;
    write!(w, ",\n  \"stations\": [")?;
    for (i, s) in schedule.stations.iter().enumerate() {
        write!(
            w,
            "{}\n    {{\"span\": {}",
            if i > 0 { "," } else { "" },
            s.span
        )?;
        let t = s.t + before[s.span];
        for (key, x) in [("u", s.u), ("s", s.s), ("t", t), ("v", s.v), ("a", s.a)] {
            write!(w, ", \"{key}\": ")?;
            num(w, x)?;
        }
        for (key, x) in [
            ("q", schedule.q(i)),
            ("qd", schedule.qd(i)),
            ("qdd", schedule.qdd(i)),
        ] {
            write!(w, ", \"{key}\": {{")?;
            for (j, (name, v)) in names.iter().zip(x).enumerate() {
                write!(w, "{}{name}: ", if j > 0 { ", " } else { "" })?;
                num(w, *v)?;
            }
            write!(w, "}}")?;
        }
        write!(w, "}}")?;
    }
    writeln!(w, "\n  ]\n}}")
}

/// The schedule as CSV, one row per station: `span,u,s,t,v,a,q_X,…,qd_X,…,qdd_X,…`. The times
/// count the program's dwells `holds` (a dwell after span s: the gap between its last station
/// and span s + 1's first, where the tool stands).
pub fn schedule_csv(schedule: &Schedule, holds: &[f64]) -> String {
    let mut out = Vec::new();
    // (Writing to a Vec cannot fail, and every byte written is UTF-8.)
    let _ = write_schedule_csv(schedule, holds, &mut out);
    String::from_utf8(out).unwrap_or_default()
}

/// [`schedule_csv`], written to `w` station by station.
pub fn write_schedule_csv(
    schedule: &Schedule,
    holds: &[f64],
    w: &mut dyn Write,
) -> std::io::Result<()> {
    let (before, _) = dwells_before(schedule, holds);
    write!(w, "span,u,s,t,v,a")?;
    for prefix in ["q", "qd", "qdd"] {
        for n in &schedule.axes {
            write!(w, ",{prefix}_{n}")?;
        }
    }
    writeln!(w)?;
    for (i, s) in schedule.stations.iter().enumerate() {
        let t = s.t + before[s.span];
        write!(w, "{},{},{},{},{},{}", s.span, s.u, s.s, t, s.v, s.a)?;
        for x in [schedule.q(i), schedule.qd(i), schedule.qdd(i)] {
            for v in x {
                write!(w, ",{v}")?;
            }
        }
        writeln!(w)?;
    }
    Ok(())
}

/// Writes `bytes` to a temporary file next to `path`, then renames it over `path`.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomically_with(path, |w| w.write_all(bytes))
}

/// [`write_atomically`] with the content written by `write` to a buffered temporary file.
pub fn write_atomically_with(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    write_atomically_try(path, |w| write(w).map_err(|e| Error::io(path, e)))
}

/// [`write_atomically_with`] for content whose writing may fail otherwise than by I/O (its
/// error is returned as it is, and nothing is left behind).
pub fn write_atomically_try(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> Result<()>,
) -> Result<()> {
    // The temporary file's own name stays out of messages: they name the target.
    let plain = |e: std::io::Error| Error::io(path, std::io::Error::from(e.kind()));
    // A temporary file is private (0600); the output gets the mode any new file would get
    // (0666 less the umask), as if written in place.
    let mut builder = tempfile::Builder::new();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut tmp = builder.tempfile_in(parent_dir(path)).map_err(plain)?;
    {
        let mut w = std::io::BufWriter::with_capacity(1 << 16, tmp.as_file_mut());
        write(&mut w)?;
        w.flush().map_err(|e| Error::io(path, e))?;
    }
    tmp.as_file().sync_all().map_err(|e| Error::io(path, e))?;
    tmp.persist(path).map_err(|e| plain(e.error))?;
    Ok(())
}
