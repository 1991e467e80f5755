//! Property tests on seeded random paths: the two solvers against each other, and the schedule
//! against the machine.
//!
//! Two families of random smooth paths, drawn from a tiny deterministic generator (an LCG, so a
//! failure names a seed that reproduces it):
//!
//! - **5-axis CL paths** on a double swivel head (`head_head`): the tool tip on a curve of a few
//!   random Fourier terms plus a drift, the tool tilted 10–40° and swinging about the vertical,
//!   random asymmetric axis limits, a random maximum feed and random programmed feeds;
//! - **joint-space paths** (`joint`, 2–7 axes): q(s) from a few random Fourier terms with the
//!   analytic dq/ds and d²q/ds² given as columns, random asymmetric limits.
//!
//! For each path both solvers run at `stations: Some(1000)` and the test asserts:
//!
//! - Clarabel reports `Optimal`;
//! - |T_reach − T_clarabel| / T_clarabel < 0.5 % (the issue's requirement at 1,000 stations)
//!   and T_reach ≥ T_clarabel (1 − 1e-7) (both solve the same discretisation; Clarabel's is its
//!   optimum). Clarabel stops at a relative duality gap of 1e-6, so its time can exceed the
//!   optimum by a few 1e-7 (measured: reach below it by up to 1.5e-7 on some of the 240 paths
//!   at 1,000 stations, and by 0.6–4.6e-7 on all 40 at 20,000): reach must stay above the
//!   default solve by that tolerance, and where it is lower by more than 1e-7 Clarabel is
//!   re-run with a 100× tighter gap and reach must be within 1e-7 of that;
//! - no NaN or infinity anywhere in either schedule (t, v, a and every axis's q, q̇, q̈), time
//!   increasing, feed ≥ 0, the cycle time the last station's time;
//! - every axis's peak velocity and acceleration ratio (the report's, at both ends of every
//!   interval) and the schedule's own q̇, q̈ at every station within 1 + 1e-6 of the limit; the
//!   tool-tip feed within the machine's maximum; b within each station's bound b_max;
//! - on every path, the default pipeline (which adds stations until the re-simulation at the
//!   servo period verifies), with the two solvers in turn, returns a verified schedule.
//!
//! The comparisons use `refine_until_verified: false`: otherwise each solver's schedule is
//! refined where *its* re-simulation fails, the grids differ (e.g. 1,128 vs 1,129 stations)
//! and the times are no longer of the same discretisation.
//!
//! The default run checks 240 paths (120 of each family) at 1,000 stations with both solvers,
//! in two tests that run in parallel: about 16 s in the test profile on 2 cores. The
//! `#[ignore]`d runs check 1,000 more paths, and compare the solvers at 20,000 stations on 40
//! of them, where they must agree to 1e-4 (`cargo test --release --test properties --
//! --ignored`: about 80 s on 2 cores).

use std::path::PathBuf;
use std::time::Instant;

use feedopt::machine::Machine;
use feedopt::optimize::{Options, Solution, optimize, optimize_joint};
use feedopt::report::Summary;
use feedopt::solver::{SolverKind, Status};
use feedopt::toolpath::joint_csv::JointPath;
use feedopt::toolpath::{ClPoint, Feed, Toolpath};
use nalgebra::Vector3;

/// A 64-bit linear congruential generator (Knuth's MMIX constants), top 53 bits as a double.
struct Lcg(u64);

impl Lcg {
    fn new(seed: u64) -> Lcg {
        let mut g = Lcg(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03);
        for _ in 0..4 {
            g.next_u64();
        }
        g
    }

    fn next_u64(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        self.0
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform integer in [lo, hi].
    fn int(&mut self, lo: usize, hi: usize) -> usize {
        lo + (self.next_u64() >> 33) as usize % (hi - lo + 1)
    }

    /// An asymmetric limit `[−max·U(0.7, 1.3), max]` with max in [lo, hi), as JSON.
    fn limit(&mut self, lo: f64, hi: f64) -> String {
        let max = self.range(lo, hi);
        let min = -max * self.range(0.7, 1.3);
        format!("[{min}, {max}]")
    }
}

const TAU: f64 = std::f64::consts::TAU;

/// A random path and its machine.
enum Case {
    Cl { machine: Machine, path: Toolpath },
    Joint { machine: Machine, path: JointPath },
}

impl Case {
    fn machine(&self) -> &Machine {
        match self {
            Case::Cl { machine, .. } | Case::Joint { machine, .. } => machine,
        }
    }

