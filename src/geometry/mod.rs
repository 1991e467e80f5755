//! Path geometry: CL points and rotary angles in, rest-to-rest [`Span`]s of C² splines out.
//!
//! Each span interpolates the path coordinates w = (Px, Py, Pz, θ1, θ2) with one
//! [`spline::CubicSpline`] in one parameter u (seed 000, eq. 1–3 and 17–18):
//!
//! - a **moving** span (the tool tip travels) uses the cumulative chord length of the tip
//!   (mm), so |P'(u)| ≈ 1 (on a four-axis machine programmed in machine coordinates, the
//!   chord in joint space, a degree counting as a millimetre: [`ROTARY_MM_PER_RAD`]);
//! - a **reorientation** span (the tip stands still while the tool turns) uses the cumulative
//!   angle between successive tool orientations (radians), with P constant, |P'| = 0.
//!
//! The path is split into spans, each run rest to rest (an exact stop), at sharp corners
//! (turning angle between successive chords above `corner_angle`) and where the tip starts or
//! stops moving while the tool turns.

pub mod biarc;
pub mod blend;
pub mod spline;

use multiversion::multiversion;
use nalgebra::Vector3;

pub use crate::base::angle_between;
use crate::base::{PATH_DIM, PathJet};
use crate::error::number;
use crate::error::{Error, Result};
use crate::machine::Machine;
use crate::toolpath::joint_csv::JointPath;
use crate::toolpath::{Feed, Toolpath};
use crate::validate::{MAX_FEED_OVERRIDE, MIN_FEED_OVERRIDE, non_negative};
use spline::CubicSpline;

/// Points closer than this (mm) count as the same tool-tip position.
pub const SAME_POSITION_MM: f64 = 1e-6;
/// Orientations closer than this (radians) count as the same.
pub const SAME_ORIENTATION_RAD: f64 = 1e-9;

/// Options of the geometry stage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeometryOptions {
    /// Turning angle (degrees) above which a corner is an exact stop (unless blended).
    pub corner_angle_deg: f64,
    /// How far a corner sharper than `corner_angle_deg` may be cut, mm, as a control does
    /// under a contour tolerance (`G64 P`, `CYCLE832`, `CYCL DEF 32`): such a corner between
    /// two feed moves becomes a blend within it ([`blend::blend_corners`]). 0: every such
    /// corner is an exact stop. Refused with jerk limits (see [`blend`]).
    pub corner_tolerance_mm: f64,
    /// How far the fitted path may stray from the programmed tool-tip positions, mm
    /// (0: interpolate them exactly). See [`smooth_within`]. Between the points, the tip stays
    /// within this plus [`CHORD_SLACK_MM`] plus the chord's sagitta allowance of the
    /// programmed chords ([`Path::build`]).
    pub tolerance_mm: f64,
    /// How far the fitted rotary angles may stray from the programmed ones, degrees.
    pub tolerance_deg: f64,
    /// Factor on every programmed feed (a feed override: 1.2 runs the program 20 % faster).
    pub feed_override: f64,
    /// Ignore the program's feeds: only the machine's limits (and its maximum feed) apply.
    pub ignore_programmed_feed: bool,
}

impl Default for GeometryOptions {
    fn default() -> Self {
        GeometryOptions {
            corner_angle_deg: 10.0,
            corner_tolerance_mm: 0.0,
            tolerance_mm: 0.005,
            tolerance_deg: 0.01,
            feed_override: 1.0,
            ignore_programmed_feed: false,
        }
    }
}

/// What moves in a span.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpanKind {
    /// The tool tip travels; u is its chord length (mm); on a four-axis machine programmed in
    /// machine coordinates, the chord in joint space ([`ROTARY_MM_PER_RAD`]).
    Moving,
    /// The tool tip stands still while the tool turns; u is the turned angle (radians).
    Reorientation,
    /// A joint-space path: u is the file's parameter s; the path coordinates are the axes.
    Joint,
}

/// A rest-to-rest piece of the path.
#[derive(Debug, Clone)]
pub struct Span {
    /// How far the fitted curve strays from the programmed path: the largest distance of the
    /// tool tip from a programmed point (at a knot) or chord (between knots, [`chord_deviation`]),
    /// mm, and of the rotary angles from theirs, radians.
    pub deviation: (f64, f64),
    /// What moves in the span.
    pub kind: SpanKind,
    /// w(u) = (Px, Py, Pz, θ1, θ2); its knots are the CL points of the span and the points
    /// [`Path::build`] inserts on the programmed chords between them ([`INSERTED`]).
    pub spline: CubicSpline<PATH_DIM>,
    /// Feed cap of the move between knot k and k+1 (`f64::INFINITY`: none): of the tip's speed
    /// (mm/s) on a moving span, of the rate of turn u̇ (rad/s) on a reorientation.
    pub feed_caps: Vec<f64>,
    /// Source line of the CL point at each knot.
    pub lines: Vec<usize>,
    /// Index into [`Toolpath::points`] of the CL point at each knot, [`INSERTED`] at a knot
    /// inserted on a programmed chord (empty where the knots are not CL points: a dresser
    /// profile refitted by biarcs, a joint-space path).
    pub points: Vec<usize>,
    /// Feed caps of a process model ([`crate::material`]), which replace `feed_caps` on this
    /// span where present: a piecewise-constant cap in u whose breaks are stations.
    pub process: Option<ProcessCaps>,
}

/// A piecewise-constant feed cap along a span's u, from the material stage
/// ([`crate::material::FeedLimits::attach`]): piece k covers `[u[k], u[k+1])` (the last one up
/// to the span's end) with cap `cap[k]` (mm/s, `f64::INFINITY`: none) set by `by[k]` (`None`:
/// the programmed or the machine's maximum feed). Every break `u[k]`, k ≥ 1, is made a station
/// ([`crate::constraints::stations`]), so each interval between stations lies in one piece.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ProcessCaps {
    /// Start of each piece in u (the first is 0).
    pub u: Vec<f64>,
    /// Feed cap of each piece, mm/s.
    pub cap: Vec<f64>,
    /// The process limit that sets each cap (`None`: programmed or maximum feed).
    pub by: Vec<Option<crate::base::ProcessLimit>>,
}

impl ProcessCaps {
    /// The piece containing `u` (the later one on a break).
    pub fn piece(&self, u: f64) -> usize {
        self.u.partition_point(|&x| x <= u).saturating_sub(1)
    }

    /// The lowest cap at `u`: on a break, the lower of the two pieces that meet there.
    pub fn at(&self, u: f64) -> (f64, Option<crate::base::ProcessLimit>) {
        let k = self.piece(u);
        let here = (self.cap[k], self.by[k]);
        if k > 0 && self.u[k] == u && self.cap[k - 1] < here.0 {
            (self.cap[k - 1], self.by[k - 1])
        } else {
            here
        }
    }
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

