//! Corner blending within a contour tolerance: what a control does at a corner when the
//! program lets it leave the programmed path by a given amount (LinuxCNC `G64 P…`, Sinumerik
//! `CYCLE832`, Heidenhain `CYCL DEF 32 T…`).
//!
//! Without it every corner sharper than [`super::GeometryOptions::corner_angle_deg`] is an
//! exact stop (the tool brakes to rest and starts again), which is what the programmed path
//! asks of a machine that must not leave it. With a tolerance ε > 0 ([`blend_corners`]), such a
//! corner between two feed moves is replaced by a blend that leaves each move tangentially and
//! with zero curvature (G2-continuous, as controls blend) and whose middle lies ε from the
//! corner: the quintic Bézier curve whose control points lie three on each move, at d, 2d/3 and
//! d/3 from the corner ([`SHAPE`]). Its middle lies d · S · sin(θ/2) / 16 from the corner
//! (turning angle θ between the moves, S = 1 + 5 · 2/3 + 10 · 1/3), so d = 16 ε / (S sin(θ/2)).
//! Where d would pass [`MAX_SHARE`] of either move, d is cut back so it does not (the blend then
//! stays closer than ε); the blends of neighbouring corners therefore never overlap. The blend
//! is written as CL points turning at most half the corner angle from one to the next, so the
//! geometry stage fits it as a smooth curve through them, not as corners.
//!
//! Why not the circular fillet of the same tolerance: its curvature jumps from 0 to 1/r where
//! it meets each move, and under jerk limits the tool must crawl through that (the axis jerk
//! grows as V³ dκ/ds): on a 20 mm square with jerk = 10 × acceleration, blending by fillets
//! within 0.02 mm took 4.6586 s against 4.5179 s with exact stops, and this blend 4.5223 s
//! (0.1 mm: 4.4818 and 4.4363 s). Acceleration-limited, the two are within 0.06 % (the fillet's
//! curvature is the lower). Under jerk limits a small tolerance gains little or nothing: a blend
//! of length ~3ε with curvature ~1/ε passes at V ~ (j ε²)^(1/3). And the jerk-limited solve is
//! ill-conditioned on such short, tight curves next to long moves (on seeded random polylines
//! its subproblems hit Clarabel's iteration cap and a 20-move path took minutes), so a corner
//! tolerance with jerk limits is refused for now ([`crate::optimize::optimize`]).
//!
//! Not blended: a corner sharper than [`MAX_BLEND_ANGLE_DEG`] (a reversal, where any blend
//! within ε is so tight that the tool all but stops anyway), one where the tool dwells, and one
//! next to a rapid move, a move without a feed or an inverse-time block (only corners between
//! two moves at programmed feeds are blended).
//!
//! The new points carry the corner's source line. The first half of the blend keeps the first
//! move's feed and the second half the second's: a control changes the feed where the blocks
//! meet. (With the lower of the two over the whole blend, a blend into a slow move took 45 %
//! of a fast one at the slow feed: a random path ran 5 % slower blended than with exact
//! stops.) Their tool orientation and programmed rotary angles are interpolated along the
//! moves (on the blend, between those of its ends).

use nalgebra::Vector3;
use std::borrow::Cow;

use super::SAME_POSITION_MM;
use crate::toolpath::{
    ClPoint, Dwell, Feed, LengthOffsetChange, MachinePoint, MachineSwitch, OffsetChange,
    SpindleChange, TapCycle, ToolChange, Toolpath,
};

/// The sharpest corner blended, degrees of turning (see the module docs).
pub const MAX_BLEND_ANGLE_DEG: f64 = 150.0;

/// The largest share of each move a blend may take (at each end), so that the blends of
/// neighbouring corners do not meet.
pub const MAX_SHARE: f64 = 0.45;

/// Where the blend's control points lie on each move, as shares of its length d along it
/// from the corner (the first at the tangent point).
pub const SHAPE: [f64; 3] = [1.0, 2.0 / 3.0, 1.0 / 3.0];

/// The most points one blend is written as.
const MAX_BLEND_POINTS: usize = 1024;