    /// Solves on a fixed grid of `stations` (no stations added after the re-simulation, so
    /// both solvers see the same discretisation).
    fn solve(&self, stations: usize, kind: SolverKind) -> feedopt::error::Result<Solution> {
        self.solve_with(&Options {
            stations: Some(stations),
            solver_kind: kind,
            refine_until_verified: false,
            ..Options::default()
        })
    }

    fn solve_with(&self, options: &Options) -> feedopt::error::Result<Solution> {
        match self {
            Case::Cl { machine, path } => optimize(machine, path, options),
            Case::Joint { machine, path } => optimize_joint(machine, path, options),
        }
    }
}

/// A random 5-axis head_head CL path (the tip on a smooth curve, tool tilt 10–40°).
fn random_cl(seed: u64) -> Case {
    let mut g = Lcg::new(seed);
    // Machine: asymmetric limits in sensible ranges, a maximum feed.
    let tool_length = g.range(100.0, 300.0);
    let machine_json = format!(
        r#"{{"name": "random head_head {seed}",
            "kinematics": {{"type": "head_head", "tool_length": {tool_length}}},
            "axes": {{"X": {{"velocity": {}, "acceleration": {}}},
                     "Y": {{"velocity": {}, "acceleration": {}}},
                     "Z": {{"velocity": {}, "acceleration": {}}},
                     "C": {{"velocity": {}, "acceleration": {}}},
                     "A": {{"velocity": {}, "acceleration": {}}}}},
            "feed": {{"max": {}}}}}"#,
        g.limit(200.0, 600.0),
        g.limit(1000.0, 5000.0),
        g.limit(200.0, 600.0),
        g.limit(1000.0, 5000.0),
        g.limit(150.0, 400.0),
        g.limit(800.0, 3000.0),
        g.limit(60.0, 180.0),
        g.limit(300.0, 1200.0),
        g.limit(30.0, 120.0),
        g.limit(200.0, 800.0),
        g.range(80.0, 250.0),
    );
    let machine = Machine::from_json("random.json".as_ref(), &machine_json).expect("machine");

    // Tip: drift along a random direction plus a few Fourier terms (amplitude ~ A/m²).
    let length = g.range(60.0, 250.0);
    let heading = g.range(0.0, TAU);
    let drift = Vector3::new(heading.cos(), heading.sin(), g.range(-0.2, 0.2)) * length;
    let amp = g.range(5.0, 40.0);
    let terms = g.int(1, 3);
    let coef: Vec<(Vector3<f64>, Vector3<f64>)> = (1..=terms)
        .map(|m| {
            let s = amp / (m * m) as f64;
            let mut v = || Vector3::new(g.range(-s, s), g.range(-s, s), g.range(-0.3 * s, 0.3 * s));
            (v(), v())
        })
        .collect();
    // Tool: tilt θ2 in [10°, 40°], azimuth θ1 a drift plus Fourier terms.
    let tilt_mid = g.range(15.0, 35.0);
    let tilt_amp = g.range(0.0, (tilt_mid - 10.0).min(40.0 - tilt_mid));
    let (tilt_freq, tilt_phase) = (g.int(1, 3) as f64, g.range(0.0, TAU));
    let az0 = g.range(0.0, TAU);
    let az_drift = g.range(-1.5, 1.5);
    let az_terms: Vec<(f64, f64)> = (1..=g.int(0, 2))
        .map(|m| (g.range(-0.6, 0.6) / m as f64, g.range(0.0, TAU)))
        .collect();
    // Programmed feeds: 1–3 blocks of a random feed (or none: the maximum applies).
    let n = g.int(60, 250);
    let blocks = g.int(1, 3);
    let feeds: Vec<Feed> = (0..blocks)
        .map(|_| {
            if g.unit() < 0.2 {
                Feed::Unspecified
            } else {
                Feed::Programmed(g.range(30.0, 200.0))
            }
        })
        .collect();
    let points = (0..=n)
        .map(|k| {
            let s = k as f64 / n as f64;
            let mut p = drift * s;
            for (m, (a, b)) in coef.iter().enumerate() {
                let w = TAU * (m + 1) as f64 * s;
                p += a * w.cos() + b * w.sin();
            }
            let t2 = (tilt_mid + tilt_amp * (TAU * tilt_freq * s + tilt_phase).sin()).to_radians();
            let mut t1 = az0 + az_drift * s;
            for (m, (a, ph)) in az_terms.iter().enumerate() {
                t1 += a * (TAU * (m + 1) as f64 * s + ph).sin();
            }
            let o = Vector3::new(t2.sin() * t1.sin(), -t2.sin() * t1.cos(), t2.cos());
            ClPoint {
                p,
                o,
                feed: feeds[(k * blocks / (n + 1)).min(blocks - 1)],
                rotary: None,
                line: k + 1,
            }
        })
        .collect();
    Case::Cl {
        machine,
        path: Toolpath {
            source: PathBuf::from(format!("random_{seed}.cls")),
            points,
            ..Default::default()
        },
    }
}

