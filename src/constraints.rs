//! Constraints on V²: one span's axis and feed limits as linear rows on b = u̇² at stations.
//!
//! With b = u̇² and ü = ½ db/du, every axis moves as (eq. 28–39 written in u)
//!
//! - q̇ = q' u̇, so the velocity limit v_min ≤ q̇ ≤ v_max is `q'² b ≤ v²` (the side of q'),
//! - q̈ = q'' b + q' ü, so the acceleration limit is `a_min ≤ q'' b + q' ü ≤ a_max`,
//!
//! and the tool-tip feed is V = |P'| u̇, so `|P'|² b ≤ F²`. On a moving span u is close to arc
//! length and q', q'' are close to the effective tangent t_q and curvature K_q.
//!
//! Discretisation: stations u_0 … u_N at every CL knot of the span, each CL segment divided
//! evenly (the spline's q'' is linear between knots, so its extremes are at stations); the
//! velocity rows of all axes and the feed are merged into the single tightest bound
//! `b_i ≤ b_max_i`; the acceleration of every axis is bounded at *both ends* of every
//! interval ([`SpanProblem::interval_rows`]), with ü between stations as the problem's
//! [`Ramp`] says:
//!
//! - [`Ramp::Linear`] (the default): ü linear on each interval, from ü⁰ at its start to ü¹ at
//!   its end, b quadratic; each end's rows hold with that end's ü. ü⁰ and ü¹ are eliminated,
//!   so the rows stay linear in (b_k, b_{k+1}), and chosen after the solve
//!   ([`SpanProblem::ramp_ends`]).
//! - [`Ramp::Constant`] (seed 000; what COPP's solvers state): one ü = (b_{k+1} − b_k)/(2Δu)
//!   per interval, b linear.
//!
//! Why the default is the linear law: along a curve the ü the limits allow changes along an
//! interval (`(a − q'' b)/q'`, with q', q'' and b all moving). One ü per interval must meet
//! the tighter end and loses time of first order in Δu on every such ramp, so the cycle time
//! converged at first order and the refinement spent its stations halving intervals on curves
//! at high feed (NX's Röders finish on the machine's limits alone: 2.7 M stations, not
//! converged; LinuxCNC's `3D_Chips.ngc` sample at ×10,000 feed: 1.81 M). An ü that follows the
//! limit linearly loses time of second order. The price is that the rows are tight at both
//! ends of an interval, so the motion between stations exceeds a limit by O(Δu²) where the
//! constant law's slack at one end hid it: the refinement halves such intervals
//! ([`SpanProblem::overshoot`]).

use crate::geometry::{Span, SpanKind};
use crate::kinematics::{AxisJets, Kinematics};
use crate::machine::{Limit, Machine};

/// Which limit gives a station's velocity bound.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub enum Bound {
    /// The velocity limit of axis `j`.
    AxisVelocity(usize),
    /// The acceleration limit of axis `j`.
    AxisAcceleration(usize),
    /// The jerk limit of axis `j` (jerk-limited schedules).
    AxisJerk(usize),
    /// The programmed feed or the machine's maximum feed.
    Feed,
    /// The chord error of one interpolation period (seed 004).
    Chord,
    /// A process limit of the material model ([`crate::material`]): chip load, material
    /// removal rate, spindle power or the air-cut feed.
    Process(crate::material::ProcessLimit),
    /// Nothing binds (no finite bound).
    #[default]
    None,
}

impl Bound {
    /// Two words that tell every bound apart (for [`SpanProblem::fingerprint`]).
    fn words(self) -> [u64; 2] {
        match self {
            Bound::AxisVelocity(j) => [0, j as u64],
            Bound::AxisAcceleration(j) => [1, j as u64],
            Bound::AxisJerk(j) => [2, j as u64],
            Bound::Feed => [3, 0],
            Bound::Chord => [4, 0],
            Bound::Process(l) => [5, l as u64],
            Bound::None => [6, 0],
        }
    }
}

/// The chord-error bound of data-sampling interpolation (seed 004): a controller moves on
/// straight chords between setpoints one period T apart; on a tool-tip path of curvature κ at
/// feed V a chord of length V T strays from the curve by about κ (V T)²/8. Keeping that below δ
/// bounds the feed: `V² ≤ 8δ/(κ T²)`, i.e. `b ≤ 8δ / (κ T² |P'|²)` — one more velocity bound.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chord {
    /// δ, mm.
    pub tolerance: f64,
    /// T, s.
    pub period: f64,
}

impl Chord {
    /// κ |P'|² at a path point: `|P' × P''| / |P'|` (the tool tip's curvature times the squared
    /// speed of u); 0 on a straight piece or where the tip stands still.
    pub fn curvature_term(w: &crate::kinematics::PathJet) -> f64 {
        let (d1, d2) = (&w.d1, &w.d2);
        let speed = (d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2]).sqrt();
        if speed <= 0.0 {
            return 0.0;
        }
        let c = [
            d1[1] * d2[2] - d1[2] * d2[1],
            d1[2] * d2[0] - d1[0] * d2[2],
            d1[0] * d2[1] - d1[1] * d2[0],
        ];
        (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt() / speed
    }

    /// The bound on b at a path point (infinite where the path is straight).
    pub fn b_max(&self, w: &crate::kinematics::PathJet) -> f64 {
        let k = Self::curvature_term(w);
        if k > 0.0 {
            8.0 * self.tolerance / (k * self.period * self.period)
        } else {
            f64::INFINITY
        }
    }

    /// The chord error (mm) of one period at b there.
    pub fn error(&self, w: &crate::kinematics::PathJet, b: f64) -> f64 {
        Self::curvature_term(w) * b * self.period * self.period / 8.0
    }
}

/// Axis positions q and their u-derivatives q', q'' at every station of a span, for the
/// machine's axes only: station after station, `n_axes` values each (an [`AxisJets`] holds
/// [`crate::base::MAX_AXES`] of each, 192 bytes; a 3-axis machine's stations need 72).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StationJets {
    n_axes: usize,
    q: Vec<f64>,
    dq: Vec<f64>,
    ddq: Vec<f64>,
}

impl StationJets {
    /// No stations yet, room for `n`, `n_axes` axes each.
    pub fn with_capacity(n_axes: usize, n: usize) -> Self {
        StationJets {
            n_axes,
            q: Vec::with_capacity(n_axes * n),
            dq: Vec::with_capacity(n_axes * n),
            ddq: Vec::with_capacity(n_axes * n),
        }
    }

    /// `jets` at every station, `n_axes` axes each.
    pub fn from_jets(n_axes: usize, jets: &[AxisJets]) -> Self {
        let mut s = Self::with_capacity(n_axes, jets.len());
        for j in jets {
            s.push(j);
        }
        s
    }

    /// Number of stations.
    pub fn len(&self) -> usize {
        self.q.len().checked_div(self.n_axes).unwrap_or(0)
    }

