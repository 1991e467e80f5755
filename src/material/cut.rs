//! The cut: the tool's swept volume removes material from the dexels, sample by sample along
//! the path, and each sample records what the tool engaged.
//!
//! **Samples.** Every CL move (from point k−1 to point k) is divided into
//! ⌈(|ΔP| + L_f·Δθ)/step⌉ equal steps, where Δθ is the angle the tool axis turns and `step`
//! the sample step (fixed by the grid, [`super::CutOptions`]): a sampling of the *path*, not of
//! the solver's stations, so the result is a piecewise-constant function of the path that any
//! station set can query.
//!
//! **Removal, vertical tool** (the axis is +Z at both ends of the move: exact). The tool moves
//! straight from P₀ to P₁. A dexel at (x, y) meets it while the horizontal distance d(t) of
//! the axis is at most R, which holds on one interval t ∈ [t_a, t_b] (d² is quadratic in t). At
//! each t the tool covers `[z(t) + f(d(t)), z(t) + L_f]` of the line (f: [`Tool::bottom`]);
//! these intervals move continuously with t, so their union is the single interval
//! `[min g, max (z + L_f)]` with `g(t) = z(t) + f(d(t))`. z is linear and f(d(t)) convex (f
//! is convex and non-decreasing, d(t) convex), so g is convex: its minimum lies at an end for
//! a flat end mill or a plunge, at the closest approach for a level move, on the capsule the
//! ball sweeps for a ball-nose tool on a ramp (in closed form, `Capsule::bottom`), and is found
//! by golden-section search (to 1e-9 mm) for a bull-nose tool on a ramp. Each dexel is thus
//! cut exactly. A level step that starts where the step before it (a vertical tool's) ended
//! leaves out the cells behind its start, whose sweep is the tool at its start, which the step
//! before removed ([`behind_cells`]; their shank is still read): on NX's Röders finish, mostly
//! level moves of 0.75 mm steps, two fifths of its cells, the same check byte for byte. A
//! rising ramp does so too where no material stands above the start's flutes' top.
//!
//! **Removal, tilted tool** (sound, conservative). The tool passes through poses at
//! t = j/m (P linear, the axis interpolated and normalised) with m chosen so that no point of
//! the cutting part moves more than δ between poses ([`pose_spacing`]). Each pose's crossing
//! with a dexel line is exact ([`Tool::line_hit`]); consecutive poses that both cross a dexel
//! are joined into `[min lo, max hi]`. The union of the continuous family of crossings between
//! two such poses is connected and contains both (for a translation exactly: the tool is
//! convex, so the line meets it on one interval of t), so the joined interval lies inside the
//! true swept volume: material is never removed that the tool does not reach. What may be left
//! is the sliver the swept surface bulges past the chord between poses, a scallop of depth
//! δ²/(8ρ) for a tool surface of smallest curvature radius ρ: the corner radius r_c of a ball
//! or bull-nose tool (whose lower surface is smooth), so δ = √(8 ρ ε) keeps the scallop at
//! ε = h/8 (h the cell size, [`SCALLOP_PER_CELL`]), well inside the grid's own error of h/2 at
//! a wall; a flat end mill's rim is a sharp edge (ρ = 0), so there δ = h/2. A scallop can only
//! make the engagement look larger, hence the feed lower (safe).
//!
//! **Shared poses.** A tilted step's last pose is the next step's first (the step ends are the
//! exact sample points, `step_of_move`): its crossings, computed for the one step, are kept
//! (`SharedPose`) and read by the next instead of being computed again; a step has two or
//! three poses at the default sample step, so this is a third to a half of the crossings.
//!
//! **Which dexels.** Each pose's tool lies inside the cylinder of radius R about its axis
//! from h = 0 to L_f, so its XY footprint lies inside the rectangle of half-width R along
//! the projected axis that reaches only R·|O_z| past its ends (`axis_row`), and within R of
//! the axis segment from its corner centre (r_c above the tip) to the flutes' top, so inside
//! the capsule of radius R about that segment projected (`Footprint::of_pose`; for a
//! ball-nose tool tilted far from the vertical, as on the LinuxCNC impeller, the capsule
//! about the tip's end held a strip behind the ball that no tool point reaches: leaving it
//! out took 7 % of the check's instructions, 19.05 → 17.78 G). Each grid row visits only
//! the cells of that capsule ([`capsule_row`]) and rectangle, pose by pose (tilted), or of
//! the capsule about the segment P₀P₁ (vertical). A cell outside the footprint is one the
//! tool does not cross, so skipping it changes nothing. The work of a step is thus its
//! footprint's cells times its poses, not its bounding box's. The shank check at a tilted
//! step's end pose reads only the lines its shank may cross: the shank (radius R about the
//! axis above the flutes' top T) lies, seen from above, in the half-infinite strip of
//! half-width R from T along the projected axis, lengthened by R·|O_z| behind T
//! (`shank_shadow`); elsewhere its depth is 0. (A tool buried beyond its flutes has material
//! above them on every line they cross, but its shank reaches only the lines near their top
//! end: on the LinuxCNC impeller, reading only those took 9 % of the instructions off the
//! check, 21.3 → 19.4 G.)
//!
//! **Where the work goes** (the LinuxCNC impeller at 0.1 mm, 9,344 steps, counted
//! 2026-11-27). The rows' cells of all steps are 66.2 M (step, dexel) pairs, 24.6 M of which
//! (37 %) remove material; their poses' crossings are 161.6 M, 99.3 M computed and 62.4 M
//! read from the shared pose. Of the crossings, 25 % take material, 64 % lie in a gap of their
//! dexel (the tunnel the poses before cut, under the material the tool is buried in), 8.6 %
//! above the dexel's top and 2 % miss. So air is mostly not above the material: blocks of
//! 4 × 4 dexels whose highest material lies below every pose would hold 6.6 % of the
//! crossings (8 × 8: 5.3 %, 16 × 16: 3.6 %); blocks with a range of z free on all their
//! dexels that holds every pose's crossings, 35 % (25 %, 13 %), of which bounds from the tool's
//! supporting planes at the block's centre find 32 % (21 %, 9 %). Built at 4 × 4 (the same
//! check, byte for byte), that skip tested 4.5 M blocks and skipped 21 % of them, but those lie
//! mostly behind the tool, reached by the shared first pose: it saved 8.6 M of the 99.3 M
//! computed crossings (the rest a copy, and a skipped end pose's crossings computed again by the
//! next step), while the tests cost more than all it saved (12.6 → 17.4 G instructions, Valgrind
//! with AVX2). Not kept. Nor would sweeping the ball exactly (one capsule per step, as a
//! vertical tool's) spare the poses there: of the crossings that take material, the flute
//! cylinder's part takes some in 76 %, the ball alone in 24 %. Time, by `perf` on two threads
//! (AVX-512): `crossings_row` 24 %, `cut_band`'s own loops (spans, runs, the removal tests,
//! the shank's candidates) 33 %, the removals 16 % (heap dexels half of it), the shank's rows
//! 3 %, the footprints' rows 4 %; the main thread's reading before the cut and the final
//! volume, freeing and output after it, 5 %.
//!
//! **Engagement of a sample** (the tool at the step's end pose P, axis O, feed direction f):
//! - removed volume ΔV (mm³) and engaged cross-section `A = ΔV / Δs` (mm²) normal to the feed,
//!   Δs the tip's travel in the step: the material removal rate is `A·V`;
//! - axial depth a_p: the highest removed material above the tip along O;
//! - radial engagement a_e = min(A / a_p, D): the width of a cut of uniform depth (exact for a
//!   flat end mill in a slot, a side step or a pocket floor);
//! - engagement angle φ of a side cut (the material reaching the tool's periphery on one side,
//!   as in slots, side steps and pocket floors): `φ = acos(1 − 2 a_e/D)` (a slot 180°, a
//!   half-width side step 90°);
//! - a plunge (f along O, |O × f| < 1e-9 |f|): a_e is the diameter of the disc of area A,
//!   φ = 360°.

use multiversion::multiversion;
use nalgebra::Vector3;
use rayon::prelude::*;

use super::dexel::{Dexels, TILE, index_f64, larger};
use super::tool::{NO_HIT, Pose, Tool};
use crate::base::angle_between;
use crate::toolpath::{Feed, Toolpath};

/// What the tool engaged over one sample step.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Sample {
    /// The CL point the move ends at (index into [`Toolpath::points`]).
    pub point: usize,
    /// The step's fractions of that move, `[t0, t1]` ⊂ [0, 1].
    pub t: [f64; 2],
    /// Source line of the CL point the move ends at.
    pub line: usize,
    /// Δs: the tool tip's travel in the step, mm.
    pub length: f64,
    /// ΔV: material removed, mm³.
    pub removed: f64,
    /// A = ΔV/Δs, mm² (0 where the tip does not travel).
    pub area: f64,
    /// a_p, mm.
    pub axial_depth: f64,
    /// a_e, mm.
    pub radial_engagement: f64,
    /// φ, degrees.
    pub engagement_angle: f64,
    /// The move is a rapid (G0 / `RAPID`).
    pub rapid: bool,
    /// The move's programmed feed, mm/s (`None`: rapid, inverse-time or none).
    pub programmed_feed: Option<f64>,
    /// How far material reaches above the flutes' top where the tool passes, mm (0: nowhere):
    /// there the shank, above the flute length, runs into it. On a vertical tool's step, the
    /// material above the flutes' top over the step's whole sweep; on a tilted tool's, the
    /// material inside the shank (the cylinder of radius R above the flutes, along the axis)
    /// at the step's end pose, on the lines its flutes cross, measured along the axis
    /// ([`Pose::shank_depth`]).
    pub shank_depth: f64,
}

/// Per-step sums over the dexels a step cut.
#[derive(Debug, Clone, Copy)]
struct Acc {
    length: f64,
    axial_max: f64,
    /// The most material left above the flutes' top over the step's cells (vertical tool).
    shank: f64,
}

impl Acc {
    const ZERO: Acc = Acc {
        length: 0.0,
        axial_max: f64::NEG_INFINITY,
        shank: 0.0,
    };
    fn join(self, o: Acc) -> Acc {
        Acc {
            length: self.length + o.length,
            axial_max: self.axial_max.max(o.axial_max),
            shank: self.shank.max(o.shank),
        }
    }
}

/// One step of a move: from tip `p0`, axis `o0` to `p1`, `o1`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Step {
    pub p0: Vector3<f64>,
    pub p1: Vector3<f64>,
    pub o0: Vector3<f64>,
    pub o1: Vector3<f64>,
}

impl Step {
    /// The axis is vertical (+Z) at both ends: removal is exact.
    fn vertical(&self) -> bool {
        (self.o0 - Vector3::z()).norm() < 1e-12 && (self.o1 - Vector3::z()).norm() < 1e-12
    }

    /// How far any point of the cutting part moves: |ΔP| + L_f·Δθ (an upper bound), mm.
    pub fn extent(&self, tool: &Tool) -> f64 {
        (self.p1 - self.p0).norm() + tool.flute_length * angle_between(&self.o0, &self.o1)
    }

