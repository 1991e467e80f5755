//! Every kinematics against itself and against LinuxCNC's statements:
//!
//! - inverse ∘ forward = id and forward ∘ inverse = id on seeded random poses;
//! - the tool axis of the forward kinematics is the vector the tool-vector inverse solved;
//! - dual-number derivatives of the axis positions equal central finite differences;
//! - the LinuxCNC trunnion machine files in ../shared/realworld/linuxcnc parse (ignored when
//!   absent) and the README's worked statements hold for their parameters;
//! - rotary angles along a path: programmed words taken as they are, travel honoured, and a
//!   near-vertical pass (singular pose) gives continuous angles without NaN.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use feedopt::error::Error;
use feedopt::geometry::angle_between;
use feedopt::geometry::spline::Jet;
use feedopt::kinematics::branch::{POLE_CONE, POLE_TOLERANCE};
use feedopt::kinematics::dresser::Dresser;
use feedopt::kinematics::head_table::HeadTable;
use feedopt::kinematics::trunnion::Trunnion;
use feedopt::kinematics::{Kinematics, MAX_AXES, PATH_DIM, PathJet};
use feedopt::machine::{
    Axis, AxisKind, KinematicsSpec, Limit, Machine, RotaryTable, TrunnionParams, TrunnionTilt,
};
use feedopt::toolpath::{ClPoint, Feed};
use nalgebra::Vector3;

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

/// A small seeded generator (xorshift64*), uniform in [lo, hi).
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
        lo + (hi - lo) * (x as f64 / (1u64 << 53) as f64)
    }

    fn unit(&mut self) -> Vector3<f64> {
        loop {
            let v = Vector3::new(
                self.uniform(-1.0, 1.0),
                self.uniform(-1.0, 1.0),
                self.uniform(-1.0, 1.0),
            );
            let n = v.norm();
            if n > 0.1 && n < 1.0 {
                return v / n;
            }
        }
    }
}

fn trunnion(tilt: TrunnionTilt, conventional: bool) -> Kinematics {
    Kinematics::TableTable(Trunnion {
        tilt,
        params: TrunnionParams {
            rot_point: [12.5, -7.25, 3.0],
            tilt_offset: if tilt.about_x() { 20.0 } else { -20.0 },
            z_offset: if tilt.about_x() { 10.0 } else { -15.0 },
            tool_offset: 42.0,
            conventional_directions: conventional,
            work_offset: [-3.0, 4.5, 13.25],
        },
    })
}

/// The LinuxCNC sims' parameters (README table): r = 0, L = 0, w = 0, σ = +1.
fn sim(tilt: TrunnionTilt) -> Trunnion {
    Trunnion {
        tilt,
        params: TrunnionParams {
            rot_point: [0.0; 3],
            tilt_offset: if tilt.about_x() { 20.0 } else { -20.0 },
            z_offset: if tilt.about_x() { 10.0 } else { -15.0 },
            tool_offset: 0.0,
            conventional_directions: false,
            work_offset: [0.0; 3],
        },
    }
}

/// Every kinematics with a tool tip, with a name for messages.
fn all() -> Vec<(&'static str, Kinematics)> {
    vec![
        ("xyz", Kinematics::Xyz),
        ("head_head", Kinematics::HeadHead { d2: 180.0 }),
        ("table_table_ac", trunnion(TrunnionTilt::A, false)),
        (
            "table_table_ac conventional",
            trunnion(TrunnionTilt::A, true),
        ),
        ("table_table_bc", trunnion(TrunnionTilt::B, false)),
        (
            "table_table_bc conventional",
            trunnion(TrunnionTilt::B, true),
        ),
        ("table_table_ab", trunnion(TrunnionTilt::AB, false)),
        (
            "table_table_ab conventional",
            trunnion(TrunnionTilt::AB, true),
        ),
        (
            "head_table",
            Kinematics::HeadTable(HeadTable {
                pivot_length: 150.0,
                table: RotaryTable::C,
            }),
        ),
        (
            "head_table L=0",
            Kinematics::HeadTable(HeadTable {
                pivot_length: 0.0,
                table: RotaryTable::C,
            }),
        ),
        (
            "head_table A",
            Kinematics::HeadTable(HeadTable {
                pivot_length: 150.0,
                table: RotaryTable::A,
            }),
        ),
        (
            "head_table A L=0",
            Kinematics::HeadTable(HeadTable {
                pivot_length: 0.0,
                table: RotaryTable::A,
            }),
        ),
        (
            "dresser",
            Kinematics::Dresser(Dresser { tool_length: 40.0 }),
        ),
        (
            "dresser L=0",
            Kinematics::Dresser(Dresser { tool_length: 0.0 }),
        ),
    ]
}

fn is_dresser(kin: &Kinematics) -> bool {
    matches!(kin, Kinematics::Dresser(_))
}

/// Path coordinates of a tool tip and two angles (the dresser's tip has y = 0).
fn path_w(kin: &Kinematics, p: Vector3<f64>, angles: [f64; 2]) -> [f64; PATH_DIM] {
    let mut w = [0.0; PATH_DIM];
    w[0] = p.x;
    w[1] = if is_dresser(kin) { 0.0 } else { p.y };
    w[2] = p.z;
    match kin {
        Kinematics::Xyz => {}
        Kinematics::Dresser(_) => w[3] = angles[0],
        _ => {
            w[3] = angles[0];
            w[4] = angles[1];
        }
    }
    w
}

fn ik(kin: &Kinematics, w: [f64; PATH_DIM]) -> [f64; MAX_AXES] {
    let mut q = [0.0; MAX_AXES];
    kin.axis_positions(w, &mut q);
    q
}

fn random_angles(rng: &mut Rng, kin: &Kinematics) -> [f64; 2] {
    match kin {
        Kinematics::Xyz => [0.0; 2],
        Kinematics::Dresser(_) => [rng.uniform(-3.0 * PI, 3.0 * PI), 0.0],
        // Any angles, beyond ±2π too: the kinematics never reduces them.
        _ => [rng.uniform(-7.0, 7.0), rng.uniform(-20.0, 20.0)],
    }
}

