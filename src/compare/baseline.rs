//! Baseline schedules to compare feedopt with: what a program's feeds and a conventional
//! controller's planner would do on the same path.
//!
//! Both baselines are built on feedopt's own path geometry ([`crate::geometry::Path`]) and
//! expressed the way feedopt expresses its own schedule: b = u̇² piecewise linear in u, so ü
//! is constant between breakpoints (a [`Profile`]). A trapezoid (constant acceleration, then
//! constant feed, then constant deceleration) is exactly such a profile, since V² is linear in
//! distance at constant acceleration. So every schedule can be re-simulated by the one
//! [`crate::verify`] on the true path, and compared like for like.
//!
//! **Blocks.** A block is one knot interval of a span: one programmed move (CL point to CL
//! point) of the fitted path. Its length L = Δu is the tool tip's chord length on a moving span
//! (mm; u is the chord-length parameter, exact at the CL points; on a four-axis machine the
//! chord in joint space, a degree as a millimetre, and a feed caps u̇ at F Δu / |ΔP|), the tool's rotation (radians)
//! on a pure reorientation, and Δs on a joint-space path. Its *joint direction* is
//! d = Δq / L per axis (the change of each machine axis over the block per unit of u), from the
//! inverse kinematics at the block's two ends.
//!
//! **The controller plans in tool-tip space** (u, the tip's chord length, as LinuxCNC plans in
//! tool-tip mode and grbl on its Cartesian axes), and applies each machine axis's limits along
//! the block's joint direction, as if every axis moved in proportion over the block:
//! V ≤ min_q v_q / |d_q| and A ≤ min_q a_q / |d_q| (the programmed feed caps V too). This is
//! stricter than LinuxCNC in tool-tip mode, which limits the Cartesian and rotary *coordinates*
//! and does not check the joints at all; it is exact for a 3-axis Cartesian machine.

use crate::error::{Error, Result};
use crate::geometry::{Path, SpanKind};
use crate::kinematics::{Kinematics, MAX_AXES};
use crate::machine::Machine;

/// grbl's default junction deviation (`$11`), mm.
pub const DEFAULT_JUNCTION_DEVIATION_MM: f64 = 0.01;

/// A feed profile as b = u̇² at breakpoints, linear in u between them (ü constant), per span
/// of the path: `spans[i]` runs from u = 0 to the span's length, u strictly increasing.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    /// Per span: (u, b) breakpoints.
    pub spans: Vec<Vec<(f64, f64)>>,
}

/// One programmed move of the fitted path.
#[derive(Debug, Clone, PartialEq)]
pub struct Block {
    /// Span of the path and knot interval within it.
    pub span: usize,
    /// Knot interval within the span.
    pub index: usize,
    /// Where it starts and ends in the span's u.
    pub u0: f64,
    /// Where the block ends in the span's u.
    pub u1: f64,
    /// Δq / Δu per axis (mm or degrees per unit of u).
    pub joint_direction: [f64; MAX_AXES],
    /// Unit direction used for the corner angle: the tool tip's chord on a moving span, the
    /// normalised joint direction elsewhere.
    pub direction: [f64; MAX_AXES],
    /// What moves along the block.
    pub kind: SpanKind,
    /// The tool tip's travel per unit of u over the block, |ΔP| / Δu: 1 where u is the tip's
    /// chord; less on a four-axis machine's moving span, whose u also counts the rotary
    /// axis's turn ([`crate::geometry::ROTARY_MM_PER_RAD`]), so that a feed F of the tip
    /// caps u̇ at F / (|ΔP| / Δu) ([`Block::u_rate_cap`]).
    pub tip_per_u: f64,
    /// Source line of the CL point the block ends at.
    pub line: usize,
}

impl Block {
    /// L = Δu.
    pub fn length(&self) -> f64 {
        self.u1 - self.u0
    }

    /// The cap on u̇ that a cap `cap` on the tip's speed makes on a moving block (`None` where
    /// the tip does not move along it).
    pub fn u_rate_cap(&self, cap: f64) -> Option<f64> {
        (self.tip_per_u > 0.0).then(|| cap / self.tip_per_u)
    }
}