    /// Poses of a tilted step (at least 2), so that no point moves more than `delta` between.
    pub fn poses(&self, tool: &Tool, delta: f64) -> usize {
        if self.vertical() {
            1
        } else {
            ((self.extent(tool) / delta).ceil() as usize).max(1) + 1
        }
    }

    /// The pose at fraction `t`: at t = 1 exactly the step's end, so that the next step's
    /// first pose is the same (shared poses, module doc).
    fn pose(&self, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let o = (self.o0 * (1.0 - t) + self.o1 * t).normalize();
        let p = if t == 1.0 {
            self.p1
        } else {
            self.p0 + (self.p1 - self.p0) * t
        };
        (p, o)
    }

    /// The XY rectangle `[x0, y0, x1, y1]` the step's tool covers (with `poses` poses).
    pub fn bounds(&self, tool: &Tool, poses: usize) -> [f64; 4] {
        let r = tool.radius();
        let mut b = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        let mut add = |p: Vector3<f64>| {
            b[0] = b[0].min(p.x - r);
            b[1] = b[1].min(p.y - r);
            b[2] = b[2].max(p.x + r);
            b[3] = b[3].max(p.y + r);
        };
        if poses <= 1 {
            add(self.p0);
            add(self.p1);
        } else {
            for j in 0..poses {
                let (p, o) = self.pose(j as f64 / (poses - 1) as f64);
                add(p);
                add(p + o * tool.flute_length);
            }
        }
        b
    }
}

/// The grid cells (i0..=i1, j0..=j1) that rectangle `b` covers, if any.
pub(crate) fn cell_range(d: &Dexels, b: &[f64; 4]) -> Option<(usize, usize, usize, usize)> {
    let i0 = ((b[0] - d.x0) / d.hx - 0.5).ceil().max(0.0);
    let j0 = ((b[1] - d.y0) / d.hy - 0.5).ceil().max(0.0);
    let i1 = ((b[2] - d.x0) / d.hx - 0.5).floor().min(d.nx as f64 - 1.0);
    let j1 = ((b[3] - d.y0) / d.hy - 0.5).floor().min(d.ny as f64 - 1.0);
    (i0 <= i1 && j0 <= j1).then_some((i0 as usize, i1 as usize, j0 as usize, j1 as usize))
}

/// The z interval a vertical tool sweeps on the dexel line through (x, y) moving straight
/// from `p0` to `p1` (module doc), if it reaches the line.
pub fn vertical_sweep(
    tool: &Tool,
    p0: &Vector3<f64>,
    p1: &Vector3<f64>,
    x: f64,
    y: f64,
) -> Option<[f64; 2]> {
    let r = tool.radius();
    let (ax, ay) = (p0.x - x, p0.y - y);
    let (dx, dy) = (p1.x - p0.x, p1.y - p0.y);
    let qa = dx * dx + dy * dy;
    let qb = ax * dx + ay * dy; // half the linear coefficient
    let qc = ax * ax + ay * ay;
    let (ta, tb) = if qa <= 1e-24 {
        if qc > r * r {
            return None;
        }
        (0.0, 1.0)
    } else {
        let (hit, ta, tb) = reach(qa, qb, qc, r);
        if !hit {
            return None;
        }
        (ta, tb)
    };
    let dz = p1.z - p0.z;
    let z = |t: f64| p0.z + dz * t;
    let dist = |t: f64| (qa * t * t + 2.0 * qb * t + qc).max(0.0).sqrt().min(r);
    let g = |t: f64| z(t) + tool.bottom(dist(t));
    let lo = if tool.corner_radius == 0.0 || qa <= 1e-24 {
        g(ta).min(g(tb))
    } else if dz == 0.0 {
        g((-qb / qa).clamp(ta, tb))
    } else if tool.corner_radius >= r {
        // A ball: the balls about P(t) + R ẑ sweep the capsule about their centres' segment.
        match Capsule::of_ball(p0, p1, r).bottom(x, y) {
            (lo, true) => lo,
            _ => golden_min(g, ta, tb),
        }
    } else {
        golden_min(g, ta, tb)
    };
    Some([lo, z(ta).max(z(tb)) + tool.flute_length])
}

/// A run of cells `a..=b` of a grid row, if not empty.
type Run = Option<(usize, usize)>;

/// The cells `ia..=ib` of the row at `y` split into those behind a step's start `p0` (moving
/// to `p1`, a vertical tool) and the rest, each a run if not empty: `(behind, rest)`.
///
/// Behind the start (the closest point of the move to the cell's line is its start, t ≤ 0:
/// (p0 − x)·(p1 − p0) ≥ 0 seen from above), the distance d(t) from the line only grows along
/// the step. On a level step the sweep on the line is then the tool's at its start
/// ([`vertical_sweep`]: the lower end z + f(d(t)) least at t = 0, the upper end p0.z + L_f);
/// on a rising ramp its lower end is the start's too (z and f(d(t)) both grow) and its upper
/// end is higher. Where the step before it was a vertical tool's ending at `p0`, that step's
/// sweep on the line holds the tool there (its end pose), so it has removed all of the start's
/// interval: cutting again takes nothing on a level step, and on a rising ramp only material
/// above the start's flutes' top, p0.z + L_f (at most a sliver of rounding besides, which a
/// removal leaves, [`super::dexel::MIN_CUT_MM`]). The cells are split at the line x where
/// (p0 − x)·Δ = 0; a cell on it either way is right (its sweep there is the start's to
/// rounding).
fn behind_cells(
    p0: &Vector3<f64>,
    p1: &Vector3<f64>,
    y: f64,
    (x0, hx): (f64, f64),
    (ia, ib): (usize, usize),
) -> (Run, Run) {
    let (dx, dy) = (p1.x - p0.x, p1.y - p0.y);
    let ay = p0.y - y;
    if dx == 0.0 {
        // (p0 − x)·Δ = ay·dy on the whole row.
        return if ay * dy >= 0.0 {
            (Some((ia, ib)), None)
        } else {
            (None, Some((ia, ib)))
        };
    }
    // The cell whose centre is the last (dx > 0) or the first (dx < 0) behind: x ≤ xc or
    // x ≥ xc, xc = p0.x + ay·dy/dx.
    let xc = p0.x + ay * dy / dx;
    let k = ((xc - x0) / hx - 0.5).clamp(-1.0, 1e15);
    let run = |a: usize, b: usize| (a <= b).then_some((a, b));
    if dx > 0.0 {
        // Behind: the cells up to floor(k).
        let last = k.floor();
        if last < ia as f64 {
            return (None, Some((ia, ib)));
        }
        let last = (last as usize).min(ib);
        (Some((ia, last)), run(last + 1, ib))
    } else {
        // Behind: the cells from ceil(k).
        let first = k.ceil();
        if first > ib as f64 {
            return (None, Some((ia, ib)));
        }
        let first = (first.max(0.0) as usize).max(ia);
        (
            Some((first, ib)),
            first.checked_sub(1).and_then(|e| run(ia, e)),
        )
    }
}

/// [`vertical_sweep`]'s lower end on a run of dexel lines of one grid row, for a level move
/// (p0.z = p1.z, not on the spot) of a flat or ball-nose tool: `out[k]` for the line through
/// x = `x0` + (ia + k + ½)·`hx` and `y`, ∞ where the tool does not reach it. The same
/// operations as [`vertical_sweep`]'s (the closest approach, clamped to the move), so the same
/// values bit for bit (test), written without branches so that the compiler vectorises them:
/// a 3-axis program's level moves are most of its check.
#[multiversion(targets("x86_64+avx512f+avx512vl", "x86_64+avx2", "aarch64+neon"))]
fn level_row(
    tool: &Tool,
    p0: &Vector3<f64>,
    p1: &Vector3<f64>,
    y: f64,
    (x0, hx): (f64, f64),
    ia: usize,
    out: &mut [f64],
) {
    let r = tool.radius();
    let (dx, dy) = (p1.x - p0.x, p1.y - p0.y);
    let ay = p0.y - y;
    let qa = dx * dx + dy * dy;
    for (k, o) in out.iter_mut().enumerate() {
        let x = x0 + (index_f64(ia + k) + 0.5) * hx;
        let ax = p0.x - x;
        let qb = ax * dx + ay * dy;
        let qc = ax * ax + ay * ay;
        let (hit, _, _) = reach(qa, qb, qc, r);
        let t = (-qb / qa).clamp(0.0, 1.0);
        let d = (qa * t * t + 2.0 * qb * t + qc).max(0.0).sqrt().min(r);
        *o = if hit {
            p0.z + tool.bottom(d)
        } else {
            f64::INFINITY
        };
    }
}

/// [`vertical_sweep`] on a run of dexel lines of one grid row, for a ramp (p0.z ≠ p1.z, not a
/// plunge) of a flat or ball-nose tool: `out[k]` for the line through x = `x0` + (ia + k +
/// ½)·`hx` and `y`, [`NO_HIT`] where the tool does not reach it, a NaN lower end where the
/// capsule's closed form needs [`vertical_sweep`]'s golden-section search (it did not meet the
/// line in rounding). The same operations as [`vertical_sweep`] (and [`Capsule::bottom`]), so the
/// same values bit for bit (test), without branches (vectorised; multiversion).
#[multiversion(targets("x86_64+avx512f+avx512vl", "x86_64+avx2", "aarch64+neon"))]
fn ramp_row(
    tool: &Tool,
    p0: &Vector3<f64>,
    p1: &Vector3<f64>,
    y: f64,
    (x0, hx): (f64, f64),
    ia: usize,
    out: &mut [[f64; 2]],
) {
    let (r, rc, lf) = (tool.radius(), tool.corner_radius, tool.flute_length);
    let ball = rc >= r;
    let (dx, dy, dz) = (p1.x - p0.x, p1.y - p0.y, p1.z - p0.z);
    let ay = p0.y - y;
    let qa = dx * dx + dy * dy;
    let capsule = Capsule::of_ball(p0, p1, r);
    for (k, o) in out.iter_mut().enumerate() {
        let x = x0 + (index_f64(ia + k) + 0.5) * hx;
        let ax = p0.x - x;
        let qb = ax * dx + ay * dy;
        let qc = ax * ax + ay * ay;
        let (hit, ta, tb) = reach(qa, qb, qc, r);
        let (za, zb) = (p0.z + dz * ta, p0.z + dz * tb);
        let hi = za.max(zb) + lf;
        // A flat end mill: the lower end at an end of the reach (vertical_sweep's g there).
        let flat = za.min(zb);
        // A ball: the capsule's bottom on the line.
        let (sphere, closed) = capsule.bottom(x, y);
        let lo = if !ball {
            flat
        } else if closed {
            sphere
        } else {
            f64::NAN
        };
        *o = if hit { [lo, hi] } else { NO_HIT };
    }
}