    /// The feed cap (mm/s) at `u` in spline segment `seg`: the process model's where the span
    /// has one ([`ProcessCaps::at`]), else the CL move's.
    pub fn feed_cap(&self, seg: usize, u: f64) -> f64 {
        match &self.process {
            Some(p) => p.at(u).0,
            None => self.feed_caps.get(seg).copied().unwrap_or(f64::INFINITY),
        }
    }

    /// The feed cap on the interval of stations around `u` (strictly inside one piece, e.g. an
    /// interval's midpoint), and the process limit that sets it (`None`: the programmed or
    /// machine feed).
    pub fn interval_cap(&self, u: f64) -> (f64, Option<crate::base::ProcessLimit>) {
        match &self.process {
            Some(p) => {
                let k = p.piece(u);
                (p.cap[k], p.by[k])
            }
            None => (self.feed_caps[self.spline.segment(u)], None),
        }
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
    /// The rest-to-rest spans, in path order.
    pub spans: Vec<Span>,
    /// The program's dwells where the tool stands, s: `holds[0]` before the first span's
    /// motion, `holds[s + 1]` after span s (empty: none). Each dwell stands at the last point
    /// the geometry keeps at or before its own, which [`span_points`] made a span boundary
    /// (one inside a span, which cannot happen, would count at the span's end).
    pub holds: Vec<f64>,
}

impl Path {
    /// How far the fitted curve strays from the programmed path over every span: the largest
    /// tool-tip distance (mm) and rotary-angle difference (rad) of [`Span::deviation`].
    pub fn deviation(&self) -> (f64, f64) {
        self.spans.iter().fold((0.0, 0.0), |(mm, rad), s| {
            (mm.max(s.deviation.0), rad.max(s.deviation.1))
        })
    }