/// Every block of the path, in order.
pub fn blocks(path: &Path, kin: &Kinematics) -> Vec<Block> {
    let na = kin.n_axes();
    let mut out = Vec::new();
    for (si, span) in path.spans.iter().enumerate() {
        let knots = span.spline.knots();
        let jets: Vec<_> = knots
            .iter()
            .map(|&u| kin.axis_jets(&span.eval(u)))
            .collect();
        for k in 0..knots.len() - 1 {
            let len = knots[k + 1] - knots[k];
            let mut d = [0.0; MAX_AXES];
            for j in 0..na {
                d[j] = (jets[k + 1].q[j] - jets[k].q[j]) / len;
            }
            let mut dir = [0.0; MAX_AXES];
            let mut tip_per_u = 1.0;
            if span.kind == SpanKind::Moving {
                let (a, b) = (span.eval(knots[k]).value, span.eval(knots[k + 1]).value);
                for j in 0..3 {
                    dir[j] = b[j] - a[j];
                }
                // (1 within rounding where u is the tip's chord.)
                let r = dir[..3].iter().map(|x| x * x).sum::<f64>().sqrt() / len;
                if (r - 1.0).abs() > 1e-9 {
                    tip_per_u = r;
                }
            } else {
                dir[..na].copy_from_slice(&d[..na]);
            }
            let norm = dir.iter().map(|x| x * x).sum::<f64>().sqrt();
            if norm > 0.0 {
                dir.iter_mut().for_each(|x| *x /= norm);
            }
            out.push(Block {
                span: si,
                index: k,
                u0: knots[k],
                u1: knots[k + 1],
                joint_direction: d,
                direction: dir,
                kind: span.kind,
                tip_per_u,
                line: span.lines[k + 1],
            });
        }
    }
    out
}

/// The fastest u̇ at which every axis keeps its velocity limit along a block's joint
/// direction, and the largest |ü| that keeps every axis's acceleration limit (the smaller
/// side of each two-sided limit, so accelerating and braking share one value).
fn axis_limits(machine: &Machine, na: usize, d: &[f64; MAX_AXES]) -> (f64, f64) {
    let (mut v, mut a) = (f64::INFINITY, f64::INFINITY);
    for (j, axis) in machine.axes.iter().enumerate().take(na) {
        let dj = d[j].abs();
        if dj > 0.0 {
            let vl = if d[j] > 0.0 {
                axis.velocity.max
            } else {
                -axis.velocity.min
            };
            v = v.min(vl / dj);
            a = a.min(axis.acceleration.max.min(-axis.acceleration.min) / dj);
        }
    }
    (v, a)
}

/// Whether the path must stop between two consecutive blocks: at a span boundary where the
/// tool tip starts or stops moving (a reorientation on one side). Corners between moving
/// spans are passed at the junction speed.
fn must_stop(a: &Block, b: &Block) -> bool {
    a.span != b.span && (a.kind != SpanKind::Moving || b.kind != SpanKind::Moving)
}

// ---------------------------------------------------------------------------------------------
// (a) The programmed feed, as is.

