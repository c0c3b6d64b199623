//! The `robocal` command-line tool: argument parsing and file I/O only; every
//! computation is a call into the library.

mod cli;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match cli::run(&args) {
        Ok(()) => {}
        Err(e) => {
            eprintln!("robocal: {e}");
            std::process::exit(e.exit_code());
        }
    }
}
