//! Approximate biarc interpolation of a dresser profile (seed 001) and the rotary-step limit.

use std::f64::consts::{FRAC_PI_2, PI};

use feedopt::geometry::biarc::*;

const TOL: f64 = 0.005;

fn round_um(p: [f64; 2]) -> [f64; 2] {
    [
        (p[0] * 1000.0).round() / 1000.0,
        (p[1] * 1000.0).round() / 1000.0,
    ]
}

/// A groove: line (0,0)→(10,0), a ccw 90° arc of radius 5 about (10,5), line (15,5)→(15,15);
/// points every ~0.1 mm of arc length, rounded to 1 µm.
fn groove() -> Vec<[f64; 2]> {
    let mut pts = Vec::new();
    for k in 0..100 {
        pts.push([0.1 * k as f64, 0.0]);
    }
    let m = 79; // 5·π/2 ≈ 7.85 mm of arc
    for k in 0..m {
        let a = -FRAC_PI_2 + FRAC_PI_2 * k as f64 / m as f64;
        pts.push([10.0 + 5.0 * a.cos(), 5.0 + 5.0 * a.sin()]);
    }
    for k in 0..=100 {
        pts.push([15.0, 5.0 + 0.1 * k as f64]);
    }
    pts.into_iter().map(round_um).collect()
}

fn assert_g1(pieces: &[Piece]) {
    for (i, w) in pieces.windows(2).enumerate() {
        assert_eq!(w[0].end(), w[1].start(), "joint {i} is not continuous");
        let (a, b) = (w[0].tangent_at_end(), w[1].tangent_at_start());
        let cross = a[0] * b[1] - a[1] * b[0];
        let dot = a[0] * b[0] + a[1] * b[1];
        assert!(
            cross.abs() < 1e-9 && dot > 0.0,
            "joint {i}: tangents {a:?} vs {b:?} ({:?} | {:?})",
            w[0],
            w[1]
        );
    }
}

fn total_length(pieces: &[Piece]) -> f64 {
    pieces.iter().map(Piece::length).sum()
}

#[test]
fn groove_is_fitted_g1_within_tolerance_with_its_true_pieces() {
    let pts = groove();
    let pieces = fit(&pts, TOL);
    assert_g1(&pieces);
    let dev = max_deviation(&pts, &pieces);
    assert!(dev <= TOL, "deviation {dev}");
    assert!(
        (3..=4).contains(&pieces.len()),
        "{} pieces: {pieces:#?}",
        pieces.len()
    );
    // Line, arc(s) of radius 5 turning 90° in all, line.
    assert!(matches!(pieces[0], Piece::Line { .. }), "{pieces:#?}");
    assert!(matches!(pieces[pieces.len() - 1], Piece::Line { .. }));
    let arcs: Vec<&Piece> = pieces
        .iter()
        .filter(|p| matches!(p, Piece::Arc { .. }))
        .collect();
    let sweep: f64 = arcs.iter().map(|p| p.sweep()).sum();
    assert!(
        (sweep - FRAC_PI_2).abs() < 1f64.to_radians(),
        "sweep {sweep}"
    );
    for a in &arcs {
        let r = a.radius().unwrap();
        assert!((r - 5.0).abs() < 0.05, "radius {r} ({a:?})");
        assert!(matches!(a, Piece::Arc { ccw: true, .. }));
    }
    // The profile's ends and length.
    let (s, e) = (pieces[0].start(), pieces[pieces.len() - 1].end());
    assert!(s[0].hypot(s[1]) < TOL && (e[0] - 15.0).hypot(e[1] - 15.0) < TOL);
    let length = 10.0 + 2.5 * PI + 10.0;
    assert!((total_length(&pieces) - length).abs() < 0.01);
    // The tool normal: up (θ = 0) on the first line, turning by −90° to θ = −90° (along −X)
    // on the wall.
    assert!(pieces[0].normal_angle_at_start().abs() < 1e-3);
    let last = pieces[pieces.len() - 1].normal_angle_at_end();
    assert!((last + FRAC_PI_2).abs() < 1e-3, "end normal {last}");
    let turn: f64 = pieces.iter().map(Piece::turn).sum();
    assert!((turn + FRAC_PI_2).abs() < 1e-4, "turn {turn}");
}

