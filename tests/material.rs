//! The material stage against closed forms (issue 13): slot, side step, air, ball-nose plunge,
//! volume convergence with the grid, a tilted tool against the vertical one, and the process
//! bounds in a real solve.

use std::f64::consts::PI;
use std::sync::Arc;

use feedopt::constraints::Bound;
use feedopt::material::{
    self, CutOptions, FeedLimits, Material, ProcessLimit, ProcessLimits, Sample, Stock, Tool,
};
use feedopt::optimize::{Options, optimize};
use feedopt::toolpath::{Feed, Toolpath};
use nalgebra::Vector3;

mod common;
use common::{UP, feedopt, machine, toolpath};

const XYZ: &str = r#"{"name": "xyz", "kinematics": {"type": "xyz"},
    "axes": {"X": {"velocity": 500, "acceleration": 5000},
             "Y": {"velocity": 500, "acceleration": 5000},
             "Z": {"velocity": 500, "acceleration": 5000}},
    "feed": {"max": 400}}"#;

/// A 100 × 40 × 20 mm block, top at z = 0.
fn block() -> Stock {
    Stock::Box {
        min: [0.0, 0.0, -20.0],
        max: [100.0, 40.0, 0.0],
    }
}

fn flat10() -> Tool {
    Tool::new(10.0, 0.0, 30.0, 3).unwrap()
}

fn material(tool: Tool, cell: f64, process: ProcessLimits) -> Material {
    Material::single(
        block(),
        tool,
        process,
        CutOptions {
            cell: Some(cell),
            step: None,
        },
    )
}

/// Tip positions, tool up, at 20 mm/s (the first move a rapid from above).
fn path(points: &[[f64; 3]]) -> Toolpath {
    let pts: Vec<(Vector3<f64>, Vector3<f64>)> = points
        .iter()
        .map(|p| (Vector3::new(p[0], p[1], p[2]), UP))
        .collect();
    let mut t = toolpath(&pts, Some(20.0));
    t.points[1].feed = Feed::Rapid;
    t
}

/// From above, down to depth `ap` at (20, y) and along X to (80, y), then up.
fn slot_points(y: f64, ap: f64) -> Vec<[f64; 3]> {
    vec![
        [20.0, y, 10.0],
        [20.0, y, 1.0],
        [20.0, y, -ap],
        [80.0, y, -ap],
        [80.0, y, 10.0],
    ]
}

/// The samples of the horizontal move (CL point 3) at least one diameter from both ends.
fn steady(samples: &[Sample]) -> Vec<&Sample> {
    samples
        .iter()
        .filter(|s| s.point == 3 && s.t[0] * 60.0 >= 10.0 && s.t[1] * 60.0 <= 50.0)
        .collect()
}

fn mean(xs: impl Iterator<Item = f64>) -> f64 {
    let v: Vec<f64> = xs.collect();
    v.iter().sum::<f64>() / v.len() as f64
}

#[test]
fn a_full_width_slot_removes_its_volume_with_a_equal_to_d_times_ap() {
    let (d, ap, len) = (10.0, 3.0, 60.0);
    let sim = material::simulate(
        &path(&slot_points(20.0, ap)),
        &material(flat10(), 0.1, ProcessLimits::default()),
    )
    .unwrap();
    // The slot and its two half-disc ends (the plunge's disc is inside).
    let exact = (d * len + PI * 25.0) * ap;
    let err = (sim.removed_volume - exact).abs() / exact;
    assert!(
        err < 0.005,
        "removed {} vs {exact}: {err:.2e}",
        sim.removed_volume
    );
    // Conservation: what the samples removed is what the stock lost.
    let lost = sim.initial_volume - sim.final_volume;
    assert!((lost - sim.removed_volume).abs() < 1e-9 * lost);
    let st = steady(&sim.samples);
    assert!(st.len() >= 10);
    for s in &st {
        assert!((s.area - d * ap).abs() < 0.03 * d * ap, "A {}", s.area);
        assert!((s.axial_depth - ap).abs() < 1e-9, "a_p {}", s.axial_depth);
        assert!(
            (s.radial_engagement - d).abs() < 0.03 * d,
            "a_e {}",
            s.radial_engagement
        );
        assert!(
            (s.engagement_angle - 180.0).abs() < 10.0,
            "φ {}",
            s.engagement_angle
        );
    }
    let a = mean(st.iter().map(|s| s.area));
    assert!((a - d * ap).abs() < 0.005 * d * ap, "mean A {a}");
}

