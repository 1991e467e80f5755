//! Approximate biarc interpolation of a planar profile (seed 001: dressing a formed grinding
//! wheel), and the dresser's limit on the rotary step between output blocks.
//!
//! Points are `[x, z]` in the program's X–Z plane (the dresser convention of
//! [`crate::kinematics::dresser`]). Arcs turn **counter-clockwise** (`ccw`) when the direction
//! angle φ = atan2(t_z, t_x) of the tangent t grows, i.e. from +X towards +Z.
//!
//! # Normal angle
//!
//! The tool stands on the profile normal n = (sin θ, 0, cos θ). The normal of a piece is its
//! tangent turned by +90° in (x, z), n = (−t_z, t_x): a profile travelled along +X has the tool
//! above it (θ = 0, the dresser's B = 0), so θ = atan2(−t_z, t_x) = −φ. A ccw arc of central
//! angle α therefore turns the tool by −α, a cw arc by +α, a line not at all. (Travel the profile
//! the other way round to put the tool on the other side.)
//!
//! # Fitting ([`fit`])
//!
//! 1. Consecutive duplicate points (closer than [`super::SAME_POSITION_MM`]) and non-finite
//!    points are skipped.
//! 2. **Runs.** The points are split greedily into runs that each fit one *primitive* within
//!    half the tolerance: a line (total least squares) or a circle (Kåsa's algebraic fit). From
//!    the first point of a run both fits are grown as far as they hold; the circle is taken only
//!    when it covers clearly more points than the line (at least 1.5 times as many, and more
//!    than two): three points on a gentle arc are collinear within tolerance, and a long line
//!    followed by a curve must stay a line.
//! 3. **Key points and tangents.** The curve passes through key points with given unit
//!    tangents: the ends of the profile projected onto their run's primitive, with its tangent;
//!    at a joint between a line run and a circle run that touch (centre-to-line distance equal
//!    to the radius within half the tolerance, same direction of travel), the point of contact
//!    on the line, with the line's direction; at any other joint, the shared data point with the
//!    mean of the two primitives' tangents there.
//! 4. **Biarcs.** Consecutive key points are joined by the classic equal-tangent-length biarc
//!    (two arcs meeting with a common tangent; an arc whose tangent runs along its chord is a
//!    line). The curve is therefore tangent-continuous (G1) at every joint by construction.
//! 5. **Refinement.** A data point farther than `tolerance` from the pieces of its segment and
//!    the two neighbouring segments splits the segment at its middle data point (projected onto
//!    the run's primitive, with the primitive's tangent); a segment with no point left to split
//!    at falls back to the data points themselves as key points. This terminates with every
//!    data point within `tolerance`.
//! 6. **Merging.** Consecutive collinear lines and consecutive arcs of the same circle (centre
//!    and radius equal to 1e-9 relative) become one piece; tangents do not change.
//!
//! On a line or circle sampled with noise well inside the tolerance this gives the line, or one
//! arc of the fitted circle; a line–arc–line groove gives line, two arcs of nearly the fitted
//! radius (the two contact points lie on the circle only to within the noise), line.
//!
//! The only loss of G1 is the degenerate biarc whose end tangents are equal and point against
//! the chord (no finite biarc exists): the segment is then a plain line. Key tangents come from
//! fitted primitives that follow the points forward, so this does not happen on profile data.
//!
//! # Rotary step ([`limit_rotation`], [`pre_rotations`])
//!
//! Seed 001 keeps the rotation between neighbouring output points below Δθ: a line needs one
//! rotation (at its start) and then plain linear interpolation; an arc whose central angle
//! exceeds Δθ is bisected repeatedly until every piece's angle is at most Δθ; where the end
//! normal differs from the current tool normal by more than Δθ the tool first turns on the spot.
//! With G1 joints the normal is continuous along the fitted profile, so such a pure rotation is
//! needed only before the first piece (from wherever the tool stands), or at a joint that is not
//! tangent-continuous; [`pre_rotations`] lists them.

use std::f64::consts::{PI, TAU};

use super::SAME_POSITION_MM;