fn cl(p: Vector3<f64>, o: Vector3<f64>, rotary: Option<[f64; 3]>, line: usize) -> ClPoint {
    ClPoint {
        p,
        o,
        feed: Feed::Unspecified,
        rotary,
        line,
    }
}

fn axis(name: &str, travel: Option<(f64, f64)>) -> Axis {
    Axis {
        name: name.to_string(),
        kind: KinematicsSpec::axis_kind(name),
        velocity: Limit::symmetric(100.0),
        acceleration: Limit::symmetric(1000.0),
        jerk: None,
        travel,
    }
}

/// Axes X Y Z plus two rotary axes with the given travel (degrees).
fn axes5(names: [&str; 2], travel: [Option<(f64, f64)>; 2]) -> Vec<Axis> {
    let mut v: Vec<Axis> = ["X", "Y", "Z"].iter().map(|n| axis(n, None)).collect();
    v.push(axis(names[0], travel[0]));
    v.push(axis(names[1], travel[1]));
    v
}

fn assert_vec(a: Vector3<f64>, b: Vector3<f64>, tol: f64, what: &str) {
    assert!((a - b).norm() <= tol, "{what}: {a:?} vs {b:?}");
}

// ---------------------------------------------------------------------------------------------
// IK ∘ FK = id, FK ∘ IK = id, tool axis
// ---------------------------------------------------------------------------------------------

#[test]
fn forward_inverts_inverse_on_random_poses() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    for (name, kin) in all() {
        for _ in 0..500 {
            let p = Vector3::new(
                rng.uniform(-150.0, 150.0),
                rng.uniform(-100.0, 100.0),
                rng.uniform(-80.0, 80.0),
            );
            let p = if is_dresser(&kin) {
                Vector3::new(p.x, 0.0, p.z)
            } else {
                p
            };
            let angles = random_angles(&mut rng, &kin);
            let q = ik(&kin, path_w(&kin, p, angles));
            let pose = kin.forward(&q[..kin.n_axes()]).expect("a tool tip");
            assert_vec(pose.p, p, 1e-9, &format!("{name}: FK∘IK tip"));
            for i in 0..2 {
                assert!(
                    (pose.angles[i] - angles[i]).abs() <= 1e-12 * (1.0 + angles[i].abs()),
                    "{name}: FK∘IK angle {i}: {} vs {}",
                    pose.angles[i],
                    angles[i]
                );
            }
            assert_vec(
                pose.k,
                kin.tool_axis(angles),
                1e-14,
                &format!("{name}: tool axis"),
            );
            assert!((pose.k.norm() - 1.0).abs() < 1e-14);
        }
    }
}

#[test]
fn inverse_inverts_forward_on_random_axis_positions() {
    let mut rng = Rng(0xD1B5_4A32_D192_ED03);
    for (name, kin) in all() {
        let n = kin.n_axes();
        for _ in 0..500 {
            let mut q = [0.0; MAX_AXES];
            for qi in q.iter_mut().take(n) {
                *qi = rng.uniform(-200.0, 200.0);
            }
            // Rotary axes in degrees, any value.
            match &kin {
                Kinematics::Xyz => {}
                Kinematics::Dresser(_) => q[2] = rng.uniform(-500.0, 500.0),
                _ => {
                    q[3] = rng.uniform(-400.0, 400.0);
                    q[4] = rng.uniform(-1000.0, 1000.0);
                }
            }
            let pose = kin.forward(&q[..n]).expect("a tool tip");
            let back = ik(&kin, path_w(&kin, pose.p, pose.angles));
            for i in 0..n {
                let rotary = match &kin {
                    Kinematics::Xyz => false,
                    Kinematics::Dresser(_) => i == 2,
                    _ => i >= 3,
                };
                // 1e-9 mm on positions, 1e-12 rad on angles (in degrees here).
                let tol = if rotary {
                    1e-12 * (1.0 + q[i].to_radians().abs()) * 180.0 / PI
                } else {
                    1e-9
                };
                assert!(
                    (back[i] - q[i]).abs() <= tol,
                    "{name}: IK∘FK axis {i}: {} vs {}",
                    back[i],
                    q[i]
                );
            }
        }
    }
}