/// Where the vertical line through (x, y) comes within R of a move's tip path from `p0` (t = 0)
/// to `p1` (t = 1), seen from above: the quadratic |A + t Δ|² = qa t² + 2 qb t + qc (A the
/// tip's start minus (x, y), Δ the move, both horizontal; qa > 0) against R², clipped to the
/// move. Whether it does, and the range [ta, tb] of t. Without branches (the rows'
/// vectorised loops share it with [`vertical_sweep`], which must give their values).
#[inline(always)]
fn reach(qa: f64, qb: f64, qc: f64, r: f64) -> (bool, f64, f64) {
    let disc = qb * qb - qa * (qc - r * r);
    let sq = disc.max(0.0).sqrt();
    let (t0, t1) = ((-qb - sq) / qa, (-qb + sq) / qa);
    let (ta, tb) = (t0.max(0.0), t1.min(1.0));
    (disc >= 0.0 && ta <= tb, ta, tb)
}

/// The capsule of radius `r` about a segment (not vertical): the swept volume of a ball-nose
/// tool's ball moving straight, whose lowest point on a vertical line is the tool's lower
/// surface there on a ramp (what golden-section search finds to 1e-12 of the range, at some
/// sixty evaluations of the tool's profile: half of a 3-axis finishing program's check).
struct Capsule {
    c0: Vector3<f64>,
    c1: Vector3<f64>,
    r: f64,
    /// A millimetre below the capsule's lowest point: where the ray up the line starts.
    z0: f64,
    ba: Vector3<f64>,
    baba: f64,
    /// a = ΔX² + ΔY² of the segment (> 0).
    a: f64,
}

impl Capsule {
    /// The capsule the ball of a ball-nose tool of radius `r` sweeps moving its tip from `p0`
    /// to `p1`: about its centres' segment.
    #[inline(always)]
    fn of_ball(p0: &Vector3<f64>, p1: &Vector3<f64>, r: f64) -> Capsule {
        let (c0, c1) = (
            Vector3::new(p0.x, p0.y, p0.z + r),
            Vector3::new(p1.x, p1.y, p1.z + r),
        );
        let ba = c1 - c0;
        let baba = ba.dot(&ba);
        Capsule {
            c0,
            c1,
            r,
            z0: c0.z.min(c1.z) - r - 1.0,
            ba,
            baba,
            a: baba - ba.z * ba.z,
        }
    }

    /// The lowest z at which the vertical line through (x, y) enters the capsule, and whether
    /// the closed form found it (not where the line misses the capsule, in rounding): a ray
    /// from below, met first by the cylinder about the segment's line between the end planes,
    /// else by the end sphere on the side where it met that cylinder (the capsule is convex).
    /// Without branches, for the rows' vectorised loop.
    #[inline(always)]
    fn bottom(&self, x: f64, y: f64) -> (f64, bool) {
        let (ba, baba, a, r, z0) = (&self.ba, self.baba, self.a, self.r, self.z0);
        let oa = Vector3::new(x - self.c0.x, y - self.c0.y, z0 - self.c0.z);
        let (bard, baoa, rdoa, oaoa) = (ba.z, ba.dot(&oa), oa.z, oa.dot(&oa));
        // The infinite cylinder: a s² + 2 b s + c = 0.
        let b = baba * rdoa - baoa * bard;
        let c = baba * oaoa - baoa * baoa - r * r * baba;
        let h = b * b - a * c;
        let s = (-b - h.max(0.0).sqrt()) / a;
        let along = baoa + s * bard;
        let body = along > 0.0 && along < baba;
        // An end sphere: |oc + s ẑ|² = r².
        let (ox, oy, oz) = if along <= 0.0 {
            (oa.x, oa.y, oa.z)
        } else {
            (x - self.c1.x, y - self.c1.y, z0 - self.c1.z)
        };
        let (b2, c2) = (oz, ox * ox + oy * oy + oz * oz - r * r);
        let h2 = b2 * b2 - c2;
        let cap = z0 - b2 - h2.max(0.0).sqrt();
        let closed = h >= 0.0 && a > 0.0 && (body || h2 >= 0.0);
        (if body { z0 + s } else { cap }, closed)
    }
}

/// The minimum of a convex function on [a, b] (golden-section search, to 1e-12 of the range,
/// checked against both ends).
fn golden_min(g: impl Fn(f64) -> f64, a0: f64, b0: f64) -> f64 {
    const G: f64 = 0.618_033_988_749_894_8;
    let (mut a, mut b) = (a0, b0);
    let (mut x1, mut x2) = (b - G * (b - a), a + G * (b - a));
    let (mut f1, mut f2) = (g(x1), g(x2));
    for _ in 0..80 {
        if b - a <= 1e-12 * (b0 - a0) {
            break;
        }
        if f1 <= f2 {
            b = x2;
            (x2, f2) = (x1, f1);
            x1 = b - G * (b - a);
            f1 = g(x1);
        } else {
            a = x1;
            (x1, f1) = (x2, f2);
            x2 = a + G * (b - a);
            f2 = g(x2);
        }
    }
    f1.min(f2).min(g(a0)).min(g(b0))
}

/// The scallop a tilted tool's sampled poses may leave, as a fraction of the cell size
/// (module doc).
pub const SCALLOP_PER_CELL: f64 = 0.125;

/// δ, mm: how far a point of the cutting part may move between two poses of a tilted step on
/// cells of `cell` mm: √(8 r_c ε) with ε = [`SCALLOP_PER_CELL`]·h, at least h/2 (module doc).
pub fn pose_spacing(tool: &Tool, cell: f64) -> f64 {
    (8.0 * tool.corner_radius * SCALLOP_PER_CELL * cell)
        .sqrt()
        .max(0.5 * cell)
}

/// The x interval where the line at `y` meets the capsule of radius `r` about the segment
/// from `a` to `b` (XY), if it does: the two end discs and the band between them, each a
/// convex set meeting the line in one interval, joined (they overlap). Widened by 1e-9 mm so
/// that a cell the tool only touches is still visited.
pub fn capsule_row(a: [f64; 2], b: [f64; 2], r: f64, y: f64) -> Option<[f64; 2]> {
    Footprint::new(a, b, r, f64::INFINITY).capsule_row(y)
}

/// The x interval where the line at `y` meets the rectangle of half-width `r` about the
/// segment from `a` to `b` (XY), lengthened by `ends` at both ends, if it does (widened by
/// 1e-9 mm as [`capsule_row`]). A tilted tool (unit axis O, tip at `a`, flute end at `b`)
/// lies in it with `ends` = R·|O_z|: a point of the disc of radius R normal to O projects
/// onto the axis' XY direction û at most R·|O_z| = R·|(û, 0) − ((û, 0)·O) O| from its centre.
/// `None` also where `a` = `b` (no direction: no bound).
#[cfg(test)]
fn axis_row(a: [f64; 2], b: [f64; 2], r: f64, ends: f64, y: f64) -> Option<[f64; 2]> {
    Footprint::new(a, b, r, ends).axis_row(y)
}

/// How much wider than the shank's shadow ([`shank_shadow`]) its lines are read, mm: a
/// margin for rounding (the shank's crossings are exact to some 1e-13 mm).
const SHADOW_MARGIN: f64 = 1e-6;

/// Where the shank of `tool` at tip `p`, unit axis `o` (the cylinder of radius R about the
/// axis above the flutes, [`Pose::shank_span`]) may cross a vertical line, seen from above;
/// `None` for a vertical axis (no direction: no bound).
///
/// Its points are T + s O + w with T = P + L_f O, s ≥ 0 and w ⊥ O, |w| ≤ R. Across the
/// projected axis direction û (the unit n̂ normal to it in XY, so (n̂, 0) ⊥ O) they lie within
/// |w·(n̂, 0)| ≤ R of T; along it at s |O_xy| + w·(û, 0) ≥ −R |O_z| from T, (û, 0) being
/// |O_z| away from the line of O: a half-infinite strip of half-width R from T, lengthened by
/// R |O_z| behind it.
fn shank_shadow(tool: &Tool, p: &Vector3<f64>, o: &Vector3<f64>) -> Option<Rectangle> {
    let top = p + o * tool.flute_length;
    let r = tool.radius();
    Rectangle::ray([top.x, top.y], [o.x, o.y], r, r * o.z.abs())
}

/// A rectangle of half-width `r` about the segment from `a` to `b` (XY), lengthened by `ends`
/// at both ends, with what its rows share (`a` ≠ `b`).
#[derive(Debug, Clone, Copy)]
struct Rectangle {
    a1: f64,
    /// b − a.
    dx: f64,
    dy: f64,
    /// a[0]·dx, a[0]·dy.
    adx: f64,
    ady: f64,
    /// −ends·|d|, |d|² + ends·|d|, r·|d|.
    e0: f64,
    e1: f64,
    w: f64,
}

impl Rectangle {
    /// `None` where `a` = `b` (no direction).
    fn new(a: [f64; 2], b: [f64; 2], r: f64, ends: f64) -> Option<Rectangle> {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len2 = dx * dx + dy * dy;
        if len2 == 0.0 {
            return None;
        }
        let len = len2.sqrt();
        let (e, w) = (ends * len, r * len);
        Some(Rectangle {
            a1: a[1],
            dx,
            dy,
            adx: a[0] * dx,
            ady: a[0] * dy,
            e0: -e,
            e1: len2 + e,
            w,
        })
    }

    /// The half-infinite strip of half-width `r` from `a` along direction `d` (XY, not zero),
    /// lengthened by `behind` behind `a`: [`Rectangle::new`] with no far end.
    fn ray(a: [f64; 2], d: [f64; 2], r: f64, behind: f64) -> Option<Rectangle> {
        Rectangle::new(a, [a[0] + d[0], a[1] + d[1]], r, behind).map(|q| Rectangle {
            e1: f64::INFINITY,
            ..q
        })
    }

    /// The x interval (empty where `[0] > [1]`) where the line at `y` meets the rectangle.
    fn row(&self, y: f64) -> [f64; 2] {
        // With q = (x, y): −ends·|d| ≤ (q − a)·d ≤ |d|² + ends·|d| and |(q − a) × d| ≤ r |d|,
        // each k x + m in a range.
        let mut band = [f64::NEG_INFINITY, f64::INFINITY];
        let mut clip = |k: f64, m: f64, c0: f64, c1: f64| {
            if k == 0.0 {
                if m < c0 || m > c1 {
                    band = [f64::INFINITY, f64::NEG_INFINITY];
                }
            } else {
                let (u, v) = ((c0 - m) / k, (c1 - m) / k);
                band[0] = band[0].max(u.min(v));
                band[1] = band[1].min(u.max(v));
            }
        };
        let (dx, dy) = (self.dx, self.dy);
        clip(dx, (y - self.a1) * dy - self.adx, self.e0, self.e1);
        clip(dy, -(y - self.a1) * dx - self.ady, -self.w, self.w);
        band
    }
}

/// Where a tool may reach, seen from above: the capsule of radius `r` about the segment from
/// `a` to `b` (XY) and, for a tilted pose, the rectangle of half-width `r` along it lengthened
/// by `ends` (module doc, "Which dexels"); what depends on the segment alone is computed once
/// for all grid rows.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Footprint {
    a: [f64; 2],
    b: [f64; 2],
    /// r².
    rr: f64,
    /// The band between the end discs (lengthened by 0).
    band: Option<Rectangle>,
    /// The rectangle lengthened by `ends` (`None`: `ends` infinite, or `a` = `b`).
    axis: Option<Rectangle>,
}