#[test]
fn noisy_arc_becomes_one_arc_with_its_radius() {
    let pts: Vec<[f64; 2]> = (0..=120)
        .map(|k| {
            let a = 0.3 + 2.0 * k as f64 / 120.0;
            round_um([3.0 + 20.0 * a.cos(), -1.0 + 20.0 * a.sin()])
        })
        .collect();
    let pieces = fit(&pts, TOL);
    assert_g1(&pieces);
    assert!(max_deviation(&pts, &pieces) <= TOL);
    assert_eq!(pieces.len(), 1, "{pieces:#?}");
    for p in &pieces {
        let r = p.radius().expect("an arc");
        assert!((r - 20.0).abs() < 0.2, "radius {r}");
    }
}

#[test]
fn bisection_limits_each_arc_to_the_rotary_step() {
    let c = [1.0, 2.0];
    let r = 20.0;
    let at = |deg: f64| {
        let a = deg.to_radians();
        [c[0] + r * a.cos(), c[1] + r * a.sin()]
    };
    let arc = Piece::Arc {
        from: at(5.0),
        to: at(175.0),
        center: c,
        ccw: true,
    };
    assert!((arc.sweep() - 170f64.to_radians()).abs() < 1e-12);
    let line = Piece::Line {
        from: at(175.0),
        to: [-30.0, 2.0],
    };
    let step = 10f64.to_radians();
    let out = limit_rotation(&[arc, line], step);
    let arcs = &out[..out.len() - 1];
    assert!(arcs.len() >= 17, "{} pieces", arcs.len());
    assert_eq!(arcs.len(), 32, "five halvings: 170°/16 > 10°");
    assert_eq!(out[0].start(), arc.start());
    assert_eq!(arcs[arcs.len() - 1].end(), arc.end());
    assert_eq!(out[out.len() - 1], line, "a line stays one piece");
    for p in arcs {
        assert!(
            p.sweep() <= step + 1e-12,
            "piece of {}°",
            p.sweep().to_degrees()
        );
        assert!((p.radius().unwrap() - r).abs() < 1e-9);
        assert!(p.turn().abs() <= step + 1e-12);
    }
    let sum: f64 = arcs.iter().map(Piece::sweep).sum();
    assert!((sum - arc.sweep()).abs() < 1e-9);
    assert_g1(arcs);
    // Arcs already within the step are untouched; a step that is not positive changes nothing.
    assert_eq!(limit_rotation(&[arc], PI), vec![arc]);
    assert_eq!(limit_rotation(&[arc], 0.0), vec![arc]);
    assert_eq!(limit_rotation(&[arc], f64::NAN), vec![arc]);
}

#[test]
fn fitted_groove_limited_turns_only_at_the_start() {
    let pieces = fit(&groove(), TOL);
    let step = 10f64.to_radians();
    let out = limit_rotation(&pieces, step);
    assert_g1(&out);
    assert!(out.iter().all(|p| p.sweep() <= step + 1e-12));
    assert!((total_length(&out) - total_length(&pieces)).abs() < 1e-9);
    // The tool already points along the first normal: no pure rotation anywhere.
    assert_eq!(pre_rotations(&out, 0.0, step), vec![]);
    // Standing at θ = 60° it must first turn, and only there.
    let pre = pre_rotations(&out, 60f64.to_radians(), step);
    assert_eq!(pre.len(), 1, "{pre:?}");
    assert_eq!(pre[0].before, 0);
    assert!(pre[0].to.abs() < 1e-3);
    // θ wraps: −179° and +179° are 2° apart.
    let line = Piece::Line {
        from: [0.0, 0.0],
        to: [-1.0, -0.001],
    };
    let theta = line.normal_angle_at_start();
    assert!(theta.abs() > 3.1);
    assert!(pre_rotations(&[line], -theta, step).is_empty());
}

