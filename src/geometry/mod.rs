//! Path geometry: CL points and rotary angles in, rest-to-rest [`Span`]s of C² splines out.
//!
//! Each span interpolates the path coordinates w = (Px, Py, Pz, θ1, θ2) with one
//! [`spline::CubicSpline`] in one parameter u (seed 000, eq. 1–3 and 17–18):
//!
//! - a **moving** span (the tool tip travels) uses the cumulative chord length of the tip
//!   (mm), so |P'(u)| ≈ 1;
//! - a **reorientation** span (the tip stands still while the tool turns) uses the cumulative
//!   angle between successive tool orientations (radians), with P constant, |P'| = 0.
//!
//! The path is split into spans, each run rest to rest (an exact stop), at sharp corners
//! (turning angle between successive chords above `corner_angle`) and where the tip starts or
//! stops moving while the tool turns.

pub mod spline;

use nalgebra::Vector3;

use crate::error::{Error, Result};
use crate::kinematics::{PATH_DIM, PathJet};
use crate::machine::Machine;
use crate::toolpath::joint_csv::JointPath;
use crate::toolpath::{Feed, Toolpath};
use spline::CubicSpline;

/// Points closer than this (mm) count as the same tool-tip position.
pub const SAME_POSITION_MM: f64 = 1e-6;
/// Orientations closer than this (radians) count as the same.
pub const SAME_ORIENTATION_RAD: f64 = 1e-9;

/// Options of the geometry stage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeometryOptions {
    /// Turning angle (degrees) above which a corner is an exact stop.
    pub corner_angle_deg: f64,
}

impl Default for GeometryOptions {
    fn default() -> Self {
        GeometryOptions {
            corner_angle_deg: 10.0,
        }
    }
}

/// What moves in a span.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpanKind {
    /// The tool tip travels; u is its chord length (mm).
    Moving,
    /// The tool tip stands still while the tool turns; u is the turned angle (radians).
    Reorientation,
    /// A joint-space path: u is the file's parameter s; the path coordinates are the axes.
    Joint,
}

/// A rest-to-rest piece of the path.
#[derive(Debug, Clone)]
pub struct Span {
    pub kind: SpanKind,
    /// w(u) = (Px, Py, Pz, θ1, θ2); its knots are the CL points of the span.
    pub spline: CubicSpline<PATH_DIM>,
    /// Feed cap (mm/s) of the move between knot k and k+1 (`f64::INFINITY`: none).
    pub feed_caps: Vec<f64>,
    /// Source line of the CL point at each knot.
    pub lines: Vec<usize>,
}

impl Span {
    /// Parameter range: u runs over `[0, length]`.
    pub fn length(&self) -> f64 {
        *self.spline.knots().last().unwrap_or(&0.0)
    }

    /// Path coordinates and their u-derivatives at `u`.
    pub fn eval(&self, u: f64) -> PathJet {
        self.spline.eval(u)
    }

    /// Source line of the CL point nearest to `u`.
    pub fn nearest_line(&self, u: f64) -> usize {
        let knots = self.spline.knots();
        let k = self.spline.segment(u);
        if (u - knots[k]).abs() <= (knots[k + 1] - u).abs() {
            self.lines[k]
        } else {
            self.lines[k + 1]
        }
    }
}

/// The whole path: spans in program order.
#[derive(Debug, Clone)]
pub struct Path {
    pub spans: Vec<Span>,
}

