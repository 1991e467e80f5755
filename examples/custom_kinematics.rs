//! A machine's kinematics written by the user. feedopt's machines with kinematics are a closed
//! set (`machine::KinematicsSpec`); any other machine plugs in through the joint-space route:
//! the user's inverse kinematics turns the toolpath (tool tip P and tool axis O along the path
//! length s) into axis positions q(s), and `optimize_joint` schedules them against the axes'
//! limits, exactly as for a built-in machine (the limits are on q̇ and q̈ either way).
//!
//! To show that the two routes agree, the user's kinematics here is the double swivel head of
//! seed 000 (eq. 15, 16 and 27), written from the paper, and the same 5-axis move is solved
//! both ways: through `SwivelHead` below and through the built-in `head_head`. The cycle
//! times agree to the discretisation error.
//!
//! ```sh
//! cargo run --release --example custom_kinematics
//! ```

use feedopt::machine::Machine;
use feedopt::optimize::{Options, optimize, optimize_joint};
use feedopt::toolpath::{ClPoint, Feed, Toolpath, joint_csv};
use nalgebra::Vector3;

/// The user's machine: a table moving in X and Y, a head moving in Z, a swivel head turning
/// the tool by C about the vertical and tilting it by A; `d2` from the pivot to the tool tip.
struct SwivelHead {
    d2: f64,
}

impl SwivelHead {
    const AXES: [&'static str; 5] = ["X", "Y", "Z", "C", "A"];

    /// Axis positions (mm, degrees) that put the tool tip at `p` with tool axis `o`.
    fn inverse(&self, p: Vector3<f64>, o: Vector3<f64>) -> [f64; 5] {
        let tilt = o.x.hypot(o.y).atan2(o.z); // A, eq. 16
        let spin = o.x.atan2(-o.y); // C
        let d2 = self.d2;
        [
            -p.x + d2 * tilt.sin() * spin.sin(),
            -p.y - d2 * tilt.sin() * spin.cos(),
            p.z + d2 - d2 * tilt.cos(),
            spin.to_degrees(),
            tilt.to_degrees(),
        ]
    }
}

/// The tool axis for spin C and tilt A (radians), eq. 15.
fn tool_axis(spin: f64, tilt: f64) -> Vector3<f64> {
    Vector3::new(
        tilt.sin() * spin.sin(),
        -tilt.sin() * spin.cos(),
        tilt.cos(),
    )
}

/// Every axis's velocity and acceleration limit (mm/s, mm/s² or °/s, °/s²), as JSON.
/// The slow table (X, Y) holds the feed down, and its motion is far from linear in s: the
/// swivel head's turn moves the pivot, which the table must follow.
const LIMITS: &str = r#""X": {"velocity": 100, "acceleration": 500},
    "Y": {"velocity": 100, "acceleration": 500},
    "Z": {"velocity": 400, "acceleration": 2000},
    "C": {"velocity": 360, "acceleration": 3000},
    "A": {"velocity": 180, "acceleration": 2000}"#;

fn main() -> Result<(), feedopt::error::Error> {
    let head = SwivelHead { d2: 200.0 };
    // The move: the tip 60 mm along X and 20 mm along Y while the tool turns from (C, A) =
    // (60°, 10°) to (120°, 40°), the angles linear in the path length.
    let (p0, p1) = (Vector3::new(0.0, 0.0, 50.0), Vector3::new(60.0, 20.0, 50.0));
    let (c0, c1) = (60f64.to_radians(), 120f64.to_radians());
    let (a0, a1) = (10f64.to_radians(), 40f64.to_radians());
    let length = (p1 - p0).norm();
    let at = |s: f64| {
        let f = s / length;
        (
            p0 + (p1 - p0) * f,
            tool_axis(c0 + (c1 - c0) * f, a0 + (a1 - a0) * f),
        )
    };

    // The user's route: q(s) at 401 rows, a joint-space machine with the same limits.
    let mut csv = format!(
        "s,{}\n",
        SwivelHead::AXES.map(|a| format!("q_{a}")).join(",")
    );
    for k in 0..=400 {
        let s = length * k as f64 / 400.0;
        let (p, o) = at(s);
        let q = head.inverse(p, o).map(|x| x.to_string());
        csv += &format!("{s},{}\n", q.join(","));
    }
    let path = joint_csv::parse("swivel head move".as_ref(), &csv)?;
    let joint_machine = Machine::from_json(
        "joint machine".as_ref(),
        &format!(r#"{{"kinematics": {{"type": "joint"}}, "axes": {{{LIMITS}}}}}"#),
    )?;
    let custom = optimize_joint(&joint_machine, &path, &Options::default())?;

    // The built-in route: the two CL points and feedopt's own head_head kinematics.
    let builtin_machine = Machine::from_json(
        "head_head machine".as_ref(),
        &format!(
            r#"{{"kinematics": {{"type": "head_head", "tool_length": {}}}, "axes": {{{LIMITS}}}}}"#,
            head.d2
        ),
    )?;
    let points = [0.0, length].map(at);
    let cl = Toolpath {
        source: "swivel head move".into(),
        points: points
            .iter()
            .enumerate()
            .map(|(k, &(p, o))| ClPoint {
                p,
                o,
                feed: Feed::Unspecified,
                rotary: None,
                line: k + 1,
            })
            .collect(),
        ..Default::default()
    };
    let builtin = optimize(&builtin_machine, &cl, &Options::default())?;

    let (t_custom, t_builtin) = (custom.schedule.cycle_time, builtin.schedule.cycle_time);
    println!(
        "custom kinematics     cycle time {t_custom:.6} s, verified {}",
        custom.verification.verified
    );
    println!(
        "built-in head_head    cycle time {t_builtin:.6} s, verified {}",
        builtin.verification.verified
    );
    println!(
        "relative difference   {:.2e}",
        (t_custom - t_builtin).abs() / t_builtin
    );
    let binding = feedopt::report::Summary::new(&joint_machine, "custom", &custom).binding;
    for b in binding
        .iter()
        .filter(|b| b.share_of_path > 0.0 && b.limit != feedopt::constraints::Bound::None)
    {
        println!(
            "custom binding        {:<16} {:5.1} % of the path",
            b.name,
            100.0 * b.share_of_path
        );
    }
    Ok(())
}