#[test]
fn a_half_width_side_step_engages_d_over_2_and_90_degrees_and_a_repeat_cuts_air() {
    let (d, ap) = (10.0, 3.0);
    let mut pts = slot_points(20.0, ap);
    // The same slot again (air), then a step over by D/2 (half width, material on +Y).
    pts.extend(slot_points(20.0, ap));
    pts.extend(slot_points(25.0, ap));
    let sim = material::simulate(
        &path(&pts),
        &material(flat10(), 0.1, ProcessLimits::default()),
    )
    .unwrap();
    let repeat: Vec<&Sample> = sim
        .samples
        .iter()
        .filter(|s| (6..=9).contains(&s.point))
        .collect();
    assert!(!repeat.is_empty());
    for s in repeat {
        assert_eq!((s.removed, s.area, s.radial_engagement), (0.0, 0.0, 0.0));
    }
    let side: Vec<&Sample> = sim
        .samples
        .iter()
        .filter(|s| s.point == 13 && s.t[0] * 60.0 >= 10.0 && s.t[1] * 60.0 <= 50.0)
        .collect();
    assert!(side.len() >= 10);
    for s in &side {
        assert!(
            (s.area - 0.5 * d * ap).abs() < 0.03 * 0.5 * d * ap,
            "A {}",
            s.area
        );
        assert!(
            (s.radial_engagement - 0.5 * d).abs() < 0.03 * 0.5 * d,
            "a_e {}",
            s.radial_engagement
        );
        assert!(
            (s.engagement_angle - 90.0).abs() < 4.0,
            "φ {}",
            s.engagement_angle
        );
    }
    let phi = mean(side.iter().map(|s| s.engagement_angle));
    assert!((phi - 90.0).abs() < 1.0, "mean φ {phi}");
}

/// A ball-nose plunge to depth d removes the spherical cap π d² (3R − d)/3; its engaged
/// cross-section at depth d is the circle π (2R d − d²).
#[test]
fn a_ball_nose_plunge_removes_the_spherical_cap() {
    let (r, depth) = (5.0, 2.0);
    let ball = Tool::new(2.0 * r, r, 20.0, 2).unwrap();
    let tp = path(&[[50.0, 20.0, 10.0], [50.0, 20.0, 1.0], [50.0, 20.0, -depth]]);
    let mut m = material(ball, 0.02, ProcessLimits::default());
    m.options.step = Some(0.1);
    let sim = material::simulate(&tp, &m).unwrap();
    let cap = |d: f64| PI * d * d * (3.0 * r - d) / 3.0;
    let err = (sim.removed_volume - cap(depth)).abs() / cap(depth);
    assert!(
        err < 0.002,
        "cap {} vs {}: {err:.2e}",
        sim.removed_volume,
        cap(depth)
    );
    // Every sample in the material: A against the circle at the step's middle depth.
    let mut checked = 0;
    for s in sim.samples.iter().filter(|s| s.point == 2) {
        let mid = 0.5 * (s.t[0] + s.t[1]) * (1.0 + depth) - 1.0; // depth below the top
        if mid < 0.2 {
            continue;
        }
        let a = PI * (2.0 * r * mid - mid * mid);
        assert!(
            (s.area - a).abs() < 0.01 * a,
            "depth {mid}: A {} vs {a}",
            s.area
        );
        assert_eq!(s.engagement_angle, 360.0);
        checked += 1;
    }
    assert!(checked >= 15, "{checked}");
}

/// Volume error against the cell size on a slot at 30° to the grid: within the boundary
/// cells' volume (perimeter × h × a_p), and falling with h.
#[test]
fn volume_converges_with_the_cell_size() {
    let (ap, len) = (2.0, 50.0);
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let (x0, y0) = (20.0, 8.0);
    let tp = path(&[
        [x0, y0, 5.0],
        [x0, y0, -ap],
        [x0 + len * c, y0 + len * s, -ap],
        [x0 + len * c, y0 + len * s, 5.0],
    ]);
    let exact = (10.0 * len + PI * 25.0) * ap;
    let perimeter = 2.0 * len + 2.0 * PI * 5.0;
    let mut errors = Vec::new();
    for h in [0.4, 0.2, 0.1, 0.05] {
        let mut m = material(flat10(), h, ProcessLimits::default());
        m.options.step = Some(2.0);
        let sim = material::simulate(&tp, &m).unwrap();
        let e = (sim.removed_volume - exact).abs();
        assert!(e < perimeter * h * ap, "h {h}: error {e}");
        errors.push(e / exact);
    }
    assert!(errors[3] < errors[0], "{errors:?}");
    assert!(errors[3] < 1e-3, "{errors:?}");
}