    /// Builds the spans of `toolpath`. `angles[k]` are the rotary angles (radians) of CL point
    /// k on one continuous branch; `feed_max` caps every feed, rapids run at it;
    /// `orientation_moves_axes` is false for machines that ignore orientation (a pure
    /// reorientation then takes no time and is dropped).
    ///
    /// `profile_normal` (a dresser, seed 001): each moving span's X–Z profile is fitted by
    /// tangent-continuous lines and arcs within `tolerance_mm` ([`biarc::fit`]) and the rotary
    /// angle follows the fitted profile's normal, on the side the program points the tool
    /// (with a zero tolerance the points are interpolated exactly, as everywhere).
    ///
    /// `angles_on_chords` (a four-axis machine, programmed in machine coordinates): on a moving
    /// span the rotary angle is held to its programmed chords as the tip is (within
    /// `tolerance_deg`), since the control moves every axis straight from block to block.
    pub fn build(
        toolpath: &Toolpath,
        angles: &[[f64; 2]],
        feed_max: Option<f64>,
        orientation_moves_axes: bool,
        profile_normal: bool,
        angles_on_chords: bool,
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
        // The cap of the move from point `a` to point `b`. Where the tip moves, on its speed
        // (mm/s): a block's programmed time (G93) implies chord / time. On a reorientation (the
        // tip stands, u is the rotary angles' travel, radians) on the rate of turn (rad/s): a
        // block's programmed time (a turn of rotary axes alone at F, as the reader times it for
        // its control) implies the angles' travel / time; a feed of the tip caps nothing
        // there, nor does the machine's maximum feed. (A turn alone at F9.8 ran at the axis's
        // limits: NX's Mazak Nexus 510 four-axis sample, 622.7 s for about 24,600 s.)
        let cap = |a: usize, b: usize, moving: bool| -> f64 {
            let m = feed_max.unwrap_or(f64::INFINITY);
            let k = options.feed_override;
            if !moving {
                return match pts[b].feed {
                    Feed::BlockTime(t) if !options.ignore_programmed_feed && t > 0.0 => {
                        let turn = ((angles[b][0] - angles[a][0]).powi(2)
                            + (angles[b][1] - angles[a][1]).powi(2))
                        .sqrt();
                        k * turn / t
                    }
                    _ => f64::INFINITY,
                };
            }
            match pts[b].feed {
                _ if options.ignore_programmed_feed => m,
                Feed::Programmed(v) => (k * v).min(m),
                Feed::BlockTime(t) => (k * (pts[b].p - pts[a].p).norm() / t).min(m),
                Feed::Rapid | Feed::Unspecified => m,
            }
        };
        let plan = span_points(
            toolpath,
            angles,
            orientation_moves_axes,
            options.corner_angle_deg,
            angles_on_chords,
        );
        // Each span on its own (its smoothing and chord refinement are most of the work).
        let threads = crate::parallel::resolve_threads(0);
        let spans: Vec<Span> = crate::parallel::par_map(&plan, threads, |idx| {
            let idx = idx.as_slice();
            let moving = (pts[idx[1]].p - pts[idx[0]].p).norm() > SAME_POSITION_MM;
            let p0: Vector3<f64> = pts[idx[0]].p;
            let mut values: Vec<[f64; PATH_DIM]> = idx
                .iter()
                .map(|&i| {
                    let p = if moving { pts[i].p } else { p0 };
                    let mut w = [0.0; PATH_DIM];
                    w[..5].copy_from_slice(&[p.x, p.y, p.z, angles[i][0], angles[i][1]]);
                    w
                })
                .collect();
            let mut feed_caps: Vec<f64> = idx.windows(2).map(|w| cap(w[0], w[1], moving)).collect();
            let mut lines: Vec<usize> = idx.iter().map(|&i| pts[i].line).collect();
            let refitted = moving && profile_normal && options.tolerance_mm > 0.0;
            if refitted {
                let fitted = dresser_profile(&values, &feed_caps, &lines, options.tolerance_mm);
                let u = chord_parameter(&fitted.values, moving, 0.0);
                return Span {
                    deviation: fitted.deviation,
                    kind: SpanKind::Moving,
                    spline: CubicSpline::new(&u, &fitted.values),
                    feed_caps: fitted.caps,
                    lines: fitted.lines,
                    points: Vec::new(),
                    process: None,
                };
            }
            let mut points = idx.to_vec();
            let tol_mm = if moving { options.tolerance_mm } else { 0.0 };
            let tol_rad = options.tolerance_deg.to_radians();
            // The curve through the points smoothed within the tolerance, its knots refined
            // where the tip strays from the programmed chords between them: a long chord next
            // to short ones lets a cubic spline swing far out (an arc's 0.3 mm chords, then a
            // 185 mm line: 440 mm). Each such interval is cut into up to [`MAX_PIECES`] on its
            // programmed chord, the new points smoothed with the rest, until the tip is within
            // the tolerance plus [`CHORD_SLACK_MM`] plus the chord's allowance (the sagitta at
            // [`chord_curvature`]) everywhere, or the span has [`max_knots`]; `deviation` says
            // how far it is (the rotary angles' too).
            // On a moving span the tip is held to its chords, and the rotary angles only
            // within [`ANGLE_SWING_RAD`] of theirs: inserting knots wherever the angles leave
            // their linear interpolation in u by the angular tolerance made jerk-limited
            // subproblems fail (Clarabel: DualInfeasible on the LinuxCNC boats, whose angles
            // stay within 1.3°), but without any bound a cubic swung them 43° off on a real
            // TRAORI program (tiny tip moves that turn A far, next to long ones), a motion of
            // the rotary axes the program does not make. Their deviation is reported. On a
            // reorientation (the tip stands, u is the angles' travel) the angles are what is
            // held: three points 0.1 and 2.2 rad apart swung B 32° past the programmed
            // positions on boat-xyzbc.
            // A four-axis program in machine coordinates: u is the chord in joint space, a
            // degree of the rotary axis counting as a millimetre ([`ROTARY_MM_PER_RAD`]).
            let rotary_mm = if moving && angles_on_chords {
                ROTARY_MM_PER_RAD
            } else {
                0.0
            };
            let bound = if moving && angles_on_chords {
                (tol_mm + CHORD_SLACK_MM, tol_rad + CHORD_SLACK_RAD)
            } else if moving {
                (
                    tol_mm + CHORD_SLACK_MM,
                    ANGLE_SWING_RAD.max(tol_rad + CHORD_SLACK_RAD),
                )
            } else {
                (f64::INFINITY, tol_rad + CHORD_SLACK_RAD)
            };
            // The curvature of each chord's allowance, from the programmed points (a chord's
            // pieces keep their chord's).
            // (None on a four-axis span: there the tip's chords turn back while the rotary
            // axis goes on, Z over a part turning on A, and the turn read as a curvature
            // π/h allowed the tip 0.4 h off its chords, 24 µm on a Vectric rotary finish.)
            let mut kchord = if moving && rotary_mm == 0.0 {
                chord_curvature(&values)
            } else {
                vec![0.0; values.len() - 1]
            };
            let (spline, deviation) = loop {
                let mut smooth = values.clone();
                let at_knots = smooth_within(&mut smooth, tol_mm, tol_rad);
                let u = chord_parameter(&smooth, moving, rotary_mm);
                let spline = CubicSpline::new(&u, &smooth);
                let between = chord_deviation(&spline, &values);
                let sag: Vec<f64> = (0..kchord.len())
                    .map(|k| (u[k + 1] - u[k]).powi(2) * kchord[k] / 8.0)
                    .collect();
                // (An interval shorter than twice the bound is not cut for the tip: a cubic
                // that swings that far off so short a chord turns back on itself, which the
                // points do not ask for, and much shorter intervals leave the solvers badly
                // scaled. A five-axis moving span's bound on the angles' swing holds on every
                // interval: a short one may turn the tool far, the tip moving 1 µm while C
                // turns 90°, and a cubic swung C 33° off there.)
                let swing = moving && !angles_on_chords;
                let far: Vec<usize> = (0..between.len())
                    .filter(|&k| {
                        let short = u[k + 1] - u[k] < 2.0 * if moving { bound.0 } else { bound.1 };
                        (!short && (between[k].0 > bound.0 + sag[k] || between[k].1 > bound.1))
                            || (swing && between[k].1 > bound.1)
                    })
                    .collect();
                if far.is_empty()
                    || values.len() + (MAX_PIECES - 1) * far.len() > max_knots(idx.len())
                {
                    let worst = between
                        .iter()
                        .fold(at_knots, |w, d| (w.0.max(d.0), w.1.max(d.1)));
                    break (spline, worst);
                }
                let mut at = far.into_iter().peekable();
                let n = values.len();
                let mut k2: Vec<f64> = Vec::with_capacity(n + 16);
                let (mut v2, mut c2, mut l2, mut p2) = (
                    Vec::with_capacity(n + 16),
                    Vec::with_capacity(n + 16),
                    Vec::with_capacity(n + 16),
                    Vec::with_capacity(n + 16),
                );
                for k in 0..n {
                    v2.push(values[k]);
                    l2.push(lines[k]);
                    p2.push(points[k]);
                    if k + 1 == n {
                        break;
                    }
                    c2.push(feed_caps[k]);
                    k2.push(kchord[k]);
                    if at.next_if_eq(&k).is_some() {
                        // m pieces: a cubic's distance from a chord falls as the square of
                        // the interval (a kink's, as the interval).
                        let r = (between[k].0 / (bound.0 + sag[k])).max(between[k].1 / bound.1);
                        let m = (r.sqrt().ceil() as usize).clamp(2, MAX_PIECES);
                        for i in 1..m {
                            let t = i as f64 / m as f64;
                            let (a, b) = (&values[k], &values[k + 1]);
                            v2.push(std::array::from_fn(|j| a[j] + t * (b[j] - a[j])));
                            c2.push(feed_caps[k]);
                            l2.push(lines[k + 1]);
                            p2.push(INSERTED);
                            k2.push(kchord[k]);
                        }
                    }
                }
                (values, feed_caps, lines, points, kchord) = (v2, c2, l2, p2, k2);
            };
            Span {
                deviation,
                kind: if moving {
                    SpanKind::Moving
                } else {
                    SpanKind::Reorientation
                },
                spline,
                feed_caps,
                lines,
                points,
                process: None,
            }
        });
        let holds = span_holds(toolpath, &plan);
        Ok(Path { spans, holds })
    }
}

/// [`Path::holds`] of the spans `plan` ([`span_points`]) makes of `toolpath`.
fn span_holds(toolpath: &Toolpath, plan: &[Vec<usize>]) -> Vec<f64> {
    let dwells = || toolpath.dwells.iter().filter(|d| d.seconds > 0.0);
    if dwells().next().is_none() {
        return Vec::new();
    }
    let mut holds = vec![0.0; plan.len() + 1];
    for d in dwells() {
        let p = d.point;
        // The span that p falls in: at its first point (or a repeat of it), the hold before
        // it; further in, the hold after it; past every span, after the last.
        let at = plan
            .iter()
            .position(|idx| p < idx[idx.len() - 1])
            .map_or(plan.len(), |s| if p < plan[s][1] { s } else { s + 1 });
        holds[at] += d.seconds;
    }
    holds
}

/// [`Span::points`] of a knot that is not a CL point: inserted on the programmed chord between
/// two, where the curve strayed from it ([`Path::build`]).
pub const INSERTED: usize = usize::MAX;

/// How far beyond the fitting tolerance the tool tip may stray from the programmed chords
/// between knots, mm (the sagitta an arc's chords may have,
/// [`crate::toolpath::gcode::MAX_CHORD_ERROR_MM`]).
pub const CHORD_SLACK_MM: f64 = 1e-3;
/// How far beyond the angular tolerance a reorientation's rotary angles may stray from their
/// linear interpolation between knots, rad (a thousandth of a degree).
pub const CHORD_SLACK_RAD: f64 = 1e-3 * std::f64::consts::PI / 180.0;

/// How far a five-axis moving span's fitted rotary angles may stray from their linear
/// interpolation between knots (the programmed chords), rad: 2°. A bound on gross swings, not
/// a fitting tolerance (the tip's is that): holding the angles to the angular tolerance made
/// jerk-limited subproblems fail on the LinuxCNC boats, whose fitted angles stay within 1.3°
/// of their chords (the impeller's within 0.3°), and left those programs' answers as they
/// were; a real TRAORI program whose angles swung 43° off is held within it (its cycle time
/// moved by 1 %).
pub const ANGLE_SWING_RAD: f64 = 2.0 * std::f64::consts::PI / 180.0;

/// The length a rotary axis's turn counts for in the parameter u of a four-axis moving span
/// (a program in machine coordinates, [`Path::build`]'s `angles_on_chords`), mm per radian: a
/// degree as a millimetre, as a grbl-style control measures a block with a rotary word for its
/// feed. With u the tip's chord alone, a block that turns A 12.4° while the tip moves 9 µm
/// (Vectric's rotary programs, Z the radius: A wraps the part) made dA/du jump a
/// hundredfold from one knot to the next; the cubic through them swung A 3.3° off its chords
/// and bent it within micrometres, and millions of stations did not resolve the bends (the
/// 76,693-line Skull roughing: 3.2 M stations, 5.8 GB, and after 12 rounds of local
/// refinement 30 intervals still over a limit, up to 6.7 %).
/// In the joint chord every axis moves at most one unit of length per unit of u, and the
/// spline runs along the program's straight blocks.
pub const ROTARY_MM_PER_RAD: f64 = 180.0 / std::f64::consts::PI;

/// The most pieces [`Path::build`]'s chord refinement cuts an interval into at once.
const MAX_PIECES: usize = 8;

/// The most knots a span of `cl` CL points may get by [`Path::build`]'s chord refinement.
fn max_knots(cl: usize) -> usize {
    8 * cl + 1024
}

/// The curvature (1/mm) that bounds how far a smooth curve through the programmed points may
/// leave each chord beyond the tolerance: the chord of length h may bulge by the sagitta h²κ/8
/// of an arc through its ends. κ is the smaller of the curvatures the points show at the
/// chord's two ends: turning angle over the mean of the two chords there, trusted only where
/// those two chords differ by at most [`EVEN_SPACING`] (points sampled from a curve — a
/// surface's polyline, an arc's chords — are spaced so; a long line after short chords is
/// not, and there κ is 0: the curve must keep to the line). At a span's end, the curvature of
/// the next point where that is trusted and the end chord is as long as the next, else 0.
fn chord_curvature(values: &[[f64; PATH_DIM]]) -> Vec<f64> {
    let n = values.len();
    let h: Vec<f64> = chord_parameter(values, true, 0.0)
        .windows(2)
        .map(|u| u[1] - u[0])
        .collect();
    let even = |a: f64, b: f64| a > 0.0 && b > 0.0 && a.max(b) <= EVEN_SPACING * a.min(b);
    let mut kappa = vec![0.0f64; n];
    for i in 1..n.saturating_sub(1) {
        let (a, b) = (h[i - 1], h[i]);
        if !even(a, b) {
            continue;
        }
        let d0: [f64; 3] = std::array::from_fn(|j| values[i][j] - values[i - 1][j]);
        let d1: [f64; 3] = std::array::from_fn(|j| values[i + 1][j] - values[i][j]);
        let cos = (0..3).map(|j| d0[j] * d1[j]).sum::<f64>() / (a * b);
        kappa[i] = cos.clamp(-1.0, 1.0).acos() / (0.5 * (a + b));
    }
    if n >= 4 {
        if even(h[0], h[1]) {
            kappa[0] = kappa[1];
        }
        if even(h[n - 2], h[n - 3]) {
            kappa[n - 1] = kappa[n - 2];
        }
    }
    (0..n.saturating_sub(1))
        .map(|k| kappa[k].min(kappa[k + 1]))
        .collect()
}

/// Neighbouring chords whose lengths differ by at most this factor are evenly spaced
/// ([`chord_curvature`]).
const EVEN_SPACING: f64 = 2.0;

/// The parameter u at every point: the tip's cumulative chord length (mm), or on a
/// reorientation (`moving` false) the rotary angles' cumulative travel (rad).
fn chord_parameter(values: &[[f64; PATH_DIM]], moving: bool, rotary_mm: f64) -> Vec<f64> {
    let mut u = Vec::with_capacity(values.len());
    let mut acc = 0.0;
    u.push(0.0);
    for w in values.windows(2) {
        let d2 = |r: std::ops::Range<usize>| r.map(|j| (w[1][j] - w[0][j]).powi(2)).sum::<f64>();
        acc += if moving {
            (d2(0..3) + rotary_mm * rotary_mm * d2(3..5)).sqrt()
        } else {
            d2(3..5).sqrt()
        };
        u.push(acc);
    }
    u
}

/// The CL points (indices into `toolpath.points`) at the knots of each span [`Path::build`]
/// makes, before any dresser refit: points that neither move the tip (by more than
/// [`SAME_POSITION_MM`]) nor, when `orientation_moves_axes`, turn the tool are dropped; the
/// rest is cut into rest-to-rest spans where the tip starts or stops moving, at corners
/// sharper than `corner_angle_deg` and where the tool dwells ([`Toolpath::dwells`]). Consecutive spans share their boundary point. Empty when
/// fewer than two points remain.
pub fn span_points(
    toolpath: &Toolpath,
    angles: &[[f64; 2]],
    orientation_moves_axes: bool,
    corner_angle_deg: f64,
    joint_corners: bool,
) -> Vec<Vec<usize>> {
    let pts = &toolpath.points;
    if pts.is_empty() {
        return Vec::new();
    }
    // Keep the points that move the tip, or turn the tool on a machine where that matters.
    let mut keep: Vec<usize> = vec![0];
    for k in 1..pts.len() {
        let last = &pts[*keep.last().unwrap_or(&0)];
        let moved = (pts[k].p - last.p).norm() > SAME_POSITION_MM;
        let last_k = *keep.last().unwrap_or(&0);
        // Where both points give their rotary positions, those are the orientation (the
        // reader's tool vector is then the program's, not the one they make: a tool-tip-mode
        // block's +Z beside a block outside it whose vector the axes give made a turn of no
        // angle, a span of zero length, and NaN).
        let given = pts[k].rotary.is_some() && last.rotary.is_some();
        let turned = orientation_moves_axes
            && ((!given && angle_between(&pts[k].o, &last.o) > SAME_ORIENTATION_RAD)
                || (0..2).any(|j| (angles[k][j] - angles[last_k][j]).abs() > SAME_ORIENTATION_RAD));
        if moved || turned {
            keep.push(k);
        }
    }
    // Segment kinds and corners.
    let seg_moving: Vec<bool> = keep
        .windows(2)
        .map(|w| (pts[w[1]].p - pts[w[0]].p).norm() > SAME_POSITION_MM)
        .collect();
    let corner_cos = corner_angle_deg.to_radians().cos();
    let mut cuts = vec![0usize];
    for k in 1..seg_moving.len() {
        let split = if seg_moving[k - 1] != seg_moving[k] {
            true
        } else if seg_moving[k] && joint_corners {
            // A corner of the axes' motion: the chords in joint space, as u measures them.
            let chord = |i: usize, j: usize| -> [f64; 5] {
                let (p, q) = (pts[keep[j]].p - pts[keep[i]].p, (keep[i], keep[j]));
                let t = |r: usize| ROTARY_MM_PER_RAD * (angles[q.1][r] - angles[q.0][r]);
                [p.x, p.y, p.z, t(0), t(1)]
            };
            let (a, b) = (chord(k - 1, k), chord(k, k + 1));
            let dot = (0..5).map(|j| a[j] * b[j]).sum::<f64>();
            let norm = |v: &[f64; 5]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
            dot / (norm(&a) * norm(&b)) < corner_cos
        } else if seg_moving[k] {
            let a = pts[keep[k]].p - pts[keep[k - 1]].p;
            let b = pts[keep[k + 1]].p - pts[keep[k]].p;
            a.dot(&b) / (a.norm() * b.norm()) < corner_cos
        } else {
            false
        };
        // The tool dwells at this point (or at a point it repeats): an exact stop.
        let dwell = toolpath
            .dwells
            .iter()
            .any(|d| d.seconds > 0.0 && d.point >= keep[k] && d.point < keep[k + 1]);
        if split || dwell {
            cuts.push(k);
        }
    }
    cuts.push(seg_moving.len());
    cuts.windows(2)
        .filter(|c| c[1] > c[0])
        .map(|c| keep[c[0]..=c[1]].to_vec())
        .collect()
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
            holds: Vec::new(),
            spans: vec![Span {
                deviation: (0.0, 0.0),
                kind: SpanKind::Joint,
                spline,
                feed_caps: vec![f64::INFINITY; u.len() - 1],
                lines: jp.lines.clone(),
                points: Vec::new(),
                process: None,
            }],
        })
    }
}