/// `toolpath` with every corner sharper than `corner_angle_deg` between two moves at
/// programmed feeds replaced by a blend within `tolerance_mm` of it (see the module docs),
/// and the number of corners blended (`toolpath` itself, borrowed, when the tolerance is 0).
/// The point indices of dwells, tool and spindle changes follow their points (a change at a
/// blended corner moves to the blend's first point).
pub fn blend_corners(
    toolpath: &Toolpath,
    tolerance_mm: f64,
    corner_angle_deg: f64,
) -> (Cow<'_, Toolpath>, usize) {
    let pts = &toolpath.points;
    let n = pts.len();
    if tolerance_mm.is_nan() || tolerance_mm <= 0.0 || n < 3 {
        return (Cow::Borrowed(toolpath), 0);
    }
    let corner_cos = corner_angle_deg.to_radians().cos();
    let max_cos = MAX_BLEND_ANGLE_DEG.to_radians().cos();
    // Half the corner angle per step of a blend: each step turns less than a corner.
    let step = 0.5 * corner_angle_deg.to_radians().max(1e-3);
    let mut out: Vec<ClPoint> = Vec::with_capacity(n);
    let mut map = Vec::with_capacity(n);
    let mut blended = 0;
    for k in 0..n {
        map.push(out.len());
        let blend = if k > 0 && k + 1 < n {
            let feeds = match (pts[k].feed, pts[k + 1].feed) {
                (Feed::Programmed(a), Feed::Programmed(b)) => Some((a, b)),
                _ => None,
            };
            let dwells = toolpath
                .dwells
                .iter()
                .any(|d| d.point == k && d.seconds > 0.0);
            let corner = [&pts[k - 1], &pts[k], &pts[k + 1]];
            feeds
                .filter(|_| !dwells)
                .and_then(|f| blend_points(corner, (corner_cos, max_cos), tolerance_mm, step, f))
        } else {
            None
        };
        match blend {
            Some(points) => {
                out.extend(points);
                blended += 1;
            }
            None => out.push(pts[k].clone()),
        }
    }
    // A point index past the last (a switch after the last move) stays past it.
    let total = out.len();
    let moved = |i: usize| if i < n { map[i] } else { total };
    let tp = Toolpath {
        source: toolpath.source.clone(),
        points: out,
        warnings: toolpath.warnings.clone(),
        files: toolpath.files.clone(),
        dwells: (toolpath.dwells.iter())
            .map(|d| Dwell {
                point: moved(d.point),
                ..*d
            })
            .collect(),
        tool_changes: (toolpath.tool_changes.iter())
            .map(|c| ToolChange {
                point: moved(c.point),
                ..c.clone()
            })
            .collect(),
        spindle_changes: (toolpath.spindle_changes.iter())
            .map(|c| SpindleChange {
                point: moved(c.point),
                ..*c
            })
            .collect(),
        switches: (toolpath.switches.iter())
            .map(|c| MachineSwitch {
                point: moved(c.point),
                ..*c
            })
            .collect(),
        work_offset: toolpath.work_offset.clone(),
        offset_changes: (toolpath.offset_changes.iter())
            .map(|c| OffsetChange {
                point: moved(c.point),
                ..c.clone()
            })
            .collect(),
        machine_points: (toolpath.machine_points.iter())
            .map(|c| MachinePoint {
                point: moved(c.point),
                ..*c
            })
            .collect(),
        length_offsets: toolpath.length_offsets.as_ref().map(|list| {
            list.iter()
                .map(|c| LengthOffsetChange {
                    point: moved(c.point),
                    ..*c
                })
                .collect()
        }),
        taps: (toolpath.taps.iter())
            .map(|t| TapCycle {
                points: moved(t.points.start)..moved(t.points.end.saturating_sub(1)) + 1,
                ..t.clone()
            })
            .collect(),
    };
    (Cow::Owned(tp), blended)
}

