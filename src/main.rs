//! The `feedopt` command: parses arguments and calls the library.

use clap::Parser;

fn main() -> std::process::ExitCode {
    let cli = feedopt::cli::Cli::parse();
    match feedopt::cli::run(&cli) {
        Ok(out) => {
            print!("{out}");
            std::process::ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("feedopt: error: {e}");
            std::process::ExitCode::from(2)
        }
    }
}
