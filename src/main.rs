//! The `feedopt` command: parses arguments and calls the library.

use clap::Parser;

fn main() -> std::process::ExitCode {
    let cli = feedopt::cli::Cli::parse();
    feedopt::cli::init_logging(cli.verbose);
    match feedopt::cli::run(&cli) {
        Ok(out) => {
            print!("{out}");
            std::process::ExitCode::SUCCESS
        }
        Err(e) => {
            // Text from an input file never breaks the line or drives the terminal.
            let message = feedopt::files::escape_control(&e.to_string());
            eprintln!("feedopt: error: {message}");
            std::process::ExitCode::from(2)
        }
    }
}