/// The CL points of the blend at corner `q` between the moves from `p` and to `r` (see the
/// module docs): from its first tangent point to its last, turning at most `step` radians from
/// one chord to the next; `None` where the corner is not one to blend (a move shorter than
/// [`SAME_POSITION_MM`], a turn whose cosine is not within `cos_range`: below the corner
/// angle's, at or above [`MAX_BLEND_ANGLE_DEG`]'s). Each half keeps its move's feed of `feeds`.
fn blend_points(
    [p, q, r]: [&ClPoint; 3],
    cos_range: (f64, f64),
    tol: f64,
    step: f64,
    feeds: (f64, f64),
) -> Option<Vec<ClPoint>> {
    let (a, b) = (q.p - p.p, r.p - q.p);
    let (la, lb) = (a.norm(), b.norm());
    if la <= SAME_POSITION_MM || lb <= SAME_POSITION_MM {
        return None;
    }
    let (ua, ub) = (a / la, b / lb);
    let c = ua.dot(&ub).clamp(-1.0, 1.0);
    if c >= cos_range.0 || c < cos_range.1 {
        return None;
    }
    let theta = c.acos();
    let half = 0.5 * theta;
    let room = MAX_SHARE * la.min(lb);
    // The quintic Bézier with three control points on each move (at SHAPE · d from the
    // corner): curvature 0 where it joins them. Its middle lies d · S · sin(θ/2) / 16 from the
    // corner (S = SHAPE₀ + 5 SHAPE₁ + 10 SHAPE₂), which d makes the tolerance.
    let sum = SHAPE[0] + 5.0 * SHAPE[1] + 10.0 * SHAPE[2];
    let d = (16.0 * tol / (sum * half.sin())).min(room);
    let ctrl: [Vector3<f64>; 6] = std::array::from_fn(|i| {
        if i < 3 {
            q.p - ua * (d * SHAPE[i])
        } else {
            q.p + ub * (d * SHAPE[5 - i])
        }
    });
    let at = |t: f64| -> Vector3<f64> {
        let u = 1.0 - t;
        let w = [
            u.powi(5),
            5.0 * t * u.powi(4),
            10.0 * t * t * u.powi(3),
            10.0 * t.powi(3) * u * u,
            5.0 * t.powi(4) * u,
            t.powi(5),
        ];
        ctrl.iter()
            .zip(w)
            .fold(Vector3::zeros(), |acc, (c, w)| acc + c * w)
    };
    // Points at equal steps of t, as many as keep every turn from one chord to the next
    // within `step` (the curvature peaks in the middle), an even number (the middle is one).
    let mut m = (2 * (theta / step).ceil() as usize).max(2);
    let points = loop {
        let pts: Vec<Vector3<f64>> = (0..=m).map(|j| at(j as f64 / m as f64)).collect();
        let worst = pts
            .windows(3)
            .map(|w| super::angle_between(&(w[1] - w[0]), &(w[2] - w[1])))
            .fold(0.0f64, f64::max);
        if worst <= step || m >= MAX_BLEND_POINTS {
            break pts;
        }
        m *= 2;
    };
    // The tool orientation and rotary angles at the tangent points, along their moves, and
    // between them on the blend by t.
    let start = mix(p, q, 1.0 - d / la);
    let end = mix(q, r, d / lb);
    Some(
        (points.into_iter().enumerate())
            .map(|(j, at)| {
                let t = j as f64 / m as f64;
                let (o, rotary) = mix_of(start, end, t);
                ClPoint {
                    p: at,
                    o: if o.iter().all(|x| x.is_finite()) {
                        o
                    } else {
                        q.o
                    },
                    // The first half of the blend is the first move's, the second the
                    // other's: the feed changes where the blocks meet, at its middle.
                    feed: Feed::Programmed(if t <= 0.5 { feeds.0 } else { feeds.1 }),
                    rotary,
                    line: q.line,
                }
            })
            .collect(),
    )
}

/// Tool orientation and programmed rotary angles.
type Pose = (Vector3<f64>, Option<[f64; 3]>);

/// The pose a share `s` of the way from `from`'s to `to`'s.
fn mix(from: &ClPoint, to: &ClPoint, s: f64) -> Pose {
    mix_of((from.o, from.rotary), (to.o, to.rotary), s)
}