/// A random joint-space path of 2–7 axes with analytic dq/ds, d²q/ds².
fn random_joint(seed: u64) -> Case {
    let mut g = Lcg::new(seed);
    let na = g.int(2, 7);
    let names: Vec<String> = (0..na).map(|j| format!("j{j}")).collect();
    let axes: Vec<String> = names
        .iter()
        .map(|n| {
            format!(
                r#""{n}": {{"velocity": {}, "acceleration": {}}}"#,
                g.limit(0.5, 2.0),
                g.limit(2.0, 10.0)
            )
        })
        .collect();
    let machine_json = format!(
        r#"{{"name": "random joint {seed}", "kinematics": {{"type": "joint"}}, "axes": {{{}}}}}"#,
        axes.join(", ")
    );
    let machine = Machine::from_json("random.json".as_ref(), &machine_json).expect("machine");
    let len = g.range(0.5, 3.0);
    let rows = g.int(101, 601);
    // q_j(s) = c_j + Σ_m a_jm sin(ω_m s + φ_jm), ω_m = 2π m / len.
    let terms: Vec<Vec<(f64, f64, f64)>> = (0..na)
        .map(|_| {
            (1..=g.int(1, 4))
                .map(|m| {
                    let a = g.range(-0.5, 0.5) / m as f64;
                    (a, TAU * m as f64 / len, g.range(0.0, TAU))
                })
                .collect()
        })
        .collect();
    let offsets: Vec<f64> = (0..na).map(|_| g.range(-1.0, 1.0)).collect();
    let (mut s, mut q, mut dq, mut ddq) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for k in 0..rows {
        let sk = len * k as f64 / (rows - 1) as f64;
        let (mut r0, mut r1, mut r2) = ([0.0; 8], [0.0; 8], [0.0; 8]);
        for j in 0..na {
            r0[j] = offsets[j];
            for &(a, w, ph) in &terms[j] {
                let (sn, cs) = (w * sk + ph).sin_cos();
                r0[j] += a * sn;
                r1[j] += a * w * cs;
                r2[j] -= a * w * w * sn;
            }
        }
        s.push(sk);
        q.push(r0);
        dq.push(r1);
        ddq.push(r2);
    }
    let path = JointPath {
        source: PathBuf::from(format!("random_{seed}.csv")),
        axes: names,
        lines: (2..rows + 2).collect(),
        s,
        q,
        dq: Some(dq),
        ddq: Some(ddq),
        dddq: None,
    };
    Case::Joint { machine, path }
}

/// The case of a seed: even seeds CL paths, odd seeds joint-space paths.
fn case(seed: u64) -> Case {
    if seed % 2 == 0 {
        random_cl(seed)
    } else {
        random_joint(seed)
    }
}