/// A ball-nose tool tilted by 10° cuts, at a depth its sphere alone engages, what the vertical
/// one cuts: the sampled-pose treatment of tilted tools against the exact vertical sweep.
#[test]
fn a_tilted_ball_cuts_what_the_vertical_one_cuts() {
    let ball = Tool::new(10.0, 5.0, 20.0, 2).unwrap();
    let tilt = Vector3::new(10f64.to_radians().sin(), 0.0, 10f64.to_radians().cos());
    let ap = 1.5;
    let run = |o: Vector3<f64>| {
        // The tip of a tilted ball is not its lowest point: keep the sphere's centre at the
        // same place, P = C − R O.
        let pts: Vec<(Vector3<f64>, Vector3<f64>)> = [
            [20.0, 20.0, 10.0],
            [20.0, 20.0, 5.0 - ap],
            [80.0, 25.0, 5.0 - ap],
            [80.0, 25.0, 10.0],
        ]
        .iter()
        .map(|c| (Vector3::new(c[0], c[1], c[2]) - 5.0 * o, o))
        .collect();
        let mut t = toolpath(&pts, Some(20.0));
        t.points[1].feed = Feed::Rapid;
        material::simulate(&t, &material(ball, 0.1, ProcessLimits::default())).unwrap()
    };
    let (v, t) = (run(UP), run(tilt));
    let rel = (t.removed_volume - v.removed_volume) / v.removed_volume;
    assert!(
        rel <= 1e-9 && rel > -0.01,
        "tilted {} vertical {}",
        t.removed_volume,
        v.removed_volume
    );
}

/// Work beyond the bound is refused before anything is cut.
#[test]
fn too_fine_a_grid_is_refused_up_front() {
    let err = material::simulate(
        &path(&slot_points(20.0, 3.0)),
        &material(flat10(), 0.001, ProcessLimits::default()),
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("dexels") && err.contains("coarser"), "{err}");
}

/// Solves the slot with process limits and returns the plateau feed in the slot's middle and
/// the binding limit there.
fn slot_feed(process: ProcessLimits) -> (f64, Bound, f64) {
    let m = material(flat10(), 0.2, process);
    let tp = path(&[
        [20.0, 20.0, 10.0],
        [20.0, 20.0, -3.0],
        [80.0, 20.0, -3.0],
        [80.0, 20.0, 10.0],
    ]);
    let sim = material::simulate(&tp, &m).unwrap();
    let limits = FeedLimits::new(&sim, &m, tp.points.len());
    let options = Options {
        process: Some(Arc::new(limits)),
        solver_kind: feedopt::solver::SolverKind::Reach,
        ..Options::default()
    };
    let sol = optimize(&machine(XYZ), &tp, &options).unwrap();
    assert!(sol.verification.verified);
    // The slot is span 1 (the plunge span 0); its middle, x = 50.
    let sch = &sol.schedule;
    let st = (0..sch.stations.len())
        .find(|&k| sch.stations[k].span == 1 && (sch.q(k)[0] - 50.0).abs() < 0.5)
        .map(|k| &sch.stations[k])
        .unwrap();
    let p = &sol.problems[1];
    let i = p.u.iter().position(|&u| (u - st.u).abs() < 1e-12).unwrap();
    let mean_a = mean(
        sim.samples
            .iter()
            .filter(|s| s.point == 2 && s.t[0] * 60.0 >= 10.0 && s.t[1] * 60.0 <= 50.0)
            .map(|s| s.area),
    );
    (st.v, p.b_max_by[i], mean_a)
}

