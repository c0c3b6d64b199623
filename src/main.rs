//! The `robocal` command-line tool: argument parsing (clap) and file I/O
//! only; every computation is a call into the library.

mod cli;

use clap::Parser;

fn main() {
    // clap prints --help and --version (exit 0) and its own usage errors
    // (exit 2) itself.
    let args = cli::Cli::parse();
    if let Err(e) = cli::run(args) {
        eprintln!("robocal: {e}");
        std::process::exit(e.exit_code());
    }
}
