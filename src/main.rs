//! The `robocal` command-line tool: argument parsing (clap) and file I/O
//! only; every computation is a call into the library.

mod cli;

#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

use clap::Parser;

fn main() {
    // clap prints --help and --version (exit 0) and its own usage errors
    // (exit 2) itself.
    if let Some(message) = non_utf8_argument() {
        eprintln!("robocal: {message}");
        std::process::exit(2);
    }
    // A codec's panic on a crafted file is caught and reported as that
    // file's decode error (robocal::image::decode): the default hook's
    // backtrace would only be noise then. Every other panic prints as usual.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !robocal::image::inside_codec_guard() {
            default_hook(info);
        }
    }));
    let args = cli::Cli::parse();
    if let Err(e) = cli::run(args) {
        // A closed stdout ends quietly, as with other Unix tools.
        if !matches!(e, cli::CliError::BrokenPipe) {
            eprintln!("robocal: {e}");
        }
        std::process::exit(e.exit_code());
    }
}

/// The first command-line argument that is not UTF-8, named: clap's own
/// error does not say which one. File names are taken as UTF-8 text (they
/// go into JSON reports and exports), so such a file needs a new name.
fn non_utf8_argument() -> Option<String> {
    std::env::args_os()
        .enumerate()
        .skip(1)
        .find(|(_, a)| a.to_str().is_none())
        .map(|(i, a)| {
            format!(
                "argument {i} ('{}') is not UTF-8 text: robocal takes file names and values in UTF-8; rename the file (\u{fffd} marks the bytes that are not UTF-8)",
                a.to_string_lossy()
            )
        })
}