#[test]
fn the_mrr_limit_runs_a_slot_at_mrr_over_a() {
    let mrr = 600.0; // mm³/s: 20 mm/s in a 10 × 3 slot
    let (v, by, _) = slot_feed(ProcessLimits {
        mrr_max: Some(mrr),
        ..Default::default()
    });
    assert_eq!(by, Bound::Process(ProcessLimit::Mrr));
    // The merged cap is the lowest of samples within 1 % of each other, each within 3 % of A.
    let expected = mrr / 30.0;
    assert!(
        (v - expected).abs() < 0.04 * expected,
        "V {v} vs {expected}"
    );
}

#[test]
fn the_chip_load_runs_a_slot_at_fz_z_n_over_60() {
    let (fz, n) = (0.05, 6000.0);
    let (v, by, _) = slot_feed(ProcessLimits {
        chip_load: Some(fz),
        spindle_speed: Some(n),
        ..Default::default()
    });
    assert_eq!(by, Bound::Process(ProcessLimit::ChipLoad));
    let expected = fz * 3.0 * n / 60.0; // 15 mm/s
    assert!(
        (v - expected).abs() < 1e-6 * expected,
        "V {v} vs {expected}"
    );
}

#[test]
fn the_power_limit_runs_a_slot_at_p_over_kc_a() {
    let (p, kc) = (1000.0, 2000.0); // W, N/mm²
    let (v, by, a) = slot_feed(ProcessLimits {
        power: Some(p),
        kc: Some(kc),
        ..Default::default()
    });
    assert_eq!(by, Bound::Process(ProcessLimit::Power));
    let expected = 1000.0 * p / (kc * a);
    assert!(
        (v - expected).abs() < 0.04 * expected,
        "V {v} vs {expected}"
    );
}

/// Chip thinning: at a_e < D/2 the allowed feed per tooth grows by D / (2 √(a_e (D − a_e))).
#[test]
fn chip_thinning_follows_its_formula() {
    use feedopt::material::process::chip_thinning;
    assert_eq!(chip_thinning(5.0, 10.0), 1.0);
    assert_eq!(chip_thinning(8.0, 10.0), 1.0);
    let k = chip_thinning(1.0, 10.0);
    assert!((k - 10.0 / (2.0 * 3.0)).abs() < 1e-12);
    let lim = ProcessLimits {
        chip_load: Some(0.05),
        spindle_speed: Some(6000.0),
        ..Default::default()
    };
    let s = Sample {
        point: 1,
        t: [0.0, 1.0],
        line: 1,
        length: 1.0,
        removed: 3.0,
        area: 3.0,
        axial_depth: 3.0,
        radial_engagement: 1.0,
        engagement_angle: 36.87,
        rapid: false,
        programmed_feed: None,
        shank_depth: 0.0,
    };
    let (v, by) = lim.bound(&s, 10.0, 3).unwrap();
    assert_eq!(by, ProcessLimit::ChipLoad);
    assert!((v - 15.0 * 10.0 / 6.0).abs() < 1e-9);
}

/// Seed 003's tool-breakage detection: two blocks 30 % over the chip load and one rapid through
/// the stock are exactly the three findings, with their lines.
#[test]
fn the_overload_check_lists_exactly_the_overloads_and_the_rapid_through_stock() {
    use feedopt::material::check::{Severity, overloads};
    let mut tp = path(&[
        [20.0, 20.0, 10.0],
        [20.0, 20.0, 1.0],
        [20.0, 20.0, -3.0],
        [40.0, 20.0, -3.0],
        [60.0, 20.0, -3.0],
        [80.0, 20.0, -3.0],
        [80.0, 20.0, 10.0],
        [90.0, 20.0, 10.0],
        [90.0, 20.0, -2.0],
    ]);
    let feeds = [5.0, 19.5, 10.0, 19.5, 10.0];
    for (k, f) in (2..=6).zip(feeds) {
        tp.points[k].feed = Feed::Programmed(f);
    }
    tp.points[7].feed = Feed::Rapid;
    tp.points[8].feed = Feed::Rapid;
    let m = material(
        flat10(),
        0.2,
        ProcessLimits {
            chip_load: Some(0.05),
            spindle_speed: Some(6000.0), // 15 mm/s with 3 flutes
            ..Default::default()
        },
    );
    let sim = material::simulate(&tp, &m).unwrap();
    let found = overloads(&sim, &m, 1.0);
    let lines: Vec<(usize, Severity)> = found.iter().map(|f| (f.line, f.severity)).collect();
    assert_eq!(
        lines,
        vec![
            (4, Severity::Warning),
            (6, Severity::Warning),
            (9, Severity::Error)
        ],
        "{found:#?}"
    );
    for f in &found[..2] {
        assert_eq!(f.limit, Some(ProcessLimit::ChipLoad));
        assert!((f.excess - 0.3).abs() < 1e-9, "{}", f.excess);
    }
    // The rapid plunges 2 mm into the stock: a disc of the tool's area.
    let disc = PI * 25.0 * 2.0;
    assert!(
        (found[2].removed - disc).abs() < 0.01 * disc,
        "{}",
        found[2].removed
    );
    // At a feed override of 0.5 nothing but the rapid is left.
    assert_eq!(overloads(&sim, &m, 0.5).len(), 1);
}