type P = [f64; 2];

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1]]
}
fn add(a: P, b: P) -> P {
    [a[0] + b[0], a[1] + b[1]]
}
fn scale(a: P, s: f64) -> P {
    [a[0] * s, a[1] * s]
}
fn dot(a: P, b: P) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
fn cross(a: P, b: P) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
fn norm(a: P) -> f64 {
    a[0].hypot(a[1])
}
fn unit(a: P) -> Option<P> {
    let n = norm(a);
    (n > 0.0 && n.is_finite()).then(|| scale(a, 1.0 / n))
}
/// `a` turned by +90° (from +X towards +Z).
fn left(a: P) -> P {
    [-a[1], a[0]]
}
fn dist(a: P, b: P) -> f64 {
    norm(sub(a, b))
}

/// One piece of a fitted profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Piece {
    /// A straight segment from `from` to `to`.
    Line {
        /// Start point (x, z).
        from: [f64; 2],
        /// End point (x, z).
        to: [f64; 2],
    },
    /// A circular arc of less than a full turn from `from` to `to` about `center`; `ccw`: it
    /// turns from +X towards +Z. The radius is `|from − center|`.
    Arc {
        /// Start point (x, z).
        from: [f64; 2],
        /// End point (x, z).
        to: [f64; 2],
        /// Centre (x, z).
        center: [f64; 2],
        /// Whether it turns from +X towards +Z.
        ccw: bool,
    },
}

impl Piece {
    /// Where the piece starts.
    pub fn start(&self) -> [f64; 2] {
        match *self {
            Piece::Line { from, .. } | Piece::Arc { from, .. } => from,
        }
    }

    /// Where the piece ends.
    pub fn end(&self) -> [f64; 2] {
        match *self {
            Piece::Line { to, .. } | Piece::Arc { to, .. } => to,
        }
    }

    /// The radius of an arc, `None` for a line.
    pub fn radius(&self) -> Option<f64> {
        match *self {
            Piece::Line { .. } => None,
            Piece::Arc { from, center, .. } => Some(dist(from, center)),
        }
    }

    /// Central angle in [0, 2π), radians (0 for a line).
    pub fn sweep(&self) -> f64 {
        match *self {
            Piece::Line { .. } => 0.0,
            Piece::Arc {
                from,
                to,
                center,
                ccw,
            } => {
                let (a, b) = (sub(from, center), sub(to, center));
                let s = cross(a, b).atan2(dot(a, b));
                let s = if ccw { s } else { -s };
                if s < 0.0 { s + TAU } else { s }
            }
        }
    }

    /// Arc length, mm.
    pub fn length(&self) -> f64 {
        match *self {
            Piece::Line { from, to } => dist(from, to),
            Piece::Arc { .. } => self.radius().unwrap_or(0.0) * self.sweep(),
        }
    }

    /// Unit tangent (direction of travel) at the point `p` of an arc.
    fn arc_tangent(center: P, ccw: bool, p: P) -> P {
        let r = unit(sub(p, center)).unwrap_or([1.0, 0.0]);
        if ccw { left(r) } else { scale(left(r), -1.0) }
    }

    /// Unit tangent at the start (a zero-length line gives +X).
    pub fn tangent_at_start(&self) -> [f64; 2] {
        match *self {
            Piece::Line { from, to } => unit(sub(to, from)).unwrap_or([1.0, 0.0]),
            Piece::Arc {
                from, center, ccw, ..
            } => Self::arc_tangent(center, ccw, from),
        }
    }

    /// Unit tangent at the end.
    pub fn tangent_at_end(&self) -> [f64; 2] {
        match *self {
            Piece::Line { .. } => self.tangent_at_start(),
            Piece::Arc {
                to, center, ccw, ..
            } => Self::arc_tangent(center, ccw, to),
        }
    }

    /// The tool's normal angle θ (radians, in (−π, π]) at the start: n = (sin θ, 0, cos θ) =
    /// the tangent turned by +90°, θ = atan2(−t_z, t_x).
    pub fn normal_angle_at_start(&self) -> f64 {
        let t = self.tangent_at_start();
        (-t[1]).atan2(t[0])
    }