/// The programmed feed run as is: u̇ constant per block at the block's programmed feed
/// (the span's feed cap: the program's feed, times the override, within the machine's maximum
/// feed; a rapid or a block without feed at the machine's maximum feed). A block that only
/// turns the tool with a programmed time (G93, or rotary axes alone at F) runs at its rate of
/// turn, the move's Δu/t (the span's cap, [`crate::geometry::Span::feed_caps`]: the whole move's, on every
/// piece of it); any other reorientation block at the fastest rate the axes' velocity limits
/// allow along it (the program gives no tool-tip feed for it).
///
/// No acceleration is planned: every change of feed (from rest at the start, between blocks,
/// to rest before a reorientation and at the end) is taken within one servo period `period`,
/// as a controller without look-ahead would, in the faster of the two blocks: b ramps
/// linearly over the distance the tip covers in that period, (F₁ + F₂)·T/2, so no block
/// runs above its own feed. A block too short for its ramps takes them over what it has (a
/// steeper ramp). Corners between moving spans are passed at the lower of the two feeds.
///
/// Returns `Ok(Err(reason))` when the program gives no feed somewhere and the machine
/// file no maximum feed (a joint-space path, for one).
pub fn programmed_feed(
    machine: &Machine,
    path: &Path,
    kin: &Kinematics,
    period: f64,
) -> Result<std::result::Result<Profile, String>> {
    let na = kin.n_axes();
    let blocks = blocks(path, kin);
    let mut feeds = Vec::with_capacity(blocks.len());
    for b in &blocks {
        let span = &path.spans[b.span];
        let f = match b.kind {
            SpanKind::Moving => b
                .u_rate_cap(span.feed_caps[b.index])
                .unwrap_or_else(|| axis_limits(machine, na, &b.joint_direction).0),
            SpanKind::Joint => f64::INFINITY,
            // (Each piece's own Δu over the move's whole time counted a move the geometry
            // cut into pieces once per piece: B0 B90 B0 at F9.8, 41,878 s for 1,102 s.)
            SpanKind::Reorientation => match span.feed_caps[b.index] {
                cap if cap.is_finite() => cap,
                _ => axis_limits(machine, na, &b.joint_direction).0,
            },
        };
        if !(f.is_finite() && f > 0.0) {
            return Ok(Err(format!(
                "no programmed feed for the move ending at line {} and no machine maximum feed",
                b.line
            )));
        }
        feeds.push(f);
    }
    // Speed at each junction: the lower of the two blocks' feeds (0 at rest and at stops).
    let n = blocks.len();
    let mut junction = vec![0.0f64; n + 1];
    for i in 1..n {
        if !must_stop(&blocks[i - 1], &blocks[i]) {
            junction[i] = feeds[i - 1].min(feeds[i]);
        }
    }
    let mut spans: Vec<Vec<(f64, f64)>> = vec![Vec::new(); path.spans.len()];
    for (i, b) in blocks.iter().enumerate() {
        let (f, c0, c1, len) = (feeds[i], junction[i], junction[i + 1], b.length());
        // Ramps within this block: up from the entry speed at its start, down to the exit
        // speed at its end, each over the distance one servo period covers.
        let mut x_in = 0.5 * (c0 + f) * period * f64::from(u8::from(c0 < f));
        let mut x_out = 0.5 * (c1 + f) * period * f64::from(u8::from(c1 < f));
        if x_in + x_out > len {
            let k = len / (x_in + x_out);
            x_in *= k;
            x_out *= k;
        }
        let pts = &mut spans[b.span];
        if pts.is_empty() {
            pts.push((b.u0, c0 * c0));
        }
        if x_in > 0.0 {
            pts.push((b.u0 + x_in, f * f));
        }
        if x_out > 0.0 && len - x_out > x_in {
            pts.push((b.u1 - x_out, f * f));
        }
        pts.push((b.u1, c1 * c1));
    }
    Ok(Ok(Profile { spans }))
}

// ---------------------------------------------------------------------------------------------
// (b) A controller's planner: per-block trapezoids, junction deviation.

/// One block as the controller planned it.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedBlock {
    /// The programmed move.
    pub block: Block,
    /// Nominal speed: the programmed feed and every axis's velocity limit along the block
    /// (u̇; mm/s of tool tip on a moving span).
    pub nominal: f64,
    /// Largest |ü| every axis's acceleration limit allows along the block.
    pub acceleration: f64,
    /// The junction speed at the block's start before the look-ahead passes (0 at stops).
    pub junction_limit: f64,
    /// Planned speeds at the block's start and end after the backward and forward passes.
    pub entry: f64,
    /// Planned speed at the block's end.
    pub exit: f64,
}