/// The shank findings (line, depth) of `tp` cut with a 10 mm flat end mill of `flutes` mm
/// flutes on the block at 0.2 mm; every finding there is an error (shank or rapid).
fn shank_findings(tp: &Toolpath, flutes: f64) -> Vec<(usize, f64)> {
    use feedopt::material::check::{FindingKind, Severity, overloads};
    let m = material(
        Tool::new(10.0, 0.0, flutes, 3).unwrap(),
        0.2,
        ProcessLimits::default(),
    );
    let sim = material::simulate(tp, &m).unwrap();
    overloads(&sim, &m, 1.0)
        .iter()
        .inspect(|f| assert_eq!(f.severity, Severity::Error, "{f:?}"))
        .filter(|f| f.kind == FindingKind::Shank)
        .map(|f| (f.line, f.shank_depth))
        .collect()
}

/// A cut deeper than the flutes are long leaves material standing above them where the shank
/// goes: an error-level finding at each such move, with how far it reaches (10 − 8 = 2 mm
/// here), but not at a plunge, which clears its own hole; with flutes long enough, none. (The CAMotics bear, a 17 mm relief, with the default
/// 2 D = 6.35 mm flutes of a 3.175 mm ball: its first plunge and every move after it; before,
/// only its last retract showed, as a rapid through the material left above the flutes.)
#[test]
fn a_cut_deeper_than_the_flutes_puts_the_shank_in_the_material() {
    let tp = path(&[
        [20.0, 20.0, 10.0],
        [20.0, 20.0, 1.0],
        [20.0, 20.0, -10.0],
        [60.0, 20.0, -10.0],
        [60.0, 20.0, 10.0],
    ]);
    let shank = |flutes: f64| shank_findings(&tp, flutes);
    let found = shank(8.0);
    // The plunge (line 3) clears its own hole: its flutes pass through everything above them.
    // The slot (line 4) leaves the top 2 mm uncut where the shank goes; the retract (line 5)
    // starts with the shank in them, the flutes' top 0.75 mm below the stock's top after its
    // first step (of 1.25 mm, D/8).
    assert_eq!(found.len(), 2, "{found:?}");
    assert_eq!((found[0].0, found[1].0), (4, 5), "{found:?}");
    assert!((found[0].1 - 2.0).abs() < 1e-9, "{found:?}");
    assert!((found[1].1 - 0.75).abs() < 1e-9, "{found:?}");
    assert!(shank(12.0).is_empty());
}

/// The same with the tool tilted 30° across its slot (5-axis): material left above the
/// flutes inside the shank is an error-level finding too, measured along the axis on the
/// lines the flutes cross at each step's end (a tilted tool's shank was not checked: the
/// LinuxCNC impeller on its cylinder blank, buried beyond its 12 mm flutes, had no finding).
/// The slot runs along Y at the tip depth 10 mm; the flutes' top stands 8·cos 30° = 6.9 mm
/// above the tip, so the top 3.1 mm of the block stand in the shank's way; with 20 mm
/// flutes (top 17.3 mm above the tip) nothing does.
#[test]
fn a_tilted_cut_deeper_than_the_flutes_puts_the_shank_in_the_material() {
    let o = Vector3::new(0.5, 0.0, 0.75_f64.sqrt());
    let pts: Vec<(Vector3<f64>, Vector3<f64>)> = [
        [50.0, 5.0, 10.0],
        [50.0, 5.0, 1.0],
        [50.0, 5.0, -10.0],
        [50.0, 35.0, -10.0],
        [50.0, 35.0, 10.0],
    ]
    .iter()
    .map(|p| (Vector3::new(p[0], p[1], p[2]), o))
    .collect();
    let mut tp = toolpath(&pts, Some(20.0));
    tp.points[1].feed = Feed::Rapid;
    let shank = |flutes: f64| shank_findings(&tp, flutes);
    let found = shank(8.0);
    eprintln!("{found:?}");
    // The slot (line 4) at least; the depth along the axis is at least the material's top
    // above the flutes' top at the axis (10/cos 30° − 8 = 3.55 mm), at most the top's
    // height in the shank at its far side (+ R tan 30° = 6.43 mm).
    let slot = found
        .iter()
        .find(|f| f.0 == 4)
        .expect("the slot's shank finding");
    assert!(slot.1 > 3.5 && slot.1 < 6.5, "{found:?}");
    assert!(shank(20.0).is_empty());
}

