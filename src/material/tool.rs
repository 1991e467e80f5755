//! The cutter: a flat, ball or bull-nose end mill as a solid of revolution about its axis.
//!
//! With the tool tip at **P** and the unit axis **O** pointing from the tip towards the spindle,
//! a point **X** lies at height `h = (X − P)·O` along the axis and radius `ρ = |X − P − h O|`
//! from it. The cutting part of the tool is the convex solid
//!
//! ```text
//! 0 ≤ h ≤ L_f,   ρ ≤ r(h),   r(h) = R − r_c + √(r_c² − (r_c − h)²)  for h < r_c,   R above,
//! ```
//!
//! with R = D/2 the tool radius, r_c the corner radius (0: flat end mill, R: ball-nose, in
//! between: bull-nose) and L_f the flute length. Seen from below along a vertical axis the
//! tool's lower surface is `z = P_z + f(d)` at horizontal distance d from the axis, with
//! `f(d) = 0` for d ≤ R − r_c and `r_c − √(r_c² − (d − R + r_c)²)` up to R: convex and
//! non-decreasing in d.

use multiversion::multiversion;
use nalgebra::Vector3;

use super::dexel::{index_f64, larger, smaller};

/// The largest tool diameter (mm) feedopt accepts: 1 m.
pub const MAX_TOOL_DIAMETER_MM: f64 = 1000.0;

/// The shape of an end mill, for messages and reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ToolKind {
    /// Corner radius 0.
    Flat,
    /// Corner radius D/2.
    Ball,
    /// Corner radius between 0 and D/2.
    BullNose,
}

/// An end mill.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Tool {
    /// D, mm.
    pub diameter: f64,
    /// r_c, mm (0 ≤ r_c ≤ D/2).
    pub corner_radius: f64,
    /// L_f, mm: the length of the cutting part above the tip (> r_c).
    pub flute_length: f64,
    /// z, the number of teeth (flutes).
    pub flutes: u32,
}

impl Tool {
    /// A tool, validated: a one-line reason naming the quantity when it is not a tool.
    pub fn new(
        diameter: f64,
        corner_radius: f64,
        flute_length: f64,
        flutes: u32,
    ) -> Result<Tool, String> {
        if !(diameter.is_finite() && diameter > 0.0 && diameter <= MAX_TOOL_DIAMETER_MM) {
            return Err(format!(
                "tool diameter {diameter} mm must be positive and at most {MAX_TOOL_DIAMETER_MM} mm"
            ));
        }
        let r = 0.5 * diameter;
        if !(corner_radius.is_finite() && (0.0..=r * (1.0 + 1e-12)).contains(&corner_radius)) {
            return Err(format!(
                "corner radius {corner_radius} mm must lie between 0 and half the diameter ({r} mm)"
            ));
        }
        if !(flute_length.is_finite()
            && flute_length > corner_radius
            && flute_length <= 100.0 * diameter.max(1.0))
        {
            return Err(format!(
                "flute length {flute_length} mm must exceed the corner radius ({corner_radius} mm) \
                 and be at most 100 diameters"
            ));
        }
        if flutes == 0 || flutes > 64 {
            return Err(format!("{flutes} flutes: a tool has 1 to 64"));
        }
        Ok(Tool {
            diameter,
            corner_radius: corner_radius.min(r),
            flute_length,
            flutes,
        })
    }

    /// R = D/2, mm.
    pub fn radius(&self) -> f64 {
        0.5 * self.diameter
    }

    /// Flat, ball or bull-nose.
    pub fn kind(&self) -> ToolKind {
        if self.corner_radius == 0.0 {
            ToolKind::Flat
        } else if self.corner_radius >= self.radius() {
            ToolKind::Ball
        } else {
            ToolKind::BullNose
        }
    }

    /// f(d): height of the lower surface above the tip at horizontal distance `d` ≤ R from
    /// the axis of a vertical tool (module doc).
    pub fn bottom(&self, d: f64) -> f64 {
        let rc = self.corner_radius;
        let x = d - (self.radius() - rc);
        if x <= 0.0 {
            0.0
        } else {
            rc - (rc * rc - x * x).max(0.0).sqrt()
        }
    }