impl PlannedBlock {
    /// Peak speed of the block's trapezoid (the nominal speed if it is reached).
    pub fn peak(&self) -> f64 {
        let (a, l) = (self.acceleration, self.block.length());
        let tri = 0.5 * (2.0 * a * l + self.entry.powi(2) + self.exit.powi(2));
        tri.min(self.nominal.powi(2)).sqrt()
    }

    /// Time of the block's trapezoid, in closed form: accelerate from `entry` to the peak,
    /// cruise, brake to `exit`.
    pub fn time(&self) -> f64 {
        let (a, l, vp) = (self.acceleration, self.block.length(), self.peak());
        if !a.is_finite() {
            return l / vp;
        }
        let x1 = (vp * vp - self.entry.powi(2)) / (2.0 * a);
        let x2 = (vp * vp - self.exit.powi(2)) / (2.0 * a);
        let cruise = (l - x1 - x2).max(0.0);
        (vp - self.entry) / a + (vp - self.exit) / a + cruise / vp
    }
}

/// The controller's plan of the whole path.
#[derive(Debug, Clone, PartialEq)]
pub struct ControllerPlan {
    /// Every block, in path order.
    pub blocks: Vec<PlannedBlock>,
    /// Junction deviation δ used, mm.
    pub junction_deviation: f64,
}

/// grbl's junction speed (planner.c): the corner is taken as a circular arc of deviation δ
/// from the corner point, tangent to both blocks, whose centripetal acceleration is
/// `acceleration`: with θ the angle between the reversed incoming and the outgoing direction
/// (θ = 180° straight on, 90° at a right-angle corner, 0 on a reversal),
///
/// `v² = a · δ · sin(θ/2) / (1 − sin(θ/2))`  (the arc's radius is δ sin(θ/2)/(1 − sin(θ/2))).
///
/// Returns u̇ (mm/s); ∞ straight on, 0 on a reversal.
pub fn junction_speed(cos_turn: f64, acceleration: f64, deviation: f64) -> f64 {
    // grbl's junction_cos_theta is −(in · out) = −cos_turn; sin(θ/2) = √(½(1 − cos θ)).
    let cos_theta = -cos_turn;
    if cos_theta > 0.999_999 {
        return 0.0;
    }
    if cos_theta < -0.999_999 {
        return f64::INFINITY;
    }
    let s = (0.5 * (1.0 - cos_theta)).sqrt();
    (acceleration * deviation * s / (1.0 - s)).sqrt()
}