/// A dresser span refitted by biarcs: samples of the fitted profile with θ on its normal.
struct FittedProfile {
    values: Vec<[f64; PATH_DIM]>,
    caps: Vec<f64>,
    lines: Vec<usize>,
    deviation: (f64, f64),
}

/// Fits a dresser span's X–Z profile (w₀, w₂) by tangent-continuous lines and arcs within
/// `tol_mm`, samples every piece (a quarter of the programmed spacing and at most 1° of turn
/// apart: the cubic through the samples must follow the curvature jumps between pieces, and at
/// the programmed spacing it rings there, which cost 3 % on a groove) and puts
/// θ (w₃) on the fitted normal — on the side of the programmed tool, unwrapped from the
/// programmed first angle. Each sample takes the feed cap and line of the programmed point
/// nearest to it. Deviation: the profile's (mm) and the largest difference between a programmed
/// angle and the fitted normal at the sample nearest its point (rad).
fn dresser_profile(
    values: &[[f64; PATH_DIM]],
    caps: &[f64],
    lines: &[usize],
    tol_mm: f64,
) -> FittedProfile {
    let pts: Vec<[f64; 2]> = values.iter().map(|w| [w[0], w[2]]).collect();
    let pieces = biarc::fit(&pts, tol_mm.max(1e-9));
    let spacing = pts
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .fold(f64::INFINITY, f64::min)
        .max(1e-6);
    let wrap = |a: f64| a - std::f64::consts::TAU * (a / std::f64::consts::TAU).round();
    // Side: flip the normal if the program points the tool the other way.
    let flip = pieces.first().map_or(0.0, |p| {
        if wrap(values[0][3] - p.normal_angle_at_start()).abs() > std::f64::consts::FRAC_PI_2 {
            std::f64::consts::PI
        } else {
            0.0
        }
    });
    let mut samples: Vec<([f64; 2], f64)> = Vec::new();
    let mut theta_prev = values[0][3];
    for (k, piece) in pieces.iter().enumerate() {
        let (a0, a1) = (
            piece.normal_angle_at_start() + flip,
            piece.normal_angle_at_end() + flip,
        );
        let turn = wrap(a1 - a0);
        let parts = ((4.0 * piece.length() / spacing).ceil() as usize)
            .max((turn.abs() / 1f64.to_radians()).ceil() as usize)
            .max(1);
        for i in usize::from(k > 0)..=parts {
            let t = i as f64 / parts as f64;
            let theta = theta_prev + wrap(a0 + turn * t - theta_prev);
            theta_prev = theta;
            samples.push((piece.point_at(t), theta));
        }
    }
    if samples.len() < 2 {
        return FittedProfile {
            values: values.to_vec(),
            caps: caps.to_vec(),
            lines: lines.to_vec(),
            deviation: (0.0, 0.0),
        };
    }
    // The programmed point nearest each sample (both run along the profile: a moving cursor).
    let mut nearest = Vec::with_capacity(samples.len());
    let mut c = 0;
    let d2 = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
    for (p, _) in &samples {
        while c + 1 < pts.len() && d2(pts[c + 1], *p) <= d2(pts[c], *p) {
            c += 1;
        }
        nearest.push(c);
    }
    let mut dev_rad: f64 = 0.0;
    for (k, (p, theta)) in samples.iter().enumerate() {
        if d2(pts[nearest[k]], *p) <= (2.0 * tol_mm).powi(2) {
            dev_rad = dev_rad.max(wrap(theta - values[nearest[k]][3]).abs());
        }
    }
    let out_values = samples
        .iter()
        .map(|(p, theta)| {
            let mut w = [0.0; PATH_DIM];
            (w[0], w[2], w[3]) = (p[0], p[1], *theta);
            w
        })
        .collect();
    let seg_cap =
        |i: usize| caps[i.min(caps.len() - 1)].min(caps[i.saturating_sub(1).min(caps.len() - 1)]);
    FittedProfile {
        values: out_values,
        caps: (0..samples.len() - 1)
            .map(|k| seg_cap(nearest[k]).min(seg_cap(nearest[k + 1])))
            .collect(),
        lines: nearest.iter().map(|&i| lines[i]).collect(),
        deviation: (biarc::max_deviation(&pts, &pieces), dev_rad),
    }
}