#[test]
fn tool_vector_inverse_reproduces_the_vector_through_the_forward_kinematics() {
    let mut rng = Rng(0x1234_5678_9ABC_DEF1);
    for (name, kin) in all() {
        if matches!(kin, Kinematics::Xyz) {
            continue;
        }
        for k in 0..300 {
            let mut o = rng.unit();
            if is_dresser(&kin) {
                o = Vector3::new(o.x, 0.0, o.z).normalize();
            }
            let p = Vector3::new(
                rng.uniform(-50.0, 50.0),
                if is_dresser(&kin) {
                    0.0
                } else {
                    rng.uniform(-50.0, 50.0)
                },
                rng.uniform(-50.0, 50.0),
            );
            let angles = kin.rotary_angles(&[cl(p, o, None, k + 1)], &[]).unwrap()[0];
            assert_vec(
                kin.tool_axis(angles),
                o,
                1e-12,
                &format!("{name}: tool_axis"),
            );
            let q = ik(&kin, path_w(&kin, p, angles));
            let pose = kin.forward(&q[..kin.n_axes()]).unwrap();
            assert_vec(pose.k, o, 1e-12, &format!("{name}: FK tool axis"));
            assert_vec(pose.p, p, 1e-9, &format!("{name}: FK tip"));
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Dual numbers against finite differences
// ---------------------------------------------------------------------------------------------

/// A smooth analytic path with exact derivatives, sweeping the angles over wide ranges.
fn path(kin: &Kinematics, u: f64) -> PathJet {
    let (s, c) = u.sin_cos();
    let (s2, c2) = (2.0 * u).sin_cos();
    let mut value = [0.0; PATH_DIM];
    let mut d1 = [0.0; PATH_DIM];
    let mut d2 = [0.0; PATH_DIM];
    let y_scale = if is_dresser(kin) { 0.0 } else { 1.0 };
    let rows: [[f64; 3]; 5] = [
        [40.0 * c, -40.0 * s, -40.0 * c],
        [
            y_scale * 25.0 * s2,
            y_scale * 50.0 * c2,
            y_scale * -100.0 * s2,
        ],
        [-10.0 + 6.0 * u, 6.0, 0.0],
        [0.4 + 0.9 * s, 0.9 * c, -0.9 * s],
        [0.3 + 1.7 * u + 0.2 * c2, 1.7 - 0.4 * s2, -0.8 * c2],
    ];
    for (i, r) in rows.iter().enumerate() {
        value[i] = r[0];
        d1[i] = r[1];
        d2[i] = r[2];
    }
    if matches!(kin, Kinematics::Dresser(_)) {
        value[4] = 0.0;
        d1[4] = 0.0;
        d2[4] = 0.0;
    }
    Jet { value, d1, d2 }
}

#[test]
fn dual_number_derivatives_match_central_differences() {
    for (name, kin) in all() {
        for j in 0..40 {
            let u = -2.0 + 0.1 * j as f64;
            let jets = kin.axis_jets_generic(&path(&kin, u));
            // Central differences with one Richardson step (error O(h⁴)).
            let h = 1e-3;
            let q = |u: f64| ik(&kin, path(&kin, u).value);
            let q0 = q(u);
            let d1 = |h: f64, i: usize| (q(u + h)[i] - q(u - h)[i]) / (2.0 * h);
            let d2 = |h: f64, i: usize| (q(u + h)[i] - 2.0 * q0[i] + q(u - h)[i]) / (h * h);
            for i in 0..kin.n_axes() {
                let fd1 = (4.0 * d1(h / 2.0, i) - d1(h, i)) / 3.0;
                let fd2 = (4.0 * d2(h / 2.0, i) - d2(h, i)) / 3.0;
                assert!(
                    (jets.q[i] - q0[i]).abs() <= 1e-12 * (1.0 + q0[i].abs()),
                    "{name}: q[{i}]"
                );
                assert!(
                    (jets.dq[i] - fd1).abs() <= 1e-6 * (1.0 + fd1.abs().max(jets.dq[i].abs())),
                    "{name} u={u}: dq[{i}] dual {} vs FD {fd1}",
                    jets.dq[i]
                );
                assert!(
                    (jets.ddq[i] - fd2).abs() <= 1e-6 * (1.0 + fd2.abs().max(jets.ddq[i].abs())),
                    "{name} u={u}: ddq[{i}] dual {} vs FD {fd2}",
                    jets.ddq[i]
                );
            }
        }
    }
}

#[test]
fn axis_jets_use_the_generic_route_for_the_new_kinematics() {
    // (head_head has closed forms of its own, checked in tests/kinematics.rs.)
    for (name, kin) in all() {
        if matches!(kin, Kinematics::HeadHead { .. }) {
            continue;
        }
        let w = path(&kin, 0.37);
        assert_eq!(kin.axis_jets(&w), kin.axis_jets_generic(&w), "{name}");
    }
}

// ---------------------------------------------------------------------------------------------
// LinuxCNC: machine files and the README's statements
// ---------------------------------------------------------------------------------------------

fn linuxcnc_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/realworld/linuxcnc")
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn linuxcnc_machine_files_parse() {
    let dir = linuxcnc_dir();
    let files = [
        ("boat-xyzac.machine.json", TrunnionTilt::A, 13.25),
        ("impeller-7bl-xyzac.machine.json", TrunnionTilt::A, 0.0),
        ("boat-xyzbc.machine.json", TrunnionTilt::B, 8.3),
    ];
    for (file, tilt, wz) in files {
        let path = dir.join(file);
        let m = Machine::from_file(&path).unwrap_or_else(|e| panic!("{e}"));
        let KinematicsSpec::TableTable { tilt: t, params } = m.kinematics else {
            panic!("{file}: {:?}", m.kinematics);
        };
        assert_eq!(t, tilt, "{file}");
        assert_eq!(
            params,
            sim(tilt).params_with_work_offset([0.0, 0.0, wz]),
            "{file}"
        );
        let names: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
        let tilt_name = if tilt == TrunnionTilt::A { "A" } else { "B" };
        assert_eq!(names, ["X", "Y", "Z", tilt_name, "C"], "{file}");
        let travel: Vec<_> = m.axes.iter().map(|a| a.travel).collect();
        assert_eq!(
            travel,
            [
                Some((-200.0, 200.0)),
                Some((-100.0, 100.0)),
                Some((-120.0, 120.0)),
                Some((-100.0, 50.0)),
                Some((-36000.0, 36000.0))
            ],
            "{file}"
        );
        assert_eq!(m.axes[3].kind, AxisKind::Rotary);
        assert_eq!(m.feed_max, Some(35.0));
        // The kinematics built from the file is the sim's with the file's work offset.
        let kin = Kinematics::new(&m);
        assert_eq!(n_and_kind(&kin), (5, true));
    }
}

fn n_and_kind(kin: &Kinematics) -> (usize, bool) {
    (kin.n_axes(), kin.uses_orientation())
}

trait WithWorkOffset {
    fn params_with_work_offset(&self, w: [f64; 3]) -> TrunnionParams;
}

impl WithWorkOffset for Trunnion {
    fn params_with_work_offset(&self, w: [f64; 3]) -> TrunnionParams {
        TrunnionParams {
            work_offset: w,
            ..self.params
        }
    }
}

#[test]
fn readme_moving_the_tip_along_the_tool_axis_moves_only_joint_z() {
    let mut rng = Rng(0xABCD_EF01_2345_6789);
    for tilt in [TrunnionTilt::A, TrunnionTilt::B] {
        for conventional in [false, true] {
            let mut t = sim(tilt);
            t.params.conventional_directions = conventional;
            let kin = Kinematics::TableTable(t);
            for _ in 0..200 {
                let p = Vector3::new(
                    rng.uniform(-60.0, 60.0),
                    rng.uniform(-60.0, 60.0),
                    rng.uniform(-30.0, 30.0),
                );
                let angles = [rng.uniform(-1.7, 0.9), rng.uniform(-7.0, 7.0)];
                let k = kin.tool_axis(angles);
                let step = rng.uniform(-25.0, 25.0);
                let a = ik(&kin, path_w(&kin, p, angles));
                let b = ik(&kin, path_w(&kin, p + step * k, angles));
                assert!((b[0] - a[0]).abs() < 1e-9 && (b[1] - a[1]).abs() < 1e-9);
                assert!((b[2] - a[2] - step).abs() < 1e-9);
                assert_eq!((a[3], a[4]), (b[3], b[4]));
            }
        }
    }
}

#[test]
fn readme_written_out_sim_formulas_hold() {
    let mut rng = Rng(0x0F0F_F0F0_1234_4321);
    for _ in 0..200 {
        let (x, y, z) = (
            rng.uniform(-60.0, 60.0),
            rng.uniform(-60.0, 60.0),
            rng.uniform(-30.0, 30.0),
        );
        let (t, c) = (rng.uniform(-1.7, 0.9), rng.uniform(-7.0, 7.0));
        let ux = x * c.cos() - y * c.sin();
        let uy = x * c.sin() + y * c.cos();
        // xyzac (dy = 20, dz = 10).
        let kin = Kinematics::TableTable(sim(TrunnionTilt::A));
        let q = ik(&kin, path_w(&kin, Vector3::new(x, y, z), [t, c]));
        let (dy, dz) = (20.0, 10.0);
        let expect = [
            ux,
            dy + (uy - dy) * t.cos() - (z - dz) * t.sin(),
            dz + (uy - dy) * t.sin() + (z - dz) * t.cos(),
        ];
        for i in 0..3 {
            assert!((q[i] - expect[i]).abs() < 1e-9, "xyzac J[{i}]");
        }
        assert!((q[3] - t.to_degrees()).abs() < 1e-12 && (q[4] - c.to_degrees()).abs() < 1e-12);
        // README's tool axis for σ = +1: (sin A sin C, sin A cos C, cos A).
        assert_vec(
            kin.tool_axis([t, c]),
            Vector3::new(t.sin() * c.sin(), t.sin() * c.cos(), t.cos()),
            1e-15,
            "xyzac k",
        );
        // xyzbc (dx = −20, dz = −15).
        let kin = Kinematics::TableTable(sim(TrunnionTilt::B));
        let q = ik(&kin, path_w(&kin, Vector3::new(x, y, z), [t, c]));
        let (dx, dz) = (-20.0, -15.0);
        let expect = [
            dx + (ux - dx) * t.cos() + (z - dz) * t.sin(),
            uy,
            dz - (ux - dx) * t.sin() + (z - dz) * t.cos(),
        ];
        for i in 0..3 {
            assert!((q[i] - expect[i]).abs() < 1e-9, "xyzbc J[{i}]");
        }
        assert_vec(
            kin.tool_axis([t, c]),
            Vector3::new(-t.sin() * c.cos(), t.sin() * c.sin(), t.cos()),
            1e-15,
            "xyzbc k",
        );
    }
}

#[test]
fn readme_tool_length_only_adds_to_joint_z_and_work_offset_shifts_the_rot_point() {
    let mut rng = Rng(0x5555_AAAA_3333_CCCC);
    for tilt in [TrunnionTilt::A, TrunnionTilt::B] {
        for conventional in [false, true] {
            let base = Trunnion {
                tilt,
                params: TrunnionParams {
                    rot_point: [5.0, -8.0, 2.5],
                    conventional_directions: conventional,
                    ..sim(tilt).params
                },
            };
            let with_tool = Trunnion {
                params: TrunnionParams {
                    tool_offset: 37.5,
                    ..base.params
                },
                ..base
            };
            // Work offset w and rot point r meet only in P − r: (r, w) acts as (r − w, 0).
            let with_work = Trunnion {
                params: TrunnionParams {
                    work_offset: [1.5, -2.0, 13.25],
                    ..base.params
                },
                ..base
            };
            let shifted = Trunnion {
                params: TrunnionParams {
                    rot_point: [5.0 - 1.5, -8.0 + 2.0, 2.5 - 13.25],
                    ..base.params
                },
                ..base
            };
            for _ in 0..100 {
                let p = Vector3::new(
                    rng.uniform(-60.0, 60.0),
                    rng.uniform(-60.0, 60.0),
                    rng.uniform(-30.0, 30.0),
                );
                let angles = [rng.uniform(-1.7, 0.9), rng.uniform(-7.0, 7.0)];
                let kb = Kinematics::TableTable(base);
                let a = ik(&kb, path_w(&kb, p, angles));
                let kt = Kinematics::TableTable(with_tool);
                let b = ik(&kt, path_w(&kt, p, angles));
                assert!((b[0] - a[0]).abs() < 1e-9 && (b[1] - a[1]).abs() < 1e-9);
                assert!((b[2] - a[2] - 37.5).abs() < 1e-9);
                let kw = Kinematics::TableTable(with_work);
                let ks = Kinematics::TableTable(shifted);
                let c = ik(&kw, path_w(&kw, p, angles));
                let d = ik(&ks, path_w(&ks, p, angles));
                // J = r + D + R(…)(… (P − r) …): the r outside differs by w, the rest agrees.
                let w = [1.5, -2.0, 13.25];
                for i in 0..3 {
                    assert!((c[i] - (d[i] + w[i])).abs() < 1e-9, "axis {i}");
                }
            }
        }
    }
}

#[test]
fn readme_conventional_directions_flip_both_rotary_axes() {
    // σ = −1 equals σ = +1 with both angles negated.
    let mut rng = Rng(0x7777_1111_2222_8888);
    for tilt in [TrunnionTilt::A, TrunnionTilt::B] {
        let plus = Kinematics::TableTable(sim(tilt));
        let mut t = sim(tilt);
        t.params.conventional_directions = true;
        let minus = Kinematics::TableTable(t);
        for _ in 0..100 {
            let p = Vector3::new(
                rng.uniform(-60.0, 60.0),
                rng.uniform(-60.0, 60.0),
                rng.uniform(-30.0, 30.0),
            );
            let angles = [rng.uniform(-1.7, 0.9), rng.uniform(-7.0, 7.0)];
            let a = ik(&minus, path_w(&minus, p, angles));
            let b = ik(&plus, path_w(&plus, p, [-angles[0], -angles[1]]));
            for i in 0..3 {
                assert!((a[i] - b[i]).abs() < 1e-9);
            }
            assert_vec(
                minus.tool_axis(angles),
                plus.tool_axis([-angles[0], -angles[1]]),
                1e-15,
                "k",
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Rotary angles along a path
// ---------------------------------------------------------------------------------------------

#[test]
fn programmed_rotary_words_are_taken_as_they_are() {
    let rotary = [-75.5, 12.25, 725.0];
    let [a, b, c] = rotary.map(f64::to_radians);
    let cases: Vec<(Kinematics, [f64; 2])> = vec![
        (Kinematics::HeadHead { d2: 100.0 }, [c, a]),
        (trunnion(TrunnionTilt::A, false), [a, c]),
        (trunnion(TrunnionTilt::B, false), [b, c]),
        (trunnion(TrunnionTilt::AB, false), [a, b]),
        (
            Kinematics::HeadTable(HeadTable {
                pivot_length: 50.0,
                table: RotaryTable::C,
            }),
            [b, c],
        ),
        (
            Kinematics::HeadTable(HeadTable {
                pivot_length: 50.0,
                table: RotaryTable::A,
            }),
            [b - PI / 2.0, a],
        ),
        (Kinematics::Dresser(Dresser { tool_length: 5.0 }), [b, 0.0]),
        (Kinematics::Xyz, [0.0, 0.0]),
    ];
    for (kin, want) in cases {
        // The tool vector disagrees on purpose: programmed words win, no IK.
        let pts = [cl(Vector3::zeros(), Vector3::z(), Some(rotary), 7)];
        let got = kin.rotary_angles(&pts, &[]).unwrap();
        assert_eq!(got, vec![want], "{kin:?}");
        assert_eq!(kin.angles_from_rotary(rotary), want);
    }
}

#[test]
fn table_table_ab_is_the_ac_table_with_its_platter_lettered_b() {
    // The same trunnion with the platter lettered B instead of C: forward, inverse and tool
    // vectors agree with the AC machine's once B is read as C.
    let mut rng = Rng(0x5EED_AB00_0000_0001);
    for conventional in [false, true] {
        let (ab, ac) = (
            trunnion(TrunnionTilt::AB, conventional),
            trunnion(TrunnionTilt::A, conventional),
        );
        for _ in 0..200 {
            let q: Vec<f64> = (0..5)
                .map(|i| match i {
                    3 => rng.uniform(-120.0, 120.0),
                    4 => rng.uniform(-720.0, 720.0),
                    _ => rng.uniform(-200.0, 200.0),
                })
                .collect();
            assert_eq!(ab.forward(&q), ac.forward(&q));
            let angles = [q[3].to_radians(), q[4].to_radians()];
            let w = path_w(&ab, Vector3::new(q[0], q[1], q[2]), angles);
            assert_eq!(ik(&ab, w), ik(&ac, w));
            let o = rng.unit();
            let p = [cl(Vector3::zeros(), o, None, 1)];
            assert_eq!(
                ab.rotary_angles(&p, &[]).unwrap(),
                ac.rotary_angles(&p, &[]).unwrap()
            );
        }
        // Programmed words: A and B here are A and C there.
        assert_eq!(
            ab.angles_from_rotary([30.0, 75.0, 0.0]),
            ac.angles_from_rotary([30.0, 0.0, 75.0])
        );
    }
    // Hand-computed tool axes (σ = +1): k = (sin A sin B, sin A cos B, cos A).
    let ab = trunnion(TrunnionTilt::AB, false);
    let deg = |a: f64, b: f64| [a.to_radians(), b.to_radians()];
    assert_vec(ab.tool_axis(deg(0.0, 37.0)), Vector3::z(), 1e-15, "A0");
    assert_vec(ab.tool_axis(deg(90.0, 0.0)), Vector3::y(), 1e-15, "A90 B0");
    assert_vec(
        ab.tool_axis(deg(90.0, 90.0)),
        Vector3::x(),
        1e-15,
        "A90 B90",
    );
    let h = 0.5f64.sqrt();
    assert_vec(
        ab.tool_axis(deg(45.0, 180.0)),
        Vector3::new(0.0, -h, h),
        1e-15,
        "A45 B180",
    );
    // At A = 0 the platter turns about machine Z through the rot-point: a tip at the centre
    // stays put whatever B, one 10 mm off it in X circles it.
    let Kinematics::TableTable(t) = &ab else {
        unreachable!()
    };
    let centre = Vector3::from(t.params.rot_point)
        - Vector3::from(t.params.work_offset)
        - Vector3::new(0.0, 0.0, t.params.tool_offset);
    let off = centre + Vector3::new(10.0, 0.0, 0.0);
    for b in [0.0, 33.0, 90.0, 250.0] {
        let q0 = ik(&ab, path_w(&ab, centre, deg(0.0, b)));
        let q1 = ik(&ab, path_w(&ab, off, deg(0.0, b)));
        assert_vec(
            Vector3::new(q0[0], q0[1], q0[2]),
            Vector3::from(t.params.rot_point),
            1e-9,
            "platter centre",
        );
        let r = Vector3::new(q1[0] - q0[0], q1[1] - q0[1], q1[2] - q0[2]);
        assert_vec(
            r,
            Vector3::new(
                10.0 * b.to_radians().cos(),
                10.0 * b.to_radians().sin(),
                0.0,
            ),
            1e-9,
            &format!("B = {b}"),
        );
    }
}

#[test]
fn table_table_ab_names_its_b_axis_outside_travel() {
    let kin = trunnion(TrunnionTilt::AB, false);
    let axes = axes5(["A", "B"], [Some((-120.0, 120.0)), Some((-90.0, 90.0))]);
    let pts = [
        cl(Vector3::zeros(), Vector3::z(), Some([10.0, 45.0, 0.0]), 3),
        cl(Vector3::zeros(), Vector3::z(), Some([10.0, 135.0, 0.0]), 4),
    ];
    let msg = kin.rotary_angles(&pts, &axes).unwrap_err().to_string();
    assert!(msg.contains("line 4") && msg.contains("B = 135"), "{msg}");
}

#[test]
fn programmed_rotary_words_outside_travel_name_the_line() {
    let kin = trunnion(TrunnionTilt::A, false);
    let axes = axes5(
        ["A", "C"],
        [Some((-100.0, 50.0)), Some((-36000.0, 36000.0))],
    );
    let pts = [
        cl(Vector3::zeros(), Vector3::z(), Some([-30.0, 0.0, 10.0]), 3),
        cl(Vector3::zeros(), Vector3::z(), Some([60.0, 0.0, 10.0]), 4),
    ];
    let e = kin.rotary_angles(&pts, &axes).unwrap_err();
    assert!(matches!(e, Error::Infeasible(_)));
    let msg = e.to_string();
    assert!(msg.contains("line 4") && msg.contains("A = 60"), "{msg}");
    // On the limit itself is fine.
    let pts = [cl(
        Vector3::zeros(),
        Vector3::z(),
        Some([50.0, 0.0, 10.0]),
        3,
    )];
    assert!(kin.rotary_angles(&pts, &axes).is_ok());
}

#[test]
fn tool_vectors_take_the_branch_within_tilt_travel() {
    // LinuxCNC's A travel [-100°, 50°]: a tool tilted 60–80° must use A < 0 throughout.
    let kin = trunnion(TrunnionTilt::A, false);
    let axes = axes5(
        ["A", "C"],
        [Some((-100.0, 50.0)), Some((-36000.0, 36000.0))],
    );
    let pts: Vec<ClPoint> = (0..50)
        .map(|k| {
            let (t, c) = ((60.0 + 0.4 * k as f64).to_radians(), 0.1 * k as f64);
            cl(Vector3::zeros(), kin.tool_axis([t, c]), None, 10 + k)
        })
        .collect();
    let a = kin.rotary_angles(&pts, &axes).unwrap();
    for (pt, ang) in pts.iter().zip(&a) {
        assert!(ang[0] < 0.0 && ang[0] >= (-100f64).to_radians());
        assert_vec(kin.tool_axis(*ang), pt.o, 1e-12, "k");
    }
    for w in a.windows(2) {
        assert!((w[1][1] - w[0][1]).abs() < 0.11, "C jumped: {w:?}");
    }
    // 110° of tilt is beyond both branches: the error names the first such CL line.
    let mut pts = pts;
    pts[30].o = kin.tool_axis([110f64.to_radians(), 0.0]);
    pts[40].o = kin.tool_axis([120f64.to_radians(), 0.0]);
    let msg = kin.rotary_angles(&pts, &axes).unwrap_err().to_string();
    assert!(msg.contains("line 40:"), "{msg}");
}

#[test]
fn spin_unwraps_past_360_degrees_until_travel_ends() {
    // The tool circles three times about the C axis at 30° tilt on a head–table machine.
    let kin = Kinematics::HeadTable(HeadTable {
        pivot_length: 100.0,
        table: RotaryTable::C,
    });
    let pts: Vec<ClPoint> = (0..300)
        .map(|k| {
            let c = 0.07 * k as f64;
            cl(Vector3::zeros(), kin.tool_axis([0.5, c]), None, k + 1)
        })
        .collect();
    let a = kin.rotary_angles(&pts, &[]).unwrap();
    for (k, w) in a.windows(2).enumerate() {
        assert!((w[1][1] - w[0][1] - 0.07).abs() < 1e-9, "point {k}: {w:?}");
        assert!((w[1][0] - 0.5).abs() < 1e-12);
    }
    // With C travel [-10°, 400°] the path leaves travel where C passes 400°.
    let axes = axes5(["B", "C"], [Some((-120.0, 120.0)), Some((-10.0, 400.0))]);
    let msg = kin.rotary_angles(&pts, &axes).unwrap_err().to_string();
    let first_out = (0..300)
        .find(|k| (0.07 * *k as f64).to_degrees() > 400.0)
        .unwrap();
    // Neither unwinding by 360° nor switching to (−B, C − 180°) is continuous: the error names
    // the first point beyond travel.
    assert!(msg.contains(&format!("line {}:", first_out + 1)), "{msg}");
    assert!(msg.contains("C = ") && msg.contains("[-10, 400]"), "{msg}");
}

#[test]
fn dresser_follows_the_profile_normal() {
    let kin = Kinematics::Dresser(Dresser { tool_length: 30.0 });
    // A full circle of normals and then some: B unwraps past 360°.
    let pts: Vec<ClPoint> = (0..100)
        .map(|k| {
            let t = 0.1 * k as f64 - 1.0;
            cl(
                Vector3::new(50.0 * t.sin(), 0.0, 50.0 * t.cos()),
                Vector3::new(t.sin(), 0.0, t.cos()),
                None,
                k + 1,
            )
        })
        .collect();
    let a = kin.rotary_angles(&pts, &[]).unwrap();
    for (k, ang) in a.iter().enumerate() {
        assert!((ang[0] - (0.1 * k as f64 - 1.0)).abs() < 1e-12, "{k}");
        assert_eq!(ang[1], 0.0);
    }
    // Travel ±200°: the path ends past it.
    let axes = vec![
        axis("X", None),
        axis("Z", None),
        axis("B", Some((-200.0, 200.0))),
    ];
    let msg = kin.rotary_angles(&pts, &axes).unwrap_err().to_string();
    let first_out = (0..100)
        .find(|k| (0.1 * *k as f64 - 1.0).to_degrees() > 200.0)
        .unwrap();
    assert!(msg.contains(&format!("line {}:", first_out + 1)), "{msg}");
    // Off the X–Z plane is an error naming the line.
    let mut off = pts.clone();
    off[5].p.y = 0.5;
    let msg = kin.rotary_angles(&off, &[]).unwrap_err().to_string();
    assert!(msg.contains("line 6"), "{msg}");
}

/// A near-vertical pass: the tool swings in a plane from −20° to +20° of tilt along x, missing
/// the C axis by `miss` radians, in steps of `step` radians.
fn vertical_pass(miss: f64, step: f64) -> Vec<ClPoint> {
    pass(miss, step, 0.0, 0.0)
}

/// As [`vertical_pass`], with the samples shifted by `phase` steps and the pass turned by
/// `psi` about z.
fn pass(miss: f64, step: f64, phase: f64, psi: f64) -> Vec<ClPoint> {
    let n = (40f64.to_radians() / step).round() as i64;
    let (sp, cp) = psi.sin_cos();
    (0..=n)
        .map(|k| {
            let phi = -20f64.to_radians() + (k as f64 + phase) * step;
            let o = Vector3::new(phi.sin(), miss.sin() * phi.cos(), miss.cos() * phi.cos());
            let o = Vector3::new(cp * o.x - sp * o.y, sp * o.x + cp * o.y, o.z);
            cl(
                Vector3::new(k as f64, 0.0, 0.0),
                o.normalize(),
                None,
                k as usize + 1,
            )
        })
        .collect()
}

/// The largest step of each path angle between neighbours (degrees) and the largest deviation
/// of the tool vector (radians).
fn worst_steps(kin: &Kinematics, pts: &[ClPoint], a: &[[f64; 2]]) -> ([f64; 2], f64) {
    let mut worst = [0.0f64; 2];
    for w in a.windows(2) {
        for i in 0..2 {
            assert!(w[1][i].is_finite());
            worst[i] = worst[i].max((w[1][i] - w[0][i]).abs().to_degrees());
        }
    }
    let dev = pts
        .iter()
        .zip(a)
        .map(|(p, x)| angle_between(&kin.tool_axis(*x), &p.o))
        .fold(0.0, f64::max);
    (worst, dev)
}

#[test]
fn near_vertical_passes_at_any_sampling_phase_and_direction_stay_continuous() {
    for (name, kin, axes, spin) in near_vertical_cases() {
        for miss_deg in [0.01, 0.003, 1e-5] {
            for step_deg in [1.0, 0.5, 0.1, 0.02] {
                for phase in [0.0, 0.1, 0.25, 0.5, 0.77] {
                    for psi_deg in [0.0, 37.0, 123.0, -90.0] {
                        let pts = pass(
                            f64::to_radians(miss_deg),
                            f64::to_radians(step_deg),
                            phase,
                            f64::to_radians(psi_deg),
                        );
                        let a = kin.rotary_angles(&pts, &axes).unwrap();
                        let (worst, dev) = worst_steps(&kin, &pts, &a);
                        let what = format!(
                            "{name}: miss {miss_deg}°, step {step_deg}°, phase {phase}, \
                             psi {psi_deg}°: steps {worst:?}°, deviation {}°",
                            dev.to_degrees()
                        );
                        assert!(worst[spin] < 3.0, "{what}");
                        assert!(worst[1 - spin] < 1.5 * step_deg, "{what}");
                        assert!(dev <= POLE_TOLERANCE, "{what}");
                    }
                }
            }
        }
    }
}

fn near_vertical_cases() -> Vec<(&'static str, Kinematics, Vec<Axis>, usize)> {
    // (name, kinematics, axes, index of the spin angle C in the pair)
    vec![
        (
            "head_head",
            Kinematics::HeadHead { d2: 200.0 },
            axes5(["C", "A"], [None, Some((-120.0, 120.0))]),
            0,
        ),
        (
            "table_table_ac",
            Kinematics::TableTable(sim(TrunnionTilt::A)),
            axes5(
                ["A", "C"],
                [Some((-100.0, 50.0)), Some((-36000.0, 36000.0))],
            ),
            1,
        ),
    ]
}

#[test]
fn near_vertical_pass_gives_continuous_angles() {
    let miss = 0.01f64.to_radians();
    let step = 0.5f64.to_radians();
    for (name, kin, axes, spin) in near_vertical_cases() {
        let pts = vertical_pass(miss, step);
        let a = kin.rotary_angles(&pts, &axes).unwrap();
        for (pt, ang) in pts.iter().zip(&a) {
            assert!(ang[0].is_finite() && ang[1].is_finite(), "{name}: NaN");
            // Exact away from the pole; within the pole cone the tool vector may deviate by
            // the pole tolerance.
            let dev = angle_between(&kin.tool_axis(*ang), &pt.o);
            let near = angle_between(&pt.o, &Vector3::z()) < POLE_CONE;
            assert!(
                dev <= if near { POLE_TOLERANCE } else { 1e-12 },
                "{name}: deviation {dev} at line {}",
                pt.line
            );
        }
        let mut worst = [0.0f64; 2];
        for w in a.windows(2) {
            for i in 0..2 {
                worst[i] = worst[i].max((w[1][i] - w[0][i]).abs().to_degrees());
            }
        }
        // Neighbours are 0.5° apart; passing 0.01° beside the pole turns C by at most
        // 2·atan(2·0.01/0.5) ≈ 4.6° between two points, the tilt by about the step.
        assert!(worst[spin] < 5.0, "{name}: C jumps {}°", worst[spin]);
        assert!(
            worst[1 - spin] < 0.6,
            "{name}: tilt jumps {}°",
            worst[1 - spin]
        );
        // The axes themselves stay continuous too.
        let q: Vec<[f64; MAX_AXES]> = pts
            .iter()
            .zip(&a)
            .map(|(pt, ang)| ik(&kin, path_w(&kin, pt.p, *ang)))
            .collect();
        for w in q.windows(2) {
            for i in 0..5 {
                assert!(w[1][i].is_finite());
                assert!(
                    (w[1][i] - w[0][i]).abs() < 6.0,
                    "{name}: axis {i} jumps: {w:?}"
                );
            }
        }
    }
}

#[test]
fn pass_exactly_through_the_pole_keeps_c_constant() {
    let step = 0.5f64.to_radians();
    for (name, kin, axes, spin) in near_vertical_cases() {
        let pts = vertical_pass(0.0, step);
        // The middle point is exactly vertical.
        assert!(
            pts.iter().any(|p| p.o == Vector3::z()),
            "{name}: no pole point"
        );
        let a = kin.rotary_angles(&pts, &axes).unwrap();
        for (pt, ang) in pts.iter().zip(&a) {
            assert!(ang[0].is_finite() && ang[1].is_finite(), "{name}: NaN");
            assert_vec(kin.tool_axis(*ang), pt.o, 1e-12, name);
            assert!(
                (ang[spin] - a[0][spin]).abs() < 1e-12,
                "{name}: C moved: {ang:?}"
            );
        }
        // The tilt runs through zero monotonically.
        for w in a.windows(2) {
            let d = (w[1][1 - spin] - w[0][1 - spin]).abs();
            assert!((d - step).abs() < 1e-9, "{name}: tilt step {d}");
        }
    }
}

#[test]
fn a_path_starting_at_the_pole_takes_c_from_its_first_defined_point() {
    // The pass starts vertical and tilts away along +x: C is undefined at first and takes the
    // value the tilted points need, so it never turns; nothing is NaN.
    for (name, kin, axes, spin) in near_vertical_cases() {
        let pts: Vec<ClPoint> = (0..20)
            .map(|k| {
                let phi = (k as f64 * 0.5).to_radians();
                cl(
                    Vector3::zeros(),
                    Vector3::new(phi.sin(), 0.0, phi.cos()),
                    None,
                    k + 1,
                )
            })
            .collect();
        let a = kin.rotary_angles(&pts, &axes).unwrap();
        for (pt, ang) in pts.iter().zip(&a) {
            assert!(ang[0].is_finite() && ang[1].is_finite(), "{name}: NaN");
            assert_vec(kin.tool_axis(*ang), pt.o, 1e-12, name);
            assert!(
                (ang[spin] - a[0][spin]).abs() < 1e-12,
                "{name}: C moved: {a:?}"
            );
        }
    }
}

/// A head–table machine with table A (a blade mill: the workpiece turns about X between
/// centres, the head swivels B about Y), worked by hand: A = 90°, B = 30°, L = 100 mm, tool
/// tip at P = (10, 20, 30) in the workpiece. The table turns the workpiece by −A:
/// m = R_x(−90°)·P = (10, 30, −20); the pivot sits L along k_m = (sin 30°, 0, cos 30°) above
/// the tip, so X = 10 + 100·sin 30° = 60, Y = 30, Z = −20 + 100·cos 30° − 100 = −33.3975; the
/// tool relative to the workpiece is R_x(90°)·k_m = (0.5, −cos 30°, 0).
#[test]
fn head_table_with_table_a_matches_a_hand_computed_pose() {
    let kin = Kinematics::HeadTable(HeadTable {
        pivot_length: 100.0,
        table: RotaryTable::A,
    });
    let angles = kin.angles_from_rotary([90.0, 30.0, 0.0]);
    let w = path_w(&kin, Vector3::new(10.0, 20.0, 30.0), angles);
    let q = ik(&kin, w);
    let want = [
        60.0,
        30.0,
        -20.0 + 100.0 * 30f64.to_radians().cos() - 100.0,
        90.0,
        30.0,
    ];
    for (j, (&g, &e)) in q.iter().zip(&want).enumerate() {
        assert!((g - e).abs() < 1e-9, "axis {j}: {g} vs {e} ({q:?})");
    }
    let k = Vector3::new(0.5, -30f64.to_radians().cos(), 0.0);
    assert_vec(kin.tool_axis(angles), k, 1e-12, "tool axis");
    let pose = kin.forward(&q[..5]).unwrap();
    assert_vec(pose.p, Vector3::new(10.0, 20.0, 30.0), 1e-9, "tip");
    assert_vec(pose.k, k, 1e-12, "forward tool axis");
    // The tool vector alone gives a pose with the same tip and tool axis (A, B or its other
    // branch, A + 180°, 180° − B).
    let pts = [cl(Vector3::new(10.0, 20.0, 30.0), k, None, 3)];
    let a = kin.rotary_angles(&pts, &[]).unwrap()[0];
    let q2 = ik(&kin, path_w(&kin, Vector3::new(10.0, 20.0, 30.0), a));
    let pose = kin.forward(&q2[..5]).unwrap();
    assert_vec(
        pose.p,
        Vector3::new(10.0, 20.0, 30.0),
        1e-9,
        "tip from the vector",
    );
    assert_vec(pose.k, k, 1e-12, "tool axis from the vector");
    let b = q2[4].rem_euclid(360.0);
    assert!(
        (b - 30.0).abs() < 1e-9 || (b - 150.0).abs() < 1e-9,
        "B = {}",
        q2[4]
    );
}

/// Messages give machine B, not the path angle B − 90°: a programmed B outside travel names
/// the programmed value and B's travel as the machine file states it.
#[test]
fn head_table_with_table_a_names_b_and_its_travel_as_programmed() {
    let kin = Kinematics::HeadTable(HeadTable {
        pivot_length: 100.0,
        table: RotaryTable::A,
    });
    let axes = vec![
        axis("X", None),
        axis("Y", None),
        axis("Z", None),
        axis("A", Some((-36000.0, 36000.0))),
        axis("B", Some((-100.0, 50.0))),
    ];
    let ok = [cl(
        Vector3::zeros(),
        Vector3::z(),
        Some([10.0, 45.0, 0.0]),
        4,
    )];
    assert!(kin.rotary_angles(&ok, &axes).is_ok());
    let bad = [cl(
        Vector3::zeros(),
        Vector3::z(),
        Some([10.0, 60.0, 0.0]),
        5,
    )];
    let msg = kin.rotary_angles(&bad, &axes).unwrap_err().to_string();
    assert!(
        msg.contains("line 5") && msg.contains("B = 60.000000°") && msg.contains("[-100, 50]"),
        "{msg}"
    );
}
