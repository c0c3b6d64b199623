//! `robocal serve`: a small static file server for the web app.
//!
//! This file reads the arguments, binds (loopback-only unless `--public` is
//! given) and prints the URL; the serving itself, with its bounds on threads,
//! header size and time, is in serve_http.rs.

use super::CliError;
use std::net::{IpAddr, SocketAddr, TcpListener};

// Sibling files rather than a `mod` line in cli/mod.rs, so the serving
// internals stay beside the argument code that calls them.
#[path = "serve_files.rs"]
mod files;
#[path = "serve_http.rs"]
mod http;
#[path = "serve_slow.rs"]
mod slow;

#[derive(clap::Args)]
#[command(
    about = "serve the web app (a static folder) on http://127.0.0.1:8080",
    long_about = "serve the web app (or any static folder)

The server prints the URL once it listens. It answers GET and HEAD, sends
correct MIME types (application/wasm for .wasm), serves index.html for a
folder that has one, and answers 404 for anything outside DIR, for missing
files and for folders without index.html (no listings).",
    after_help = "Examples:
  robocal serve
  robocal serve www
  robocal serve --dir www --port 9000",
    args_override_self = true
)]
pub struct ServeArgs {
    /// Folder to serve (default: www); the same as --dir DIR
    #[arg(value_name = "DIR", conflicts_with = "dir")]
    folder: Option<String>,
    /// Folder to serve (default: www)
    #[arg(long, value_name = "DIR")]
    dir: Option<String>,
    /// Address to bind (default: 127.0.0.1). Addresses other than loopback
    /// are refused unless --public is also given.
    #[arg(long, value_name = "ADDR")]
    host: Option<String>,
    /// TCP port (0 picks a free port)
    #[arg(long, value_name = "N", default_value_t = 8080)]
    port: u16,
    /// Allow binding to a non-loopback address (serves the folder to your
    /// network; the app itself never uploads anything)
    #[arg(long)]
    public: bool,
}

pub fn run(args: ServeArgs) -> Result<(), CliError> {
    let dir = args
        .folder
        .as_deref()
        .or(args.dir.as_deref())
        .unwrap_or("www");
    let host: IpAddr = args
        .host
        .as_deref()
        .unwrap_or("127.0.0.1")
        .parse()
        .map_err(|_| CliError::usage("serve", "--host must be an IP address such as 127.0.0.1"))?;
    let port = args.port;
    if !host.is_loopback() && !args.public {
        return Err(CliError::usage(
            "serve",
            format!("refusing to bind to {host}: it is not a loopback address; add --public to serve to the network"),
        ));
    }
    let root = std::fs::canonicalize(dir)
        .map_err(|e| CliError::Io(format!("cannot serve '{dir}': {e}")))?;
    if !root.is_dir() {
        return Err(CliError::Io(format!("cannot serve '{dir}': not a folder")));
    }
    let listener = TcpListener::bind(SocketAddr::new(host, port))
        .map_err(|e| CliError::Io(format!("cannot listen on {host}:{port}: {e}")))?;
    let local = listener
        .local_addr()
        .map_err(|e| CliError::Io(e.to_string()))?;
    let shown = match local.ip() {
        IpAddr::V6(ip) => format!("[{ip}]"),
        IpAddr::V4(ip) => ip.to_string(),
    };
    // The banner is a courtesy: serving goes on if nobody reads stdout.
    let _ = super::output::println_stdout(&format!(
        "robocal {} serving {} at http://{shown}:{}/",
        robocal::VERSION,
        root.display(),
        local.port()
    ));
    http::serve(listener, root, http::Limits::default())
        .map_err(|e| CliError::Io(format!("serving on {host}:{}: {e}", local.port())))
}