    /// No station.
    pub fn is_empty(&self) -> bool {
        self.q.is_empty()
    }

    /// Appends a station's jets (its first `n_axes` axes).
    pub fn push(&mut self, j: &AxisJets) {
        let n = self.n_axes;
        self.q.extend_from_slice(&j.q[..n]);
        self.dq.extend_from_slice(&j.dq[..n]);
        self.ddq.extend_from_slice(&j.ddq[..n]);
    }

    /// Appends station `i` of `from`.
    pub fn copy_from(&mut self, from: &StationJets, i: usize) {
        let r = from.at(i);
        self.q.extend_from_slice(&from.q[r.clone()]);
        self.dq.extend_from_slice(&from.dq[r.clone()]);
        self.ddq.extend_from_slice(&from.ddq[r]);
    }

    /// Stations `a..=b`.
    pub fn range(&self, a: usize, b: usize) -> StationJets {
        let r = self.at(a).start..self.at(b).end;
        StationJets {
            n_axes: self.n_axes,
            q: self.q[r.clone()].to_vec(),
            dq: self.dq[r.clone()].to_vec(),
            ddq: self.ddq[r].to_vec(),
        }
    }

    fn at(&self, i: usize) -> std::ops::Range<usize> {
        i * self.n_axes..(i + 1) * self.n_axes
    }

    /// q at station `i`, per axis.
    pub fn q(&self, i: usize) -> &[f64] {
        &self.q[self.at(i)]
    }

    /// q' at station `i`, per axis.
    pub fn dq(&self, i: usize) -> &[f64] {
        &self.dq[self.at(i)]
    }

    /// q'' at station `i`, per axis.
    pub fn ddq(&self, i: usize) -> &[f64] {
        &self.ddq[self.at(i)]
    }

    /// Station `i`'s q, q', q'' (the machine's axes), borrowed.
    pub fn view(&self, i: usize) -> JetRef<'_> {
        JetRef {
            q: self.q(i),
            dq: self.dq(i),
            ddq: self.ddq(i),
        }
    }

    /// Station `i` as an [`AxisJets`] (zero past `n_axes`).
    pub fn get(&self, i: usize) -> AxisJets {
        let mut j = AxisJets::default();
        let n = self.n_axes;
        j.q[..n].copy_from_slice(self.q(i));
        j.dq[..n].copy_from_slice(self.dq(i));
        j.ddq[..n].copy_from_slice(self.ddq(i));
        j
    }
}

/// One station's q, q', q'' per axis, borrowed from a [`StationJets`] or an [`AxisJets`].
#[derive(Debug, Clone, Copy)]
pub struct JetRef<'a> {
    /// Axis positions, mm or degrees.
    pub q: &'a [f64],
    /// dq/du.
    pub dq: &'a [f64],
    /// d²q/du².
    pub ddq: &'a [f64],
}

impl<'a> From<&'a AxisJets> for JetRef<'a> {
    fn from(j: &'a AxisJets) -> Self {
        JetRef {
            q: &j.q,
            dq: &j.dq,
            ddq: &j.ddq,
        }
    }
}

/// The discretised problem of one span, ready for a solver.
#[derive(Debug, Clone)]
pub struct SpanProblem {
    /// Stations u_0 … u_N (every knot of the span, and even subdivisions).
    pub u: Vec<f64>,
    /// Tightest velocity bound on b at each station (`f64::INFINITY`: none).
    pub b_max: Vec<f64>,
    /// The limit that gives `b_max`.
    pub b_max_by: Vec<Bound>,
    /// |P'(u)| at each station (0 on a reorientation span).
    pub tip_speed: Vec<f64>,
    /// Axis positions and u-derivatives at each station ([`StationJets`]: the machine's axes
    /// only).
    pub jets: StationJets,
    /// Acceleration limit of each axis.
    pub acceleration: Vec<Limit>,
    /// Acceleration rows that shape the feasible set at each station (bit 2j: axis j's
    /// `≤ a_max` row, bit 2j+1: its `≥ a_min` row); the others are implied (see
    /// [`essential_rows`]).
    pub essential: Vec<u16>,
    /// b at the first and last station (0: at rest).
    pub b_start: f64,
    pub b_end: f64,
    /// How ü varies between stations ([`Ramp`]).
    pub ramp: Ramp,
}

impl SpanProblem {
    /// Appends to `out` the exact bits of everything a solver reads of this problem, so that
    /// two problems with equal fingerprints have the same solution (a drilling cycle's plunge
    /// at every hole; [`crate::optimize`] solves such spans once). The axis positions q are
    /// left out: no solver reads them, only their derivatives and the bounds (which is what
    /// makes the same move at another place the same problem).
    pub fn fingerprint(&self, out: &mut Vec<u64>) {
        // Every field named, so that a new one cannot be missed here.
        let SpanProblem {
            u,
            b_max,
            b_max_by,
            tip_speed,
            jets,
            acceleration,
            essential,
            b_start,
            b_end,
            ramp,
        } = self;
        let StationJets {
            n_axes,
            q: _,
            dq,
            ddq,
        } = jets;
        out.extend([
            u.len() as u64,
            *n_axes as u64,
            b_start.to_bits(),
            b_end.to_bits(),
            *ramp as u64,
        ]);
        for v in [u, b_max, tip_speed, dq, ddq] {
            out.push(v.len() as u64);
            out.extend(v.iter().map(|x| x.to_bits()));
        }
        out.extend(b_max_by.iter().flat_map(|b| b.words()));
        out.extend(
            acceleration
                .iter()
                .flat_map(|l| [l.min.to_bits(), l.max.to_bits()]),
        );
        out.extend(essential.iter().map(|&e| u64::from(e)));
    }

    /// Discretises `span` at the stations of [`stations`].
    pub fn build(span: &Span, kin: &Kinematics, machine: &Machine, grid: Grid) -> Self {
        Self::at_stations(span, kin, machine, stations(span, grid))
    }

    /// [`SpanProblem::at_stations`], the velocity bounds tightened by `chord` where it is given
    /// ([`SpanProblem::apply_chord`]): the problem every solve of a path states on its stations
    /// (the refinement's, the jerk-limited windows', the sweep's steps), so that none of them
    /// leaves the chord bound out.
    pub fn at_stations_within(
        span: &Span,
        kin: &Kinematics,
        machine: &Machine,
        u: Vec<f64>,
        chord: Option<&Chord>,
    ) -> Self {
        let mut p = Self::at_stations(span, kin, machine, u);
        if let Some(c) = chord {
            p.apply_chord(span, c);
        }
        p
    }

