//! Solve an APT CL file on a machine: the time-optimal feed, its cycle time, which limit holds
//! the feed down where, and the re-simulation that checks it.
//!
//! ```sh
//! cargo run --release --example solve_apt                       # the bundled seed blade
//! cargo run --release --example solve_apt -- MACHINE.json PATH.cls
//! ```

use std::path::PathBuf;

use feedopt::machine::Machine;
use feedopt::optimize::{Options, optimize};
use feedopt::report::Summary;
use feedopt::toolpath;

fn main() -> Result<(), feedopt::error::Error> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("problems/seed_head_head");
    let mut args = std::env::args_os().skip(1).map(PathBuf::from);
    let machine_file = args.next().unwrap_or(root.join("machine.json"));
    let cl_file = args.next().unwrap_or(root.join("impeller_blade.cls"));

    let machine = Machine::from_file(&machine_file)?;
    let path = toolpath::read(&cl_file)?;
    let solution = optimize(&machine, &path, &Options::default())?;

    let summary = Summary::new(&machine, &cl_file.display().to_string(), &solution);
    let length = solution.schedule.stations.last().map_or(0.0, |s| s.s);
    println!("cycle time      {:.6} s", solution.schedule.cycle_time);
    println!("path length     {length:.6} mm");
    println!("stations        {}", solution.stations());
    println!(
        "verified        {} (worst ratio to a limit {:.5})",
        solution.verification.verified,
        solution.verification.worst_ratio()
    );
    for b in summary.binding.iter().filter(|b| b.share_of_path > 0.0) {
        println!(
            "binding         {:<24} {:5.1} % of the path",
            b.name,
            100.0 * b.share_of_path
        );
    }
    Ok(())
}