    /// r(h): the tool's radius at height `h` (0 ≤ h) above the tip.
    pub fn radius_at(&self, h: f64) -> f64 {
        let (r, rc) = (self.radius(), self.corner_radius);
        if h >= rc {
            r
        } else {
            let y = rc - h;
            r - rc + (rc * rc - y * y).max(0.0).sqrt()
        }
    }

    /// The interval of z (mm) where the vertical line through (x, y) crosses the tool at tip
    /// `p` and unit axis `o` (a static pose), if it does. Exact for flat and ball-nose tools
    /// (quadratics); for a bull-nose tool the torus part is solved as a convex problem in z
    /// (ρ(z) − r(h(z)) is convex: a norm of an affine function minus a concave one) to 1e-9 mm.
    /// The same as [`Pose::hit`], which keeps what depends on the pose alone for many lines.
    pub fn line_hit(&self, p: &Vector3<f64>, o: &Vector3<f64>, x: f64, y: f64) -> Option<[f64; 2]> {
        Pose::new(self, p, o).hit(x, y)
    }
}

/// A tool at a static pose (tip `p`, unit axis `o`), with what its crossings with the dexel
/// lines share: [`Tool::line_hit`] for line after line.
///
/// With s = z − P_z along the line through (x, y), d = (x − P_x, y − P_y) and c = d·(O_x, O_y):
/// the height above the tip is h(s) = c + s O_z and the squared distance from the axis
/// ρ²(s) = a s² − 2 c O_z s + (|d|² − c²), a = 1 − O_z².
#[derive(Debug, Clone, Copy)]
pub struct Pose<'a> {
    tool: &'a Tool,
    p: Vector3<f64>,
    o: Vector3<f64>,
    /// 1 − O_z² and its inverse (∞ for a vertical axis: then ρ does not depend on s).
    a: f64,
    inv_a: f64,
    /// 1/O_z (∞ for a horizontal axis: then h does not depend on s).
    inv_oz: f64,
}