impl Footprint {
    fn new(a: [f64; 2], b: [f64; 2], r: f64, ends: f64) -> Footprint {
        Footprint {
            a,
            b,
            rr: r * r,
            band: Rectangle::new(a, b, r, 0.0),
            axis: if ends.is_finite() {
                Rectangle::new(a, b, r, ends)
            } else {
                None
            },
        }
    }

    /// A tilted pose's: tip `p`, corner centre `c` (on the axis r_c above the tip) and
    /// flutes' top `t` (XY). The tool lies within R of the axis segment from c to t (the
    /// corner: a point at height h < r_c and radius r(h) lies (R − r_c + s)² + (r_c − h)² =
    /// (R − r_c)² + 2 (R − r_c) s + r_c² ≤ R² from c, s = √(r_c² − (r_c − h)²) ≤ r_c), so in
    /// the capsule about c t, which for a ball-nose tool leaves out the strip of about
    /// R·|O_xy| behind the tip that the capsule about p t holds and no tool point reaches;
    /// and in the rectangle about p t lengthened by `ends` (module doc).
    fn of_pose(p: [f64; 2], c: [f64; 2], t: [f64; 2], r: f64, ends: f64) -> Footprint {
        Footprint {
            axis: Rectangle::new(p, t, r, ends),
            ..Footprint::new(c, t, r, f64::INFINITY)
        }
    }

    /// [`capsule_row`].
    fn capsule_row(&self, y: f64) -> Option<[f64; 2]> {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for c in [self.a, self.b] {
            let e = self.rr - (y - c[1]) * (y - c[1]);
            if e >= 0.0 {
                let s = e.sqrt();
                lo = lo.min(c[0] - s);
                hi = hi.max(c[0] + s);
            }
        }
        // The band between the end discs: the rectangle of half-width r along the segment.
        if let Some(band) = self
            .band
            .map(|b| b.row(y))
            .filter(|band| band[0] <= band[1])
        {
            lo = lo.min(band[0]);
            hi = hi.max(band[1]);
        }
        (lo <= hi).then_some([lo - 1e-9, hi + 1e-9])
    }

    /// The rectangle's row, widened by 1e-9 mm as [`capsule_row`] (`None`: no rectangle).
    fn axis_row(&self, y: f64) -> Option<[f64; 2]> {
        self.axis
            .map(|q| q.row(y))
            .map(|band| [band[0] - 1e-9, band[1] + 1e-9])
    }

    /// The cells `i0..=i1` of row `y` (clipped to `[i_min, i_max]`) inside the capsule and the
    /// rectangle, on a grid of cells `d` = (x of cell 0's edge, cell width).
    fn cells(&self, d: (f64, f64), y: f64, range: (usize, usize)) -> Option<(usize, usize)> {
        clip_span(self.span(d, y)?, range)
    }

    /// [`Footprint::cells`] before the clipping: the first and last cell as floats (not
    /// rounded to the grid's range).
    fn span(&self, d: (f64, f64), y: f64) -> Option<(f64, f64)> {
        let [mut x0, mut x1] = self.capsule_row(y)?;
        if let Some([u0, u1]) = self.axis_row(y) {
            (x0, x1) = (x0.max(u0), x1.min(u1));
        }
        let (ox, hx) = d;
        Some((
            ((x0 - ox) / hx - 0.5).ceil(),
            ((x1 - ox) / hx - 0.5).floor(),
        ))
    }
}

/// A [`Footprint::span`] clipped to the cells `range` ([`Footprint::cells`]).
fn clip_span((i0, i1): (f64, f64), range: (usize, usize)) -> Option<(usize, usize)> {
    let i0 = i0.max(index_f64(range.0));
    let i1 = i1.min(index_f64(range.1));
    (i0 <= i1).then_some((i0 as usize, i1 as usize))
}

/// One pose's crossings `row` (the previous pose's `before`) joined into each cell's `run`,
/// `starts` counting the poses that cross a cell after one that does not ([`cut_step`]).
///
/// Without branches, and compiled also for the vector instructions of newer processors
/// (`multiversion`, as [`Pose::hits_row`]): a cut does this once per pose and cell, as often as
/// it crosses. The minimum and maximum are comparisons, not `f64::min`/`max`, whose handling of
/// NaN costs instructions here: a crossing is finite or [`NO_HIT`] (±∞), never NaN, and on
/// numbers both give the same value.
#[multiversion(targets("x86_64+avx512f+avx512vl", "x86_64+avx2", "aarch64+neon"))]
fn join_row(run: &mut [[f64; 2]], starts: &mut [f64], before: &[[f64; 2]], row: &[[f64; 2]]) {
    for (((run, n), p), h) in run.iter_mut().zip(starts.iter_mut()).zip(before).zip(row) {
        let start = (h[0] <= h[1]) & (p[0] > p[1]);
        *n += if start { 1.0 } else { 0.0 };
        run[0] = if h[0] < run[0] { h[0] } else { run[0] };
        run[1] = if h[1] > run[1] { h[1] } else { run[1] };
    }
}

/// The runs of a step of two poses (the first line joined with the second by [`join_row`]) in
/// one pass over the cells rather than three: the same values (the same comparisons; a
/// minimum or a maximum of numbers does not depend on the order it is taken in).
#[multiversion(targets("x86_64+avx512f+avx512vl", "x86_64+avx2", "aarch64+neon"))]
fn runs_of_two(run: &mut [[f64; 2]], starts: &mut [f64], a: &[[f64; 2]], b: &[[f64; 2]]) {
    for (((run, n), a), b) in run.iter_mut().zip(starts.iter_mut()).zip(a).zip(b) {
        let (hit_a, hit_b) = (a[0] <= a[1], b[0] <= b[1]);
        *n = if hit_a { 1.0 } else { 0.0 } + if hit_b & !hit_a { 1.0 } else { 0.0 };
        run[0] = if b[0] < a[0] { b[0] } else { a[0] };
        run[1] = if b[1] > a[1] { b[1] } else { a[1] };
    }
}

/// [`runs_of_two`] for a step of three poses (the default sample step's on a tilted tool are
/// two or three); returns whether some cell has two runs (a miss between two crossings, rare),
/// so that a row where none has is not scanned for them. (Told by an or of the cells'
/// booleans, which vectorises, where a maximum of their counts did not.)
#[multiversion(targets("x86_64+avx512f+avx512vl", "x86_64+avx2", "aarch64+neon"))]
fn runs_of_three(run: &mut [[f64; 2]], starts: &mut [f64], [a, b, c]: [&[[f64; 2]]; 3]) -> bool {
    let mut several = false;
    for ((((run, n), a), b), c) in run.iter_mut().zip(starts.iter_mut()).zip(a).zip(b).zip(c) {
        let (hit_a, hit_b, hit_c) = (a[0] <= a[1], b[0] <= b[1], c[0] <= c[1]);
        *n = if hit_a { 1.0 } else { 0.0 }
            + if hit_b & !hit_a { 1.0 } else { 0.0 }
            + if hit_c & !hit_b { 1.0 } else { 0.0 };
        several |= hit_a & !hit_b & hit_c;
        let lo = if b[0] < a[0] { b[0] } else { a[0] };
        let hi = if b[1] > a[1] { b[1] } else { a[1] };
        run[0] = if c[0] < lo { c[0] } else { lo };
        run[1] = if c[1] > hi { c[1] } else { hi };
    }
    several
}

/// The crossings of a tilted step's last pose with the dexel lines, kept for the next step,
/// whose first pose it is (shared poses, module doc).
#[derive(Debug, Clone, Default)]
pub(crate) struct SharedPose {
    /// The pose (tip, axis) and the number of the step it ended.
    pose: Option<(Vector3<f64>, Vector3<f64>)>,
    step: u64,
    /// The tip where the last step ended, if that step's tool was vertical: a level step
    /// starting there finds the cells behind its start swept already ([`behind_cells`]).
    vertical_end: Option<Vector3<f64>>,
    /// Per grid row.
    rows: Vec<SharedRow>,
}

/// One grid row's crossings with a pose: `hits[k]` for cell `start + k`, [`NO_HIT`] where the
/// tool does not cross, on the cells `valid` (the pose's, those it was computed on).
#[derive(Debug, Clone, Default)]
struct SharedRow {
    step: u64,
    start: usize,
    valid: (usize, usize),
    hits: Vec<[f64; 2]>,
    /// The pose's [`Footprint::span`] on this row, and the step that found it.
    span: Option<(f64, f64)>,
    span_step: u64,
}

impl SharedPose {
    /// For a grid of `rows` rows.
    pub fn new(rows: usize) -> SharedPose {
        SharedPose {
            pose: None,
            step: 0,
            vertical_end: None,
            rows: vec![SharedRow::default(); rows],
        }
    }
}

/// What one step's cut needs, worked out before any row is cut ([`plan_step`]).
struct StepPlan<'t> {
    step: Step,
    poses: usize,
    vertical: bool,
    /// A level move or a ramp of a flat or ball-nose tool: rows at once.
    level: bool,
    /// A level step or a rising ramp whose start is where the step before it (vertical, the
    /// same tool) ended: the cells behind its start are left out of its cut
    /// ([`behind_cells`]).
    behind: bool,
    ramp: bool,
    /// Every pose once (tilted): the tool there and its projected axis segment.
    pose_list: Vec<(Pose<'t>, Footprint)>,
    /// A vertical step's tool lies in the capsule about its tip's path.
    vertical_foot: Footprint,
    /// Where the end pose's shank may cross a dexel line, seen from above (tilted; `None`:
    /// anywhere): the shank check reads no line outside it ([`shank_shadow`]).
    shank_shadow: Option<Rectangle>,
    /// Its first pose's crossings are the previous step's last (step numbers `prev`, `this`).
    reuse: bool,
    prev: u64,
    this: u64,
    /// The cells its tool covers, `(i0, i1, j0, j1)`.
    range: Option<(usize, usize, usize, usize)>,
    /// The end pose (where the engagement is measured) and the feed direction.
    pe: Vector3<f64>,
    oe: Vector3<f64>,
    f: Vector3<f64>,
    plunge: bool,
}

/// Per task, per row: every pose's crossings with the row's cells (pose-major), the run of
/// consecutive poses crossing each cell and how many runs it has, and the runs a miss ended
/// (the pose that ended it, cell, interval), reused from row to row.
#[derive(Default)]
struct Scratch {
    hits: Vec<[f64; 2]>,
    /// The last pose's line, apart: it becomes the row's shared crossings by a swap of
    /// buffers, not a copy.
    last_line: Vec<[f64; 2]>,
    run: Vec<[f64; 2]>,
    starts: Vec<f64>,
    ended: Vec<(usize, usize, [f64; 2])>,
    ranges: Vec<Option<(usize, usize)>>,
    /// The end pose's shank crossings, and the cells where the shank may meet material.
    shank: Vec<[f64; 2]>,
    candidates: Vec<usize>,
}