/// Most steps of [`smooth_within`]'s descent.
const SMOOTH_ITERATIONS: usize = 500;

/// Smooths a span's points within a tolerance tube: projected gradient descent on the bending
/// energy Σ|D²w|² (second differences over the programmed spacing, per coordinate), every step
/// followed by a projection back into the tube — a ball of radius `tol_mm` around each
/// programmed tool-tip position and ±`tol_rad` around each programmed rotary angle; the span's
/// end points stay. CAM writes points to a few decimals (the LinuxCNC impeller to 0.001 mm and
/// 0.001°); a cubic through every point turns that noise into curvature, and curvature into
/// slow feed. (Minimising length instead — moving each point to its neighbours' chord — would
/// converge to a taut string with kinks at the tube's wall, the opposite of smooth.) Returns
/// the largest deviation (mm, rad). Zero tolerances leave the points as they are.
pub fn smooth_within(values: &mut [[f64; PATH_DIM]], tol_mm: f64, tol_rad: f64) -> (f64, f64) {
    let n = values.len();
    if n < 4 || (tol_mm <= 0.0 && tol_rad <= 0.0) {
        return (0.0, 0.0);
    }
    let orig = values.to_vec();
    let dist = |a: &[f64; PATH_DIM], b: &[f64; PATH_DIM]| {
        (0..3).map(|j| (a[j] - b[j]).powi(2)).sum::<f64>().sqrt()
    };
    let Descent {
        rows,
        cols,
        step,
        dims,
    } = Descent::of(&orig);
    let tube = Tube {
        orig: &orig,
        rows: &rows,
        cols: &cols,
        step,
        tol_mm,
        tol_rad,
    };
    match dims {
        3 => tube.descend::<3>(values),
        _ => tube.descend::<5>(values),
    }
    let dev_mm = (0..n)
        .map(|i| dist(&values[i], &orig[i]))
        .fold(0.0, f64::max);
    let dev_rad = (0..n)
        .flat_map(|i| (3..5).map(move |j| (i, j)))
        .map(|(i, j)| (values[i][j] - orig[i][j]).abs())
        .fold(0.0, f64::max);
    (dev_mm, dev_rad)
}