/// Checks one schedule against the machine; `Err` says what failed.
fn check_schedule(case: &Case, sol: &Solution, what: &str) -> Result<(), String> {
    let m = case.machine();
    let na = m.axes.len();
    let tol = 1e-6;
    let st = &sol.schedule.stations;
    let mut t_prev = -1.0;
    let sch = &sol.schedule;
    for (i, s) in st.iter().enumerate() {
        let finite = [s.t, s.v, s.a, s.u, s.s]
            .into_iter()
            .chain(sch.q(i)[..na].iter().copied())
            .chain(sch.qd(i)[..na].iter().copied())
            .chain(sch.qdd(i)[..na].iter().copied())
            .all(f64::is_finite);
        if !finite {
            return Err(format!("{what}: station {i} not finite: {s:?}"));
        }
        if s.t < t_prev || (s.t == t_prev && s.span == st[i - 1].span) {
            return Err(format!("{what}: time does not increase at station {i}"));
        }
        t_prev = s.t;
        if s.v < 0.0 {
            return Err(format!("{what}: negative feed at station {i}"));
        }
        if let Some(f) = m.feed_max {
            if s.v > f * (1.0 + tol) {
                return Err(format!(
                    "{what}: feed {} above the maximum {f} at station {i}",
                    s.v
                ));
            }
        }
        for (j, axis) in m.axes.iter().enumerate() {
            let (rv, ra) = (
                axis.velocity.ratio(sch.qd(i)[j]),
                axis.acceleration.ratio(sch.qdd(i)[j]),
            );
            if rv > 1.0 + tol || ra > 1.0 + tol {
                return Err(format!(
                    "{what}: axis {} at station {i}: velocity ratio {rv}, acceleration ratio {ra}",
                    axis.name
                ));
            }
        }
    }
    let last = st.last().ok_or(format!("{what}: empty schedule"))?;
    if (last.t - sol.schedule.cycle_time).abs() > 1e-12 * sol.schedule.cycle_time {
        return Err(format!(
            "{what}: cycle time {} but the last station is at {}",
            sol.schedule.cycle_time, last.t
        ));
    }
    if !(sol.schedule.cycle_time.is_finite() && sol.schedule.cycle_time > 0.0) {
        return Err(format!("{what}: cycle time {}", sol.schedule.cycle_time));
    }
    for (si, (p, x)) in sol.problems.iter().zip(&sol.solutions).enumerate() {
        for (i, (&b, &bmax)) in x.b.iter().zip(&p.b_max).enumerate() {
            if !(b.is_finite() && b >= -tol * bmax.min(1.0) && b <= bmax * (1.0 + tol)) {
                return Err(format!(
                    "{what}: span {si} station {i}: b = {b} outside [0, {bmax}]"
                ));
            }
        }
    }
    let summary = Summary::new(m, "random", sol);
    for (name, p) in &summary.axes {
        if !(p.peak_velocity_ratio <= 1.0 + tol && p.peak_acceleration_ratio <= 1.0 + tol) {
            return Err(format!("{what}: axis {name} peaks {p:?}"));
        }
    }
    Ok(())
}

/// The convex program's objective at a solution's profiles: eq. 43 with b linear between
/// stations, summed over the spans.
fn objective(sol: &Solution) -> f64 {
    sol.problems
        .iter()
        .zip(&sol.solutions)
        .map(|(p, s)| {
            feedopt::motion::interval_times(&p.u, &s.b, Default::default())
                .expect("finite")
                .iter()
                .sum::<f64>()
        })
        .sum()
}

/// What one comparison found.
struct Compared {
    /// (T_reach − T_clarabel) / T_clarabel.
    gap: f64,
}