    /// The normal angle θ at the end, in (−π, π].
    pub fn normal_angle_at_end(&self) -> f64 {
        let t = self.tangent_at_end();
        (-t[1]).atan2(t[0])
    }

    /// Signed change of the normal angle θ along the piece (radians): −sweep for a ccw arc,
    /// +sweep for a cw arc, 0 for a line.
    pub fn turn(&self) -> f64 {
        match *self {
            Piece::Line { .. } => 0.0,
            Piece::Arc { ccw, .. } => {
                if ccw {
                    -self.sweep()
                } else {
                    self.sweep()
                }
            }
        }
    }

    /// The point at fraction `t` ∈ [0, 1] of the length (clamped); exact end points at 0 and 1.
    pub fn point_at(&self, t: f64) -> [f64; 2] {
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        if t == 0.0 {
            return self.start();
        }
        if t == 1.0 {
            return self.end();
        }
        match *self {
            Piece::Line { from, to } => add(from, scale(sub(to, from), t)),
            Piece::Arc {
                from, center, ccw, ..
            } => {
                let r = self.radius().unwrap_or(0.0);
                let a0 = (from[1] - center[1]).atan2(from[0] - center[0]);
                let a = a0 + if ccw { t } else { -t } * self.sweep();
                [center[0] + r * a.cos(), center[1] + r * a.sin()]
            }
        }
    }

