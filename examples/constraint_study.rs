//! A constraint study in a dozen lines: how the cycle time of the bundled pocket depends on the
//! X axis's acceleration limit, with the sensitivity dT/da from the solver's duals and from
//! finite differences (`feedopt::sweep`).
//!
//! ```sh
//! cargo run --release --example constraint_study            # 8 values from 500 to 4000 mm/s²
//! cargo run --release --example constraint_study -- 3       # 3 values
//! ```

use feedopt::machine::Machine;
use feedopt::sweep::{SweepOptions, SweptLimit, sweep};
use feedopt::toolpath;

fn main() -> Result<(), feedopt::error::Error> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("problems/xyz_pocket");
    let machine = Machine::from_file(&dir.join("machine.json"))?;
    let input = toolpath::Input::Cl(toolpath::read(&dir.join("pocket_contour.cls"))?);
    let steps = std::env::args()
        .nth(1)
        .and_then(|n| n.parse().ok())
        .unwrap_or(8);
    let options = SweepOptions::new("X", SweptLimit::Acceleration, 500.0, 4000.0, steps);
    let study = sweep(&machine, &input, "pocket", &options)?;
    println!("X acceleration [mm/s²]  cycle time [s]  dT/da dual  dT/da fd");
    for p in &study.points {
        let dual = p
            .sensitivity_dual
            .map_or("-".into(), |d| format!("{d:.3e}"));
        println!(
            "{:>22.1}  {:>14.6}  {:>10}  {:>8.3e}",
            p.limit, p.cycle_time_s, dual, p.sensitivity_fd
        );
    }
    Ok(())
}