/// A second identical pass cuts air: it runs at the air feed (or the machine's limits), the
/// first at the chip load.
#[test]
fn a_repeated_pass_runs_at_the_air_feed() {
    let m = material(
        flat10(),
        0.2,
        ProcessLimits {
            chip_load: Some(0.05),
            spindle_speed: Some(6000.0),
            air_feed: Some(100.0),
            ..Default::default()
        },
    );
    let tp = path(&[
        [20.0, 20.0, 10.0],
        [20.0, 20.0, -3.0],
        [80.0, 20.0, -3.0],
        [20.0, 20.0, -3.0],
    ]);
    let sim = material::simulate(&tp, &m).unwrap();
    let options = Options {
        process: Some(Arc::new(FeedLimits::new(&sim, &m, tp.points.len()))),
        solver_kind: feedopt::solver::SolverKind::Reach,
        ..Options::default()
    };
    let sol = optimize(&machine(XYZ), &tp, &options).unwrap();
    assert!(sol.verification.verified);
    let at = |span: usize| {
        let sch = &sol.schedule;
        let st = (0..sch.stations.len())
            .find(|&k| sch.stations[k].span == span && (sch.q(k)[0] - 50.0).abs() < 0.5)
            .map(|k| &sch.stations[k])
            .unwrap();
        let p = &sol.problems[span];
        let i = p.u.iter().position(|&u| u == st.u).unwrap();
        (st.v, p.b_max_by[i])
    };
    let (v1, by1) = at(1);
    assert_eq!(by1, Bound::Process(ProcessLimit::ChipLoad));
    assert!((v1 - 15.0).abs() < 1e-6, "{v1}");
    let (v2, by2) = at(2);
    assert_eq!(by2, Bound::Process(ProcessLimit::Air));
    assert!((v2 - 100.0).abs() < 1e-6, "{v2}");
}

const POCKET: [&str; 3] = [
    "--machine",
    "problems/material_pocket/machine.json",
    "problems/material_pocket/pocket.cls",
];

/// The bundled pocket: the removed volume is the pocket's analytic volume (a 32 × 12 mm
/// rectangle of tool centres swept by a disc of radius 4, 3 mm deep) within 1 %, the solve
/// verifies with process limits binding, and it is faster than the programmed feeds but slower
/// than the axes alone allow.
#[test]
fn the_bundled_pocket_removes_its_volume_and_solves_under_process_limits() {
    let out = feedopt(&[&["solve", "--json", "--solver", "reach"], &POCKET[..]].concat());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let m = &v["material"];
    let exact = (32.0 * 12.0 + 8.0 * 44.0 + PI * 16.0) * 3.0;
    let removed = m["removed_volume_mm3"].as_f64().unwrap();
    assert!(
        (removed - exact).abs() < 0.01 * exact,
        "{removed} vs {exact}"
    );
    let lost = m["initial_volume_mm3"].as_f64().unwrap() - m["final_volume_mm3"].as_f64().unwrap();
    assert!((lost - removed).abs() < 1e-6 * removed);
    assert_eq!(v["verified"], true);
    let limits: Vec<&str> = v["binding"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["limit"].as_str().unwrap())
        .collect();
    for l in ["chip load", "power", "air"] {
        assert!(limits.contains(&l), "{limits:?}");
    }
    let t = v["cycle_time_s"].as_f64().unwrap();
    let time_of = |extra: &[&str]| {
        let out = feedopt(
            &[
                &["solve", "--json", "--solver", "reach"],
                &POCKET[..],
                extra,
            ]
            .concat(),
        );
        assert!(out.status.success());
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert!(v.get("material").is_none());
        v["cycle_time_s"].as_f64().unwrap()
    };
    let programmed = time_of(&["--no-material"]);
    let axes_only = time_of(&["--no-material", "--ignore-programmed-feed"]);
    assert!(
        axes_only < t && t < programmed,
        "{axes_only} {t} {programmed}"
    );
}