/// The plan of one step; `shared` (the previous step's last pose) is updated to this step's.
fn plan_step<'t>(
    dexels: &Dexels,
    tool: &'t Tool,
    step: &Step,
    delta: f64,
    shared: &mut SharedPose,
) -> StepPlan<'t> {
    let poses = step.poses(tool, delta);
    let bounds = step.bounds(tool, poses);
    let (pe, oe) = (step.p1, step.o1.normalize());
    let f = step.p1 - step.p0;
    let plunge = oe.cross(&f).norm() <= 1e-9 * f.norm();
    let r = tool.radius();
    let vertical = poses == 1;
    // Every pose once (tilted): the tool there and its projected axis segment.
    let pose_list: Vec<(Pose<'t>, Footprint)> = if vertical {
        Vec::new()
    } else {
        (0..poses)
            .map(|j| {
                let (p, o) = step.pose(j as f64 / (poses - 1) as f64);
                let top = p + o * tool.flute_length;
                let centre = p + o * tool.corner_radius;
                let ends = r * o.z.abs();
                let foot =
                    Footprint::of_pose([p.x, p.y], [centre.x, centre.y], [top.x, top.y], r, ends);
                (Pose::new(tool, &p, &o), foot)
            })
            .collect()
    };
    // A level vertical step of a flat or ball-nose tool (not on the spot): its dexels' lower
    // ends row by row.
    let (dx, dy) = (step.p1.x - step.p0.x, step.p1.y - step.p0.y);
    let level = vertical
        && step.p1.z == step.p0.z
        && dx * dx + dy * dy > 1e-24
        && (tool.corner_radius == 0.0 || tool.corner_radius >= r);
    // A ramp (not a plunge) of such a tool: its dexels' ends row by row ([`ramp_row`]).
    let ramp = vertical
        && step.p1.z != step.p0.z
        && dx * dx + dy * dy > 1e-24
        && (tool.corner_radius == 0.0 || tool.corner_radius >= r);
    // A vertical step's tool lies in the capsule about its tip's path.
    let vertical_foot = Footprint::new(
        [step.p0.x, step.p0.y],
        [step.p1.x, step.p1.y],
        r,
        f64::INFINITY,
    );
    let shank_shadow = pose_list
        .last()
        .and_then(|(pose, _)| shank_shadow(tool, &pose.tip(), &pose.axis()));
    // This step's number; its first pose's crossings where the previous step's last pose is it.
    let (prev, this) = (shared.step, shared.step + 1);
    let reuse = !vertical && shared.pose == Some((pose_list[0].0.tip(), pose_list[0].0.axis()));
    let behind = (level || ramp && step.p1.z > step.p0.z) && shared.vertical_end == Some(step.p0);
    shared.vertical_end = vertical.then_some(step.p1);
    shared.step = this;
    shared.pose = pose_list.last().map(|l| (l.0.tip(), l.0.axis()));
    StepPlan {
        step: *step,
        poses,
        vertical,
        level,
        behind,
        ramp,
        pose_list,
        vertical_foot,
        shank_shadow,
        reuse,
        prev,
        this,
        range: cell_range(dexels, &bounds),
        pe,
        oe,
        f,
        plunge,
    }
}

/// Cuts the rows of `band` that step `plan` covers and returns their sums.
fn cut_band(
    plan: &StepPlan,
    tool: &Tool,
    (x0, y0, hx, hy): (f64, f64, f64, f64),
    band: &mut super::dexel::Band,
    shared_rows: &mut [SharedRow],
    scratch: &mut Scratch,
) -> Acc {
    let Some((i0, i1, j0, j1)) = plan.range else {
        return Acc::ZERO;
    };
    let StepPlan {
        step,
        poses,
        vertical,
        level,
        behind,
        ramp,
        ref pose_list,
        ref vertical_foot,
        ref shank_shadow,
        reuse,
        prev,
        this,
        pe,
        oe,
        ..
    } = *plan;
    let step = &step;
    let Scratch {
        hits,
        last_line,
        run,
        starts,
        ended,
        ranges,
        shank: shank_z,
        candidates,
    } = scratch;
    let cx = |i: usize| x0 + (index_f64(i) + 0.5) * hx;
    let mut acc = Acc::ZERO;
    let rows = band.rows();
    for (j, row_shared) in rows.zip(shared_rows) {
        if j < j0 || j > j1 {
            continue;
        }
        let y = y0 + (index_f64(j) + 0.5) * hy;
        let mut shank = 0.0_f64;
        // (The cell's x only where it cut: most removals take nothing.)
        let mut note = |i: usize, c: super::dexel::Cut| {
            if c.length <= 0.0 {
                return;
            }
            let x = cx(i);
            let top = Vector3::new(x, y, c.z_hi) - pe;
            let bottom = Vector3::new(x, y, c.z_lo) - pe;
            acc.length += c.length;
            acc.axial_max = larger(larger(acc.axial_max, top.dot(&oe)), bottom.dot(&oe));
        };
        if vertical {
            let Some((ia, ib)) = vertical_foot.cells((x0, hx), y, (i0, i1)) else {
                continue;
            };
            // A level step or a rising ramp that starts where the step before it ended: the
            // cells behind its start are not cut again ([`behind_cells`]): a level step's
            // shank only read there, a ramp's cells cut only where material stands above the
            // start's flutes' top (the cut and the shank as below). In cell order, as without
            // the skip (the sums add up in one order): the cells behind before the rest where
            // they lie to its left, after it where to its right.
            let behind_row = |band: &mut super::dexel::Band,
                              note: &mut dyn FnMut(usize, super::dexel::Cut),
                              shank: &mut f64,
                              (ba, bb): (usize, usize)| {
                let (p, hi) = (&step.p0, step.p0.z + tool.flute_length);
                let r2 = tool.radius() * tool.radius();
                band.each(j, ba, bb, |i, cell| {
                    let x = cx(i);
                    let (ex, ey) = (x - p.x, y - p.y);
                    let d2 = ex * ex + ey * ey;
                    if level {
                        if d2 <= r2 {
                            *shank = shank.max(cell.top() - hi);
                        }
                    } else if d2 <= r2 * (1.0 + 1e-9) && cell.top() > hi {
                        // (Within R of the start, in rounding: the sweep says.)
                        if let Some([lo, h]) = vertical_sweep(tool, &step.p0, &step.p1, x, y) {
                            note(i, cell.remove(lo, h));
                            if let Some([_, top]) = cell.extent() {
                                *shank = shank.max(top - h);
                            }
                        }
                    }
                });
            };
            let mut after = None;
            let (ia, ib) = if behind {
                match behind_cells(&step.p0, &step.p1, y, (x0, hx), (ia, ib)) {
                    (Some(b), Some(rest)) if b.0 > rest.1 => {
                        after = Some(b);
                        rest
                    }
                    (Some(b), rest) => {
                        behind_row(band, &mut note, &mut shank, b);
                        match rest {
                            Some(r) => r,
                            None => {
                                acc.shank = acc.shank.max(shank);
                                continue;
                            }
                        }
                    }
                    (None, rest) => rest.unwrap_or((ia, ib)),
                }
            } else {
                (ia, ib)
            };
            // A level move or a ramp: the row's ends at once
            // ([`level_row`], [`ramp_row`]; a ramp's cells it leaves to
            // golden-section search are NaN).
            if level {
                starts.resize(ib - ia + 1, 0.0);
                level_row(tool, &step.p0, &step.p1, y, (x0, hx), ia, starts);
            } else if ramp {
                run.resize(ib - ia + 1, NO_HIT);
                ramp_row(tool, &step.p0, &step.p1, y, (x0, hx), ia, run);
            }
            band.each(j, ia, ib, |i, cell| {
                if cell.is_empty() {
                    return;
                }
                let x = cx(i);
                let swept = if level {
                    let lo = starts[i - ia];
                    (lo < f64::INFINITY).then_some([lo, step.p0.z + tool.flute_length])
                } else if ramp && !run[i - ia][0].is_nan() {
                    let h = run[i - ia];
                    (h[0] <= h[1]).then_some(h)
                } else {
                    vertical_sweep(tool, &step.p0, &step.p1, x, y)
                };
                if let Some([lo, hi]) = swept {
                    note(i, cell.remove(lo, hi));
                    // [lo, hi] reaches the flutes' top: what stands
                    // above it is in the shank's way.
                    if let Some([_, top]) = cell.extent() {
                        shank = shank.max(top - hi);
                    }
                }
            });
            if let Some(b) = after {
                behind_row(band, &mut note, &mut shank, b);
            }
            acc.shank = acc.shank.max(shank);
            continue;
        }
        // Pose by pose over the cells of its capsule: each pose's crossings
        // (no dexel is read), joined into runs; then the runs are removed.
        // (The first pose's span is the previous step's last's where it
        // is that pose, on this row: the same footprint.)
        let first = if reuse && row_shared.span_step == prev {
            row_shared.span
        } else {
            pose_list[0].1.span((x0, hx), y)
        };
        let end = pose_list[poses - 1].1.span((x0, hx), y);
        (row_shared.span, row_shared.span_step) = (end, this);
        ranges.clear();
        ranges.extend(pose_list.iter().enumerate().map(|(k, (_, foot))| {
            let span = match k {
                0 => first,
                _ if k == poses - 1 => end,
                _ => foot.span((x0, hx), y),
            };
            span.and_then(|s| clip_span(s, (i0, i1)))
        }));
        let (mut ua, mut ub) = (usize::MAX, 0);
        for &(ia, ib) in ranges.iter().flatten() {
            (ua, ub) = (ua.min(ia), ub.max(ib));
        }
        if ua > ub {
            continue;
        }
        let width = ub - ua + 1;
        // Each pose's line of `hits` (the last pose's: `last_line`): its
        // crossings on its cells, misses on the others (every entry written
        // once).
        hits.resize((poses - 1) * width, NO_HIT);
        last_line.resize(width, NO_HIT);
        let mut share = None;
        for k in 0..poses {
            let line = if k + 1 < poses {
                &mut hits[k * width..(k + 1) * width]
            } else {
                &mut last_line[..width]
            };
            let Some((ia, ib)) = ranges[k] else {
                line.fill(NO_HIT);
                continue;
            };
            line[..ia - ua].fill(NO_HIT);
            line[ib - ua + 1..].fill(NO_HIT);
            let pose = &pose_list[k].0;
            let row = &mut line[ia - ua..=ib - ua];
            // k = 0 reads the shared row where it has the cells, k = poses − 1
            // ≥ 1 becomes it (below).
            let (s0, (v0, v1)) = (row_shared.start, row_shared.valid);
            let known = if k == 0 && reuse && row_shared.step == prev {
                v0.max(ia)..v1.min(ib + 1)
            } else {
                0..0
            };
            if known.is_empty() {
                pose.hits_row(y, x0, hx, ia, row);
            } else {
                let (before, rest) = row.split_at_mut(known.start - ia);
                let (mid, after) = rest.split_at_mut(known.len());
                pose.hits_row(y, x0, hx, ia, before);
                mid.copy_from_slice(&row_shared.hits[known.start - s0..known.end - s0]);
                pose.hits_row(y, x0, hx, known.end, after);
            }
            if k == poses - 1 {
                share = Some((ia, ib + 1));
            }
        }
        let line = |k: usize| -> &[[f64; 2]] {
            if k + 1 < poses {
                &hits[k * width..(k + 1) * width]
            } else {
                &last_line[..width]
            }
        };
        // The runs of consecutive poses that cross each cell, each joined
        // into [min lo, max hi]. First, without branches, every cell's
        // crossings joined and its runs counted (`starts`: the poses that
        // cross it after one that does not); a miss between two crossings
        // (at least three poses) leaves several runs, taken apart cell by
        // cell below, the ones a miss ended kept aside. (A miss is
        // [∞, −∞], which min and max leave out exactly.)
        run.resize(width, NO_HIT);
        starts.resize(width, 0.0);
        // Whether some cell may have two runs or more (two poses make one at most).
        let mut several = poses > 2;
        if poses == 2 {
            runs_of_two(run, starts, line(0), line(1));
        } else if poses == 3 {
            several = runs_of_three(run, starts, [line(0), line(1), line(2)]);
        } else {
            run.copy_from_slice(line(0));
            for (n, h) in starts.iter_mut().zip(run.iter()) {
                *n = f64::from(u8::from(h[0] <= h[1]));
            }
            for k in 1..poses {
                join_row(run, starts, line(k - 1), line(k));
            }
        }
        ended.clear();
        for (c, run) in run
            .iter_mut()
            .enumerate()
            .take(if several { width } else { 0 })
        {
            if starts[c] < 2.0 {
                continue;
            }
            *run = NO_HIT;
            let mut open = false;
            for k in 0..poses {
                let h = line(k)[c];
                if h[0] > h[1] {
                    open = false;
                    continue;
                }
                if open {
                    *run = [run[0].min(h[0]), run[1].max(h[1])];
                } else {
                    if run[0] <= run[1] {
                        ended.push((k, ua + c, *run));
                    }
                    *run = h;
                }
                open = true;
            }
        }
        // In the order the poses ended them (the sums then add up in one
        // order whatever the grid).
        ended.sort_unstable_by_key(|&(k, i, _)| (k, i));
        for &(_, i, [lo, hi]) in ended.iter() {
            note(i, band.dexel(i, j).remove(lo, hi));
        }
        // (A cell no pose crosses has the run [∞, −∞], which removes
        // nothing: Dexel::remove tells it without a call.) Then the shank
        // at the step's end pose, where its flutes cross a line with
        // material left above them (the shank lies above the flutes).
        // (Only on the lines the shank may cross: where it cannot, the depth is 0.)
        let end_pose = &pose_list[poses - 1].0;
        let end_hits = &last_line[..width];
        let (sa, sb) = shank_shadow.as_ref().map_or((0, usize::MAX), |q| {
            let [a, b] = q.row(y);
            (
                ((a - SHADOW_MARGIN - x0) / hx - 0.5).ceil() as usize,
                ((b + SHADOW_MARGIN - x0) / hx - 0.5).floor() as usize,
            )
        });
        candidates.clear();
        let mut remove = |i: usize, cell: &mut super::dexel::Dexel| {
            let [lo, hi] = run[i - ua];
            note(i, cell.remove(lo, hi));
        };
        // The cells in order: those outside the shadow only cut, those inside it also told
        // as candidates (not one test of the shadow per cell).
        let (ma, mb) = (sa.max(ua), sb.min(ub));
        if ma > mb {
            band.each(j, ua, ub, remove);
        } else {
            if ua < ma {
                band.each(j, ua, ma - 1, &mut remove);
            }
            band.each(j, ma, mb, |i, cell| {
                remove(i, cell);
                let h = end_hits[i - ua];
                if h[0] <= h[1] && cell.top() > h[1] {
                    candidates.push(i);
                }
            });
            if mb < ub {
                band.each(j, mb + 1, ub, &mut remove);
            }
        }
        if let (Some(&first), Some(&last)) = (candidates.first(), candidates.last()) {
            // Many candidates (a tool buried beyond its flutes): the row's
            // shank spans at once, with vector instructions; few: each alone
            // (the same spans bit for bit).
            let many = 4 * candidates.len() > last - first;
            let mut depth = |i: usize, z: [f64; 2], cell: &super::dexel::Dexel| {
                if z[0] < z[1] && cell.top() > z[0] {
                    shank = larger(shank, end_pose.shank_depth(cx(i), y, z, cell.intervals()));
                }
            };
            if many {
                // The candidates told again as above, on the dexels in order
                // rather than each looked up.
                shank_z.resize(last - first + 1, NO_HIT);
                end_pose.shank_row(y, x0, hx, first, shank_z);
                band.each(j, first, last, |i, cell| {
                    let h = end_hits[i - ua];
                    if h[0] <= h[1] && cell.top() > h[1] {
                        depth(i, shank_z[i - first], cell);
                    }
                });
            } else {
                for &i in candidates.iter() {
                    let z = end_pose.shank_span(cx(i), y).unwrap_or(NO_HIT);
                    depth(i, z, band.dexel(i, j));
                }
            }
        }
        // The last pose's crossings become the row's shared ones.
        if let Some(valid) = share {
            std::mem::swap(last_line, &mut row_shared.hits);
            row_shared.step = this;
            row_shared.start = ua;
            row_shared.valid = valid;
        }
        acc.shank = acc.shank.max(shank);
    }
    acc
}