    /// Discretises `span` at the given stations (increasing, from 0 to the span's length).
    pub fn at_stations(span: &Span, kin: &Kinematics, machine: &Machine, u: Vec<f64>) -> Self {
        let feed = station_feed_caps(span, &u);
        let acceleration = axis_accelerations(kin, machine);
        let mut p = SpanProblem {
            u: Vec::with_capacity(u.len()),
            b_max: Vec::with_capacity(u.len()),
            b_max_by: Vec::with_capacity(u.len()),
            tip_speed: Vec::with_capacity(u.len()),
            jets: StationJets::with_capacity(acceleration.len(), u.len()),
            acceleration,
            essential: Vec::with_capacity(u.len()),
            b_start: 0.0,
            b_end: 0.0,
            ramp: Ramp::default(),
        };
        for (&ui, &cap) in u.iter().zip(&feed) {
            p.push_station(span, kin, machine, None, ui, cap);
        }
        p
    }

    /// Appends station `u` (after the last one) with feed cap `cap` (mm/s) and, if given, the
    /// chord bound of `chord`: its jets, its merged velocity bound and its essential rows.
    fn push_station(
        &mut self,
        span: &Span,
        kin: &Kinematics,
        machine: &Machine,
        chord: Option<&Chord>,
        u: f64,
        cap: (f64, Option<crate::material::ProcessLimit>),
    ) {
        let w = span.eval(u);
        let jet = kin.axis_jets(&w);
        let pb = point_bound(machine, &self.acceleration, &jet, &w, span.kind, cap, chord);
        self.u.push(u);
        self.b_max.push(pb.b_max);
        self.b_max_by.push(pb.by);
        self.tip_speed.push(pb.tip_speed);
        self.jets.push(&jet);
        self.essential.push(pb.essential);
    }

    /// The same problem with a station added inside every interval `k` of `split` (sorted,
    /// distinct), at `at(k)` (strictly between u_k and u_{k+1}); the existing stations keep
    /// their data, only the new ones are evaluated ([`SpanProblem::with_added`]).
    pub fn with_inserted(
        &self,
        span: &Span,
        kin: &Kinematics,
        machine: &Machine,
        chord: Option<&Chord>,
        split: &[usize],
        at: impl Fn(usize) -> f64,
    ) -> SpanProblem {
        let added: Vec<(usize, f64)> = split.iter().map(|&k| (k, at(k))).collect();
        self.with_added(span, kin, machine, chord, &added)
    }

    /// The same problem with every interval `k` of `ks` (`(k, m)`, sorted by k, distinct)
    /// divided into `m` equal parts at [`divide`]'s stations, as [`crate::optimize`]'s local
    /// refinement divides them ([`SpanProblem::with_added`]). The same problem, bit for bit,
    /// as [`SpanProblem::at_stations_within`] on the divided stations, which evaluated every
    /// station again each round.
    pub fn with_divided(
        &self,
        span: &Span,
        kin: &Kinematics,
        machine: &Machine,
        chord: Option<&Chord>,
        ks: &[(usize, usize)],
    ) -> SpanProblem {
        let u = &self.u;
        let added: Vec<(usize, f64)> = ks
            .iter()
            .flat_map(|&(k, m)| {
                (1..m).map(move |j| (k, u[k] + (u[k + 1] - u[k]) * j as f64 / m as f64))
            })
            .collect();
        self.with_added(span, kin, machine, chord, &added)
    }

    /// The same problem with the stations `added` (`(k, u)`: u strictly inside interval k, in
    /// order): the existing stations keep their data, only the new ones are evaluated. Every
    /// CL knot is a station, so each interval lies within one CL move and a new station takes
    /// that move's feed cap.
    fn with_added(
        &self,
        span: &Span,
        kin: &Kinematics,
        machine: &Machine,
        chord: Option<&Chord>,
        added: &[(usize, f64)],
    ) -> SpanProblem {
        let mut p = self.empty_like(self.u.len() + added.len());
        let mut next = added.iter().peekable();
        for i in 0..self.u.len() {
            p.copy_station(self, i);
            while let Some(&&(_, u)) = next.peek().filter(|(k, _)| *k == i) {
                next.next();
                debug_assert!(u >= self.u[i] && u <= self.u[i + 1]);
                let cap = span.interval_cap(u);
                p.push_station(span, kin, machine, chord, u, cap);
            }
        }
        p
    }

    /// The stations `i` with `keep[i]` (the first and the last must be kept), as a problem.
    pub fn select(&self, keep: &[bool]) -> SpanProblem {
        let n = keep.iter().filter(|&&k| k).count();
        let mut p = self.empty_like(n);
        debug_assert!(keep[0] && keep[keep.len() - 1]);
        for (i, _) in keep.iter().enumerate().filter(|(_, k)| **k) {
            p.copy_station(self, i);
        }
        p
    }

    /// No stations yet (room for `n`), the same limits and end speeds.
    fn empty_like(&self, n: usize) -> SpanProblem {
        SpanProblem {
            u: Vec::with_capacity(n),
            b_max: Vec::with_capacity(n),
            b_max_by: Vec::with_capacity(n),
            tip_speed: Vec::with_capacity(n),
            jets: StationJets::with_capacity(self.n_axes(), n),
            acceleration: self.acceleration.clone(),
            essential: Vec::with_capacity(n),
            b_start: self.b_start,
            b_end: self.b_end,
            ramp: self.ramp,
        }
    }

    fn copy_station(&mut self, from: &SpanProblem, i: usize) {
        self.u.push(from.u[i]);
        self.b_max.push(from.b_max[i]);
        self.b_max_by.push(from.b_max_by[i]);
        self.tip_speed.push(from.tip_speed[i]);
        self.jets.copy_from(&from.jets, i);
        self.essential.push(from.essential[i]);
    }

    /// Tightens the velocity bounds of a moving span by the chord error of `chord` (seed 004).
    /// The acceleration row masks stay valid: a lower bound on b only adds implied rows.
    pub fn apply_chord(&mut self, span: &Span, chord: &Chord) {
        if span.kind != SpanKind::Moving {
            return;
        }
        for (i, &u) in self.u.iter().enumerate() {
            let b = chord.b_max(&span.eval(u));
            if b < self.b_max[i] {
                self.b_max[i] = b;
                self.b_max_by[i] = Bound::Chord;
            }
        }
    }

    /// Stations `a..=b` as a problem of their own, with b fixed at both ends to the given
    /// values (a window of a long span).
    pub fn window(&self, a: usize, b: usize, b_start: f64, b_end: f64) -> SpanProblem {
        SpanProblem {
            u: self.u[a..=b].to_vec(),
            b_max: self.b_max[a..=b].to_vec(),
            b_max_by: self.b_max_by[a..=b].to_vec(),
            tip_speed: self.tip_speed[a..=b].to_vec(),
            jets: self.jets.range(a, b),
            acceleration: self.acceleration.clone(),
            essential: self.essential[a..=b].to_vec(),
            b_start,
            b_end,
            ramp: self.ramp,
        }
    }

    /// Number of intervals N.
    pub fn intervals(&self) -> usize {
        self.u.len() - 1
    }

    /// Number of axes.
    pub fn n_axes(&self) -> usize {
        self.acceleration.len()
    }

