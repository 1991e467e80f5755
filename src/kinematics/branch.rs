//! Rotary angles along a path on one continuous branch within the rotary axes' travel.
//!
//! Every two-rotary kinematics here (head_head, table_table_ac/bc/ab, head_table) turns the
//! tool by a *tilt* angle t and a *spin* angle s about the C axis (table_table_ab's platter
//! B; head_table's A with table A, whose tilt t is then B − 90°, [`super::head_table`]), and
//! its tool-vector inverse kinematics has exactly two solutions, (t, s) with t ≥ 0 and
//! (−t, s + π), each defined up to 2π in either angle. Where the tool is parallel to the C
//! axis (sin t = 0, the singular pose, "the pole") s is free.
//!
//! [`follow`] walks the CL points in order:
//!
//! 1. A point programmed with rotary words keeps them as they are (never reduced modulo 360°);
//!    outside travel it is an error naming its line.
//! 2. A point given by a tool vector takes, of the two solutions shifted by every multiple of 2π,
//!    the one nearest (Euclidean in (t, s), radians) to the previous point. If that nearest
//!    solution is outside travel and no solution within travel is as near, the path cannot be
//!    followed continuously within travel: an error naming the CL line.
//! 3. **Near the pole** the spin is ill-conditioned: a tool passing a hundredth of a degree
//!    beside the C axis needs C to turn by up to 180° between two neighbouring points. A run of
//!    consecutive points within [`POLE_CONE`] of the C axis therefore does not solve each point
//!    exactly: the spin runs linearly (in the turned tool angle) from its value before the run to
//!    the one the first point after the run needs, and each point's tilt is the signed angle
//!    that best approximates its tool vector with that spin. This is taken when every point of
//!    the run stays within [`POLE_TOLERANCE`] of its programmed tool vector (the tool tip is
//!    never moved; a straight pass missing the pole by ε deviates by about ε) and within travel;
//!    otherwise the run is solved exactly by rule 2. A point exactly at the pole keeps the
//!    previous spin (rule 3 with zero deviation).
//! 4. The first tool-vector point has no predecessor: it takes the shifts nearest zero (at the
//!    pole: the spin of the first point that defines one). The path is followed from its t ≥ 0
//!    solution and, if that fails, from its t ≤ 0 one; when both fail, the error of the walk that
//!    got further is returned.

use nalgebra::Vector3;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

use crate::base::angle_between;
use crate::error::{Error, Result};

/// Below this |sin t| the tool is parallel to the C axis and the spin angle is free.
pub const SINGULAR: f64 = 1e-12;

/// Half-angle of the cone about the C axis (radians, 1°) inside which the spin is interpolated
/// rather than solved point by point (module documentation, rule 3).
pub const POLE_CONE: f64 = 1.0 * PI / 180.0;

/// Largest deviation (radians, 0.05°) of the tool vector from the programmed one that the
/// interpolated spin near the pole may cause.
pub const POLE_TOLERANCE: f64 = 0.05 * PI / 180.0;

/// Slack (radians) on the travel bounds, for angles programmed exactly at a limit.
const TRAVEL_SLACK: f64 = 1e-9;

/// What the CL point asks of the rotary angles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    /// Rotary axis positions programmed by the input (radians, in path-angle order).
    Programmed([f64; 2]),
    /// A unit tool vector `k`, solved: tilt t ≥ 0 and spin s (`None` at the singular pose).
    Vector {
        /// The unit tool vector.
        k: Vector3<f64>,
        /// Tilt t ≥ 0, radians.
        tilt: f64,
        /// Spin s, radians (`None` at the singular pose).
        spin: Option<f64>,
    },
}

/// Where tilt and spin sit in the pair of path angles, the travel of each (radians) and the
/// axis names for messages.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layout {
    /// Index of the tilt angle in the pair (the other one is the spin).
    pub tilt: usize,
    /// Travel of path angle 0 and 1, radians.
    pub travel: [Option<(f64, f64)>; 2],
    /// Axis names of path angle 0 and 1.
    pub names: [&'static str; 2],
    /// The machine axis's position minus path angle 0 and 1, radians (messages give axis
    /// positions): 0, but 90° for the tilt of a head–table machine with table A
    /// ([`super::head_table`]).
    pub offset: [f64; 2],
}