impl Path {
    /// Builds the spans of `toolpath`. `angles[k]` are the rotary angles (radians) of CL point
    /// k on one continuous branch; `feed_max` caps every feed, rapids run at it;
    /// `orientation_moves_axes` is false for machines that ignore orientation (a pure
    /// reorientation then takes no time and is dropped).
    pub fn build(
        toolpath: &Toolpath,
        angles: &[[f64; 2]],
        feed_max: Option<f64>,
        orientation_moves_axes: bool,
        options: &GeometryOptions,
    ) -> Result<Path> {
        let pts = &toolpath.points;
        if pts.len() < 2 {
            return Err(Error::parse(
                &toolpath.source,
                pts.first().map_or(1, |p| p.line),
                "the toolpath needs at least two CL points",
            ));
        }
        // The cap of the move from point `a` to point `b`: a G93 block's programmed time
        // implies the tool-tip speed chord/time.
        let cap = |a: usize, b: usize| -> f64 {
            let m = feed_max.unwrap_or(f64::INFINITY);
            match pts[b].feed {
                Feed::Programmed(v) => v.min(m),
                Feed::BlockTime(t) => ((pts[b].p - pts[a].p).norm() / t).min(m),
                Feed::Rapid | Feed::Unspecified => m,
            }
        };
        // Keep the points that move the tip, or turn the tool on a machine where that matters.
        let mut keep: Vec<usize> = vec![0];
        for k in 1..pts.len() {
            let last = &pts[*keep.last().unwrap_or(&0)];
            let moved = (pts[k].p - last.p).norm() > SAME_POSITION_MM;
            let turned =
                orientation_moves_axes && angle_between(&pts[k].o, &last.o) > SAME_ORIENTATION_RAD;
            if moved || turned {
                keep.push(k);
            }
        }
        // Segment kinds and corners.
        let seg_moving: Vec<bool> = keep
            .windows(2)
            .map(|w| (pts[w[1]].p - pts[w[0]].p).norm() > SAME_POSITION_MM)
            .collect();
        let corner_cos = options.corner_angle_deg.to_radians().cos();
        let mut cuts = vec![0usize];
        for k in 1..seg_moving.len() {
            let split = if seg_moving[k - 1] != seg_moving[k] {
                true
            } else if seg_moving[k] {
                let a = pts[keep[k]].p - pts[keep[k - 1]].p;
                let b = pts[keep[k + 1]].p - pts[keep[k]].p;
                a.dot(&b) / (a.norm() * b.norm()) < corner_cos
            } else {
                false
            };
            if split {
                cuts.push(k);
            }
        }
        cuts.push(seg_moving.len());
        let mut spans = Vec::with_capacity(cuts.len() - 1);
        for c in cuts.windows(2) {
            let idx = &keep[c[0]..=c[1]];
            let moving = seg_moving[c[0]];
            let mut u = Vec::with_capacity(idx.len());
            let mut acc = 0.0;
            u.push(0.0);
            for w in idx.windows(2) {
                let (a, b) = (&pts[w[0]], &pts[w[1]]);
                acc += if moving {
                    (b.p - a.p).norm()
                } else {
                    angle_between(&a.o, &b.o)
                };
                u.push(acc);
            }
            let p0: Vector3<f64> = pts[idx[0]].p;
            let values: Vec<[f64; PATH_DIM]> = idx
                .iter()
                .map(|&i| {
                    let p = if moving { pts[i].p } else { p0 };
                    let mut w = [0.0; PATH_DIM];
                    w[..5].copy_from_slice(&[p.x, p.y, p.z, angles[i][0], angles[i][1]]);
                    w
                })
                .collect();
            spans.push(Span {
                kind: if moving {
                    SpanKind::Moving
                } else {
                    SpanKind::Reorientation
                },
                spline: CubicSpline::new(&u, &values),
                feed_caps: idx.windows(2).map(|w| cap(w[0], w[1])).collect(),
                lines: idx.iter().map(|&i| pts[i].line).collect(),
            });
        }
        Ok(Path { spans })
    }
}

impl Path {
    /// The one span of a joint-space path, with its axes put in the machine's order. With
    /// derivatives in the file the curve is the Hermite interpolant that takes them; without,
    /// a not-a-knot cubic spline. Rest to rest, unless start and end speeds are given.
    pub fn from_joint(jp: &JointPath, machine: &Machine) -> Result<Path> {
        let first = jp.lines.first().copied().unwrap_or(1);
        let err = |msg: String| Error::parse(&jp.source, first.saturating_sub(1).max(1), msg);
        // Column of each machine axis.
        let cols: Vec<usize> = machine
            .axes
            .iter()
            .map(|a| {
                jp.axes.iter().position(|n| *n == a.name).ok_or_else(|| {
                    err(format!(
                        "no column `q_{}` for the machine's axis `{}`",
                        a.name, a.name
                    ))
                })
            })
            .collect::<Result<_>>()?;
        if let Some(extra) = jp
            .axes
            .iter()
            .find(|n| !machine.axes.iter().any(|a| &a.name == *n))
        {
            return Err(err(format!(
                "column `q_{extra}` names an axis the machine does not have"
            )));
        }
        let reorder = |rows: &[[f64; PATH_DIM]]| -> Vec<[f64; PATH_DIM]> {
            rows.iter()
                .map(|r| std::array::from_fn(|j| cols.get(j).map_or(0.0, |&c| r[c])))
                .collect()
        };
        let u: Vec<f64> = jp.s.iter().map(|s| s - jp.s[0]).collect();
        let q = reorder(&jp.q);
        let spline = match &jp.dq {
            Some(dq) => CubicSpline::hermite(
                &u,
                &q,
                &reorder(dq),
                jp.ddq.as_deref().map(reorder).as_deref(),
            ),
            None => CubicSpline::new(&u, &q),
        };
        Ok(Path {
            spans: vec![Span {
                kind: SpanKind::Joint,
                spline,
                feed_caps: vec![f64::INFINITY; u.len() - 1],
                lines: jp.lines.clone(),
            }],
        })
    }
}

/// Angle between two unit vectors, accurate for small angles.
pub fn angle_between(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}