/// Solves `case` with both solvers at `stations`, checks both schedules, and compares the
/// cycle times: `max_gap` relative, and reach never below Clarabel by more than 1e-7.
fn compare(seed: u64, stations: usize, max_gap: f64) -> Result<Compared, String> {
    let case = case(seed);
    let kind = if seed % 2 == 0 { "CL" } else { "joint" };
    let tag = format!("seed {seed} ({kind}, {stations} stations)");
    let c = case
        .solve(stations, SolverKind::Clarabel)
        .map_err(|e| format!("{tag}: Clarabel: {e}"))?;
    let r = case
        .solve(stations, SolverKind::Reach)
        .map_err(|e| format!("{tag}: reach: {e}"))?;
    if c.status != Status::Optimal {
        return Err(format!("{tag}: Clarabel status {:?}", c.status));
    }
    check_schedule(&case, &c, &format!("{tag}: Clarabel"))?;
    check_schedule(&case, &r, &format!("{tag}: reach"))?;
    // The program's objective, which both solvers minimise (the schedules' times differ from
    // it by O(Δu³) an interval under the linear-ü law).
    let (tc, tr) = (objective(&c), objective(&r));
    let gap = (tr - tc) / tc;
    if gap.abs() >= max_gap {
        return Err(format!(
            "{tag}: reach {tr} vs Clarabel {tc}: {gap:+e} (limit {max_gap:e})"
        ));
    }
    // Clarabel stops at a relative duality gap of `tol_gap` (1e-6): its cycle time may sit up
    // to that far above the optimum, and reach was measured up to 1.3e-7 below it. Where reach
    // is below by more than 1e-7, re-solve with a 100× tighter gap: reach must then be within
    // 1e-7 of it (measured: 3e-8 at worst), and never below the default solve by its tolerance.
    let tol_gap = clarabel_tol_gap();
    if tr < tc * (1.0 - tol_gap) {
        return Err(format!(
            "{tag}: reach {tr} beats the convex optimum {tc} by more than Clarabel's gap \
             tolerance {tol_gap:e}"
        ));
    }
    if tr < tc * (1.0 - 1e-7) {
        let mut options = Options {
            stations: Some(stations),
            refine_until_verified: false,
            ..Options::default()
        };
        options.solver.tol_gap = 1e-2 * tol_gap;
        let tight = case
            .solve_with(&options)
            .map_err(|e| format!("{tag}: Clarabel (tight gap): {e}"))?;
        let tt = objective(&tight);
        if tr < tt * (1.0 - 1e-7) {
            return Err(format!(
                "{tag}: reach {tr} beats the convex optimum {tc} (tight gap: {tt}, {:?})",
                tight.status
            ));
        }
    }
    // Every path (of both families) at 1,000 stations: the default pipeline (stations added
    // until the re-simulation at the servo period verifies), with the two solvers in turn,
    // returns a schedule that verifies.
    if stations == 1000 {
        let solver_kind = if (seed / 2) % 2 == 0 {
            SolverKind::Clarabel
        } else {
            SolverKind::Reach
        };
        let v = case
            .solve_with(&Options {
                stations: Some(stations),
                solver_kind,
                ..Options::default()
            })
            .map_err(|e| format!("{tag}: default pipeline: {e}"))?;
        let w = v.verification.worst_ratio();
        if !v.verification.verified || w > 1.0 + Options::default().verify.tolerance {
            return Err(format!(
                "{tag}: default pipeline: verified {}, worst ratio {w}",
                v.verification.verified
            ));
        }
    }
    Ok(Compared { gap })
}

/// Clarabel's default relative duality-gap tolerance.
fn clarabel_tol_gap() -> f64 {
    feedopt::solver::SolverSettings::default().tol_gap
}

