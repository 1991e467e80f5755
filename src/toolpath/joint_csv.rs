//! Joint-space paths: axis positions along a path parameter, as CSV.
//!
//! For robots, custom kinematics and solver comparisons, a path may be given directly as the
//! positions of the machine's axes along a parameter s:
//!
//! ```text
//! s,q_0,q_1,dq_0,dq_1,ddq_0,ddq_1
//! 0.0,0.1,-0.3,0.0,0.0,0.0,0.0
//! 0.001,0.1002,-0.2999,0.79,0.45,1535.2,873.1
//! ```
//!
//! The first column is `s` (strictly increasing); then `q_<axis>` for every axis (the machine
//! file of kinematics `joint` names the same axes), and optionally `dq_<axis>`, `ddq_<axis>`,
//! `dddq_<axis>`: derivatives with respect to s, each family given for all axes or none. When
//! derivatives are given they are used as given (the path between rows is the Hermite
//! interpolant that takes them); when absent a cubic spline is fitted. Units are the axes' own
//! (mm or degrees); s is unit-free. Errors name the file, the line and the column.
//!
//! Degenerate paths are refused (they would otherwise be refined to millions of stations on
//! infinite violations): every q within ±[`MAX_POSITION`]; s within ±[`MAX_S`] and rows at
//! least [`MIN_S_STEP`] apart in s; some axis moving by more than [`MIN_MOTION`]; and every given
//! derivative small enough that its Taylor term over one row step, |dᵏq/dsᵏ| hᵏ/k!, stays
//! within [`MAX_TAYLOR_TERM`] (h the larger of the row's two steps in s).

use std::path::{Path, PathBuf};

use crate::base::MAX_AXES;
use crate::error::{Error, Result};

/// Per-row values of every axis, in [`JointPath::axes`] order (unused entries zero).
pub type Row = [f64; MAX_AXES];

/// A joint-space path as read from a CSV file.
#[derive(Debug, Clone, PartialEq)]
pub struct JointPath {
    pub source: PathBuf,
    /// Axis names, in the order of the `q_` columns.
    pub axes: Vec<String>,
    /// The path parameter at each row, strictly increasing.
    pub s: Vec<f64>,
    pub q: Vec<Row>,
    /// dq/ds, d²q/ds², d³q/ds³ when the file gives them.
    pub dq: Option<Vec<Row>>,
    pub ddq: Option<Vec<Row>>,
    pub dddq: Option<Vec<Row>>,
    /// Source line of each row.
    pub lines: Vec<usize>,
}

/// The largest axis position a joint-space path may give, mm or degrees (1 km).
pub const MAX_POSITION: f64 = crate::machine::MAX_LENGTH;

/// The largest |s|: s is unit-free, but beyond this it is not a path parameter.
pub const MAX_S: f64 = 1e9;

/// The smallest step in s between two rows: closer rows make the derivatives dq/ds (and with
/// them the solver's numbers) overflow. s is unit-free: rescale it (0 to 1, or mm).
pub const MIN_S_STEP: f64 = 1e-9;

/// The largest Taylor term |dᵏq/dsᵏ| hᵏ/k! of a given derivative over one row step h, mm or
/// degrees: ten times [`MAX_POSITION`]. A path sampled finely enough to follow (above two rows
/// per oscillation) has terms of at most about 5 times its amplitude (π³/6 for the third
/// derivative of a sine at two rows per period), so only derivatives of absurd size, or not
/// with respect to s, are refused.
pub const MAX_TAYLOR_TERM: f64 = 10.0 * MAX_POSITION;

/// The least motion of the whole path, on some axis, mm or degrees (a picometre: below any
/// machine's resolution).
pub const MIN_MOTION: f64 = 1e-9;

/// Reads a joint-space CSV file.
pub fn read(path: &Path) -> Result<JointPath> {
    let text = crate::files::utf8(path, super::read_bytes(path)?)?;
    parse(path, &text)
}

/// What a column holds: derivative order (0 = q) and axis index.
#[derive(Debug, Clone, Copy)]
enum Column {
    S,
    Axis { order: usize, axis: usize },
}