/// The fixed parts of [`smooth_within`]'s descent for the programmed points `orig`.
struct Descent {
    /// D²'s rows: for row i (1 ≤ i ≤ n−2) the coefficients on w[i−1], w[i], w[i+1].
    rows: Vec<[f64; 3]>,
    /// Per point k, the coefficients of the rows k − 1, k, k + 1 on it.
    cols: Vec<[f64; 3]>,
    step: f64,
    /// The coordinates that move: 3 (the tip) or 5 (and the rotary angles).
    dims: usize,
}

impl Descent {
    fn of(orig: &[[f64; PATH_DIM]]) -> Descent {
        let n = orig.len();
        let dist = |a: &[f64; PATH_DIM], b: &[f64; PATH_DIM]| {
            (0..3).map(|j| (a[j] - b[j]).powi(2)).sum::<f64>().sqrt()
        };
        // Parameter spacing: the programmed tip chords, or angle steps on a reorientation.
        let h: Vec<f64> = orig
            .windows(2)
            .map(|w| {
                let d = dist(&w[0], &w[1]);
                let a = ((w[1][3] - w[0][3]).powi(2) + (w[1][4] - w[0][4]).powi(2)).sqrt();
                if d > 0.0 { d } else { a.max(f64::MIN_POSITIVE) }
            })
            .collect();
        // D² row i (1 ≤ i ≤ n−2): coefficients on w[i−1], w[i], w[i+1]; computed once (the
        // iterations below read each row sixteen times a point: recomputing its three divisions
        // there took 80 % of a 36,000-line Fusion APT program's solve).
        let rows: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                if i == 0 || i + 1 == n {
                    return [0.0; 3];
                }
                let (a, b) = (h[i - 1], h[i]);
                [2.0 / (a * (a + b)), -2.0 / (a * b), 2.0 / (b * (a + b))]
            })
            .collect();
        let row = |i: usize| rows[i];
        // Step 1/L with L ≥ the largest eigenvalue of D²ᵀD² (Gershgorin: the largest absolute row
        // sum of D² squared is a bound on ‖D²‖²).
        let l = (1..n - 1)
            .map(|i| row(i).iter().map(|c| c.abs()).sum::<f64>())
            .fold(0.0, f64::max)
            .powi(2);
        let step = 1.0 / l;
        // Angles that do not change along the span (a three-axis program's zeros) have no bending
        // to smooth: only the tip's coordinates are iterated then.
        let dims = if orig.iter().all(|w| w[3..5] == orig[0][3..5]) {
            3
        } else {
            5
        };
        // Per point k, the coefficients of the rows k − 1, k, k + 1 on it (D² is tridiagonal).
        let cols: Vec<[f64; 3]> = (0..n)
            .map(|k| {
                if k == 0 || k + 1 == n {
                    [0.0; 3]
                } else {
                    [row(k - 1)[2], row(k)[1], row(k + 1)[0]]
                }
            })
            .collect();
        Descent {
            rows,
            cols,
            step,
            dims,
        }
    }
}

/// The projected gradient descent of [`smooth_within`]: the tube about the programmed points
/// `orig`, the rows of D² and their coefficients per point, the step.
struct Tube<'a> {
    orig: &'a [[f64; PATH_DIM]],
    rows: &'a [[f64; 3]],
    cols: &'a [[f64; 3]],
    step: f64,
    tol_mm: f64,
    tol_rad: f64,
}

impl Tube<'_> {
    /// Up to [`SMOOTH_ITERATIONS`] steps on the first `D` coordinates (3: the tip; 5: and the
    /// rotary angles), each followed by the projection into the tube. The coordinates are
    /// held one array each (so that a step runs along them with vector instructions: the same
    /// operations in the same order per point, so the same bits as point by point).
    fn descend<const D: usize>(&self, values: &mut [[f64; PATH_DIM]]) {
        let n = values.len();
        let column = |v: &[[f64; PATH_DIM]], j: usize| v.iter().map(|p| p[j]).collect::<Vec<f64>>();
        let mut w: [Vec<f64>; D] = std::array::from_fn(|j| column(values, j));
        let o: [Vec<f64>; D] = std::array::from_fn(|j| column(self.orig, j));
        let r: [Vec<f64>; 3] = std::array::from_fn(|c| self.rows.iter().map(|x| x[c]).collect());
        let c: [Vec<f64>; 3] = std::array::from_fn(|k| self.cols.iter().map(|x| x[k]).collect());
        let mut d2: [Vec<f64>; D] = std::array::from_fn(|_| vec![0.0; n]);
        let mut g: [Vec<f64>; D] = std::array::from_fn(|_| vec![0.0; n]);
        for _ in 0..SMOOTH_ITERATIONS {
            let moved = tube_step::<D>(self, &mut w, &o, &r, &c, &mut d2, &mut g);
            if moved < 1e-12 {
                break;
            }
        }
        for (k, p) in values.iter_mut().enumerate() {
            for j in 0..D {
                p[j] = w[j][k];
            }
        }
    }
}