    /// Length Δu_k of interval k.
    pub fn du(&self, k: usize) -> f64 {
        self.u[k + 1] - self.u[k]
    }

    /// The range of ü that every axis's acceleration row allows at station `i` with b there
    /// (`q'' b + q' ü` within its limits, solved for ü).
    ///
    /// An axis whose q' is below [`STILL_AXIS`] of the largest there (an axis turning round,
    /// q' through 0) bounds b alone (`q'' b` within its limits, which `b_max` holds): solved
    /// for ü its row is `(a − q'' b)/q'`, a rounding error over almost nothing at b = b*.
    pub fn udd_range(&self, i: usize, b: f64) -> (f64, f64) {
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        let (dq, ddq) = (self.jets.dq(i), self.jets.ddq(i));
        let still = STILL_AXIS * dq.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
        for (j, lim) in self.acceleration.iter().enumerate() {
            let (d, dd) = (dq[j], ddq[j]);
            if d.abs() > still {
                let (x, y) = ((lim.max - dd * b) / d, (lim.min - dd * b) / d);
                lo = lo.max(x.min(y));
                hi = hi.min(x.max(y));
            }
        }
        (lo, hi)
    }

    /// ü of interval k at its station `i` (k or k + 1): its end of `ends` (the profile's
    /// [`Ramp::Linear`] ü, [`SpanProblem::ramp_ends`]), or without them the constant
    /// (b_{k+1} − b_k) / (2Δu_k).
    pub fn path_acceleration(
        &self,
        b: &[f64],
        ends: Option<&[[f64; 2]]>,
        k: usize,
        i: usize,
    ) -> f64 {
        match ends {
            Some(e) => e[k][usize::from(i > k)],
            None => (b[k + 1] - b[k]) / (2.0 * self.du(k)),
        }
    }

    /// Acceleration q̈ = q'' b + q' ü of axis `j` at station `i`, with interval `k`'s ü there
    /// (`k` is `i − 1` or `i`; `ends` as in [`SpanProblem::path_acceleration`]).
    pub fn axis_acceleration(
        &self,
        b: &[f64],
        ends: Option<&[[f64; 2]]>,
        k: usize,
        i: usize,
        j: usize,
    ) -> f64 {
        self.jets.ddq(i)[j] * b[i] + self.jets.dq(i)[j] * self.path_acceleration(b, ends, k, i)
    }

    /// Interval `k`'s acceleration rows as rows `cx b_k + cy b_{k+1} ≤ d` on its two stations'
    /// b, under the problem's [`Ramp`]; only the essential rows ([`essential_rows`]) and those
    /// with a nonzero coefficient.
    ///
    /// - [`Ramp::Constant`]: every essential row of both ends, `q''_e b_e + q'_e ü ≤ a_max` (and
    ///   `≥ a_min`) with the interval's one ü = (b_{k+1} − b_k)/(2Δu).
    /// - [`Ramp::Linear`]: ü⁰ at the start and ü¹ at the end are free but for
    ///   `ü⁰ + ü¹ = (b_{k+1} − b_k)/Δu`; each end's rows bound its own ü between lines in its b,
    ///   `L(b) ≤ ü ≤ U(b)` (the envelopes of [`essential_rows`]). Eliminating ü⁰ and ü¹ (Fourier–
    ///   Motzkin) leaves, for every pair of an upper line at the start and one at the end,
    ///   `(b_{k+1} − b_k)/Δu ≤ U⁰(b_k) + U¹(b_{k+1})`, and the same with the lower lines and
    ///   `≥`. (The pairs of one end alone, `L(b) ≤ U(b)`, say that b is below the
    ///   acceleration-limited b* there, which `b_max` holds already; the rows with q' = 0, a
    ///   bound on b alone, are in b* too.)
    ///
    /// `cache` keeps the last two stations' bounds on ü (a pass over the intervals in either
    /// direction computes each station's once).
    pub fn interval_rows(&self, k: usize, cache: &mut LineCache, mut f: impl FnMut(IntervalRow)) {
        let du = self.du(k);
        match self.ramp {
            Ramp::Linear if !self.steep(k, cache) => self.linear_rows(k, du, cache, &mut f),
            _ => {
                let inv = 1.0 / (2.0 * du);
                for (e, at_end) in [(k, false), (k + 1, true)] {
                    let (dq, ddq) = (self.jets.dq(e), self.jets.ddq(e));
                    for (j, lim) in self.acceleration.iter().enumerate() {
                        let rows = self.essential[e] >> (2 * j) & 3;
                        let (d, dd) = (dq[j], ddq[j]);
                        if rows == 0 || (d == 0.0 && dd == 0.0) {
                            continue;
                        }
                        // dd b_e + d (y − x)/(2Δu) as cx x + cy y.
                        let (mut cx, mut cy) = (-d * inv, d * inv);
                        if at_end {
                            cy += dd;
                        } else {
                            cx += dd;
                        }
                        if rows & 1 != 0 {
                            f(IntervalRow {
                                cx,
                                cy,
                                d: lim.max,
                                scale: lim.max.abs(),
                                limits: [Some((j, true, 1.0)), None],
                            });
                        }
                        if rows & 2 != 0 {
                            f(IntervalRow {
                                cx: -cx,
                                cy: -cy,
                                d: -lim.min,
                                scale: lim.min.abs(),
                                limits: [Some((j, false, -1.0)), None],
                            });
                        }
                    }
                }
            }
        }
    }

    /// Whether a bound on ü at an end of interval `k` is steeper in b than 1/Δu:
    /// |q''/q'| Δu > 1 for an axis that bounds ü there. Such an interval takes the constant
    /// law's rows ([`SpanProblem::interval_rows`]) and its ü is its chord's
    /// ([`SpanProblem::ramp_ends`]): with ü linear its rows join two steep lines into one that
    /// is not max-closed. The 20 COPP paths end with q' falling to 0 over their last
    /// intervals, and there the reach pass's largest b one station before the end left the
    /// next none (taking only the intervals where every bound is steep, or where the
    /// parameter's speed falls by half, left the greedy profile 0.09 % above the optimum of the
    /// same 1,000 stations, and the refined solves of the twenty paths 6 times slower). On a
    /// curve an axis turning round makes its own bound steep, so those intervals too keep the
    /// constant law (NX's Röders finish on the machine's limits: 637k stations, where the
    /// linear law everywhere took 407k and the constant law 2.7 M); as Δu falls there are
    /// fewer of them.
    fn steep(&self, k: usize, cache: &mut LineCache) -> bool {
        let du = self.du(k);
        let (a, b) = cache.pair(self, k);
        a.iter().chain(b).any(|l| l.beta.abs() * du > 1.0)
    }

