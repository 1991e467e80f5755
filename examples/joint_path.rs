//! A joint-space path: axis positions along a parameter s, given in code (the CSV layout
//! `feedopt solve` reads: `s,q_<axis>,…`), solved on a machine of kinematics `joint`. Here two
//! axes move along a straight line in joint space, `a` by L and `b` by L/2; the path speed
//! ds/dt is what the schedule chooses.
//!
//! ```sh
//! cargo run --release --example joint_path                 # L = 50, v = 100, a = 1000
//! cargo run --release --example joint_path -- 5 100 1000   # L, v, a of both axes
//! ```

use feedopt::machine::Machine;
use feedopt::optimize::{Options, optimize_joint};
use feedopt::toolpath::joint_csv;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let arg = |k: usize, default: f64| -> Result<f64, Box<dyn std::error::Error>> {
        std::env::args()
            .nth(k)
            .map_or(Ok(default), |a| Ok(a.parse()?))
    };
    let (length, velocity, acceleration) = (arg(1, 50.0)?, arg(2, 100.0)?, arg(3, 1000.0)?);

    let machine = Machine::from_json(
        "joint machine".as_ref(),
        &format!(
            r#"{{"kinematics": {{"type": "joint"}},
                "axes": {{"a": {{"velocity": {velocity}, "acceleration": {acceleration}}},
                         "b": {{"velocity": {velocity}, "acceleration": {acceleration}}}}}}}"#
        ),
    )?;
    // 11 rows along s ∈ [0, 1]: q_a = L s, q_b = L s / 2.
    let mut csv = String::from("s,q_a,q_b\n");
    for k in 0..=10 {
        let s = k as f64 / 10.0;
        csv += &format!("{s},{},{}\n", length * s, length * s / 2.0);
    }
    let path = joint_csv::parse("in-memory path".as_ref(), &csv)?;

    let solution = optimize_joint(&machine, &path, &Options::default())?;
    let v = &solution.verification;
    println!("cycle time      {:.9} s", solution.schedule.cycle_time);
    println!("stations        {}", solution.stations());
    println!(
        "verified        {} (worst ratio {:.5})",
        v.verified,
        v.worst_ratio()
    );
    for (axis, w) in machine.axes.iter().zip(&v.worst) {
        println!(
            "axis {}          peak |q̇|/v {:.4}, peak |q̈|/a {:.4}",
            axis.name, w.velocity, w.acceleration
        );
    }
    Ok(())
}