/// `feedopt check` lists the pocket's overloads with file and line; without a stock it says
/// what to add.
#[test]
fn check_prints_findings_and_needs_a_stock() {
    let out = feedopt(&[&["check"], &POCKET[..]].concat());
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("problems/material_pocket/pocket.cls:14: warning")
            && text.contains("power limit"),
        "{text}"
    );
    let out = feedopt(&[
        "check",
        "--machine",
        "problems/xyz_pocket/machine.json",
        "problems/xyz_pocket/pocket_contour.cls",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("needs a stock") && err.lines().count() == 1,
        "{err}"
    );
}

/// Bad material sections are one error naming the field.
#[test]
fn bad_material_sections_name_the_field() {
    use feedopt::material::MaterialSpec;
    let f = std::path::Path::new("m.json");
    let err = |json: &str| MaterialSpec::from_json(f, json).unwrap_err().to_string();
    let e = err(r#"{"stock": {"box": {"min": [0, 0, 0], "max": [10, 10, -1]}}}"#);
    assert!(
        e.contains("field `stock`") && e.contains("must exceed"),
        "{e}"
    );
    let e =
        err(r#"{"stock": {"cylinder": {"center": [0, 0], "radius": 5, "z": [0, 1]}, "box": {}}}"#);
    assert!(e.contains("exactly one"), "{e}");
    let e = err(r#"{"process": {"chip_lode": 0.05}}"#);
    assert!(
        e.contains("process.chip_lode") && e.contains("unknown field"),
        "{e}"
    );
    let e = err(r#"{"process": {"power": 800}}"#);
    assert!(e.contains("kc"), "{e}");
    let e = err(r#"{"tool": {"diameter": -8}}"#);
    assert!(e.contains("tool.diameter"), "{e}");
    // Process limits without a stock: resolve says what to add.
    let spec = MaterialSpec::from_json(f, r#"{"process": {"mrr_max": 100}}"#).unwrap();
    let e = feedopt::material::Material::resolve(f, spec, &Default::default(), &Default::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("field `stock`"), "{e}");
    // A chip load without flutes or spindle speed.
    let spec = MaterialSpec::from_json(
        f,
        r#"{"stock": {"box": {"min": [0, 0, 0], "max": [1, 1, 1]}}, "tool": {"diameter": 6},
            "process": {"chip_load": 0.05}}"#,
    )
    .unwrap();
    let e = feedopt::material::Material::resolve(f, spec, &Default::default(), &Default::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("flutes"), "{e}");
}

/// The row interval of a capsule: a horizontal segment's end discs and band, and a diagonal
/// segment's band (the points within r of the line y = x: |x − y|/√2 ≤ r).
#[test]
fn capsule_rows_are_the_closed_form_intervals() {
    use material::cut::capsule_row;
    let near = |a: Option<[f64; 2]>, b: [f64; 2]| {
        a.is_some_and(|a| (a[0] - b[0]).abs() < 1e-8 && (a[1] - b[1]).abs() < 1e-8)
    };
    let r = capsule_row([0.0, 0.0], [10.0, 0.0], 2.0, 1.0);
    assert!(near(r, [-3f64.sqrt(), 10.0 + 3f64.sqrt()]), "{r:?}");
    assert_eq!(capsule_row([0.0, 0.0], [10.0, 0.0], 2.0, 2.5), None);
    let r = capsule_row([0.0, 0.0], [10.0, 10.0], 1.0, 5.0);
    assert!(near(r, [5.0 - 2f64.sqrt(), 5.0 + 2f64.sqrt()]), "{r:?}");
    // A point (vertical tool standing still): its disc.
    let r = capsule_row([1.0, 1.0], [1.0, 1.0], 5.0, 4.0);
    assert!(near(r, [-3.0, 5.0]), "{r:?}");
}

/// Poses of a tilted step keep the scallop at h/8: δ = √(8 r_c h/8) = √(r_c h) for a ball
/// or bull-nose tool, h/2 for a flat end mill's sharp rim.
#[test]
fn pose_spacing_keeps_the_scallop_at_an_eighth_of_a_cell() {
    use material::cut::pose_spacing;
    let ball = Tool::new(6.0, 3.0, 12.0, 2).unwrap();
    assert!((pose_spacing(&ball, 0.1) - 0.3f64.sqrt()).abs() < 1e-12);
    assert_eq!(pose_spacing(&flat10(), 0.1), 0.05);
    let bull = Tool::new(10.0, 0.01, 20.0, 4).unwrap();
    assert_eq!(pose_spacing(&bull, 0.1), 0.05);
}

/// A G-code program in tool-tip mode gives rotary words, not a tool vector: on a table-table
/// A/C machine the tool axis in workpiece coordinates is tilted by |A| from +Z, and turning C
/// by 90° turns it by 90° about Z.
#[test]
fn rotary_words_give_the_tool_axis_in_workpiece_coordinates() {
    let m = machine(
        r#"{"name": "trt", "kinematics": {"type": "table_table_ac", "x-rot-point": 0,
            "y-rot-point": 0, "z-rot-point": 0, "y-offset": 0, "z-offset": 0, "tool-offset": 0,
            "conventional-directions": false, "work-offset": [0, 0, 0]},
        "axes": {"X": {"velocity": 20, "acceleration": 300},
                 "Y": {"velocity": 20, "acceleration": 300},
                 "Z": {"velocity": 20, "acceleration": 300},
                 "A": {"velocity": 30, "acceleration": 300, "min": -100, "max": 50},
                 "C": {"velocity": 30, "acceleration": 300}}}"#,
    );
    let mut tp = toolpath(
        &[
            (Vector3::new(0.0, 0.0, 10.0), UP),
            (Vector3::new(5.0, 0.0, 10.0), UP),
        ],
        Some(5.0),
    );
    tp.points[0].rotary = Some([-30.0, 0.0, 0.0]);
    tp.points[1].rotary = Some([-30.0, 0.0, 90.0]);
    let axes = material::tool_axes(&tp, &m).unwrap();
    let (o0, o1) = (axes.points[0].o, axes.points[1].o);
    for o in [o0, o1] {
        assert!((o.norm() - 1.0).abs() < 1e-12);
        assert!((o.z - 30f64.to_radians().cos()).abs() < 1e-12, "{o}");
    }
    assert!(o0.x * o1.x + o0.y * o1.y < 1e-12, "{o0} {o1}");
    // Without rotary words the points are borrowed unchanged.
    let plain = toolpath(&[(Vector3::zeros(), UP), (Vector3::x(), UP)], Some(5.0));
    assert!(matches!(
        material::tool_axes(&plain, &m).unwrap(),
        std::borrow::Cow::Borrowed(_)
    ));
}

/// The written program of a process-limited schedule carries its caps: where a process limit's
/// cap changes along a move the block is cut there, so a control that runs each block's F
/// (feedopt's own solve of the written program, without the material stage) takes the
/// schedule's time, not less. With one block per move at its peak the bundled pocket's
/// program took 7.83 s against the schedule's 8.66 s: the air's feed into the material.
#[test]
fn the_written_pocket_runs_no_faster_than_its_process_limits() {
    let dir = tempfile::tempdir().unwrap();
    let written = dir.path().join("pocket.ngc");
    let out = feedopt(
        &[
            &[
                "gcode",
                "--dialect",
                "linuxcnc",
                "-o",
                written.to_str().unwrap(),
            ],
            &POCKET[..],
        ]
        .concat(),
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let schedule: f64 = stdout
        .split("schedule cycle time ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!(
        !stdout.contains(" 0 where a process limit changes"),
        "{stdout}"
    );
    let again = feedopt(&[
        "solve",
        "--json",
        "--no-material",
        "--machine",
        "problems/material_pocket/machine.json",
        written.to_str().unwrap(),
    ]);
    assert!(
        again.status.success(),
        "{}",
        String::from_utf8_lossy(&again.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&again.stdout).unwrap();
    let t = v["cycle_time_s"].as_f64().unwrap();
    assert!(
        (t - schedule).abs() <= 1e-3 * schedule,
        "written program {t} s, schedule {schedule} s"
    );
}