    /// [`SpanProblem::interval_rows`] under [`Ramp::Linear`] on an interval that is not
    /// [steep](SpanProblem::steep).
    fn linear_rows(
        &self,
        k: usize,
        du: f64,
        cache: &mut LineCache,
        f: &mut impl FnMut(IntervalRow),
    ) {
        let inv = 1.0 / du;
        // b stays well above 0 inside: as a quadratic Bézier on the interval b has the
        // control points b_k, P = b_k + Δu ü⁰ (= b_{k+1} − Δu ü¹) and b_{k+1}, and
        // P ≥ (b_k + b_{k+1})/4 keeps b ≥ 0, and from or to rest (b = 0 at an end) keeps
        // ü away from 0 there, so the interval takes finite time, at most twice the
        // linear law's. Near a stop, without it, a convex b bottoms out below 0 between
        // two small b, or reaches b = 0 at a station with ü = 0 or still braking. It is
        // ü⁰ ≥ (b_{k+1} − 3 b_k)/(4Δu): against each upper bound on ü⁰ a row, and against
        // each lower bound on ü¹ (ü⁰ = S − ü¹) another. (A linear b has P at the mean.)
        let quarter = 0.25 * inv;
        let (start, end) = cache.pair(self, k);
        for p in start.iter().filter(|p| p.upper) {
            // (y − 3x)/(4Δu) ≤ α_p + β_p x
            f(IntervalRow {
                cx: -3.0 * quarter - p.beta,
                cy: quarter,
                d: p.alpha,
                scale: p.alpha.abs(),
                limits: [Some((p.axis, p.max, p.per_limit)), None],
            });
        }
        for q in end.iter().filter(|q| !q.upper) {
            // α_q + β_q y ≤ (3y − x)/(4Δu)
            f(IntervalRow {
                cx: quarter,
                cy: q.beta - 3.0 * quarter,
                d: -q.alpha,
                scale: q.alpha.abs(),
                limits: [Some((q.axis, q.max, -q.per_limit)), None],
            });
        }
        for p in start {
            for q in end.iter().filter(|q| q.upper == p.upper) {
                // upper: (y − x)/Δu ≤ α_p + β_p x + α_q + β_q y; lower: ≥, negated.
                let s = if p.upper { 1.0 } else { -1.0 };
                f(IntervalRow {
                    cx: s * (-inv - p.beta),
                    cy: s * (inv - q.beta),
                    d: s * (p.alpha + q.alpha),
                    scale: p.alpha.abs() + q.alpha.abs(),
                    limits: [
                        Some((p.axis, p.max, s * p.per_limit)),
                        Some((q.axis, q.max, s * q.per_limit)),
                    ],
                });
            }
        }
    }

    /// The lines that station `i`'s essential rows with q' ≠ 0 put on ü: `ü ≤ α + β b`
    /// (upper) or `ü ≥ α + β b` (lower), each given to `f`.
    fn each_udd_line(&self, i: usize, mut f: impl FnMut(UddLine)) {
        let (dq, ddq) = (self.jets.dq(i), self.jets.ddq(i));
        let rows = self.essential[i];
        let still = STILL_AXIS * dq.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
        for (j, lim) in self.acceleration.iter().enumerate() {
            let (d, dd) = (dq[j], ddq[j]);
            if d.abs() <= still || rows >> (2 * j) & 3 == 0 {
                continue;
            }
            for (bit, a, max) in [(1, lim.max, true), (2, lim.min, false)] {
                if rows >> (2 * j) & bit != 0 {
                    // dd b + d ü ≤ a_max (or ≥ a_min): ü on the side the sign of d gives.
                    f(UddLine {
                        alpha: a / d,
                        beta: -dd / d,
                        upper: max == (d > 0.0),
                        axis: j,
                        max,
                        per_limit: 1.0 / d,
                    });
                }
            }
        }
    }

    /// ü at both ends of every interval of the profile `b` under [`Ramp::Linear`]: with
    /// `S = (b_{k+1} − b_k)/Δu`, ü⁰ + ü¹ = S, and each end's ü within what every axis allows
    /// there ([`SpanProblem::udd_range`]), ü⁰ as close to S/2 as those ranges let it be. So b is
    /// linear in u wherever that meets the limits, and bends only as much as they make it;
    /// where no split meets them (a profile off the discretisation's feasible set by rounding),
    /// the middle of the conflicting range. `None` under [`Ramp::Constant`].
    pub fn ramp_ends(&self, b: &[f64]) -> Option<Vec<[f64; 2]>> {
        if self.ramp == Ramp::Constant {
            return None;
        }
        let range: Vec<(f64, f64)> = (0..b.len())
            .map(|i| self.udd_range(i, b[i].max(0.0)))
            .collect();
        let mut cache = LineCache::default();
        Some(
            (0..self.intervals())
                .map(|k| {
                    let (x, y) = (b[k].max(0.0), b[k + 1].max(0.0));
                    let s = (y - x) / self.du(k);
                    if self.steep(k, &mut cache) {
                        return [0.5 * s; 2];
                    }
                    let ((l0, u0), (l1, u1)) = (range[k], range[k + 1]);
                    // ü⁰ ≥ (y − 3x)/(4Δu): b well above 0 inside ([`SpanProblem::interval_rows`]).
                    let floor = (y - 3.0 * x) / (4.0 * self.du(k));
                    let (lo, hi) = (l0.max(s - u1).max(floor), u0.min(s - l1));
                    let a0 = if lo <= hi {
                        (0.5 * s).clamp(lo, hi)
                    } else {
                        0.5 * (lo + hi)
                    };
                    [a0, s - a0]
                })
                .collect(),
        )
    }
}

impl SpanProblem {
    /// How far interval `k` of profile `b` (ü at its ends `ends`, [`Ramp::Linear`]) exceeds an
    /// acceleration limit *between* its stations, estimated: the largest `q̈/limit − 1` of any
    /// axis at a quarter, half and three quarters of the interval (0 if none is above), with
    /// every axis's q' and q'' continued from the start station by the q''' their difference
    /// gives (exact where the span is a cubic spline in the axes, as on a 3-axis machine).
    ///
    /// The rows hold the acceleration at the stations; inside, q̈ = q'' b + q' ü with b
    /// quadratic and ü linear departs from them by O(Δu²). Under [`Ramp::Constant`] the rows
    /// leave an O(Δu) slack at one end that hides it; under [`Ramp::Linear`] both ends are
    /// often on their limit, and a grid fine enough for the cycle time can still exceed a limit
    /// between stations by more than the re-simulation allows. The adaptive refinement halves
    /// such intervals before the final solve.
    pub fn overshoot(&self, b: &[f64], ends: &[[f64; 2]], k: usize) -> f64 {
        let h = self.du(k);
        let (b0, [a0, a1]) = (b[k].max(0.0), ends[k]);
        let alpha = (a1 - a0) / h;
        let (dq0, ddq0, ddq1) = (self.jets.dq(k), self.jets.ddq(k), self.jets.ddq(k + 1));
        let mut worst: f64 = 0.0;
        for f in [0.25, 0.5, 0.75] {
            let t = f * h;
            let (bt, at) = (b0 + t * (2.0 * a0 + alpha * t), a0 + alpha * t);
            for (j, lim) in self.acceleration.iter().enumerate() {
                let q3 = (ddq1[j] - ddq0[j]) / h;
                let q2 = ddq0[j] + q3 * t;
                let q1 = dq0[j] + t * (ddq0[j] + 0.5 * q3 * t);
                let acc = q2 * bt + q1 * at;
                worst = worst.max(acc / lim.max - 1.0).max(acc / lim.min - 1.0);
            }
        }
        worst
    }
}