    /// Distance from `p` to the piece, mm.
    pub fn distance_to(&self, p: [f64; 2]) -> f64 {
        match *self {
            Piece::Line { from, to } => {
                let d = sub(to, from);
                let l2 = dot(d, d);
                let s = if l2 > 0.0 {
                    (dot(sub(p, from), d) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                dist(p, add(from, scale(d, s)))
            }
            Piece::Arc {
                from,
                to,
                center,
                ccw,
            } => {
                let ends = dist(p, from).min(dist(p, to));
                let v = sub(p, center);
                if norm(v) == 0.0 {
                    return ends;
                }
                // Within the sweep: the arc from `from` to `p`'s direction from the centre.
                let probe = Piece::Arc {
                    from,
                    to: add(center, v),
                    center,
                    ccw,
                };
                if probe.sweep() <= self.sweep() {
                    (norm(v) - self.radius().unwrap_or(0.0)).abs().min(ends)
                } else {
                    ends
                }
            }
        }
    }
}

/// A run's fitted primitive.
#[derive(Debug, Clone, Copy)]
enum Prim {
    /// A point on the line and its unit direction (along travel).
    Line {
        q: P,
        d: P,
    },
    Circle {
        c: P,
        r: f64,
        ccw: bool,
    },
}

impl Prim {
    fn project(&self, p: P) -> P {
        match *self {
            Prim::Line { q, d } => add(q, scale(d, dot(sub(p, q), d))),
            Prim::Circle { c, r, .. } => match unit(sub(p, c)) {
                Some(u) => add(c, scale(u, r)),
                None => p,
            },
        }
    }

    fn tangent(&self, p: P) -> P {
        match *self {
            Prim::Line { d, .. } => d,
            Prim::Circle { c, ccw, .. } => Piece::arc_tangent(c, ccw, p),
        }
    }
}

/// Total least-squares line through `pts` (≥ 2 distinct), oriented first → last, and the largest
/// distance of a point from it.
fn fit_line(pts: &[P]) -> Option<(Prim, f64)> {
    let n = pts.len() as f64;
    let m = scale(pts.iter().fold([0.0, 0.0], |a, &p| add(a, p)), 1.0 / n);
    let (mut sxx, mut sxz, mut szz) = (0.0, 0.0, 0.0);
    for p in pts {
        let v = sub(*p, m);
        sxx += v[0] * v[0];
        sxz += v[0] * v[1];
        szz += v[1] * v[1];
    }
    let a = 0.5 * (2.0 * sxz).atan2(sxx - szz);
    let mut d = [a.cos(), a.sin()];
    let travel = sub(*pts.last()?, pts[0]);
    if dot(d, travel) < 0.0 {
        d = scale(d, -1.0);
    }
    let dev = pts
        .iter()
        .map(|p| cross(d, sub(*p, m)).abs())
        .fold(0.0, f64::max);
    Some((Prim::Line { q: m, d }, dev))
}

/// Kåsa's algebraic circle fit (≥ 3 points), with the direction of travel, and the largest
/// radial deviation. `None` when the points are (nearly) collinear.
fn fit_circle(pts: &[P]) -> Option<(Prim, f64)> {
    if pts.len() < 3 {
        return None;
    }
    let n = pts.len() as f64;
    let m = scale(pts.iter().fold([0.0, 0.0], |a, &p| add(a, p)), 1.0 / n);
    let (mut suu, mut suv, mut svv, mut suuu, mut svvv, mut suvv, mut svuu) =
        (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for p in pts {
        let [u, v] = sub(*p, m);
        suu += u * u;
        suv += u * v;
        svv += v * v;
        suuu += u * u * u;
        svvv += v * v * v;
        suvv += u * v * v;
        svuu += v * u * u;
    }
    let det = suu * svv - suv * suv;
    if det.is_nan() || det <= 1e-12 * (suu + svv).powi(2) {
        return None;
    }
    let (bu, bv) = (0.5 * (suuu + suvv), 0.5 * (svvv + svuu));
    let cu = (bu * svv - bv * suv) / det;
    let cv = (suu * bv - suv * bu) / det;
    let c = add(m, [cu, cv]);
    let r = (cu * cu + cv * cv + (suu + svv) / n).sqrt();
    if !(r.is_finite() && c[0].is_finite() && c[1].is_finite()) {
        return None;
    }
    let turn: f64 = pts
        .windows(2)
        .map(|w| cross(sub(w[0], c), sub(w[1], c)))
        .sum();
    let dev = pts
        .iter()
        .map(|p| (dist(*p, c) - r).abs())
        .fold(0.0, f64::max);
    Some((
        Prim::Circle {
            c,
            r,
            ccw: turn > 0.0,
        },
        dev,
    ))
}

/// A key point of the curve: position, unit tangent, the data point it stands for, and whether
/// it was moved off that data point (so it may fall back to it).
#[derive(Debug, Clone, Copy)]
struct Key {
    p: P,
    t: P,
    idx: usize,
    snapped: bool,
}

/// Equal-tangent-length biarc from (p0, t0) to (p1, t1); one or two pieces (a piece is a line
/// when its tangent runs along its chord).
fn biarc(p0: P, t0: P, p1: P, t1: P) -> Vec<Piece> {
    let v = sub(p1, p0);
    let c = dot(v, v);
    if c == 0.0 {
        return Vec::new();
    }
    let t = add(t0, t1);
    let vt = dot(v, t);
    let a = 2.0 * (dot(t0, t1) - 1.0);
    // a d² − 2 (v·t) d + v·v = 0, positive root in a cancellation-free form.
    let disc = (vt * vt - a * c).max(0.0).sqrt();
    let den = vt + disc;
    let d = c / den;
    if !(den > 0.0 && d.is_finite() && d > 0.0) {
        return vec![Piece::Line { from: p0, to: p1 }];
    }
    let q0 = add(p0, scale(t0, d));
    let q1 = sub(p1, scale(t1, d));
    let j = scale(add(q0, q1), 0.5);
    let tj = unit(sub(q1, q0)).unwrap_or(t0);
    let mut out = Vec::with_capacity(2);
    out.extend(arc_from(p0, t0, j));
    out.extend(arc_from(j, tj, p1));
    out
}

/// The arc (or line) leaving `a` with unit tangent `t` and ending at `b`.
fn arc_from(a: P, t: P, b: P) -> Option<Piece> {
    let ch = sub(b, a);
    let l2 = dot(ch, ch);
    if l2 == 0.0 {
        return None;
    }
    let cr = cross(t, ch);
    if cr.abs() <= 1e-12 * l2.sqrt() || !(l2 / cr).is_finite() {
        return Some(Piece::Line { from: a, to: b });
    }
    let rho = l2 / (2.0 * cr);
    let center = add(a, scale(left(t), rho));
    Some(Piece::Arc {
        from: a,
        to: b,
        center,
        ccw: rho > 0.0,
    })
}

/// Fits G1 lines and arcs to `points` (x, z), every point within `tolerance` (mm) of the curve;
/// see the [module documentation](self) for the method. Fewer than two distinct points give no
/// pieces, two give one line. Deterministic; never panics.
pub fn fit(points: &[[f64; 2]], tolerance: f64) -> Vec<Piece> {
    let mut pts: Vec<P> = Vec::with_capacity(points.len());
    for &p in points {
        if p[0].is_finite()
            && p[1].is_finite()
            && pts.last().is_none_or(|&q| dist(p, q) > SAME_POSITION_MM)
        {
            pts.push(p);
        }
    }
    let n = pts.len();
    if n < 2 {
        return Vec::new();
    }
    if n == 2 {
        return vec![Piece::Line {
            from: pts[0],
            to: pts[1],
        }];
    }
    let tol = if tolerance.is_finite() && tolerance > 0.0 {
        tolerance
    } else {
        0.0
    };
    let tol_fit = 0.5 * tol;

    // 2. Runs [start, end] (sharing their end points) with their primitives.
    let mut runs: Vec<(usize, usize, Prim)> = Vec::new();
    let mut i = 0;
    while i < n - 1 {
        let line_fit = |j: usize| fit_line(&pts[i..=j]).filter(|f| f.1 <= tol_fit);
        let circle_fit = |j: usize| fit_circle(&pts[i..=j]).filter(|f| f.1 <= tol_fit);
        let mut jl = i + 1;
        while jl + 1 < n && line_fit(jl + 1).is_some() {
            jl += 1;
        }
        let mut jc = i + 1;
        while jc + 1 < n && circle_fit(jc + 1).is_some() {
            jc += 1;
        }
        let (lc, cc) = (jl - i + 1, jc - i + 1);
        let run = match circle_fit(jc) {
            Some((prim, _)) if cc > 2 && 2 * cc >= 3 * lc => (i, jc, prim),
            _ => match line_fit(jl) {
                Some((prim, _)) => (i, jl, prim),
                // tol = 0 and the line through two points still deviates by rounding.
                None => {
                    let d = unit(sub(pts[i + 1], pts[i])).unwrap_or([1.0, 0.0]);
                    (i, i + 1, Prim::Line { q: pts[i], d })
                }
            },
        };
        i = run.1;
        runs.push(run);
    }

    // 3. Key points.
    let mean_tangent = |idx: usize, before: Option<&Prim>, after: Option<&Prim>| -> P {
        let p = pts[idx];
        let s = [before, after]
            .iter()
            .flatten()
            .fold([0.0, 0.0], |acc, pr| add(acc, pr.tangent(p)));
        unit(s)
            .or_else(|| after.or(before).map(|pr| pr.tangent(p)))
            .unwrap_or([1.0, 0.0])
    };
    let span = |r: &(usize, usize, Prim)| dist(pts[r.0], pts[r.1]);
    let mut keys: Vec<Key> = Vec::with_capacity(runs.len() + 1);
    let first = &runs[0].2;
    keys.push(Key {
        p: first.project(pts[0]),
        t: first.tangent(pts[0]),
        idx: 0,
        snapped: true,
    });
    for w in runs.windows(2) {
        let (ra, rb) = (&w[0], &w[1]);
        let idx = ra.1;
        let pj = pts[idx];
        let contact = match (ra.2, rb.2) {
            (Prim::Line { q, d }, circ @ Prim::Circle { c, r, .. })
            | (circ @ Prim::Circle { c, r, .. }, Prim::Line { q, d }) => {
                let f = add(q, scale(d, dot(sub(c, q), d)));
                let ok = (dist(f, c) - r).abs() <= tol_fit
                    && dist(f, pj) <= 0.25 * span(ra).min(span(rb))
                    && dot(circ.tangent(f), d) > 0.99;
                ok.then_some((f, d))
            }
            _ => None,
        };
        keys.push(match contact {
            Some((p, t)) => Key {
                p,
                t,
                idx,
                snapped: true,
            },
            None => Key {
                p: pj,
                t: mean_tangent(idx, Some(&ra.2), Some(&rb.2)),
                idx,
                snapped: false,
            },
        });
    }
    let last = &runs[runs.len() - 1].2;
    keys.push(Key {
        p: last.project(pts[n - 1]),
        t: last.tangent(pts[n - 1]),
        idx: n - 1,
        snapped: true,
    });
    // The run of the data point range starting at `idx`.
    let run_of = |idx: usize| runs.iter().rposition(|r| r.0 <= idx).unwrap_or(0);
    let demote = |k: &mut Key| {
        let r = run_of(k.idx);
        let before = (k.idx > 0 && runs[r].0 == k.idx && r > 0).then(|| &runs[r - 1].2);
        let here = (k.idx < n - 1).then(|| &runs[r].2);
        let here = here.or(before.is_none().then(|| &runs[r].2));
        k.p = pts[k.idx];
        k.t = mean_tangent(k.idx, before, here);
        k.snapped = false;
    };
    // A snapped key that does not move forward along the data falls back to its data point.
    for s in 1..keys.len() - 1 {
        let fwd = |a: &Key, b: &Key| dot(sub(b.p, a.p), sub(pts[b.idx], pts[a.idx])) > 0.0;
        if keys[s].snapped && !(fwd(&keys[s - 1], &keys[s]) && fwd(&keys[s], &keys[s + 1])) {
            demote(&mut keys[s]);
        }
    }

    // 4–5. Biarcs and refinement.
    let segments = loop {
        let segs: Vec<Vec<Piece>> = keys
            .windows(2)
            .map(|w| biarc(w[0].p, w[0].t, w[1].p, w[1].t))
            .collect();
        let mut demotions: Vec<usize> = Vec::new();
        let mut inserts: Vec<(usize, Key)> = Vec::new();
        for s in 0..segs.len() {
            let (a, b) = (keys[s].idx, keys[s + 1].idx);
            let near = &segs[s.saturating_sub(1)..(s + 2).min(segs.len())];
            let ok = (a..=b).all(|i| {
                near.iter()
                    .flatten()
                    .map(|pc| pc.distance_to(pts[i]))
                    .fold(f64::INFINITY, f64::min)
                    <= tol
            });
            if ok {
                continue;
            }
            let mut split = None;
            if b >= a + 2 {
                let m = (a + b) / 2;
                let prim = &runs[run_of(m)].2;
                let p = prim.project(pts[m]);
                let ch = sub(keys[s + 1].p, keys[s].p);
                let f = dot(sub(p, keys[s].p), ch) / dot(ch, ch);
                let mut k = Key {
                    p,
                    t: prim.tangent(pts[m]),
                    idx: m,
                    snapped: true,
                };
                if !(f > 1e-6 && f < 1.0 - 1e-6) {
                    demote(&mut k);
                }
                split = Some(k);
            }
            match split {
                Some(k) => inserts.push((s + 1, k)),
                None => {
                    demotions.extend([s, s + 1].into_iter().filter(|&k| keys[k].snapped));
                }
            }
        }
        if demotions.is_empty() && inserts.is_empty() {
            break segs;
        }
        for k in demotions {
            demote(&mut keys[k]);
        }
        for (at, k) in inserts.into_iter().rev() {
            keys.insert(at, k);
        }
    };

    // 6. Merge.
    let mut out: Vec<Piece> = Vec::new();
    for pc in segments.into_iter().flatten() {
        if let Some(prev) = out.last_mut()
            && let Some(m) = merge(prev, &pc)
        {
            *prev = m;
            continue;
        }
        out.push(pc);
    }
    out
}

/// `a` and `b` as one piece, when they are collinear lines or arcs of the same circle.
fn merge(a: &Piece, b: &Piece) -> Option<Piece> {
    match (*a, *b) {
        (Piece::Line { from, to }, Piece::Line { from: f2, to: t2 }) => {
            let (u, v) = (sub(to, from), sub(t2, f2));
            (to == f2 && cross(u, v).abs() <= 1e-12 * norm(u) * norm(v) && dot(u, v) > 0.0)
                .then_some(Piece::Line { from, to: t2 })
        }
        (
            Piece::Arc {
                from,
                to,
                center,
                ccw,
            },
            Piece::Arc {
                from: f2,
                to: t2,
                center: c2,
                ccw: w2,
            },
        ) => {
            let r = dist(from, center);
            let eps = 1e-9 * r.max(1.0);
            let same = to == f2
                && ccw == w2
                && dist(center, c2) <= eps
                && (dist(f2, c2) - r).abs() <= eps
                && a.sweep() + b.sweep() < TAU - 1e-6;
            same.then_some(Piece::Arc {
                from,
                to: t2,
                center,
                ccw,
            })
        }
        _ => None,
    }
}

/// Largest distance from a point of `points` to the nearest piece (0 with no points; infinite
/// with points but no pieces).
pub fn max_deviation(points: &[[f64; 2]], pieces: &[Piece]) -> f64 {
    points
        .iter()
        .map(|&p| {
            pieces
                .iter()
                .map(|pc| pc.distance_to(p))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

/// Most halvings of one arc (2²⁰ pieces).
const MAX_HALVINGS: u32 = 20;

/// Seed 001's output rule: every arc whose central angle exceeds `max_step_rad` (Δθ) is
/// bisected repeatedly — into 2ᵏ equal arcs, k the fewest halvings that bring each to ≤ Δθ
/// (at most 2²⁰ pieces) — so the tool turns by at most Δθ within any output block; lines keep
/// their single rotation (done before the line, see [`pre_rotations`]). End points are kept
/// exactly; the new joints lie on the arc. A Δθ that is not positive and finite returns the
/// pieces unchanged.
pub fn limit_rotation(pieces: &[Piece], max_step_rad: f64) -> Vec<Piece> {
    if !(max_step_rad > 0.0 && max_step_rad.is_finite()) {
        return pieces.to_vec();
    }
    let mut out = Vec::with_capacity(pieces.len());
    for pc in pieces {
        let Piece::Arc {
            from,
            to,
            center,
            ccw,
        } = *pc
        else {
            out.push(*pc);
            continue;
        };
        let sweep = pc.sweep();
        let mut k = 0;
        while k < MAX_HALVINGS && sweep / f64::from(1u32 << k) > max_step_rad {
            k += 1;
        }
        let m = 1usize << k;
        let mut prev = from;
        for j in 1..=m {
            let next = if j == m {
                to
            } else {
                pc.point_at(j as f64 / m as f64)
            };
            out.push(Piece::Arc {
                from: prev,
                to: next,
                center,
                ccw,
            });
            prev = next;
        }
    }
    out
}

/// A pure rotation of the tool, on the spot, before piece `before`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreRotation {
    /// Index of the piece it precedes.
    pub before: usize,
    /// Normal angle θ (radians) the tool has.
    pub from: f64,
    /// Normal angle θ (radians) the piece starts with.
    pub to: f64,
}

/// Where the tool must first turn on the spot: where the start normal of a piece differs by
/// more than `max_step_rad` from the current tool normal — `current_theta` (radians) before the
/// first piece, the previous piece's end normal after it. With a G1 profile from [`fit`] this
/// is at most the first piece. Angle differences are taken modulo 2π.
pub fn pre_rotations(pieces: &[Piece], current_theta: f64, max_step_rad: f64) -> Vec<PreRotation> {
    let mut out = Vec::new();
    let mut theta = current_theta;
    for (i, pc) in pieces.iter().enumerate() {
        let start = pc.normal_angle_at_start();
        let diff = (start - theta + PI).rem_euclid(TAU) - PI;
        if diff.abs() > max_step_rad {
            out.push(PreRotation {
                before: i,
                from: theta,
                to: start,
            });
        }
        theta = pc.normal_angle_at_end();
    }
    out
}