/// One step of [`Tube::descend`] on the coordinate arrays `w` (`o`: the programmed ones;
/// `r`, `c`: D²'s rows and their coefficients per point, by column; `d2`, `g`: scratch of the
/// points' length): the gradient step, then the projection into the tube. Returns the largest
/// move of a coordinate.
#[multiversion(targets("x86_64+avx512f+avx512vl", "x86_64+avx2", "aarch64+neon"))]
fn tube_step<const D: usize>(
    tube: &Tube,
    w: &mut [Vec<f64>; D],
    o: &[Vec<f64>; D],
    r: &[Vec<f64>; 3],
    c: &[Vec<f64>; 3],
    d2: &mut [Vec<f64>; D],
    g: &mut [Vec<f64>; D],
) -> f64 {
    let n = w[0].len();
    // (D² w)_i, 1 ≤ i ≤ n − 2 (the end rows stay zero).
    for j in 0..D {
        let (x, d) = (&w[j][..n], &mut d2[j][..n]);
        for i in 1..n - 1 {
            d[i] = r[0][i] * x[i - 1] + r[1][i] * x[i] + r[2][i] * x[i + 1];
        }
    }
    // (D²ᵀ D² w)_k = Σ_i D²[i][k] · (D² w)_i over the rows i = k−1, k, k+1; the step.
    for j in 0..D {
        let (d, x, gj) = (&d2[j][..n], &w[j][..n], &mut g[j][..n]);
        for k in 1..n - 1 {
            let mut s = 0.0;
            s += c[0][k] * d[k - 1];
            s += c[1][k] * d[k];
            s += c[2][k] * d[k + 1];
            gj[k] = x[k] - tube.step * s;
        }
    }
    // The projection: onto the ball of radius tol_mm about the programmed tip, the angles
    // clamped.
    let tol = tube.tol_mm;
    {
        let [ox, oy, oz] = [&o[0][..n], &o[1][..n], &o[2][..n]];
        let [gx, gy, gz] = g.split_first_chunk_mut::<3>().expect("D ≥ 3").0;
        let (gx, gy, gz) = (&mut gx[..n], &mut gy[..n], &mut gz[..n]);
        for k in 1..n - 1 {
            let (a, b, e) = (gx[k], gy[k], gz[k]);
            if tol > 0.0 {
                let s = (a - ox[k]).powi(2) + (b - oy[k]).powi(2) + (e - oz[k]).powi(2);
                let d = s.sqrt();
                // (Without branches, so that it runs along the arrays.)
                let out = d > tol;
                gx[k] = if out {
                    ox[k] + (a - ox[k]) * tol / d
                } else {
                    a
                };
                gy[k] = if out {
                    oy[k] + (b - oy[k]) * tol / d
                } else {
                    b
                };
                gz[k] = if out {
                    oz[k] + (e - oz[k]) * tol / d
                } else {
                    e
                };
            } else {
                (gx[k], gy[k], gz[k]) = (ox[k], oy[k], oz[k]);
            }
        }
    }
    for j in 3..D {
        let (gj, oj) = (&mut g[j][..n], &o[j][..n]);
        for k in 1..n - 1 {
            gj[k] = gj[k].clamp(oj[k] - tube.tol_rad, oj[k] + tube.tol_rad);
        }
    }
    // The largest move, in eight lanes (a maximum is the same in any order; `>` rather than
    // f64::max, which does not run along the arrays: both leave a NaN out), and the new
    // values.
    const LANES: usize = 8;
    let mut lanes = [0.0f64; LANES];
    for j in 0..D {
        let (gj, wj) = (&g[j][1..n - 1], &mut w[j][1..n - 1]);
        let mut wc = wj.chunks_exact_mut(LANES);
        let mut gc = gj.chunks_exact(LANES);
        for (wk, gk) in (&mut wc).zip(&mut gc) {
            for l in 0..LANES {
                let m = (gk[l] - wk[l]).abs();
                lanes[l] = if m > lanes[l] { m } else { lanes[l] };
                wk[l] = gk[l];
            }
        }
        for (wk, gk) in wc.into_remainder().iter_mut().zip(gc.remainder()) {
            let m = (gk - *wk).abs();
            lanes[0] = if m > lanes[0] { m } else { lanes[0] };
            *wk = *gk;
        }
    }
    lanes.iter().fold(0.0f64, |a, &m| if m > a { m } else { a })
}

/// Interior samples per interval at which [`chord_deviation`] compares the curve with the
/// programmed chord (the deviation of a cubic from a line is a cubic in the interval's
/// parameter; nine samples find its largest value to within 2 % of it).
pub const CHORD_SAMPLES: usize = 9;