impl Layout {
    fn spin(&self) -> usize {
        1 - self.tilt
    }

    fn pair(&self, tilt: f64, spin: f64) -> [f64; 2] {
        let mut a = [0.0; 2];
        a[self.tilt] = tilt;
        a[self.spin()] = spin;
        a
    }

    fn split(&self, a: [f64; 2]) -> (f64, f64) {
        (a[self.tilt], a[self.spin()])
    }

    fn travel_text(&self, i: usize) -> String {
        self.travel[i].map_or("unlimited".to_string(), |(lo, hi)| {
            // To 1e-9°: 120° read back through radians is 119.99999999999999°.
            let deg = |x: f64| (self.position(i, x) * 1e9).round() / 1e9;
            format!("[{}, {}]°", deg(lo), deg(hi))
        })
    }

    /// Axis `i`'s position, degrees, at path angle `x` (radians), unrounded.
    pub fn position(&self, i: usize, x: f64) -> f64 {
        (x + self.offset[i]).to_degrees()
    }

    /// Axis `i`'s position, degrees, at path angle `x` (radians); with an offset, to 1e-9°
    /// (a travel of −100° reads back as −99.99999999999999° through the offset).
    fn degrees(&self, i: usize, x: f64) -> f64 {
        if self.offset[i] == 0.0 {
            return x.to_degrees();
        }
        ((x + self.offset[i]).to_degrees() * 1e9).round() / 1e9
    }
}

/// `x + 2πn` nearest to `reference` among those within `travel` (any n without travel);
/// `None` if no shift of `x` lies within travel.
pub fn fit(x: f64, reference: f64, travel: Option<(f64, f64)>) -> Option<f64> {
    let n0 = ((reference - x) / TAU).round();
    let Some((lo, hi)) = travel else {
        return Some(x + TAU * n0);
    };
    let (lo, hi) = (lo - TRAVEL_SLACK, hi + TRAVEL_SLACK);
    let n_min = ((lo - x) / TAU).ceil();
    let n_max = ((hi - x) / TAU).floor();
    if n_min > n_max {
        return None;
    }
    Some(x + TAU * n0.clamp(n_min, n_max))
}

/// Whether `x` lies within `travel` (always, without travel).
pub fn within(x: f64, travel: Option<(f64, f64)>) -> bool {
    travel.is_none_or(|(lo, hi)| x >= lo - TRAVEL_SLACK && x <= hi + TRAVEL_SLACK)
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

/// One walk along the path, or the index of the point that failed and its error.
type Walk = std::result::Result<Vec<[f64; 2]>, (usize, Error)>;

struct Walker<'a> {
    targets: &'a [Target],
    lines: &'a [usize],
    layout: &'a Layout,
    axis: &'a dyn Fn([f64; 2]) -> Vector3<f64>,
    start_positive: bool,
    /// The C axis direction in program coordinates (the tool axis at zero tilt).
    pole: Vector3<f64>,
}