/// Parses joint-space CSV text; `source` names the file in errors.
pub fn parse(source: &Path, text: &str) -> Result<JointPath> {
    let err = |line: usize, msg: String| Error::parse(source, line, msg);
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let (hline, header) = lines
        .next()
        .ok_or_else(|| err(1, "empty file: expected a header `s,q_<axis>,…`".into()))?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    if names.first() != Some(&"s") {
        return Err(err(
            hline,
            format!("the first column must be `s`, found `{}`", names[0]),
        ));
    }
    // Axes from the q_ columns, in order.
    let axes: Vec<String> = names
        .iter()
        .filter_map(|n| n.strip_prefix("q_").map(str::to_string))
        .collect();
    if axes.is_empty() || axes.len() > MAX_AXES {
        return Err(err(
            hline,
            format!(
                "expected 1 to {MAX_AXES} `q_<axis>` columns, found {}",
                axes.len()
            ),
        ));
    }
    let mut columns = Vec::with_capacity(names.len());
    let mut seen = [[false; MAX_AXES]; 4];
    for (c, name) in names.iter().enumerate() {
        if c == 0 {
            columns.push(Column::S);
            continue;
        }
        let (order, axis) = ["q_", "dq_", "ddq_", "dddq_"]
            .iter()
            .enumerate()
            .find_map(|(o, p)| name.strip_prefix(p).map(|a| (o, a)))
            .ok_or_else(|| {
                err(hline, format!("column {}: unknown column `{name}` (expected s, q_<axis>, dq_<axis>, ddq_<axis>, dddq_<axis>)", c + 1))
            })?;
        let axis = axes.iter().position(|a| a == axis).ok_or_else(|| {
            err(
                hline,
                format!(
                    "column {}: `{name}` names an axis with no `q_{axis}` column",
                    c + 1
                ),
            )
        })?;
        if seen[order][axis] {
            return Err(err(
                hline,
                format!("column {}: `{name}` appears twice", c + 1),
            ));
        }
        seen[order][axis] = true;
        columns.push(Column::Axis { order, axis });
    }
    let present: Vec<bool> = (1..4)
        .map(|o| seen[o][..axes.len()].iter().any(|&x| x))
        .collect();
    for (o, prefix) in [(1, "dq_"), (2, "ddq_"), (3, "dddq_")] {
        if present[o - 1] {
            if let Some(a) = (0..axes.len()).find(|&a| !seen[o][a]) {
                return Err(err(
                    hline,
                    format!(
                        "`{prefix}` columns are given for some axes but not for `{}`",
                        axes[a]
                    ),
                ));
            }
        }
    }
    if present[1] && !present[0] {
        return Err(err(hline, "`ddq_` columns need `dq_` columns too".into()));
    }
    let mut out = JointPath {
        source: source.to_path_buf(),
        axes,
        s: Vec::new(),
        q: Vec::new(),
        dq: present[0].then(Vec::new),
        ddq: present[1].then(Vec::new),
        dddq: present[2].then(Vec::new),
        lines: Vec::new(),
    };
    for (line, text) in lines {
        let fields: Vec<&str> = text.split(',').map(str::trim).collect();
        if fields.len() != columns.len() {
            return Err(err(
                line,
                format!("expected {} values, found {}", columns.len(), fields.len()),
            ));
        }
        let mut rows = [[0.0; MAX_AXES]; 4];
        let mut s = 0.0;
        for (c, (field, col)) in fields.iter().zip(&columns).enumerate() {
            let v: f64 = field
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| {
                    err(
                        line,
                        format!(
                            "column {} (`{}`): `{field}` is not a finite number",
                            c + 1,
                            names[c]
                        ),
                    )
                })?;
            let too_large = |max: f64| {
                err(
                    line,
                    format!(
                        "column {} (`{}`): {} is implausibly large (at most {max:e} in size)",
                        c + 1,
                        names[c],
                        crate::error::number(v)
                    ),
                )
            };
            match *col {
                Column::S if v.abs() > MAX_S => return Err(too_large(MAX_S)),
                Column::S => s = v,
                Column::Axis { order: 0, .. } if v.abs() > MAX_POSITION => {
                    return Err(too_large(MAX_POSITION));
                }
                Column::Axis { order, axis } => rows[order][axis] = v,
            }
        }
        if let Some(&prev) = out.s.last() {
            if s <= prev {
                return Err(err(
                    line,
                    format!(
                        "column 1 (`s`): s must increase strictly: {} after {}",
                        crate::error::number(s),
                        crate::error::number(prev)
                    ),
                ));
            }
            if s - prev < MIN_S_STEP {
                return Err(err(
                    line,
                    format!(
                        "column 1 (`s`): {} is only {:e} after the row before ({}); rows \
                         must be at least {MIN_S_STEP:e} apart in s: rescale s (it is \
                         unit-free: e.g. 0 to 1, or the path length in mm)",
                        crate::error::number(s),
                        s - prev,
                        crate::error::number(prev)
                    ),
                ));
            }
        }
        out.s.push(s);
        out.q.push(rows[0]);
        for (o, v) in [&mut out.dq, &mut out.ddq, &mut out.dddq]
            .into_iter()
            .enumerate()
        {
            if let Some(v) = v {
                v.push(rows[o + 1]);
            }
        }
        out.lines.push(line);
    }
    if out.s.len() < 2 {
        return Err(err(
            hline,
            "a joint-space path needs at least two rows".into(),
        ));
    }
    check_motion(&out, hline)?;
    check_derivatives(&out, &names, &columns)?;
    Ok(out)
}