impl<'a> Pose<'a> {
    /// `tool` with its tip at `p` and unit axis `o`.
    pub fn new(tool: &'a Tool, p: &Vector3<f64>, o: &Vector3<f64>) -> Pose<'a> {
        let a = 1.0 - o.z * o.z;
        Pose {
            tool,
            p: *p,
            o: *o,
            a,
            inv_a: if a < 1e-15 { f64::INFINITY } else { 1.0 / a },
            inv_oz: if o.z.abs() < 1e-15 {
                f64::INFINITY
            } else {
                1.0 / o.z
            },
        }
    }

    /// The tip.
    pub fn tip(&self) -> Vector3<f64> {
        self.p
    }

    /// The unit axis.
    pub fn axis(&self) -> Vector3<f64> {
        self.o
    }

    /// The interval of z (mm) where the vertical line through (x, y) crosses the tool, if it
    /// does ([`Tool::line_hit`]).
    #[inline]
    pub fn hit(&self, x: f64, y: f64) -> Option<[f64; 2]> {
        let (p, o, tool) = (&self.p, &self.o, self.tool);
        let (dx, dy) = (x - p.x, y - p.y);
        let (r, rc, lf) = (tool.radius(), tool.corner_radius, tool.flute_length);
        let c = dx * o.x + dy * o.y;
        let q0 = dx * dx + dy * dy - c * c;
        // The s where h(s) lies within [h0, h1].
        let slab = |h0: f64, h1: f64| -> Option<(f64, f64)> {
            if self.inv_oz.is_infinite() {
                return (c >= h0 && c <= h1).then_some((f64::NEG_INFINITY, f64::INFINITY));
            }
            let (s0, s1) = ((h0 - c) * self.inv_oz, (h1 - c) * self.inv_oz);
            Some((s0.min(s1), s0.max(s1)))
        };
        // The s where ρ²(s) ≤ rad².
        let within = |rad: f64| -> Option<(f64, f64)> {
            let cc = q0 - rad * rad;
            if self.inv_a.is_infinite() {
                return (cc <= 0.0).then_some((f64::NEG_INFINITY, f64::INFINITY));
            }
            let bh = -c * o.z; // half of the linear coefficient
            let disc = bh * bh - self.a * cc;
            if disc < 0.0 {
                return None;
            }
            let sq = disc.sqrt();
            Some(((-bh - sq) * self.inv_a, (-bh + sq) * self.inv_a))
        };
        let meet = |x: Option<(f64, f64)>, y: Option<(f64, f64)>| -> Option<(f64, f64)> {
            let (x, y) = (x?, y?);
            let lo = x.0.max(y.0);
            let hi = x.1.min(y.1);
            (lo <= hi).then_some((lo, hi))
        };
        // The cylinder h ∈ [r_c, L_f], ρ ≤ R.
        let mut hit = meet(slab(rc, lf), within(r));
        // The end h ∈ [0, r_c].
        let end = if rc == 0.0 {
            None
        } else if rc >= r {
            // Ball: the sphere of radius R about P + R O (its part above h = R lies in the
            // cylinder).
            let (ex, ey, ez) = (dx - r * o.x, dy - r * o.y, -r * o.z);
            // |(ex, ey, ez + s)|² ≤ R²
            let disc = r * r - ex * ex - ey * ey;
            (disc >= 0.0).then(|| {
                let sq = disc.sqrt();
                (-ez - sq, -ez + sq)
            })
        } else {
            // No part of the torus section reaches the line outside the slab h ∈ [0, r_c] or
            // the cylinder of radius R.
            let a = self.a;
            meet(slab(0.0, rc), within(r)).and_then(|(s0, s1)| {
                let f = |s: f64| {
                    let rho2 = (a * s * s - 2.0 * c * o.z * s + q0).max(0.0);
                    rho2.sqrt() - tool.radius_at(c + s * o.z)
                };
                convex_sublevel(f, s0, s1, 1e-9)
            })
        };
        hit = match (hit, end) {
            (Some(x), Some(y)) => Some((x.0.min(y.0), x.1.max(y.1))),
            (x, y) => x.or(y),
        };
        hit.filter(|h| h.0.is_finite() && h.1.is_finite())
            .map(|(lo, hi)| [p.z + lo, p.z + hi])
    }

    /// The interval of z (mm) where the vertical line through (x, y) crosses the shank: the
    /// cylinder of radius R about the axis above the flutes (h ≥ L_f), unbounded, as a
    /// vertical tool's shank is taken; its upper end may be +∞.
    pub fn shank_span(&self, x: f64, y: f64) -> Option<[f64; 2]> {
        let (p, o) = (&self.p, &self.o);
        let (dx, dy) = (x - p.x, y - p.y);
        let (r, lf) = (self.tool.radius(), self.tool.flute_length);
        let c = dx * o.x + dy * o.y;
        let q0 = dx * dx + dy * dy - c * c;
        // The s (= z − P_z) where h(s) = c + s O_z ≥ L_f.
        let (mut s0, mut s1) = if self.inv_oz.is_infinite() {
            if c < lf {
                return None;
            }
            (f64::NEG_INFINITY, f64::INFINITY)
        } else if o.z > 0.0 {
            ((lf - c) * self.inv_oz, f64::INFINITY)
        } else {
            (f64::NEG_INFINITY, (lf - c) * self.inv_oz)
        };
        // And ρ²(s) ≤ R².
        let cc = q0 - r * r;
        if self.inv_a.is_infinite() {
            if cc > 0.0 {
                return None;
            }
        } else {
            let bh = -c * o.z;
            let disc = bh * bh - self.a * cc;
            if disc < 0.0 {
                return None;
            }
            let sq = disc.sqrt();
            s0 = s0.max((-bh - sq) * self.inv_a);
            s1 = s1.min((-bh + sq) * self.inv_a);
        }
        (s0 < s1).then_some([p.z + s0, p.z + s1])
    }

    /// [`Pose::shank_span`] on a run of dexel lines of one grid row (as [`Pose::hits_row`]):
    /// `out[k]` for the line through x = `x0` + (i0 + k + ½)·`hx` and `y`, [`NO_HIT`] where
    /// the shank does not cross it. Without branches where the axis is neither vertical nor
    /// horizontal (vector instructions, `multiversion`).
    pub fn shank_row(&self, y: f64, x0: f64, hx: f64, i0: usize, out: &mut [[f64; 2]]) {
        if self.inv_a.is_infinite() || self.inv_oz.is_infinite() {
            for (k, h) in out.iter_mut().enumerate() {
                *h = self
                    .shank_span(x0 + (index_f64(i0 + k) + 0.5) * hx, y)
                    .unwrap_or(NO_HIT);
            }
            return;
        }
        shank_row(self, y, x0, hx, i0, out);
    }

    /// How far material on the vertical line through (x, y) reaches into the shank
    /// ([`Pose::shank_span`]; `span` is it), measured along the axis above the flutes' top (mm;
    /// 0: not at all); `intervals`: the line's material. For a vertical axis it is the
    /// material's top less the flutes' top, where the line passes within R of the axis.
    pub fn shank_depth(&self, x: f64, y: f64, span: [f64; 2], intervals: &[[f64; 2]]) -> f64 {
        let (p, o) = (&self.p, &self.o);
        let c = (x - p.x) * o.x + (y - p.y) * o.y;
        let lf = self.tool.flute_length;
        let mut depth = 0.0_f64;
        for iv in intervals {
            // (By comparisons: the ends are numbers, never NaN, as in [`smaller`].)
            let (a, b) = (larger(iv[0], span[0]), smaller(iv[1], span[1]));
            if b - a > super::dexel::MIN_CUT_MM {
                // h is linear in z: its largest value over [a, b] at one end.
                let h = |z: f64| c + (z - p.z) * o.z - lf;
                depth = larger(larger(depth, h(a)), h(b));
            }
        }
        depth
    }

    /// [`Pose::hit`] on a run of dexel lines of one grid row: `out[k]` for the line through
    /// x = `x0` + (i0 + k + ½)·`hx` and `y`, [`NO_HIT`] where the tool does not cross it.
    ///
    /// The same arithmetic as [`Pose::hit`], so the same crossings bit for bit (a test keeps
    /// them so); for a flat or ball-nose tool on a pose neither vertical nor horizontal it is
    /// written without branches (every candidate interval computed, the answer selected), which
    /// the compiler turns into vector instructions: the crossings are most of a tilted cut's
    /// work. Other tools and poses take [`Pose::hit`] line by line.
    pub fn hits_row(&self, y: f64, x0: f64, hx: f64, i0: usize, out: &mut [[f64; 2]]) {
        let tool = self.tool;
        let (r, rc) = (tool.radius(), tool.corner_radius);
        let ball = rc >= r;
        if !(ball || rc == 0.0) || self.inv_a.is_infinite() || self.inv_oz.is_infinite() {
            for (k, h) in out.iter_mut().enumerate() {
                *h = self
                    .hit(x0 + (index_f64(i0 + k) + 0.5) * hx, y)
                    .unwrap_or(NO_HIT);
            }
            return;
        }
        crossings_row(self, ball, y, x0, hx, i0, out);
    }
}

/// [`Pose::hits_row`]'s branch-free loop (a flat or ball-nose tool on a pose neither vertical nor
/// horizontal), compiled also for the vector instructions of newer processors and chosen by
/// what the processor running it has (`multiversion`): the same operations in the same order
/// on every path, so the same crossings bit for bit (Rust never fuses a product and a sum).
/// Its minima and maxima are comparisons ([`smaller`], [`larger`]; one instruction each in
/// vector registers), not `f64::min`/`max`, whose handling of NaN costs two more: nothing
/// here is NaN (the square roots' arguments are clamped at 0 first), and on numbers both give
/// the same value, so the same crossings as [`Pose::hit`]'s.
#[multiversion(targets("x86_64+avx512f+avx512vl", "x86_64+avx2", "aarch64+neon"))]
fn crossings_row(
    pose: &Pose,
    ball: bool,
    y: f64,
    x0: f64,
    hx: f64,
    i0: usize,
    out: &mut [[f64; 2]],
) {
    let tool = pose.tool;
    let (r, rc, lf) = (tool.radius(), tool.corner_radius, tool.flute_length);
    let (p, o, a, inv_a, inv_oz) = (pose.p, pose.o, pose.a, pose.inv_a, pose.inv_oz);
    let dy = y - p.y;
    for (k, h) in out.iter_mut().enumerate() {
        let dx = x0 + (index_f64(i0 + k) + 0.5) * hx - p.x;
        let c = dx * o.x + dy * o.y;
        let q0 = dx * dx + dy * dy - c * c;
        // The cylinder h ∈ [r_c, L_f], ρ ≤ R: the slab, the disc, their meet.
        let (t0, t1) = ((rc - c) * inv_oz, (lf - c) * inv_oz);
        let bh = -c * o.z;
        let disc = bh * bh - a * (q0 - r * r);
        let sq = larger(disc, 0.0).sqrt();
        let (w0, w1) = ((-bh - sq) * inv_a, (-bh + sq) * inv_a);
        let (c0, c1) = (larger(smaller(t0, t1), w0), smaller(larger(t0, t1), w1));
        let cylinder = disc >= 0.0 && c0 <= c1;
        // The ball about P + R O (flat end mill: none).
        let (ex, ey, ez) = (dx - r * o.x, dy - r * o.y, -r * o.z);
        let d2 = r * r - ex * ex - ey * ey;
        let sq2 = larger(d2, 0.0).sqrt();
        let (b0, b1) = (-ez - sq2, -ez + sq2);
        let sphere = ball && d2 >= 0.0;
        // The union of the parts that cross, each left out as a miss [∞, −∞] (which the
        // minimum and maximum leave out exactly): no part, a miss.
        let (m0, m1) = if cylinder {
            (c0, c1)
        } else {
            (f64::INFINITY, f64::NEG_INFINITY)
        };
        let (s0, s1) = if sphere {
            (b0, b1)
        } else {
            (f64::INFINITY, f64::NEG_INFINITY)
        };
        let (lo, hi) = (smaller(m0, s0), larger(m1, s1));
        // `lo` and `hi` finite, as `Pose::hit` asks, in half the instructions: where the
        // tool crosses, lo = +∞ comes only with hi = +∞ and hi = −∞ with lo = −∞ (lo ≤ hi or
        // a NaN, which both comparisons refuse), so these two tests tell the same; where no
        // part crosses, [lo, hi] is the miss and passes them, giving [∞, −∞] = NO_HIT.
        let any = lo > f64::NEG_INFINITY && hi < f64::INFINITY;
        *h = if any { [p.z + lo, p.z + hi] } else { NO_HIT };
    }
}

/// [`Pose::shank_row`]'s branch-free loop (an axis neither vertical nor horizontal), as
/// [`crossings_row`].
#[multiversion(targets("x86_64+avx512f+avx512vl", "x86_64+avx2", "aarch64+neon"))]
fn shank_row(pose: &Pose, y: f64, x0: f64, hx: f64, i0: usize, out: &mut [[f64; 2]]) {
    let tool = pose.tool;
    let (r, lf) = (tool.radius(), tool.flute_length);
    let (p, o, a, inv_a, inv_oz) = (pose.p, pose.o, pose.a, pose.inv_a, pose.inv_oz);
    let up = o.z > 0.0;
    let dy = y - p.y;
    for (k, h) in out.iter_mut().enumerate() {
        let dx = x0 + (index_f64(i0 + k) + 0.5) * hx - p.x;
        let c = dx * o.x + dy * o.y;
        let q0 = dx * dx + dy * dy - c * c;
        let t = (lf - c) * inv_oz;
        let (t0, t1) = if up {
            (t, f64::INFINITY)
        } else {
            (f64::NEG_INFINITY, t)
        };
        let bh = -c * o.z;
        let disc = bh * bh - a * (q0 - r * r);
        let sq = larger(disc, 0.0).sqrt();
        let (s0, s1) = (
            larger(t0, (-bh - sq) * inv_a),
            smaller(t1, (-bh + sq) * inv_a),
        );
        *h = if disc >= 0.0 && s0 < s1 {
            [p.z + s0, p.z + s1]
        } else {
            NO_HIT
        };
    }
}

/// A crossing that is none: `[∞, −∞]` (its lower end above its upper).
pub const NO_HIT: [f64; 2] = [f64::INFINITY, f64::NEG_INFINITY];

/// The interval of [s0, s1] where the convex function f ≤ 0, to within `tol`: golden-section
/// search for the minimum, then bisection for both ends.
fn convex_sublevel(f: impl Fn(f64) -> f64, s0: f64, s1: f64, tol: f64) -> Option<(f64, f64)> {
    const G: f64 = 0.618_033_988_749_894_8;
    let (mut a, mut b) = (s0, s1);
    let (mut x1, mut x2) = (b - G * (b - a), a + G * (b - a));
    let (mut f1, mut f2) = (f(x1), f(x2));
    let mut guard = 0;
    while b - a > tol && guard < 200 {
        if f1 <= f2 {
            b = x2;
            (x2, f2) = (x1, f1);
            x1 = b - G * (b - a);
            f1 = f(x1);
        } else {
            a = x1;
            (x1, f1) = (x2, f2);
            x2 = a + G * (b - a);
            f2 = f(x2);
        }
        guard += 1;
    }
    let m = 0.5 * (a + b);
    if f(m) > 0.0 {
        return None;
    }
    let root = |mut inside: f64, mut outside: f64| {
        if f(outside) <= 0.0 {
            return outside;
        }
        let mut guard = 0;
        while (outside - inside).abs() > tol && guard < 200 {
            let mid = 0.5 * (inside + outside);
            if f(mid) <= 0.0 {
                inside = mid;
            } else {
                outside = mid;
            }
            guard += 1;
        }
        inside
    };
    Some((root(m, s0), root(m, s1)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn membership(t: &Tool, p: &Vector3<f64>, o: &Vector3<f64>, x: &Vector3<f64>) -> bool {
        let d = x - p;
        let h = d.dot(o);
        let rho = (d - h * o).norm();
        (0.0..=t.flute_length).contains(&h) && rho <= t.radius_at(h)
    }

    /// A row of crossings is the crossings line by line, bit for bit: for every shape, on
    /// vertical, horizontal and tilted poses, over rows that pass through, beside and far from
    /// the tool (whichever vector instructions this processor runs the row with).
    #[test]
    fn a_row_of_crossings_is_the_crossings_line_by_line() {
        let mut rnd = crate::test_rng(7);
        let (x0, hx) = (-20.0, 0.1);
        let mut out = vec![[0.0; 2]; 400];
        let (mut crossed, mut missed) = (0, 0);
        for tool in [
            Tool::new(10.0, 0.0, 20.0, 3).unwrap(),
            Tool::new(10.0, 5.0, 20.0, 2).unwrap(),
            Tool::new(10.0, 2.0, 20.0, 4).unwrap(),
        ] {
            for case in 0..120 {
                let o = match case % 6 {
                    0 => Vector3::z(),
                    1 => Vector3::new(rnd() - 0.5, rnd() - 0.5, 0.0).normalize(),
                    2 => Vector3::new(rnd() - 0.5, rnd() - 0.5, -0.2 - rnd()).normalize(),
                    _ => Vector3::new(rnd() - 0.5, rnd() - 0.5, 0.1 + rnd()).normalize(),
                };
                let p = Vector3::new(10.0 * (rnd() - 0.5), 10.0 * (rnd() - 0.5), rnd());
                let pose = Pose::new(&tool, &p, &o);
                let y = p.y + 30.0 * (rnd() - 0.5);
                let i0 = (rnd() * 20.0) as usize;
                pose.hits_row(y, x0, hx, i0, &mut out);
                for (k, h) in out.iter().enumerate() {
                    let one = pose.hit(x0 + ((i0 + k) as f64 + 0.5) * hx, y);
                    assert_eq!(
                        h.map(f64::to_bits),
                        one.unwrap_or(NO_HIT).map(f64::to_bits),
                        "{tool:?} tip {p:?} axis {o:?} line {}",
                        i0 + k
                    );
                    if one.is_some() {
                        crossed += 1;
                    } else {
                        missed += 1;
                    }
                }
            }
        }
        assert!(
            crossed > 10_000 && missed > 10_000,
            "{crossed} crossed, {missed} missed"
        );
    }

    /// The line hit agrees with point membership for every shape and many tilted poses.
    #[test]
    fn line_hit_agrees_with_membership() {
        let mut rnd = crate::test_rng(11);
        for tool in [
            Tool::new(10.0, 0.0, 20.0, 3).unwrap(),
            Tool::new(10.0, 5.0, 20.0, 2).unwrap(),
            Tool::new(10.0, 2.0, 20.0, 4).unwrap(),
        ] {
            for case in 0..400 {
                // A quarter of the poses with a horizontal axis (O_z = 0).
                let oz = if case % 4 == 0 { 0.0 } else { 0.3 + rnd() };
                let o = Vector3::new(rnd() - 0.5, rnd() - 0.5, oz).normalize();
                let p = Vector3::new(rnd(), rnd(), rnd());
                let (x, y) = (p.x + 16.0 * (rnd() - 0.5), p.y + 16.0 * (rnd() - 0.5));
                let hit = tool.line_hit(&p, &o, x, y);
                for k in 0..400 {
                    let z = p.z - 5.0 + 30.0 * k as f64 / 400.0;
                    let inside = membership(&tool, &p, &o, &Vector3::new(x, y, z));
                    let by_hit = hit.is_some_and(|[lo, hi]| z >= lo - 1e-7 && z <= hi + 1e-7);
                    let near =
                        hit.is_some_and(|[lo, hi]| (z - lo).abs() < 1e-6 || (z - hi).abs() < 1e-6);
                    assert!(inside == by_hit || near, "{tool:?} z {z} hit {hit:?}");
                }
            }
        }
    }

    /// The shank's depth against sampling the line: the largest h − L_f over the points of the
    /// line's material that lie within R of the axis and above the flutes (h ≥ L_f).
    #[test]
    fn shank_depth_agrees_with_sampling_the_line() {
        let mut rnd = crate::test_rng(12);
        let tool = Tool::new(6.0, 3.0, 12.0, 2).unwrap();
        let mut reached = 0;
        for case in 0..600 {
            // A sixth vertical, a sixth horizontal.
            let o = match case % 6 {
                0 => Vector3::z(),
                1 => Vector3::new(rnd() - 0.5, rnd() - 0.5, 0.0).normalize(),
                _ => Vector3::new(rnd() - 0.5, rnd() - 0.5, 0.2 + rnd()).normalize(),
            };
            let p = Vector3::new(rnd(), rnd(), rnd());
            let pose = Pose::new(&tool, &p, &o);
            let (x, y) = (p.x + 12.0 * (rnd() - 0.5), p.y + 12.0 * (rnd() - 0.5));
            // Material: two intervals somewhere on z ∈ [−10, 40].
            let mut z: Vec<f64> = (0..4).map(|_| -10.0 + 50.0 * rnd()).collect();
            z.sort_by(f64::total_cmp);
            let intervals = [[z[0], z[1]], [z[2], z[3]]];
            let depth = pose
                .shank_span(x, y)
                .map_or(0.0, |span| pose.shank_depth(x, y, span, &intervals));
            // The row form gives the same span, bit for bit.
            let mut row = [NO_HIT; 1];
            pose.shank_row(y, x - 0.5 * 0.1, 0.1, 0, &mut row);
            assert_eq!(
                pose.shank_span(x - 0.05 + 0.05, y).unwrap_or(NO_HIT),
                row[0]
            );
            let mut sampled = 0.0_f64;
            let n = 20_000;
            for k in 0..=n {
                let zz = -10.0 + 50.0 * k as f64 / n as f64;
                if !intervals.iter().any(|iv| zz >= iv[0] && zz <= iv[1]) {
                    continue;
                }
                let q = Vector3::new(x, y, zz) - p;
                let h = q.dot(&o);
                let rho = (q - o * h).norm();
                if rho <= 3.0 && h >= 12.0 {
                    sampled = sampled.max(h - 12.0);
                }
            }
            // The sampling's step is 2.5e-3 mm in z.
            assert!(
                (depth - sampled).abs() < 5e-3,
                "case {case}: {depth} against {sampled} (o {o:?})"
            );
            reached += usize::from(depth > 0.0);
        }
        assert!(reached > 50, "{reached}");
    }

    #[test]
    fn vertical_bottom_matches_the_profile() {
        let t = Tool::new(10.0, 2.0, 20.0, 4).unwrap();
        let o = Vector3::z();
        let p = Vector3::zeros();
        for k in 0..50 {
            let d = 5.0 * k as f64 / 50.0;
            let [lo, hi] = t.line_hit(&p, &o, d, 0.0).unwrap();
            assert!((lo - t.bottom(d)).abs() < 1e-9 && (hi - 20.0).abs() < 1e-12);
        }
    }
}