impl Walker<'_> {
    fn line(&self, k: usize) -> usize {
        self.lines.get(k).copied().unwrap_or(k + 1)
    }

    /// Angle between a tool vector and the C axis, either way along it.
    fn pole_distance(&self, k: &Vector3<f64>) -> f64 {
        let a = angle_between(k, &self.pole);
        a.min(PI - a)
    }

    fn in_cone(&self, t: &Target) -> bool {
        matches!(t, Target::Vector { k, .. } if self.pole_distance(k) < POLE_CONE)
    }

    /// The candidate solutions (t, s) of a tool-vector point, preferred first; `fallback` is
    /// the spin at the pole.
    fn branches(&self, tilt: f64, spin: Option<f64>, fallback: f64) -> [(f64, f64); 2] {
        let b = match spin {
            Some(s) => [(tilt, s), (-tilt, s + PI)],
            // Any spin gives the same tool vector: keep it, only the tilt's sign varies.
            None => [(tilt, fallback), (-tilt, fallback)],
        };
        if self.start_positive { b } else { [b[1], b[0]] }
    }

    /// The spin the first spin-defining point asks for (on the preferred branch), if any.
    fn lead_spin(&self, from: usize) -> Option<f64> {
        let s = self.layout.spin();
        self.targets[from..].iter().find_map(|t| match *t {
            Target::Programmed(a) => Some(a[s]),
            Target::Vector {
                tilt,
                spin: Some(sp),
                ..
            } => Some(self.branches(tilt, Some(sp), 0.0)[0].1),
            Target::Vector { spin: None, .. } => None,
        })
    }

    /// The first point of the path: the preferred branch within travel, shifts nearest zero.
    fn first(
        &self,
        k: usize,
        tilt: f64,
        spin: Option<f64>,
    ) -> std::result::Result<[f64; 2], (usize, Error)> {
        let fallback = self.lead_spin(k).unwrap_or(0.0);
        let spin_ref = if spin.is_some() { 0.0 } else { fallback };
        for (t, s) in self.branches(tilt, spin, fallback) {
            if let (Some(ft), Some(fs)) = (
                fit(t, 0.0, self.layout.travel[self.layout.tilt]),
                fit(s, spin_ref, self.layout.travel[self.layout.spin()]),
            ) {
                return Ok(self.layout.pair(ft, fs));
            }
        }
        Err((k, self.no_solution(k, tilt)))
    }

    fn no_solution(&self, k: usize, tilt: f64) -> Error {
        let l = self.layout;
        Error::Infeasible(format!(
            "CL point at line {}: the tool vector needs {} and no solution lies within travel \
             ({} {}, {} {})",
            self.line(k),
            if l.offset[l.tilt] == 0.0 {
                format!("{} = ±{:.4}°", l.names[l.tilt], tilt.to_degrees())
            } else {
                format!(
                    "{} = {:.4}° or {:.4}°",
                    l.names[l.tilt],
                    l.degrees(l.tilt, tilt),
                    l.degrees(l.tilt, -tilt)
                )
            },
            l.names[0],
            l.travel_text(0),
            l.names[1],
            l.travel_text(1)
        ))
    }

    /// Rule 2: the nearest solution to `prev`, which must be within travel.
    fn nearest(
        &self,
        k: usize,
        prev: [f64; 2],
        tilt: f64,
        spin: Option<f64>,
    ) -> std::result::Result<[f64; 2], (usize, Error)> {
        let l = self.layout;
        let (pt, ps) = l.split(prev);
        let mut free_best: Option<([f64; 2], f64)> = None;
        let mut best: Option<([f64; 2], f64)> = None;
        for (t, s) in self.branches(tilt, spin, ps) {
            let free = l.pair(fit(t, pt, None).unwrap_or(t), fit(s, ps, None).unwrap_or(s));
            let d = dist(free, prev);
            if free_best.is_none_or(|(_, bd)| d < bd) {
                free_best = Some((free, d));
            }
            if let (Some(ft), Some(fs)) =
                (fit(t, pt, l.travel[l.tilt]), fit(s, ps, l.travel[l.spin()]))
            {
                let cand = l.pair(ft, fs);
                let d = dist(cand, prev);
                if best.is_none_or(|(_, bd)| d < bd) {
                    best = Some((cand, d));
                }
            }
        }
        let (free, free_d) = free_best.unwrap_or((prev, 0.0));
        match best {
            Some((cand, d)) if d <= free_d + 1e-9 => Ok(cand),
            Some((cand, d)) => {
                let out: Vec<String> = (0..2)
                    .filter(|&i| !within(free[i], l.travel[i]))
                    .map(|i| {
                        format!(
                            "{} = {:.4}° (travel {})",
                            l.names[i],
                            l.degrees(i, free[i]),
                            l.travel_text(i)
                        )
                    })
                    .collect();
                Err((
                    k,
                    Error::Infeasible(format!(
                        "CL point at line {}: following the tool vector continuously needs {}; the \
                         nearest solution within travel ({} = {:.4}°, {} = {:.4}°) is a jump of \
                         {:.4}° from the previous point",
                        self.line(k),
                        out.join(", "),
                        l.names[0],
                        l.degrees(0, cand[0]),
                        l.names[1],
                        l.degrees(1, cand[1]),
                        d.to_degrees()
                    )),
                ))
            }
            None => Err((k, self.no_solution(k, tilt))),
        }
    }

    /// Rule 3 for the run `run` of points within the pole cone, between `prev` (if any) and the
    /// point after the run: the angles, or `None` when the run is better solved exactly.
    fn pole_run(
        &self,
        run: std::ops::Range<usize>,
        prev: Option<[f64; 2]>,
    ) -> Option<Vec<[f64; 2]>> {
        let l = self.layout;
        let vector = |i: usize| match self.targets[i] {
            Target::Vector { k, tilt, spin } => Some((k, tilt, spin)),
            Target::Programmed(_) => None,
        };
        // The spin after the run, as the next point would take it.
        let exit: Option<([f64; 2], Vector3<f64>)> = match self.targets.get(run.end) {
            Some(Target::Programmed(a)) => Some((*a, (self.axis)(*a))),
            Some(Target::Vector { k, tilt, spin }) => {
                let a = match prev {
                    Some(p) => self.nearest(run.end, p, *tilt, *spin).ok()?,
                    None => self.first(run.end, *tilt, *spin).ok()?,
                };
                Some((a, *k))
            }
            None => None,
        };
        let s_in = prev.map(|p| l.split(p).1);
        let s_out = exit.map(|(a, _)| l.split(a).1);
        let (s_in, s_out) = match (s_in, s_out) {
            (Some(a), Some(b)) => (a, b),
            (Some(a), None) => (a, a),
            (None, Some(b)) => (b, b),
            (None, None) => {
                let s = self.lead_spin(run.start).unwrap_or(0.0);
                (s, s)
            }
        };
        // Progress along the run: the turned tool angle from the entry to the exit.
        let mut ks: Vec<Vector3<f64>> = Vec::with_capacity(run.len() + 2);
        if let Some(p) = prev {
            ks.push((self.axis)(p));
        }
        for i in run.clone() {
            ks.push(vector(i)?.0);
        }
        if let Some((_, k)) = exit {
            ks.push(k);
        }
        let mut acc = vec![0.0];
        for w in ks.windows(2) {
            acc.push(acc.last().unwrap_or(&0.0) + angle_between(&w[0], &w[1]));
        }
        let total = *acc.last().unwrap_or(&0.0);
        let offset = usize::from(prev.is_some());
        let mut out = Vec::with_capacity(run.len());
        let mut last_tilt = prev.map(|p| l.split(p).0);
        for (j, i) in run.enumerate() {
            let (k, tilt, _) = vector(i)?;
            let lambda = if total > 0.0 {
                acc[j + offset] / total
            } else {
                0.0
            };
            let s = s_in + (s_out - s_in) * lambda;
            let z = (self.axis)(l.pair(0.0, s));
            let e = (self.axis)(l.pair(FRAC_PI_2, s));
            let t = k.dot(&e).atan2(k.dot(&z));
            let t = fit(
                t,
                last_tilt.unwrap_or(if self.start_positive { tilt } else { -tilt }),
                l.travel[l.tilt],
            )?;
            let pose = l.pair(t, s);
            if angle_between(&(self.axis)(pose), &k) > POLE_TOLERANCE
                || !within(s, l.travel[l.spin()])
            {
                return None;
            }
            last_tilt = Some(t);
            out.push(pose);
        }
        Some(out)
    }

    fn walk(&self) -> Walk {
        let n = self.targets.len();
        let mut out: Vec<[f64; 2]> = Vec::with_capacity(n);
        let mut k = 0;
        while k < n {
            let prev = out.last().copied();
            match self.targets[k] {
                Target::Programmed(a) => {
                    for i in 0..2 {
                        if !within(a[i], self.layout.travel[i]) {
                            return Err((
                                k,
                                Error::Infeasible(format!(
                                    "CL point at line {}: programmed {} = {:.6}° is outside its \
                                     travel {}",
                                    self.line(k),
                                    self.layout.names[i],
                                    self.layout.degrees(i, a[i]),
                                    self.layout.travel_text(i)
                                )),
                            ));
                        }
                    }
                    out.push(a);
                    k += 1;
                }
                Target::Vector { tilt, spin, .. } => {
                    if self.in_cone(&self.targets[k]) {
                        let end = (k..n)
                            .find(|&i| !self.in_cone(&self.targets[i]))
                            .unwrap_or(n);
                        if let Some(run) = self.pole_run(k..end, prev) {
                            out.extend(run);
                            k = end;
                            continue;
                        }
                    }
                    out.push(match prev {
                        None => self.first(k, tilt, spin)?,
                        Some(p) => self.nearest(k, p, tilt, spin)?,
                    });
                    k += 1;
                }
            }
        }
        Ok(out)
    }
}