#[test]
fn degenerate_inputs() {
    assert!(fit(&[], TOL).is_empty());
    assert!(fit(&[[1.0, 2.0]], TOL).is_empty());
    assert!(fit(&[[1.0, 2.0], [1.0, 2.0], [1.0, 2.0]], TOL).is_empty());
    assert_eq!(
        fit(&[[0.0, 0.0], [3.0, 4.0]], TOL),
        vec![Piece::Line {
            from: [0.0, 0.0],
            to: [3.0, 4.0]
        }]
    );
    // Duplicates (and non-finite points) are skipped.
    let two = fit(
        &[
            [0.0, 0.0],
            [0.0, 0.0],
            [f64::NAN, 1.0],
            [3.0, 4.0],
            [3.0, 4.0],
        ],
        TOL,
    );
    assert_eq!(
        two,
        vec![Piece::Line {
            from: [0.0, 0.0],
            to: [3.0, 4.0]
        }]
    );
    // Collinear points with rounding noise and repeated points: one line.
    let mut pts: Vec<[f64; 2]> = (0..50)
        .map(|k| round_um([0.37 * k as f64, 1.0 - 0.213 * k as f64]))
        .collect();
    pts.insert(10, pts[10]);
    pts.insert(30, pts[30]);
    let line = fit(&pts, TOL);
    assert_eq!(line.len(), 1, "{line:?}");
    assert!(matches!(line[0], Piece::Line { .. }));
    assert!(max_deviation(&pts, &line) <= TOL);
    // Three collinear points.
    let three = fit(&[[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]], TOL);
    assert_eq!(three.len(), 1);
    assert!(matches!(three[0], Piece::Line { .. }));
    // Zero or invalid tolerance: still G1, through every point.
    for tol in [0.0, -1.0, f64::NAN] {
        let pts = groove();
        let p = fit(&pts[90..200], tol);
        assert_g1(&p);
        assert!(max_deviation(&pts[90..200], &p) <= 1e-9);
    }
    assert_eq!(max_deviation(&[], &[]), 0.0);
}

#[test]
fn corners_and_wiggles_stay_g1_within_tolerance() {
    // A sharp 90° corner: no line–line G1 joint exists, so biarcs round it within tolerance.
    let mut corner: Vec<[f64; 2]> = (0..=50).map(|k| [0.1 * k as f64, 0.0]).collect();
    corner.extend((1..=50).map(|k| [5.0, 0.1 * k as f64]));
    let p = fit(&corner, TOL);
    assert_g1(&p);
    assert!(max_deviation(&corner, &p) <= TOL);
    // A reversal (the profile turns back on itself).
    let mut back: Vec<[f64; 2]> = (0..=20).map(|k| [0.1 * k as f64, 0.0]).collect();
    back.extend((0..20).rev().map(|k| [0.1 * k as f64, 0.01]));
    let p = fit(&back, TOL);
    assert!(max_deviation(&back, &p) <= TOL);
    // Pseudo-random wiggle (deterministic LCG): sparse points, large noise.
    let mut s: u64 = 12345;
    let mut rnd = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let wig: Vec<[f64; 2]> = (0..200)
        .map(|k| {
            let x = 0.2 * k as f64;
            [x, (0.7 * x).sin() * 2.0 + 0.05 * rnd()]
        })
        .collect();
    let p = fit(&wig, TOL);
    assert_g1(&p);
    assert!(max_deviation(&wig, &p) <= TOL);
    let again = fit(&wig, TOL);
    assert_eq!(p, again, "deterministic");
}

#[test]
fn piece_helpers() {
    let line = Piece::Line {
        from: [0.0, 0.0],
        to: [4.0, 0.0],
    };
    assert_eq!(line.length(), 4.0);
    assert_eq!(line.point_at(0.25), [1.0, 0.0]);
    assert_eq!(line.normal_angle_at_start(), 0.0);
    assert_eq!(line.distance_to([2.0, 3.0]), 3.0);
    assert_eq!(line.distance_to([7.0, 4.0]), 5.0);
    // A cw half circle over the top: the tool normal turns from θ = −90° (n = −X) through
    // θ = 0 (n = +Z) to θ = +90° (n = +X).
    let arc = Piece::Arc {
        from: [-1.0, 0.0],
        to: [1.0, 0.0],
        center: [0.0, 0.0],
        ccw: false,
    };
    assert!((arc.sweep() - PI).abs() < 1e-15);
    assert!((arc.length() - PI).abs() < 1e-15);
    let top = arc.point_at(0.5);
    assert!(top[0].abs() < 1e-12 && (top[1] - 1.0).abs() < 1e-12);
    assert!((arc.turn() - PI).abs() < 1e-15);
    let (t0, t1) = (arc.tangent_at_start(), arc.tangent_at_end());
    assert!(t0[0].abs() < 1e-15 && (t0[1] - 1.0).abs() < 1e-15);
    assert!(t1[0].abs() < 1e-15 && (t1[1] + 1.0).abs() < 1e-15);
    assert!((arc.normal_angle_at_start() + FRAC_PI_2).abs() < 1e-15);
    assert!((arc.normal_angle_at_end() - FRAC_PI_2).abs() < 1e-15);
    assert!((arc.distance_to([0.0, 3.0]) - 2.0).abs() < 1e-15);
    assert!((arc.distance_to([0.0, -3.0]) - 10f64.sqrt()).abs() < 1e-12);
}