/// Plans the path as a controller with look-ahead does (grbl's planner; LinuxCNC's planner
/// with trapezoidal blocks is alike): per block a nominal speed and an acceleration from the
/// axes' limits along the block, a speed limit at every junction by the junction deviation
/// `deviation` (mm), then a backward pass (every block can brake to its exit speed) and a
/// forward pass (every block can reach its exit speed from its entry speed), and one trapezoid
/// per block.
///
/// The junction's centripetal acceleration is limited by every axis: the tool tip's direction
/// changes by Δe at the corner while the axes' directions change by Δd = d₂ − d₁, so a tip
/// acceleration a along the corner's arc moves axis q at a |Δd_q| / |Δe|; the junction's
/// acceleration is min_q a_q |Δe| / |Δd_q|. On a Cartesian machine (d = e) this is grbl's
/// `limit_value_by_axis_maximum` along the junction vector.
///
/// The path starts and ends at rest, and stops where a reorientation begins or ends.
pub fn plan_controller(
    machine: &Machine,
    path: &Path,
    kin: &Kinematics,
    deviation: f64,
) -> Result<ControllerPlan> {
    if !(deviation.is_finite() && deviation >= 0.0) {
        return Err(Error::Usage(format!(
            "--junction-deviation must be ≥ 0 mm, got {deviation}"
        )));
    }
    let na = kin.n_axes();
    let blocks = blocks(path, kin);
    let mut planned: Vec<PlannedBlock> = Vec::with_capacity(blocks.len());
    for b in blocks {
        let (v, a) = axis_limits(machine, na, &b.joint_direction);
        // Of the tip's speed on a moving span, of the rate of turn on a reorientation.
        let cap = path.spans[b.span].feed_caps[b.index];
        let cap = match b.kind {
            SpanKind::Moving => b.u_rate_cap(cap).unwrap_or(f64::INFINITY),
            _ => cap,
        };
        let nominal = v.min(cap);
        if !nominal.is_finite() {
            return Err(Error::Usage(format!(
                "the move ending at line {} has no speed limit: give a feed or the machine's \
                 maximum feed",
                b.line
            )));
        }
        planned.push(PlannedBlock {
            block: b,
            nominal,
            acceleration: a,
            junction_limit: 0.0,
            entry: 0.0,
            exit: 0.0,
        });
    }
    // Junction limits (block 0 starts at rest).
    for i in 1..planned.len() {
        let (p, n) = (&planned[i - 1], &planned[i]);
        let limit = if must_stop(&p.block, &n.block) {
            0.0
        } else {
            let (e1, e2) = (&p.block.direction, &n.block.direction);
            let cos_turn: f64 = (0..MAX_AXES).map(|j| e1[j] * e2[j]).sum();
            let de = (0..MAX_AXES)
                .map(|j| (e2[j] - e1[j]).powi(2))
                .sum::<f64>()
                .sqrt();
            let mut a = f64::INFINITY;
            for (j, axis) in machine.axes.iter().enumerate().take(na) {
                let dd = (n.block.joint_direction[j] - p.block.joint_direction[j]).abs();
                if dd > 0.0 {
                    let lim = axis.acceleration.max.min(-axis.acceleration.min);
                    a = a.min(lim * de / dd);
                }
            }
            junction_speed(cos_turn, a, deviation)
        };
        planned[i].junction_limit = limit.min(p.nominal).min(n.nominal);
    }
    let n = planned.len();
    // Speeds at the junctions: v[i] at the start of block i, v[n] = 0 at the end.
    let mut v: Vec<f64> = planned.iter().map(|p| p.junction_limit).collect();
    v.push(0.0);
    let reach =
        |v0: f64, p: &PlannedBlock| (v0 * v0 + 2.0 * p.acceleration * p.block.length()).sqrt();
    for i in (0..n).rev() {
        v[i] = v[i].min(reach(v[i + 1], &planned[i]));
    }
    for i in 0..n {
        v[i + 1] = v[i + 1].min(reach(v[i], &planned[i]));
    }
    for (i, p) in planned.iter_mut().enumerate() {
        p.entry = v[i];
        p.exit = v[i + 1];
    }
    Ok(ControllerPlan {
        blocks: planned,
        junction_deviation: deviation,
    })
}

impl ControllerPlan {
    /// Cycle time of the plan, in closed form (the sum of every block's trapezoid).
    pub fn time(&self) -> f64 {
        self.blocks.iter().map(PlannedBlock::time).sum()
    }

    /// The plan as b = u̇² at breakpoints: each trapezoid is exactly linear in u piecewise.
    pub fn profile(&self, path: &Path) -> Profile {
        let mut spans: Vec<Vec<(f64, f64)>> = vec![Vec::new(); path.spans.len()];
        for p in &self.blocks {
            let b = &p.block;
            let pts = &mut spans[b.span];
            if pts.is_empty() {
                pts.push((b.u0, p.entry.powi(2)));
            }
            let (l, a, vp) = (b.length(), p.acceleration, p.peak());
            if a.is_finite() {
                let x1 = ((vp * vp - p.entry.powi(2)) / (2.0 * a)).clamp(0.0, l);
                let x2 = ((vp * vp - p.exit.powi(2)) / (2.0 * a)).clamp(0.0, l - x1);
                let min_gap = 1e-12 * (1.0 + l);
                if x1 > min_gap {
                    pts.push((b.u0 + x1, vp * vp));
                }
                if x2 > min_gap && l - x1 - x2 > min_gap {
                    pts.push((b.u1 - x2, vp * vp));
                }
            }
            pts.push((b.u1, p.exit.powi(2)));
        }
        Profile { spans }
    }
}