/// Runs `compare` over `seeds`, prints the spread of the gaps, and fails listing every failure.
fn run(seeds: impl Iterator<Item = u64>, stations: usize, max_gap: f64) {
    let t0 = Instant::now();
    let mut gaps = Vec::new();
    let mut failures = Vec::new();
    for seed in seeds {
        match compare(seed, stations, max_gap) {
            Ok(c) => gaps.push(c.gap),
            Err(e) => failures.push(e),
        }
    }
    gaps.sort_by(f64::total_cmp);
    let (n, mean) = (
        gaps.len(),
        gaps.iter().sum::<f64>() / gaps.len().max(1) as f64,
    );
    eprintln!(
        "{stations} stations: {n} paths passed, {} failed in {:.1} s; (T_reach − T_clarabel)/T_clarabel \
         min {:+.3e}, median {:+.3e}, mean {mean:+.3e}, max {:+.3e}",
        failures.len(),
        t0.elapsed().as_secs_f64(),
        gaps.first().copied().unwrap_or(f64::NAN),
        gaps.get(n / 2).copied().unwrap_or(f64::NAN),
        gaps.last().copied().unwrap_or(f64::NAN),
    );
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// The default run: 240 paths (seeds 0–239, half of each family), both solvers, 1,000 stations.
/// Split into two tests so the two halves run in parallel.
#[test]
fn solvers_agree_and_schedules_respect_limits_1000_stations_a() {
    run(0..120, 1000, 5e-3);
}

#[test]
fn solvers_agree_and_schedules_respect_limits_1000_stations_b() {
    run(120..240, 1000, 5e-3);
}

/// The large run: 1,000 paths at 1,000 stations (seeds 1000–1999).
#[test]
#[ignore = "large: cargo test --release --test properties -- --ignored"]
fn large_1000_paths_1000_stations() {
    run(1000..2000, 1000, 5e-3);
}

/// The large run at 20,000 stations: the solvers agree to 1e-4 (seeds 1000–1039).
#[test]
#[ignore = "large: cargo test --release --test properties -- --ignored"]
fn large_20000_stations_agree_to_1e4() {
    run(1000..1040, 20_000, 1e-4);
}

/// The generator is deterministic: the same seed gives the same path.
#[test]
fn random_paths_are_reproducible() {
    let (a, b) = (case(7), case(7));
    match (a, b) {
        (Case::Joint { path: p, .. }, Case::Joint { path: q, .. }) => assert_eq!(p, q),
        _ => panic!("seed 7 is a joint-space path"),
    }
    match (case(8), case(8)) {
        (Case::Cl { path: p, .. }, Case::Cl { path: q, .. }) => assert_eq!(p, q),
        _ => panic!("seed 8 is a CL path"),
    }
}

/// Corner blending (`--corner-tolerance`) on seeded random 3-axis polylines: 4–24 moves of
/// 0.01–20 mm turning 0–175° (reversals, gentle turns and tiny moves among them), programmed
/// feeds 5–100 mm/s, tolerances 1e-4–0.5 mm. Every solve succeeds and verifies, and with the
/// acceleration limits alone the blended path is no slower than the exact stops (beyond the
/// refinement's own 1e-4 each).
#[test]
fn blended_corners_solve_verify_and_are_no_slower_than_stops() {
    let machine = Machine::from_json(
        "xyz.json".as_ref(),
        r#"{"kinematics": {"type": "xyz"},
            "axes": {"X": {"velocity": 500, "acceleration": 2000},
                     "Y": {"velocity": 500, "acceleration": 1500},
                     "Z": {"velocity": 300, "acceleration": 1000}}}"#,
    )
    .expect("machine");
    let (mut blended_total, mut cases) = (0, 0);
    for seed in 0..40u64 {
        let mut g = Lcg::new(seed + 7000);
        let moves = g.int(4, 24);
        let mut p = Vector3::zeros();
        let mut dir = Vector3::new(1.0, 0.0, 0.0);
        let mut points = vec![ClPoint {
            p,
            o: Vector3::z(),
            feed: Feed::Rapid,
            rotary: None,
            line: 1,
        }];
        for k in 0..moves {
            // Turn by 0–175° about a random axis near +Z (some moves climb or dive).
            let turn = g.range(0.0, 175f64.to_radians());
            let axis = Vector3::new(g.range(-0.3, 0.3), g.range(-0.3, 0.3), 1.0).normalize();
            dir = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), turn)
                * dir;
            let len = if g.unit() < 0.2 {
                g.range(0.01, 0.1)
            } else {
                g.range(0.5, 20.0)
            };
            p += dir * len;
            points.push(ClPoint {
                p,
                o: Vector3::z(),
                feed: Feed::Programmed(g.range(5.0, 100.0)),
                rotary: None,
                line: k + 2,
            });
        }
        let path = Toolpath {
            source: PathBuf::from(format!("blend_{seed}.cls")),
            points,
            ..Default::default()
        };
        let tolerance = 10f64.powf(g.range(-4.0, -0.3));
        let stop = optimize(&machine, &path, &Options::default())
            .unwrap_or_else(|e| panic!("seed {seed}, exact stops: {e}"));
        let mut options = Options::default();
        options.geometry.corner_tolerance_mm = tolerance;
        let sol = optimize(&machine, &path, &options)
            .unwrap_or_else(|e| panic!("seed {seed}, tolerance {tolerance}: {e}"));
        assert!(sol.verification.verified, "seed {seed}");
        let (t, t0) = (sol.schedule.cycle_time, stop.schedule.cycle_time);
        assert!(
            t <= t0 * (1.0 + 2e-4),
            "seed {seed}, tolerance {tolerance}: blended {t} s, stops {t0} s"
        );
        blended_total += sol.corners_blended;
        cases += 1;
    }
    // The draw blends corners (most turns exceed the 10° corner angle).
    assert!(
        blended_total > 5 * cases,
        "{blended_total} corners in {cases} paths"
    );
}