/// Some axis must move by more than [`MIN_MOTION`] over the path.
fn check_motion(path: &JointPath, hline: usize) -> Result<()> {
    let na = path.axes.len();
    let moves = (0..na).any(|a| {
        let (lo, hi) = path
            .q
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), r| {
                (lo.min(r[a]), hi.max(r[a]))
            });
        hi - lo > MIN_MOTION
    });
    if moves {
        return Ok(());
    }
    let first = path.lines[0];
    let last = path.lines[path.lines.len() - 1];
    Err(Error::parse(
        &path.source,
        hline,
        format!(
            "no `q_` column changes by more than {MIN_MOTION:e} from line {first} to line \
             {last}: the path does not move; give the axis positions along s"
        ),
    ))
}

/// Every given derivative's Taylor term over one row step, |dᵏq/dsᵏ| hᵏ/k!, within
/// [`MAX_TAYLOR_TERM`] (module doc).
fn check_derivatives(path: &JointPath, names: &[&str], columns: &[Column]) -> Result<()> {
    let n = path.s.len();
    for (order, rows) in [(1, &path.dq), (2, &path.ddq), (3, &path.dddq)] {
        let Some(rows) = rows else { continue };
        let factorial = [1.0, 1.0, 2.0, 6.0][order];
        for i in 0..n {
            let h = (if i > 0 {
                path.s[i] - path.s[i - 1]
            } else {
                0.0
            })
            .max(if i + 1 < n {
                path.s[i + 1] - path.s[i]
            } else {
                0.0
            });
            for a in 0..path.axes.len() {
                let d = rows[i][a];
                let term = d.abs() * h.powi(order as i32) / factorial;
                if term > MAX_TAYLOR_TERM {
                    let c = columns
                        .iter()
                        .position(|c| {
                            matches!(*c, Column::Axis { order: o, axis } if o == order && axis == a)
                        })
                        .unwrap_or(0);
                    return Err(Error::parse(
                        &path.source,
                        path.lines[i],
                        format!(
                            "column {} (`{}`): {} would move the axis by {} over one row step \
                             (Δs = {h:e}), more than {MAX_TAYLOR_TERM:e}: derivatives are with \
                             respect to s, in the axis's unit",
                            c + 1,
                            names[c],
                            crate::error::number(d),
                            if term.is_finite() {
                                crate::error::number(term)
                            } else {
                                "more than f64 can hold".to_string()
                            }
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}
