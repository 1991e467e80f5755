//! Two independent routes to the effective tangents and curvatures must agree: seed 000's
//! closed forms (eq. 31–39) and dual numbers pushed through eq. 27.

use feedopt::geometry::spline::Jet;
use feedopt::kinematics::{Effective, Kinematics, PathJet, head_head};

/// An analytic 5-axis path w(u) = (P(u), θ1(u), θ2(u)) with exact derivatives.
fn path(u: f64) -> PathJet {
    let (s, c) = u.sin_cos();
    let (s2, c2) = (2.0 * u).sin_cos();
    let pad = |w: [f64; 5]| std::array::from_fn(|i| if i < 5 { w[i] } else { 0.0 });
    Jet {
        value: pad([
            30.0 * c,
            20.0 * s2,
            5.0 * u,
            0.3 + 0.5 * u + 0.1 * s,
            0.4 + 0.2 * s,
        ]),
        d1: pad([-30.0 * s, 40.0 * c2, 5.0, 0.5 + 0.1 * c, 0.2 * c]),
        d2: pad([-30.0 * c, -80.0 * s2, 0.0, -0.1 * s, -0.2 * s]),
    }
}

fn assert_close(a: f64, b: f64, scale: f64, what: &str) {
    assert!(
        (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(scale),
        "{what}: closed form {a} vs generic {b}"
    );
}

#[test]
fn closed_form_matches_generic_route_on_a_smooth_path() {
    for d2 in [0.0, 150.0, 250.0] {
        let kin = Kinematics::HeadHead { d2 };
        for k in 0..200 {
            let w = path(k as f64 * 0.031);
            let closed = head_head::effective(d2, &w).expect("moving path");
            let generic =
                Effective::from_u_derivatives(&kin.axis_jets_generic(&w), &w).expect("moving path");
            // Scale for values that are zero in exact arithmetic: the size of the terms.
            let scale_t = 1.0 + d2 * 1e-2;
            let scale_k = 1e-2 * (1.0 + d2 * 1e-2);
            for q in 0..5 {
                assert_close(
                    closed.t[q],
                    generic.t[q],
                    scale_t,
                    &format!("t[{q}] d2={d2} k={k}"),
                );
                assert_close(
                    closed.k[q],
                    generic.k[q],
                    scale_k,
                    &format!("K[{q}] d2={d2} k={k}"),
                );
            }
        }
    }
}

#[test]
fn u_and_arc_length_forms_convert_both_ways() {
    let kin = Kinematics::HeadHead { d2: 200.0 };
    let w = path(0.7);
    let e = head_head::effective(200.0, &w).unwrap();
    let back = Effective::from_u_derivatives(&e.to_u_derivatives(&w), &w).unwrap();
    for q in 0..5 {
        assert!((e.t[q] - back.t[q]).abs() < 1e-12 * (1.0 + e.t[q].abs()));
        assert!((e.k[q] - back.k[q]).abs() < 1e-10 * (1.0 + e.k[q].abs()));
    }
    // axis_jets (closed form where the tip moves) agrees with the generic route in u.
    let (a, b) = (kin.axis_jets(&w), kin.axis_jets_generic(&w));
    for q in 0..5 {
        assert_close(a.q[q], b.q[q], 1.0, "q");
        assert_close(a.dq[q], b.dq[q], 1.0, "dq/du");
        assert_close(a.ddq[q], b.ddq[q], 1.0, "d2q/du2");
    }
}

#[test]
fn effective_tangent_is_the_arc_length_derivative_of_eq_27() {
    // Independent of both routes: central differences of eq. 27 along arc length.
    let d2 = 180.0;
    let kin = Kinematics::HeadHead { d2 };
    let u0 = 1.1;
    let w = path(u0);
    let e = head_head::effective(d2, &w).unwrap();
    let speed = (w.d1[0].powi(2) + w.d1[1].powi(2) + w.d1[2].powi(2)).sqrt();
    let h = 1e-5;
    let mut qp = [0.0; feedopt::kinematics::MAX_AXES];
    let mut qm = [0.0; feedopt::kinematics::MAX_AXES];
    kin.axis_positions(path(u0 + h).value, &mut qp);
    kin.axis_positions(path(u0 - h).value, &mut qm);
    for q in 0..5 {
        let t_fd = (qp[q] - qm[q]) / (2.0 * h) / speed;
        assert!(
            (t_fd - e.t[q]).abs() < 1e-6 * (1.0 + e.t[q].abs()),
            "t[{q}]"
        );
    }
}