/// Below this share of the largest |q'| at a station an axis's acceleration row bounds b
/// alone under [`Ramp::Linear`] ([`SpanProblem::udd_range`]): its ü term is then at most 1e-9
/// of the others' (on a circle through an axis-aligned point, q' of the axis turning round was
/// 2.6e-15, and its row solved for ü gave −2147 mm/s² out of b's last bits).
pub const STILL_AXIS: f64 = 1e-9;

/// How ü = ½ db/du varies between two stations of an acceleration-limited profile.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Ramp {
    /// ü constant on each interval, b linear in u (seed 000; COPP's TOPP2-RA and COPP2-SOCP
    /// state the same problem): every axis's acceleration is bounded at both ends of the
    /// interval with that one ü. On a curve the ü the limits allow changes along the
    /// interval, and the one ü must meet the tighter end: on every acceleration ramp along a
    /// curve the profile loses time of first order in Δu.
    Constant,
    /// ü linear on each interval, from ü⁰ at its start to ü¹ at its end (b quadratic,
    /// `b_{k+1} − b_k = Δu (ü⁰ + ü¹)`, [`crate::motion::Law::Quadratic`]), each end's rows
    /// with its own ü ([`SpanProblem::interval_rows`]): a ramp follows a limit that changes
    /// along the curve to second order in Δu.
    #[default]
    Linear,
}

/// One acceleration row of an interval, `cx b_k + cy b_{k+1} ≤ d`
/// ([`SpanProblem::interval_rows`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntervalRow {
    /// Coefficient of b_k.
    pub cx: f64,
    /// Coefficient of b_{k+1}.
    pub cy: f64,
    /// Right-hand side.
    pub d: f64,
    /// The row's natural size, to normalise it (the limit's magnitude, or the sum of the two
    /// ü bounds' constants).
    pub scale: f64,
    /// The limits in `d`: (axis, whether it is a_max (else a_min), ∂d/∂limit); the second
    /// only for a [`Ramp::Linear`] row, which joins a row of each end.
    pub limits: [Option<(usize, bool, f64)>; 2],
}

/// The bounds on ü of the last two stations [`SpanProblem::interval_rows`] asked for.
#[derive(Debug)]
pub struct LineCache {
    at: [usize; 2],
    lines: [Vec<UddLine>; 2],
}

impl Default for LineCache {
    fn default() -> Self {
        LineCache {
            at: [usize::MAX; 2],
            lines: [Vec::new(), Vec::new()],
        }
    }
}

impl LineCache {
    /// Stations k's and k + 1's lines, computing those not kept.
    fn pair(&mut self, p: &SpanProblem, k: usize) -> (&[UddLine], &[UddLine]) {
        for i in [k, k + 1] {
            if !self.at.contains(&i) {
                // The slot not holding the other station of the pair.
                let slot = usize::from(self.at[0] == k || self.at[0] == k + 1);
                self.at[slot] = i;
                let lines = &mut self.lines[slot];
                lines.clear();
                p.each_udd_line(i, |l| lines.push(l));
            }
        }
        let a = usize::from(self.at[1] == k);
        (&self.lines[a], &self.lines[1 - a])
    }
}

/// A line `ü ≤ α + β b` (upper) or `ü ≥ α + β b` of one acceleration row at a station.
#[derive(Debug, Clone, Copy)]
struct UddLine {
    alpha: f64,
    beta: f64,
    upper: bool,
    axis: usize,
    /// a_max's row (else a_min's).
    max: bool,
    /// ∂α/∂limit = 1/q'.
    per_limit: f64,
}

/// Every velocity bound of one path point merged: what [`point_bound`] finds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointBound {
    /// The tightest bound on b there (`f64::INFINITY`: none).
    pub b_max: f64,
    /// The limit that sets it.
    pub by: Bound,
    /// The acceleration rows that are edges of the feasible polygon there
    /// ([`essential_rows`]).
    pub essential: u16,
    /// |P'| there (0 off a moving span).
    pub tip_speed: f64,
}

/// The one merge of a path point's velocity bounds, for the stations and for the jerk
/// solver's collocation points alike: the axes' velocity rows and the feed cap
/// ([`velocity_bound`]; the cap named by its process limit when the material model set it),
/// the acceleration polygon's largest b* under them ([`essential_rows`], which also picks the
/// rows that stay), then, on a moving span, the chord bound of `chord` (a lower bound on b
/// only adds implied rows, so the rows stay valid).
pub fn point_bound(
    machine: &Machine,
    acceleration: &[Limit],
    jet: &AxisJets,
    w: &crate::kinematics::PathJet,
    kind: SpanKind,
    cap: (f64, Option<crate::material::ProcessLimit>),
    chord: Option<&Chord>,
) -> PointBound {
    let moving = kind == SpanKind::Moving;
    let tip_speed = if moving {
        (w.d1[0].powi(2) + w.d1[1].powi(2) + w.d1[2].powi(2)).sqrt()
    } else {
        0.0
    };
    let mut best = velocity_bound(machine, acceleration.len(), jet, tip_speed, cap.0);
    // On a reorientation the cap is on u̇ itself, the rate of turn (rad/s; [`Span::feed_caps`]).
    if kind == SpanKind::Reorientation && cap.0 * cap.0 < best.0 {
        best = (cap.0 * cap.0, Bound::Feed);
    }
    if let (Bound::Feed, Some(limit)) = (best.1, cap.1) {
        best.1 = Bound::Process(limit);
    }
    let (essential, b_star, by) = essential_rows(jet, acceleration, best.0);
    // b* is implied by the rows kept; stating it as the bound helps the solver's scaling.
    if b_star < best.0 {
        best = (b_star, by);
    }
    if let Some(c) = chord.filter(|_| moving) {
        let b = c.b_max(w);
        if b < best.0 {
            best = (b, Bound::Chord);
        }
    }
    PointBound {
        b_max: best.0,
        by: best.1,
        essential,
        tip_speed,
    }
}