/// Removes the swept volume of `steps` (one tool's, in order) from the dexels and returns each
/// step's engagement (its `point`, `t`, `line`, `rapid` and feed are the caller's to fill).
/// `delta`: [`pose_spacing`]; `shared`: the previous step's last pose, updated to the last
/// step's.
///
/// The steps are planned first; then the bands of grid rows they cover are cut in parallel,
/// each band taking every step in order (a step's cut of one band depends only on that band's
/// dexels and the steps before it), so the threads meet once per batch rather than once per
/// step (9,344 times on the LinuxCNC impeller). Each step's sums are joined band by band in
/// grid order, as a step cut alone would join them: the same values on any number of threads
/// and for any batch.
pub(crate) fn cut_steps(
    dexels: &mut Dexels,
    tool: &Tool,
    steps: &[Step],
    delta: f64,
    shared: &mut SharedPose,
) -> Vec<Sample> {
    let plans: Vec<StepPlan> = steps
        .iter()
        .map(|st| plan_step(dexels, tool, st, delta, shared))
        .collect();
    let rows = plans
        .iter()
        .filter_map(|p| p.range.map(|r| (r.2, r.3)))
        .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)));
    let mut accs = vec![Acc::ZERO; plans.len()];
    if let Some((j0, j1)) = rows {
        let geometry = (dexels.x0, dexels.y0, dexels.hx, dexels.hy);
        let bands = dexels.bands(j0, j1);
        let first_row = bands[0].rows().start;
        let last_row = bands[bands.len() - 1].rows().end;
        let shared_rows = &mut shared.rows[first_row..last_row];
        let per_band: Vec<Vec<Acc>> = bands
            .into_par_iter()
            .zip(shared_rows.par_chunks_mut(TILE))
            .map_init(Scratch::default, |scratch, (mut band, shared_rows)| {
                let rows = band.rows();
                plans
                    .iter()
                    .map(|plan| match plan.range {
                        Some((_, _, a, b)) if a < rows.end && b >= rows.start => {
                            cut_band(plan, tool, geometry, &mut band, shared_rows, scratch)
                        }
                        _ => Acc::ZERO,
                    })
                    .collect()
            })
            .collect();
        // Band by band in grid order, whatever thread cut which.
        for band in &per_band {
            for (acc, b) in accs.iter_mut().zip(band) {
                *acc = acc.join(*b);
            }
        }
    }
    let cell_area = dexels.hx * dexels.hy;
    plans
        .iter()
        .zip(accs)
        .map(|(plan, acc)| sample_of(plan, acc, cell_area, tool))
        .collect()
}

/// Removes one step's swept volume ([`cut_steps`] of one step; the tests' entry).
#[cfg(test)]
pub(crate) fn cut_step(
    dexels: &mut Dexels,
    tool: &Tool,
    step: &Step,
    delta: f64,
    shared: &mut SharedPose,
) -> Sample {
    cut_steps(dexels, tool, std::slice::from_ref(step), delta, shared)
        .pop()
        .expect("one step, one sample")
}

/// A step's sample from its sums.
fn sample_of(plan: &StepPlan, acc: Acc, cell_area: f64, tool: &Tool) -> Sample {
    let (f, plunge) = (plan.f, plan.plunge);
    let removed = acc.length * cell_area;
    let length = f.norm();
    let area = if length > 0.0 { removed / length } else { 0.0 };
    let d = tool.diameter;
    let axial_depth = if acc.length > 0.0 {
        acc.axial_max.max(0.0)
    } else {
        0.0
    };
    let (radial_engagement, engagement_angle) = if area <= 0.0 {
        (0.0, 0.0)
    } else if plunge {
        ((4.0 * area / std::f64::consts::PI).sqrt().min(d), 360.0)
    } else {
        let ae = if axial_depth > 0.0 {
            (area / axial_depth).min(d)
        } else {
            d
        };
        (
            ae,
            (1.0 - 2.0 * ae / d).clamp(-1.0, 1.0).acos().to_degrees(),
        )
    };
    Sample {
        point: 0,
        t: [0.0, 1.0],
        line: 0,
        length,
        removed,
        area,
        axial_depth,
        radial_engagement,
        engagement_angle,
        rapid: false,
        programmed_feed: None,
        shank_depth: acc.shank,
    }
}

/// The steps of CL move k (from point k−1 to k) at sample step `step`: their count (0 where
/// the tool neither moves nor turns).
pub(crate) fn steps_of_move(tp: &Toolpath, k: usize, tool: &Tool, step: f64) -> usize {
    let (a, b) = (&tp.points[k - 1], &tp.points[k]);
    let whole = Step {
        p0: a.p,
        p1: b.p,
        o0: a.o,
        o1: b.o,
    };
    let e = whole.extent(tool);
    if e <= 1e-9 {
        0
    } else {
        (e / step).ceil().max(1.0) as usize
    }
}

/// Step `s` of `n` of CL move k (its last step ends exactly at CL point k, where the next
/// move starts).
pub(crate) fn step_of_move(tp: &Toolpath, k: usize, s: usize, n: usize) -> Step {
    let (a, b) = (&tp.points[k - 1], &tp.points[k]);
    let (t0, t1) = (s as f64 / n as f64, (s + 1) as f64 / n as f64);
    let at = |t: f64| {
        (
            if t == 1.0 { b.p } else { a.p + (b.p - a.p) * t },
            (a.o * (1.0 - t) + b.o * t).normalize(),
        )
    };
    let ((p0, o0), (p1, o1)) = (at(t0), at(t1));
    Step { p0, p1, o0, o1 }
}

/// The programmed feed of the move ending at CL point k, mm/s, and whether it is a rapid.
pub(crate) fn move_feed(tp: &Toolpath, k: usize) -> (Option<f64>, bool) {
    match tp.points[k].feed {
        Feed::Programmed(v) => (Some(v), false),
        Feed::Rapid => (None, true),
        Feed::BlockTime(t) => (
            Some((tp.points[k].p - tp.points[k - 1].p).norm() / t),
            false,
        ),
        Feed::Unspecified => (None, false),
    }
}

#[cfg(test)]
mod tests {
    use super::super::dexel::remove;
    use super::super::stock::Stock;
    use super::*;

