//! `texsim`: see `texsim --help`. Without arguments it renders the built-in demo into ./out.

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = match texsim::cli::Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() {
                ExitCode::from(2)
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    match texsim::cli::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("texsim: error: {e}");
            ExitCode::FAILURE
        }
    }
}