/// The tightest bound on b from every axis's velocity limit (q'² b ≤ v², on the side of q')
/// and the feed cap (|P'|² b ≤ F², where the tip moves: `tip_speed` = |P'| > 0), with the
/// limit that sets it: the velocity rows of one point of the path merged into one.
pub fn velocity_bound(
    machine: &Machine,
    n_axes: usize,
    jet: &AxisJets,
    tip_speed: f64,
    cap: f64,
) -> (f64, Bound) {
    let mut best = (f64::INFINITY, Bound::None);
    for (j, axis) in machine.axes.iter().enumerate().take(n_axes) {
        let d = jet.dq[j];
        if d != 0.0 {
            let v = if d > 0.0 {
                axis.velocity.max
            } else {
                axis.velocity.min
            };
            let b = (v / d).powi(2);
            if b < best.0 {
                best = (b, Bound::AxisVelocity(j));
            }
        }
    }
    if tip_speed > 0.0 && cap.is_finite() {
        let b = (cap / tip_speed).powi(2);
        if b < best.0 {
            best = (b, Bound::Feed);
        }
    }
    best
}

/// The acceleration limit of each axis the kinematics drives.
fn axis_accelerations(kin: &Kinematics, machine: &Machine) -> Vec<Limit> {
    machine
        .axes
        .iter()
        .take(kin.n_axes())
        .map(|a| a.acceleration)
        .collect()
}

/// How finely to place stations on a span.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// Largest distance between stations (in u).
    pub spacing: f64,
    /// Fewest intervals per CL segment.
    pub min_parts: usize,
}

/// Stations of a span: every knot and every break of its process caps
/// ([`crate::geometry::ProcessCaps`]), and each piece between them divided into equal parts, at
/// least `grid.min_parts` per knot segment and none longer than `grid.spacing`; at least two
/// intervals in all.
pub fn stations(span: &Span, grid: Grid) -> Vec<f64> {
    let mut merged;
    let knots = match &span.process {
        Some(pc) if pc.u.len() > 1 => {
            merged = span.spline.knots().to_vec();
            merged.extend_from_slice(&pc.u[1..]);
            merged.sort_by(f64::total_cmp);
            merged.dedup();
            &merged[..]
        }
        _ => span.spline.knots(),
    };
    let min_parts = grid.min_parts.max(if knots.len() == 2 { 2 } else { 1 });
    let spacing = grid.spacing;
    let mut u = Vec::with_capacity(knots.len());
    u.push(knots[0]);
    for w in knots.windows(2) {
        let len = w[1] - w[0];
        // (a hair of tolerance so a segment exactly `spacing` long stays one part)
        let parts = ((len / spacing * (1.0 - 1e-9)).ceil() as usize).max(min_parts);
        for p in 1..parts {
            u.push(w[0] + len * p as f64 / parts as f64);
        }
        u.push(w[1]);
    }
    u
}

/// Feed cap at each station: the lower cap of the CL moves (or the process model's pieces,
/// [`Span::interval_cap`]) that contain its two neighbouring intervals, with the process limit
/// that sets it. Every CL point and every process break is a station, so each interval lies
/// within one move and one piece, and b linear between stations keeps that cap over the whole
/// interval. (Taking every move that merely touches the neighbourhood would smear each cap one
/// interval into the next move: an O(Δu) error at every CL point of a program whose feed
/// changes block by block.)
fn station_feed_caps(span: &Span, u: &[f64]) -> Vec<(f64, Option<crate::material::ProcessLimit>)> {
    let n = u.len() - 1;
    let interval_cap = |k: usize| span.interval_cap(0.5 * (u[k] + u[k + 1]));
    let none = (f64::INFINITY, None);
    (0..=n)
        .map(|i| {
            let before = if i > 0 { interval_cap(i - 1) } else { none };
            let after = if i < n { interval_cap(i) } else { none };
            if before.0 <= after.0 { before } else { after }
        })
        .collect()
}

/// The acceleration rows at one station that are edges of its feasible polygon.
///
/// At station e every acceleration row involves only (b_e, ü) — with ü of either neighbouring
/// interval, but the same rows for both. So the rows and `0 ≤ b ≤ b_max` cut out one polygon in
/// the (b, ü) plane. A row that is no edge of it is implied by the others and can be dropped
/// without changing the problem: an exact presolve, which leaves typically two to four of the
/// 2 × axes rows. Writing each row as a line ü = α + β b, the polygon is bounded above by the
/// lower envelope of the "ü ≤" lines and below by the upper envelope of the "ü ≥" lines; the
/// rows kept are those on an envelope somewhere on the feasible b range.
///
/// Returns the row mask, the largest feasible b* (the acceleration-limited maximum-velocity
/// curve at the station, at most `b_max`) and the limit that sets it.
pub fn essential_rows(jet: &AxisJets, limits: &[Limit], b_max: f64) -> (u16, f64, Bound) {
    const ALL: u16 = u16::MAX;
    // (α, β, row bit, is an upper bound on ü)
    let mut lines: [(f64, f64, u16, bool); 2 * crate::kinematics::MAX_AXES] =
        [(0.0, 0.0, 0, false); 2 * crate::kinematics::MAX_AXES];
    let mut nl = 0;
    let mut b_hi = b_max;
    let mut b_rows: u16 = 0; // rows with q' = 0: a bound on b alone
    let mut b_row_bound = f64::INFINITY;
    for (j, lim) in limits.iter().enumerate() {
        let (d, dd) = (jet.dq[j], jet.ddq[j]);
        for (bit, a, is_max) in [
            (1u16 << (2 * j), lim.max, true),
            (1u16 << (2 * j + 1), lim.min, false),
        ] {
            if d != 0.0 {
                // dd b + d ü ≤ a (is_max) or ≥ a: ü on the side given by the sign of d.
                lines[nl] = (a / d, -dd / d, bit, is_max == (d > 0.0));
                nl += 1;
            } else if dd != 0.0 && (a / dd) > 0.0 {
                // dd b ≤ a_max (dd > 0) or dd b ≥ a_min (dd < 0): b ≤ a/dd.
                let bound = a / dd;
                if bound < b_row_bound {
                    b_row_bound = bound;
                    b_rows = bit;
                }
            }
        }
    }
    let mut keep: u16 = 0;
    if b_row_bound <= b_hi {
        b_hi = b_row_bound;
        keep |= b_rows;
    }
    let row_axis = |bits: u16| Bound::AxisAcceleration(bits.trailing_zeros() as usize / 2);
    if nl == 0 {
        return if b_hi.is_finite() {
            (
                keep,
                b_hi,
                if keep != 0 {
                    row_axis(keep)
                } else {
                    Bound::None
                },
            )
        } else {
            (ALL, b_max, Bound::None)
        };
    }
    let lines = &lines[..nl];
    // The "ü ≤" and "ü ≥" lines apart, each in the order given (the envelopes take the first
    // of equal lines).
    const MAX_LINES: usize = 2 * crate::kinematics::MAX_AXES;
    let (mut ups, mut lows) = ([(0.0, 0.0, 0u16); MAX_LINES], [(0.0, 0.0, 0u16); MAX_LINES]);
    let (mut nu, mut nw) = (0, 0);
    for l in lines {
        if l.3 {
            ups[nu] = (l.0, l.1, l.2);
            nu += 1;
        } else {
            lows[nw] = (l.0, l.1, l.2);
            nw += 1;
        }
    }
    let (ups, lows) = (&ups[..nu], &lows[..nw]);
    let upper = |b: f64| {
        ups.iter()
            .map(|l| (l.0 + l.1 * b, l.2))
            .fold((f64::INFINITY, 0u16), |m, x| if x.0 < m.0 { x } else { m })
    };
    let lower = |b: f64| {
        lows.iter()
            .map(|l| (l.0 + l.1 * b, l.2))
            .fold(
                (f64::NEG_INFINITY, 0u16),
                |m, x| if x.0 > m.0 { x } else { m },
            )
    };
    // Breakpoints: every pairwise intersection inside (0, b_hi).
    let mut pts = [0.0; 2 + MAX_LINES * (MAX_LINES - 1) / 2];
    let mut np = 2;
    pts[1] = b_hi;
    for (i, a) in lines.iter().enumerate() {
        for c in &lines[i + 1..] {
            if a.1 != c.1 {
                let b = (c.0 - a.0) / (a.1 - c.1);
                if b > 0.0 && b < b_hi {
                    pts[np] = b;
                    np += 1;
                }
            }
        }
    }
    let pts = &mut pts[..np];
    pts.sort_unstable_by(f64::total_cmp);
    // The gap U(b) − L(b) is concave and ≥ 0 at b = 0: the feasible b form [0, b*].
    let gap = |b: f64| upper(b).0 - lower(b).0;
    let mut b_star = b_hi;
    let mut g1 = gap(pts[0]);
    for w in pts.windows(2) {
        let g0 = g1;
        g1 = gap(w[1]);
        if g1 < 0.0 {
            b_star = if g0 > 0.0 {
                w[0] + (w[1] - w[0]) * g0 / (g0 - g1)
            } else {
                w[0]
            };
            break;
        }
    }
    if !(b_star > 0.0 && b_star.is_finite()) {
        // Degenerate (only rest is feasible here) or unbounded: keep every row.
        return (ALL, b_max, Bound::None);
    }
    if b_star < b_hi {
        keep = 0; // the b-only rows are no edges if the envelopes close the polygon first
    }
    let mut prev = 0.0;
    for &p in pts.iter().skip(1).chain(std::iter::once(&b_star)) {
        let p = p.min(b_star);
        if p > prev {
            let mid = 0.5 * (prev + p);
            keep |= upper(mid).1 | lower(mid).1;
            prev = p;
        }
        if p >= b_star {
            break;
        }
    }
    // The rows meeting at b = 0 and at b* (vertices) are edges adjacent to the kept ones.
    keep |= upper(0.0).1 | lower(0.0).1 | upper(b_star).1 | lower(b_star).1;
    let by = if b_star < b_hi {
        row_axis(upper(b_star).1)
    } else if b_rows != 0 && b_hi < b_max {
        row_axis(b_rows)
    } else {
        Bound::None
    };
    (keep, b_star, by)
}