/// Heidenhain's `PLANE … SEQ+` / `SEQ−` ("selecting one of several solutions"): of the two
/// solutions of a tool vector (tilt ≥ 0 and spin, or the tilt negated and the spin turned by
/// π), the one whose tilt axis stands at a positive (`positive`) or negative angle. The tilt
/// axis is the control's *master axis*: the first rotary axis from the tool, the second from
/// the table (A of an A/C table, A of a C/A head, B of a B head over a C table). Each solution
/// is shifted by multiples of 2π nearest `current` within travel, as rule 2 shifts them, and
/// its tilt axis's position there must have the sign asked for (0, the singular pose, has
/// either); where both qualify, the nearer to `current` is taken. `Err` (a message naming the
/// axes, without a line) when no solution with that sign lies within travel: the control
/// reports an error there too.
///
/// `about` (degrees of the master axis) is the point the sign is taken from: 0 for `SEQ`, the
/// centre of the master axis's travel for `SYM` (its "symmetry point", TNC7 user's manual,
/// "Tilting solution").
pub fn sequence(
    tilt: f64,
    spin: Option<f64>,
    layout: &Layout,
    positive: bool,
    about: f64,
    current: [f64; 2],
) -> std::result::Result<[f64; 2], String> {
    let l = layout;
    let (pt, ps) = l.split(current);
    let master = l.names[l.tilt];
    let wanted = |x: f64| {
        let deg = l.degrees(l.tilt, x) - about;
        if positive { deg >= -1e-9 } else { deg <= 1e-9 }
    };
    let branches = match spin {
        Some(s) => [(tilt, s), (-tilt, s + PI)],
        // Any spin gives the tool vector: it stays.
        None => [(tilt, ps), (-tilt, ps)],
    };
    let mut best: Option<([f64; 2], f64)> = None;
    let mut outside: Vec<String> = Vec::new();
    for (t, s) in branches {
        match (fit(t, pt, l.travel[l.tilt]), fit(s, ps, l.travel[l.spin()])) {
            (Some(ft), Some(fs)) if wanted(ft) => {
                let cand = l.pair(ft, fs);
                let d = dist(cand, current);
                if best.is_none_or(|(_, bd)| d < bd) {
                    best = Some((cand, d));
                }
            }
            _ if wanted(t) => {
                let a = l.pair(t, fit(s, ps, None).unwrap_or(s));
                outside.push(format!(
                    "{} = {:.4}°, {} = {:.4}°",
                    l.names[0],
                    l.degrees(0, a[0]),
                    l.names[1],
                    l.degrees(1, a[1])
                ));
            }
            _ => {}
        }
    }
    if let Some((a, _)) = best {
        return Ok(a);
    }
    let sign = match (positive, about == 0.0) {
        (true, true) => "positive".to_string(),
        (false, true) => "negative".to_string(),
        (true, false) => format!("above {about}° (its symmetry point)"),
        (false, false) => format!("below {about}° (its symmetry point)"),
    };
    let travel = format!(
        "{} {}, {} {}",
        l.names[0],
        l.travel_text(0),
        l.names[1],
        l.travel_text(1)
    );
    Err(if outside.is_empty() {
        format!(
            "no solution has {master} {sign}: the tool axis needs {master} = {:.4}° or {:.4}° \
             (travel {travel})",
            l.degrees(l.tilt, tilt),
            l.degrees(l.tilt, -tilt)
        )
    } else {
        format!(
            "the solution with {master} {sign} ({}) is outside the rotary axes' travel \
             ({travel})",
            outside.join("; ")
        )
    })
}