    /// [`cut_step`]'s rules (module doc) on a plain grid of interval lists, cell by cell over
    /// the whole grid and every pose, without tiles, capsules or rows in parallel: the
    /// removed length.
    fn reference_step(
        d: &Dexels,
        cells: &mut [Vec<[f64; 2]>],
        tool: &Tool,
        step: &Step,
        delta: f64,
    ) -> f64 {
        let poses = step.poses(tool, delta);
        let mut length = 0.0;
        for j in 0..d.ny {
            for i in 0..d.nx {
                let (x, y) = (d.x(i), d.y(j));
                let cell = &mut cells[j * d.nx + i];
                if poses == 1 {
                    if let (false, Some([lo, hi])) = (
                        cell.is_empty(),
                        vertical_sweep(tool, &step.p0, &step.p1, x, y),
                    ) {
                        length += remove(cell, lo, hi).length;
                    }
                    continue;
                }
                let mut run: Option<(usize, [f64; 2])> = None;
                for k in 0..poses {
                    if cell.is_empty() {
                        continue;
                    }
                    let (p, o) = step.pose(k as f64 / (poses - 1) as f64);
                    let goes_on = run.is_some_and(|(last, _)| last + 1 == k);
                    let Some(h) = tool.line_hit(&p, &o, x, y) else {
                        continue;
                    };
                    run = Some(match run {
                        Some((_, r)) if goes_on => (k, [r[0].min(h[0]), r[1].max(h[1])]),
                        Some((_, r)) => {
                            length += remove(cell, r[0], r[1]).length;
                            (k, h)
                        }
                        None => (k, h),
                    });
                }
                if let Some((_, r)) = run {
                    length += remove(cell, r[0], r[1]).length;
                }
            }
        }
        length
    }

    /// Every point of a tilted tool lies in the rectangle of `axis_row`, whose ends are
    /// tighter than the capsule's.
    /// A level move's row of lower ends is [`vertical_sweep`]'s, bit for bit, for flat and
    /// ball-nose tools, over rows that miss, graze and cross the swept capsule.
    #[test]
    fn a_level_rows_lower_ends_are_vertical_sweeps() {
        for tool in [
            Tool::new(6.0, 3.0, 12.0, 2).unwrap(),
            Tool::new(8.0, 0.0, 16.0, 3).unwrap(),
        ] {
            let (p0, p1) = (Vector3::new(0.3, -0.2, -1.5), Vector3::new(0.9, 0.55, -1.5));
            let (x0, hx, ia) = (-6.0, 0.1, 3);
            let mut out = vec![0.0; 120];
            let mut hits = 0;
            for jy in 0..100 {
                let y = -4.5 + 0.093 * jy as f64;
                level_row(&tool, &p0, &p1, y, (x0, hx), ia, &mut out);
                for (k, &lo) in out.iter().enumerate() {
                    let x = x0 + ((ia + k) as f64 + 0.5) * hx;
                    match vertical_sweep(&tool, &p0, &p1, x, y) {
                        Some([l, h]) => {
                            assert_eq!(lo.to_bits(), l.to_bits(), "({x}, {y})");
                            assert_eq!(h, p0.z + tool.flute_length);
                            hits += 1;
                        }
                        None => assert_eq!(lo, f64::INFINITY, "({x}, {y})"),
                    }
                }
            }
            assert!(hits > 1000, "{hits}");
        }
    }

    /// A ramp's row of crossings is [`vertical_sweep`]'s, bit for bit, for flat and ball-nose
    /// tools, up and down, over rows that miss, graze and cross the swept volume.
    #[test]
    fn a_ramps_row_is_vertical_sweeps() {
        for tool in [
            Tool::new(6.0, 3.0, 12.0, 2).unwrap(),
            Tool::new(8.0, 0.0, 16.0, 3).unwrap(),
        ] {
            for dz in [0.37, -0.21, 2.5] {
                let (p0, p1) = (
                    Vector3::new(0.3, -0.2, -1.5),
                    Vector3::new(0.9, 0.55, -1.5 + dz),
                );
                let (x0, hx, ia) = (-6.0, 0.1, 3);
                let mut out = vec![[0.0; 2]; 120];
                let mut hits = 0;
                for jy in 0..100 {
                    let y = -4.5 + 0.093 * jy as f64;
                    ramp_row(&tool, &p0, &p1, y, (x0, hx), ia, &mut out);
                    for (k, h) in out.iter().enumerate() {
                        let x = x0 + ((ia + k) as f64 + 0.5) * hx;
                        match vertical_sweep(&tool, &p0, &p1, x, y) {
                            Some([l, u]) => {
                                assert_eq!(h[0].to_bits(), l.to_bits(), "({x}, {y})");
                                assert_eq!(h[1].to_bits(), u.to_bits(), "({x}, {y})");
                                hits += 1;
                            }
                            None => assert!(h[0] > h[1], "({x}, {y}): {h:?}"),
                        }
                    }
                }
                assert!(hits > 1000, "{hits}");
            }
        }
    }

    /// The closed form for a ball on a ramp agrees with golden-section search on the swept
    /// ball's lower surface, on random ramps and lines (up, down, steep, shallow; lines near
    /// the capsule's edge and through its ends).
    #[test]
    fn a_ramping_balls_lower_surface_is_its_capsules() {
        let tool = Tool::new(6.0, 3.0, 12.0, 2).unwrap();
        let mut next = crate::test_rng(0x2545_f491_4f6c_dd1d);
        let mut checked = 0;
        for _ in 0..20_000 {
            let p0 = Vector3::new(next() * 4.0 - 2.0, next() * 4.0 - 2.0, next() * 4.0 - 2.0);
            let d = Vector3::new(next() * 2.0 - 1.0, next() * 2.0 - 1.0, next() * 2.0 - 1.0);
            let p1 = p0 + d * (0.01 + 3.0 * next());
            let (x, y) = (next() * 12.0 - 6.0, next() * 12.0 - 6.0);
            let Some([lo, _]) = vertical_sweep(&tool, &p0, &p1, x, y) else {
                continue;
            };
            // The reference: the lowest ball point on the line over the t where the line is
            // within R of the centre, by golden-section search.
            let (ax, ay, dx, dy) = (p0.x - x, p0.y - y, p1.x - p0.x, p1.y - p0.y);
            let (qa, qb, qc) = (dx * dx + dy * dy, ax * dx + ay * dy, ax * ax + ay * ay);
            let sq = (qb * qb - qa * (qc - 9.0)).sqrt();
            let (ta, tb) = (((-qb - sq) / qa).max(0.0), ((-qb + sq) / qa).min(1.0));
            let g = |t: f64| {
                let d2 = (qa * t * t + 2.0 * qb * t + qc).clamp(0.0, 9.0);
                p0.z + (p1.z - p0.z) * t + 3.0 - (9.0 - d2).sqrt()
            };
            let best = golden_min(g, ta, tb);
            assert!(
                (lo - best).abs() <= 1e-9,
                "p0 {p0:?} p1 {p1:?} ({x}, {y}): {lo} against {best}"
            );
            checked += 1;
        }
        assert!(checked > 1000, "{checked}");
    }

    #[test]
    fn a_tilted_tool_lies_in_its_axis_rectangle() {
        let mut rnd = crate::test_rng(9);
        let tool = Tool::new(6.0, 3.0, 12.0, 2).unwrap();
        let r = tool.radius();
        for _ in 0..200 {
            let o = Vector3::new(rnd() - 0.5, rnd() - 0.5, 0.2 + rnd()).normalize();
            let p = Vector3::new(rnd(), rnd(), rnd());
            let top = p + o * tool.flute_length;
            let (a, b) = ([p.x, p.y], [top.x, top.y]);
            // Two unit vectors normal to O.
            let e1 = o.cross(&Vector3::x()).normalize();
            let e2 = o.cross(&e1);
            for _ in 0..200 {
                let h = tool.flute_length * rnd();
                let (rho, phi) = (
                    tool.radius_at(h) * rnd().sqrt(),
                    std::f64::consts::TAU * rnd(),
                );
                let x = p + o * h + (e1 * phi.cos() + e2 * phi.sin()) * rho;
                let [x0, x1] = axis_row(a, b, r, r * o.z.abs(), x.y).unwrap();
                assert!(x0 <= x.x && x.x <= x1, "{x:?} outside [{x0}, {x1}]");
            }
            // Beyond the tip, along the axis' direction, the capsule reaches R; the rectangle
            // R·|O_z|.
            let u = Vector3::new(o.x, o.y, 0.0).normalize() * (-r * (1.0 + o.z.abs()) / 2.0);
            let q = p + u;
            let inside = |row: Option<[f64; 2]>| row.is_some_and(|[x0, x1]| x0 <= q.x && q.x <= x1);
            assert!(inside(capsule_row(a, b, r, q.y)));
            assert!(!inside(axis_row(a, b, r, r * o.z.abs(), q.y)) || o.z.abs() > 0.999);
        }
    }

    /// Every point of a tilted flat, ball or bull-nose tool, on its surface or inside, lies in
    /// its pose's footprint: the capsule about its corner centre and flutes' top, and the
    /// rectangle about its tip and top ([`Footprint::of_pose`]).
    #[test]
    fn a_tilted_tool_lies_in_its_footprint() {
        let mut rnd = crate::test_rng(17);
        for tool in [
            Tool::new(6.0, 3.0, 12.0, 2).unwrap(),
            Tool::new(6.0, 0.0, 12.0, 2).unwrap(),
            Tool::new(6.0, 1.2, 12.0, 2).unwrap(),
        ] {
            let r = tool.radius();
            for case in 0..200 {
                let oz = if case % 4 == 0 {
                    -0.2 - rnd()
                } else {
                    0.05 + rnd()
                };
                let o = Vector3::new(rnd() - 0.5, rnd() - 0.5, oz).normalize();
                let p = Vector3::new(rnd(), rnd(), rnd());
                let (c, t) = (p + o * tool.corner_radius, p + o * tool.flute_length);
                let foot = Footprint::of_pose([p.x, p.y], [c.x, c.y], [t.x, t.y], r, r * o.z.abs());
                let e1 = o.cross(&Vector3::x()).normalize();
                let e2 = o.cross(&e1);
                for k in 0..400 {
                    let h = match k % 4 {
                        0 => tool.corner_radius * rnd(),
                        _ => tool.flute_length * rnd(),
                    };
                    // Half of them on the surface.
                    let rho = tool.radius_at(h) * if k % 2 == 0 { 1.0 } else { rnd().sqrt() };
                    let phi = std::f64::consts::TAU * rnd();
                    let x = p + o * h + (e1 * phi.cos() + e2 * phi.sin()) * rho;
                    let [x0, x1] = foot.capsule_row(x.y).unwrap();
                    assert!(
                        x0 <= x.x && x.x <= x1,
                        "{tool:?} {x:?} outside [{x0}, {x1}]"
                    );
                    let [u0, u1] = foot.axis_row(x.y).unwrap();
                    assert!(
                        u0 <= x.x && x.x <= u1,
                        "{tool:?} {x:?} outside [{u0}, {u1}]"
                    );
                }
            }
        }
    }