/// How far the fitted curve strays from the programmed path *between* knots: for interval k,
/// the largest distance of the curve's tool tip from the programmed chord between knots k and
/// k+1 (mm; the segment between the programmed positions `prog[k]`, `prog[k + 1]`) and of its
/// rotary angles from their linear interpolation in u (rad), at [`CHORD_SAMPLES`] interior
/// points.
pub fn chord_deviation(
    spline: &CubicSpline<PATH_DIM>,
    prog: &[[f64; PATH_DIM]],
) -> Vec<(f64, f64)> {
    let u = spline.knots();
    (0..u.len() - 1)
        .map(|k| {
            let (a, b) = (&prog[k], &prog[k + 1]);
            let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let len2 = ab.iter().map(|c| c * c).sum::<f64>();
            let (mut mm, mut rad) = (0.0f64, 0.0f64);
            for m in 1..=CHORD_SAMPLES {
                let th = m as f64 / (CHORD_SAMPLES + 1) as f64;
                let w = spline.eval_in(k, u[k] + th * (u[k + 1] - u[k])).value;
                let ap = [w[0] - a[0], w[1] - a[1], w[2] - a[2]];
                // The nearest point of the segment (its ends where the tip does not move).
                let t = if len2 > 0.0 {
                    ((0..3).map(|j| ap[j] * ab[j]).sum::<f64>() / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let d = (0..3)
                    .map(|j| (ap[j] - t * ab[j]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                mm = mm.max(d);
                for j in 3..5 {
                    rad = rad.max((w[j] - (a[j] + th * (b[j] - a[j]))).abs());
                }
            }
            (mm, rad)
        })
        .collect()
}

impl GeometryOptions {
    /// Checks every field's range ([`crate::validate`]); the error names the field.
    pub fn validate(&self) -> Result<()> {
        let a = self.corner_angle_deg;
        if !(a.is_finite() && a > 0.0 && a < 180.0) {
            return Err(Error::option(
                "corner_angle_deg",
                format!(
                    "must be between 0 and 180 degrees (exclusive), got {}",
                    number(a)
                ),
            ));
        }
        non_negative("tolerance_mm", self.tolerance_mm, "mm")?;
        non_negative("corner_tolerance_mm", self.corner_tolerance_mm, "mm")?;
        non_negative("tolerance_deg", self.tolerance_deg, "degrees")?;
        if !(MIN_FEED_OVERRIDE..=MAX_FEED_OVERRIDE).contains(&self.feed_override) {
            return Err(Error::option(
                "feed_override",
                format!(
                    "{}: give a factor from {MIN_FEED_OVERRIDE} to {MAX_FEED_OVERRIDE} (1: the \
                     programmed feeds)",
                    number(self.feed_override)
                ),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(n: usize, noise: f64) -> Vec<[f64; PATH_DIM]> {
        // Radius 20 mm, points 0.2 mm apart, rounded to `noise` like a CAM post.
        let round = |x: f64| {
            if noise > 0.0 {
                (x / noise).round() * noise
            } else {
                x
            }
        };
        (0..n)
            .map(|k| {
                let a = k as f64 * 0.01;
                let mut w = [0.0; PATH_DIM];
                w[0] = round(20.0 * a.cos());
                w[1] = round(20.0 * a.sin());
                w
            })
            .collect()
    }

    /// Largest curvature of the circle through three neighbouring points (Menger curvature,
    /// 4·area / product of the sides: blind to uneven spacing along the path), 1/mm, away from
    /// the two ends (which stay where they were programmed, rounding and all).
    fn roughness(w: &[[f64; PATH_DIM]]) -> f64 {
        w[3..w.len() - 3]
            .windows(3)
            .map(|t| {
                let (a, b, c) = ([t[0][0], t[0][1]], [t[1][0], t[1][1]], [t[2][0], t[2][1]]);
                let len = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).hypot(p[1] - q[1]);
                let cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
                2.0 * cross.abs() / (len(a, b) * len(b, c) * len(a, c))
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn smoothing_removes_rounding_noise_within_the_tube() {
        let orig = circle(300, 0.001);
        let mut w = orig.clone();
        let (dev, _) = smooth_within(&mut w, 0.005, 0.0);
        assert!(dev <= 0.005 + 1e-12, "deviation {dev}");
        for (a, b) in w.iter().zip(&orig) {
            assert!(((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt() <= 0.005 + 1e-12);
        }
        // 1 µm rounding on 0.2 mm spacing puts curvature noise of ~0.05 /mm on a 0.05 /mm
        // circle; smoothed, the curvature is the circle's again.
        let (before, after) = (roughness(&orig), roughness(&w));
        assert!(before > 0.08, "noisy curvature {before}");
        assert!(after < 0.06, "smoothed curvature {after} (circle: 0.05)");
        assert_eq!((w[0], w[299]), (orig[0], orig[299]), "ends stay");
    }

    /// [`smooth_within`]'s descent written point by point, as it was before it ran along
    /// coordinate arrays: each step's rows of D² w first, then every point's gradient step and
    /// projection.
    fn descend_point_by_point(values: &mut [[f64; PATH_DIM]], tol_mm: f64, tol_rad: f64) {
        let n = values.len();
        let orig = values.to_vec();
        let dist = |a: &[f64; PATH_DIM], b: &[f64; PATH_DIM]| {
            (0..3).map(|j| (a[j] - b[j]).powi(2)).sum::<f64>().sqrt()
        };
        let Descent {
            rows, step, dims, ..
        } = Descent::of(&orig);
        let row = |i: usize| rows[i];
        let mut d2 = vec![[0.0; 5]; n];
        for _ in 0..SMOOTH_ITERATIONS {
            for i in 1..n - 1 {
                let r = row(i);
                for j in 0..dims {
                    d2[i][j] =
                        r[0] * values[i - 1][j] + r[1] * values[i][j] + r[2] * values[i + 1][j];
                }
            }
            let mut moved = 0.0f64;
            for k in 1..n - 1 {
                let mut w = values[k];
                let (before, here, after) = (row(k - 1)[2], row(k)[1], row(k + 1)[0]);
                for j in 0..dims {
                    let mut g = 0.0;
                    g += before * d2[k - 1][j];
                    g += here * d2[k][j];
                    g += after * d2[k + 1][j];
                    w[j] -= step * g;
                }
                if tol_mm > 0.0 {
                    let d = dist(&w, &orig[k]);
                    if d > tol_mm {
                        for j in 0..3 {
                            w[j] = orig[k][j] + (w[j] - orig[k][j]) * tol_mm / d;
                        }
                    }
                } else {
                    w[..3].copy_from_slice(&orig[k][..3]);
                }
                for j in 3..5 {
                    w[j] = w[j].clamp(orig[k][j] - tol_rad, orig[k][j] + tol_rad);
                }
                moved = moved.max(
                    (0..5)
                        .map(|j| (w[j] - values[k][j]).abs())
                        .fold(0.0, f64::max),
                );
                values[k] = w;
            }
            if moved < 1e-12 {
                break;
            }
        }
    }

    #[test]
    fn the_descent_along_coordinate_arrays_is_the_point_by_point_one_to_the_bit() {
        // Noisy circles of many lengths (the vector loops' remainders), a tip that stands
        // still for a step, and five-axis points whose angles move.
        // (Rounded to 0.02 mm, most points reach the tube's wall: the projection acts.)
        let mut cases: Vec<Vec<[f64; PATH_DIM]>> = [4, 5, 9, 17, 64, 100, 301]
            .iter()
            .flat_map(|&n| [circle(n, 0.001), circle(n, 0.02)])
            .collect();
        let mut standing = circle(40, 0.001);
        standing[20] = standing[19];
        cases.push(standing);
        let mut turning = circle(90, 0.02);
        for (k, w) in turning.iter_mut().enumerate() {
            w[3] = ((k as f64 * 0.013).sin() * 1e3).round() / 1e3;
            w[4] = ((k as f64 * 0.007).cos() * 1e3).round() / 1e3;
        }
        cases.push(turning);
        let mut on_the_wall = 0;
        for (c, case) in cases.iter().enumerate() {
            for (tol_mm, tol_rad) in [(0.005, 0.0), (0.02, 1e-3), (0.0, 2e-3)] {
                let (mut a, mut b) = (case.clone(), case.clone());
                smooth_within(&mut a, tol_mm, tol_rad);
                descend_point_by_point(&mut b, tol_mm, tol_rad);
                let bits = |v: &[[f64; PATH_DIM]]| -> Vec<u64> {
                    v.iter().flatten().map(|x| x.to_bits()).collect()
                };
                assert_eq!(
                    bits(&a),
                    bits(&b),
                    "case {c}, tolerances {tol_mm} mm {tol_rad} rad"
                );
                // (Four or five rounded points may lie on a line: nothing to smooth.)
                assert!(
                    !(tol_mm > 0.0 && case.len() > 8 && a == *case),
                    "case {c}: nothing moved"
                );
                on_the_wall += (a.iter().zip(case))
                    .filter(|(p, q)| {
                        let d = (0..3).map(|j| (p[j] - q[j]).powi(2)).sum::<f64>().sqrt();
                        tol_mm > 0.0 && (d - tol_mm).abs() < 1e-9 * tol_mm
                    })
                    .count();
            }
        }
        assert!(on_the_wall > 100, "{on_the_wall} points projected");
    }

    #[test]
    fn zero_tolerance_keeps_every_point() {
        let orig = circle(50, 0.001);
        let mut w = orig.clone();
        assert_eq!(smooth_within(&mut w, 0.0, 0.0), (0.0, 0.0));
        assert_eq!(w, orig);
    }
}