/// Stations `u` with every interval k of `ks` (pairs (k, m), sorted by k, distinct k) divided
/// into m equal parts.
pub(crate) fn divide(u: &[f64], ks: &[(usize, usize)]) -> Vec<f64> {
    let extra: usize = ks.iter().map(|&(_, m)| m.saturating_sub(1)).sum();
    let mut out = Vec::with_capacity(u.len() + extra);
    let mut next = ks.iter().peekable();
    for k in 0..u.len() - 1 {
        out.push(u[k]);
        if let Some(&&(_, m)) = next.peek().filter(|(kk, _)| *kk == k) {
            for j in 1..m {
                out.push(u[k] + (u[k + 1] - u[k]) * j as f64 / m as f64);
            }
            next.next();
        }
    }
    out.push(u[u.len() - 1]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (no dependency needed for a unit test).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn range(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.next()
        }
    }

    fn row_ok(jet: &AxisJets, limits: &[Limit], b: f64, udd: f64) -> bool {
        limits.iter().enumerate().all(|(j, l)| {
            let a = jet.ddq[j] * b + jet.dq[j] * udd;
            a <= l.max * (1.0 + 1e-9) && a >= l.min * (1.0 + 1e-9)
        })
    }

    fn kept_ok(jet: &AxisJets, limits: &[Limit], keep: u16, b: f64, udd: f64) -> bool {
        limits.iter().enumerate().all(|(j, l)| {
            let a = jet.ddq[j] * b + jet.dq[j] * udd;
            (keep >> (2 * j) & 1 == 0 || a <= l.max) && (keep >> (2 * j + 1) & 1 == 0 || a >= l.min)
        })
    }

    #[test]
    fn dropped_rows_are_implied_by_the_kept_ones() {
        let mut rng = Lcg(7);
        for case in 0..2000 {
            let na = 1 + case % 5;
            let mut jet = AxisJets::default();
            let limits: Vec<Limit> = (0..na)
                .map(|j| {
                    // Some axes do not move along the path at all, or only curve.
                    jet.dq[j] = if rng.next() < 0.15 {
                        0.0
                    } else {
                        rng.range(-2.0, 2.0)
                    };
                    jet.ddq[j] = if rng.next() < 0.15 {
                        0.0
                    } else {
                        rng.range(-0.05, 0.05)
                    };
                    Limit {
                        min: -rng.range(100.0, 3000.0),
                        max: rng.range(100.0, 3000.0),
                    }
                })
                .collect();
            let b_max = rng.range(1e3, 1e6);
            let (keep, b_star, _) = essential_rows(&jet, &limits, b_max);
            assert!(b_star <= b_max && b_star > 0.0);
            // Any (b, ü) with 0 ≤ b ≤ b* that meets the kept rows meets every row.
            for _ in 0..200 {
                let b = rng.range(0.0, b_star);
                let udd = rng.range(-1e4, 1e4);
                if kept_ok(&jet, &limits, keep, b, udd) {
                    assert!(
                        row_ok(&jet, &limits, b, udd),
                        "case {case}: b {b} ü {udd} keep {keep:b}"
                    );
                }
            }
            // b* itself is feasible: the ü allowed by every row there form a non-empty interval.
            let b = b_star * (1.0 - 1e-9);
            let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
            let mut reachable = true;
            for (j, l) in limits.iter().enumerate() {
                let (d, dd) = (jet.dq[j], jet.ddq[j]);
                if d == 0.0 {
                    reachable &= dd * b <= l.max * (1.0 + 1e-9) && dd * b >= l.min * (1.0 + 1e-9);
                } else {
                    let (x, y) = ((l.max - dd * b) / d, (l.min - dd * b) / d);
                    lo = lo.max(x.min(y));
                    hi = hi.min(x.max(y));
                }
            }
            reachable &= lo <= hi + 1e-6 * (1.0 + hi.abs());
            assert!(reachable, "case {case}: b* {b_star} not feasible");
        }
    }
}