    /// The runs of two and of three poses in one pass are [`join_row`]'s, pose after pose, bit
    /// for bit, on lines of crossings and misses.
    #[test]
    fn runs_in_one_pass_are_join_rows() {
        let mut rnd = crate::test_rng(19);
        let mut line = |n: usize| -> Vec<[f64; 2]> {
            (0..n)
                .map(|_| {
                    if rnd() < 0.3 {
                        NO_HIT
                    } else {
                        let lo = 10.0 * rnd() - 5.0;
                        [lo, lo + 3.0 * rnd()]
                    }
                })
                .collect()
        };
        let n = 999;
        let lines: Vec<Vec<[f64; 2]>> = (0..3).map(|_| line(n)).collect();
        for poses in [2, 3] {
            let (mut run, mut starts) = (lines[0].clone(), vec![0.0; n]);
            for (s, h) in starts.iter_mut().zip(&run) {
                *s = f64::from(u8::from(h[0] <= h[1]));
            }
            for k in 1..poses {
                join_row(&mut run, &mut starts, &lines[k - 1], &lines[k]);
            }
            let (mut run1, mut starts1) = (vec![[0.0; 2]; n], vec![7.0; n]);
            if poses == 2 {
                runs_of_two(&mut run1, &mut starts1, &lines[0], &lines[1]);
            } else {
                let several =
                    runs_of_three(&mut run1, &mut starts1, [&lines[0], &lines[1], &lines[2]]);
                assert_eq!(several, starts.contains(&2.0));
                // Without a cell of two runs (the middle pose crossing wherever the others
                // do), or with no cells, it says none.
                let hull: Vec<[f64; 2]> = lines[0]
                    .iter()
                    .zip(&lines[2])
                    .zip(&lines[1])
                    .map(|((a, c), b)| {
                        if a[0] <= a[1] && c[0] <= c[1] {
                            [0.0, 1.0]
                        } else {
                            *b
                        }
                    })
                    .collect();
                let (mut r2, mut s2) = (vec![[0.0; 2]; n], vec![0.0; n]);
                assert!(!runs_of_three(
                    &mut r2,
                    &mut s2,
                    [&lines[0], &hull, &lines[2]]
                ));
                assert!(!runs_of_three(&mut [], &mut [], [&[], &[], &[]]));
            }
            for c in 0..n {
                assert_eq!(run[c].map(f64::to_bits), run1[c].map(f64::to_bits), "{c}");
                assert_eq!(starts[c].to_bits(), starts1[c].to_bits(), "{c}");
            }
            assert!(starts.contains(&2.0) || poses == 2);
        }
    }

    /// Every line a tilted tool's shank crosses ([`Pose::shank_span`]) lies in its shadow,
    /// and so does every point of the shank, on poses tilted every way, up and down.
    #[test]
    fn a_shank_lies_in_its_shadow() {
        let mut rnd = crate::test_rng(13);
        let tool = Tool::new(6.0, 3.0, 12.0, 2).unwrap();
        let r = tool.radius();
        let (mut crossed, mut points) = (0, 0);
        for case in 0..300 {
            let oz = if case % 5 == 0 {
                -0.3 - rnd()
            } else {
                0.05 + rnd()
            };
            let o = Vector3::new(rnd() - 0.5, rnd() - 0.5, oz).normalize();
            let p = Vector3::new(rnd(), rnd(), rnd());
            let pose = Pose::new(&tool, &p, &o);
            let shadow = shank_shadow(&tool, &p, &o).unwrap();
            let inside = |x: f64, y: f64| {
                let [x0, x1] = shadow.row(y);
                x0 - SHADOW_MARGIN <= x && x <= x1 + SHADOW_MARGIN
            };
            for _ in 0..200 {
                let (x, y) = (p.x + 40.0 * (rnd() - 0.5), p.y + 40.0 * (rnd() - 0.5));
                if pose.shank_span(x, y).is_some() {
                    assert!(inside(x, y), "case {case}: line ({x}, {y}) outside");
                    crossed += 1;
                }
            }
            // Two unit vectors normal to O.
            let e1 = o.cross(&Vector3::x()).normalize();
            let e2 = o.cross(&e1);
            for _ in 0..200 {
                let h = tool.flute_length + 20.0 * rnd();
                let (rho, phi) = (r * rnd().sqrt(), std::f64::consts::TAU * rnd());
                let x = p + o * h + (e1 * phi.cos() + e2 * phi.sin()) * rho;
                assert!(inside(x.x, x.y), "case {case}: {x:?} outside");
                points += 1;
            }
        }
        assert!(crossed > 1000 && points > 1000, "{crossed} {points}");
    }

    /// Random tilted and vertical passes into a block: the cut and the reference remove the
    /// same material, dexel by dexel.
    /// A step of a vertical tool from `p0` to `p1`.
    fn vertical_step(p0: Vector3<f64>, p1: Vector3<f64>) -> Step {
        let o = Vector3::z();
        Step {
            p0,
            p1,
            o0: o,
            o1: o,
        }
    }

    /// A level step or a rising ramp that starts where a vertical tool's step ended leaves
    /// out the cells behind its start ([`behind_cells`]): the same dexels and removed lengths
    /// as the plain reference, and the same samples (removed volume, depths, shank) as the
    /// step cut without the step before's end known, which cuts every cell of its footprint.
    /// Flutes short enough that the shank meets the material above them (and a rising ramp
    /// cuts some behind its start).
    #[test]
    fn a_level_step_after_a_vertical_one_cuts_as_every_cell() {
        let mut rnd = crate::test_rng(9);
        let stock = Stock::Box {
            min: [0.0, 0.0, -5.0],
            max: [12.0, 9.0, 0.0],
        };
        let (mut level, mut rising) = (0, 0);
        for case in 0..8 {
            let dia = 2.0 + 2.0 * rnd();
            let rc = if case % 2 == 0 { 0.0 } else { 0.5 * dia };
            let tool = Tool::new(dia, rc, rc + 0.4, 2).unwrap();
            let cell = 0.1 + 0.1 * rnd();
            let mut d = Dexels::new(&stock, cell);
            let mut alone = d.clone();
            let mut cells = d.dense_reference(&stock);
            let delta = pose_spacing(&tool, cell);
            let top = -(rc + 0.6);
            // First an uneven top: pockets of other depths, by a longer tool.
            let rough = Tool::new(1.5 * dia, 0.0, 6.0, 2).unwrap();
            for _ in 0..6 {
                let at = |r: &mut dyn FnMut() -> f64, z: f64| {
                    Vector3::new(1.0 + 10.0 * r(), 1.0 + 7.0 * r(), z)
                };
                let z = -(rc + 0.5) * rnd();
                let (p0, p1) = (at(&mut rnd, z), at(&mut rnd, z));
                let step = vertical_step(p0, p1);
                let delta = pose_spacing(&rough, cell);
                reference_step(&d, &mut cells, &rough, &step, delta);
                for g in [&mut d, &mut alone] {
                    cut_step(g, &rough, &step, delta, &mut SharedPose::new(g.ny));
                }
            }
            let mut p = Vector3::new(6.0, 4.5, top);
            let mut shared = SharedPose::new(d.ny);
            let mut shank = 0.0_f64;
            for _ in 0..40 {
                // Mostly level, of lengths below and above the tool's radius, along the axes
                // and not; now and then a ramp to another level.
                let z = if rnd() < 0.2 { top - 3.0 * rnd() } else { p.z };
                let len = [0.05, 0.3, 1.0, 2.5][(4.0 * rnd()) as usize % 4];
                let a = if rnd() < 0.3 {
                    std::f64::consts::FRAC_PI_2 * (4.0 * rnd()).floor()
                } else {
                    std::f64::consts::TAU * rnd()
                };
                let p1 = Vector3::new(
                    (p.x + len * a.cos()).clamp(1.0, 11.0),
                    (p.y + len * a.sin()).clamp(1.0, 8.0),
                    z,
                );
                if p1.z == p.z && p1 != p {
                    level += 1;
                } else if p1.z > p.z && (p1.x, p1.y) != (p.x, p.y) {
                    rising += 1;
                }
                let step = vertical_step(p, p1);
                let want = reference_step(&d, &mut cells, &tool, &step, delta);
                let got = cut_step(&mut d, &tool, &step, delta, &mut shared);
                let each = cut_step(&mut alone, &tool, &step, delta, &mut SharedPose::new(d.ny));
                assert_eq!(got, each);
                let length = got.removed / (d.hx * d.hy);
                assert!(
                    (length - want).abs() <= 1e-12 * want.max(1.0),
                    "{length} {want}"
                );
                shank = shank.max(got.shank_depth);
                p = p1;
            }
            assert!(shank > 0.1, "case {case}: the shank met no material");
            for j in 0..d.ny {
                for i in 0..d.nx {
                    assert_eq!(d.dexel(i, j).intervals(), &cells[j * d.nx + i][..]);
                    assert_eq!(d.dexel(i, j), alone.dexel(i, j));
                }
            }
        }
        assert!(
            level > 150 && rising > 20,
            "{level} level steps, {rising} rising ramps"
        );
    }

    #[test]
    fn the_cut_agrees_with_a_plain_reference() {
        let mut rnd = crate::test_rng(3);
        let stock = Stock::Box {
            min: [0.0, 0.0, -5.0],
            max: [12.0, 9.0, 0.0],
        };
        for case in 0..12 {
            let dia = 2.0 + 2.0 * rnd();
            let rc = [0.0, 0.5 * dia, 0.2 * dia][case % 3];
            let tool = Tool::new(dia, rc, 6.0, 2).unwrap();
            let cell = 0.1 + 0.1 * rnd();
            let mut d = Dexels::new(&stock, cell);
            let mut cells = d.dense_reference(&stock);
            let delta = pose_spacing(&tool, cell);
            let tilt = if case < 9 { 0.7 } else { 0.0 };
            let axis = |r: &mut dyn FnMut() -> f64| {
                Vector3::new(tilt * (r() - 0.5), tilt * (r() - 0.5), 1.0).normalize()
            };
            let (mut p, mut o) = (Vector3::new(6.0, 4.5, 1.0), axis(&mut rnd));
            let mut shared = SharedPose::new(d.ny);
            let mut total = 0.0;
            for _ in 0..15 {
                let p1 = Vector3::new(
                    (p.x + 2.0 * (rnd() - 0.5)).clamp(1.0, 11.0),
                    (p.y + 2.0 * (rnd() - 0.5)).clamp(1.0, 8.0),
                    -3.0 * rnd(),
                );
                let o1 = axis(&mut rnd);
                let step = Step {
                    p0: p,
                    p1,
                    o0: o,
                    o1,
                };
                let want = reference_step(&d, &mut cells, &tool, &step, delta);
                let got =
                    cut_step(&mut d, &tool, &step, delta, &mut shared).removed / (d.hx * d.hy);
                assert!((got - want).abs() <= 1e-12 * want.max(1.0), "{got} {want}");
                total += want;
                (p, o) = (p1, o1);
            }
            assert!(total > 100.0, "case {case} cuts {total} mm of dexels");
            for j in 0..d.ny {
                for i in 0..d.nx {
                    assert_eq!(d.dexel(i, j).intervals(), &cells[j * d.nx + i][..]);
                }
            }
        }
    }
}