/// The rotary angles of every CL point on one continuous branch within travel (see the module
/// documentation). `lines` names each point's source line for errors; `axis` is the
/// kinematics' tool axis for a pair of path angles.
pub fn follow(
    targets: &[Target],
    lines: &[usize],
    layout: &Layout,
    axis: &dyn Fn([f64; 2]) -> Vector3<f64>,
) -> Result<Vec<[f64; 2]>> {
    let walker = |start_positive| Walker {
        targets,
        lines,
        layout,
        axis,
        start_positive,
        pole: axis(layout.pair(0.0, 0.0)),
    };
    match walker(true).walk() {
        Ok(a) => Ok(a),
        Err((ka, ea)) => match walker(false).walk() {
            Ok(b) => Ok(b),
            Err((kb, eb)) => Err(if kb > ka { eb } else { ea }),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_picks_the_nearest_shift_within_travel() {
        assert!((fit(0.1, 6.3, None).unwrap() - (0.1 + TAU)).abs() < 1e-15);
        // Nearest would be 0.1 + 2π, but travel ends at 3 rad.
        assert!((fit(0.1, 6.3, Some((-10.0, 3.0))).unwrap() - 0.1).abs() < 1e-15);
        assert_eq!(fit(2.0, 0.0, Some((-1.0, 1.0))), None);
        assert!((fit(2.0, 0.0, Some((-5.0, -3.0))).unwrap() - (2.0 - TAU)).abs() < 1e-15);
    }

    /// A head–table-like tool axis: (sin t cos s, sin t sin s, cos t), tilt first.
    fn axis(a: [f64; 2]) -> Vector3<f64> {
        Vector3::new(a[0].sin() * a[1].cos(), a[0].sin() * a[1].sin(), a[0].cos())
    }

    fn target(t: f64, s: f64) -> Target {
        let k = axis([t, s]);
        let h = k.x.hypot(k.y);
        Target::Vector {
            k,
            tilt: h.atan2(k.z),
            spin: (h >= SINGULAR).then(|| k.y.atan2(k.x)),
        }
    }

    #[test]
    fn sequence_takes_the_tilt_sign_asked_for_within_travel() {
        let layout = |tilt_travel: Option<(f64, f64)>, offset: f64| Layout {
            tilt: 0,
            travel: [tilt_travel, None],
            names: ["B", "C"],
            offset: [offset, 0.0],
        };
        let (t, s) = (60f64.to_radians(), 30f64.to_radians());
        let deg = |a: [f64; 2]| a.map(|x| (x.to_degrees() * 1e9).round() / 1e9);
        let free = layout(None, 0.0);
        assert_eq!(
            deg(sequence(t, Some(s), &free, true, 0.0, [0.0, 0.0]).unwrap()),
            [60.0, 30.0]
        );
        // The other solution: tilt negated, spin turned by 180°, shifted nearest C 0.
        assert_eq!(
            deg(sequence(t, Some(s), &free, false, 0.0, [0.0, 0.0]).unwrap()),
            [-60.0, -150.0]
        );
        // B −60° outside travel [−50°, 120°]: an error naming B and its travel.
        let e = sequence(
            t,
            Some(s),
            &layout(Some((-50f64.to_radians(), 120f64.to_radians())), 0.0),
            false,
            0.0,
            [0.0; 2],
        )
        .unwrap_err();
        assert!(
            e.contains("B negative") && e.contains("B = -60.0000°"),
            "{e}"
        );
        // A tilt axis offset by 90° stands at 150° or 30°: never negative.
        let e = sequence(t, Some(s), &layout(None, FRAC_PI_2), false, 0.0, [0.0; 2]).unwrap_err();
        assert!(e.contains("no solution has B negative"), "{e}");
        // At the pole both solutions are one: either sign takes it.
        assert_eq!(
            sequence(0.0, None, &free, false, 0.0, [0.0, 1.0]).unwrap(),
            [0.0, 1.0]
        );
    }

    #[test]
    fn the_start_branch_is_chosen_to_stay_within_travel() {
        // Tilt travel [-100°, 50°]: a tool tilted 60° needs the negative branch throughout.
        let layout = Layout {
            tilt: 0,
            travel: [
                Some((-100f64.to_radians(), 50f64.to_radians())),
                Some((-TAU * 100.0, TAU * 100.0)),
            ],
            names: ["B", "C"],
            offset: [0.0; 2],
        };
        let targets: Vec<Target> = (0..10)
            .map(|k| target((20.0 + 5.0 * k as f64).to_radians(), 0.3))
            .collect();
        let lines: Vec<usize> = (1..=10).collect();
        let a = follow(&targets, &lines, &layout, &axis).unwrap();
        assert!(a.iter().all(|p| p[0] < 0.0), "{a:?}");
        // 120° is out of travel on both branches.
        let bad = [target(120f64.to_radians(), 0.0)];
        let e = follow(&bad, &[42], &layout, &axis).unwrap_err().to_string();
        assert!(e.contains("line 42"), "{e}");
    }
}