/// The pose a share `s` of the way from `a` to `b`: orientations interpolated and normalised
/// (NaN where they are opposite), rotary angles interpolated where both are given.
fn mix_of(a: Pose, b: Pose, s: f64) -> Pose {
    let o = (a.0 * (1.0 - s) + b.0 * s).normalize();
    let rotary = match (a.1, b.1) {
        (Some(x), Some(y)) => Some(std::array::from_fn(|i| x[i] + s * (y[i] - x[i]))),
        _ => None,
    };
    (o, rotary)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pt(x: f64, y: f64, feed: Feed) -> ClPoint {
        ClPoint {
            p: Vector3::new(x, y, 0.0),
            o: Vector3::z(),
            feed,
            rotary: None,
            line: 1,
        }
    }

    fn toolpath(points: Vec<ClPoint>) -> Toolpath {
        Toolpath::new("t.ngc".into(), points)
    }

    /// A 90° corner: the blend leaves each move at d = 16 ε / (S sin 45°) from the corner,
    /// tangentially and without curvature; its middle is ε from the corner and no point is
    /// closer; each chord turns at most 5° from the one before.
    #[test]
    fn a_right_angle_gets_the_blend_of_its_tolerance() {
        let f = Feed::Programmed(10.0);
        let tp = toolpath(vec![
            pt(0.0, 0.0, Feed::Rapid),
            pt(10.0, 0.0, f),
            pt(10.0, 10.0, f),
        ]);
        let eps = 0.02;
        let (out, n) = blend_corners(&tp, eps, 10.0);
        assert_eq!(n, 1);
        let sum = 1.0 + 5.0 * 2.0 / 3.0 + 10.0 / 3.0;
        let d = 16.0 * eps / (sum * std::f64::consts::FRAC_PI_4.sin());
        let b = &out.points[1..out.points.len() - 1];
        assert!((b[0].p - Vector3::new(10.0 - d, 0.0, 0.0)).norm() < 1e-12);
        assert!((b[b.len() - 1].p - Vector3::new(10.0, d, 0.0)).norm() < 1e-12);
        // Zero curvature at the joints: the turn from chord to chord grows from 0 there (a
        // fillet's is the same all along).
        let turns: Vec<f64> = b
            .windows(3)
            .map(|w| super::super::angle_between(&(w[1].p - w[0].p), &(w[2].p - w[1].p)))
            .collect();
        let most = turns.iter().copied().fold(0.0, f64::max);
        assert!(
            turns[0] < 0.25 * most && turns[turns.len() - 1] < 0.25 * most,
            "{turns:?}"
        );
        let corner = Vector3::new(10.0, 0.0, 0.0);
        let dist: Vec<f64> = b.iter().map(|q| (q.p - corner).norm()).collect();
        let nearest = dist.iter().copied().fold(f64::INFINITY, f64::min);
        assert!((nearest - eps).abs() < 1e-12, "{nearest}");
        assert!((dist[dist.len() / 2] - eps).abs() < 1e-12);
        for w in out.points.windows(3) {
            let (u, v) = ((w[1].p - w[0].p).normalize(), (w[2].p - w[1].p).normalize());
            assert!(u.dot(&v) >= 5f64.to_radians().cos() - 1e-12);
        }
    }

    /// A short move limits the blend to MAX_SHARE of it; reversals, rapids, dwells and gentle
    /// turns are left alone; the dwell's index follows its point.
    #[test]
    fn short_moves_cap_the_blend_and_other_corners_stay() {
        let f = Feed::Programmed(10.0);
        let tp = toolpath(vec![pt(0.0, 0.0, f), pt(1.0, 0.0, f), pt(1.0, 0.01, f)]);
        let (out, n) = blend_corners(&tp, 0.5, 10.0);
        assert_eq!(n, 1);
        let last = &out.points[out.points.len() - 2];
        assert!((last.p - Vector3::new(1.0, MAX_SHARE * 0.01, 0.0)).norm() < 1e-12);
        for (points, why) in [
            (
                vec![pt(0.0, 0.0, f), pt(1.0, 0.0, f), pt(0.0, 0.01, f)],
                "reversal",
            ),
            (
                vec![pt(0.0, 0.0, f), pt(1.0, 0.0, Feed::Rapid), pt(1.0, 1.0, f)],
                "rapid",
            ),
            (
                vec![pt(0.0, 0.0, f), pt(1.0, 0.0, f), pt(2.0, 0.1, f)],
                "gentle",
            ),
        ] {
            let tp = toolpath(points.clone());
            let (out, n) = blend_corners(&tp, 0.1, 10.0);
            assert_eq!((n, &out.points), (0, &points), "{why}");
        }
        let mut tp = toolpath(vec![pt(0.0, 0.0, f), pt(1.0, 0.0, f), pt(1.0, 1.0, f)]);
        tp.dwells.push(crate::toolpath::Dwell {
            point: 1,
            seconds: 1.0,
            line: 1,
        });
        assert_eq!(blend_corners(&tp, 0.1, 10.0).1, 0);
        tp.dwells[0].point = 2;
        let (out, _) = blend_corners(&tp, 0.1, 10.0);
        assert_eq!(out.dwells[0].point, out.points.len() - 1);
    }
}
