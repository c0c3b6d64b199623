//! `robocal serve`: a small static file server for the web app.
//!
//! GET and HEAD only, no directory listing, path traversal answered with 404,
//! loopback-only unless `--public` is given. One thread per connection,
//! `Connection: close` (the app is a handful of files).

use super::args::{Args, Spec};
use super::CliError;
use std::io::{BufRead, BufReader, Write};
use std::net::{IpAddr, SocketAddr, TcpListener, TcpStream};
use std::path::{Component, Path, PathBuf};

pub const HELP: &str = "robocal serve - serve the web app (or any static folder)

Usage: robocal serve [--dir DIR] [--host ADDR] [--port N] [--public]

Options:
  --dir DIR     folder to serve (default: www)
  --host ADDR   address to bind (default: 127.0.0.1). Addresses other than
                loopback are refused unless --public is also given.
  --port N      TCP port (default: 8080; 0 picks a free port)
  --public      allow binding to a non-loopback address (serves the folder to
                your network; the app itself never uploads anything)

The server prints the URL once it listens. It answers GET and HEAD, sends
correct MIME types (application/wasm for .wasm), serves index.html for a
folder that has one, and answers 404 for anything outside DIR, for missing
files and for folders without index.html (no listings).

Examples:
  robocal serve
  robocal serve --dir www --port 9000";

/// Largest request head accepted, in bytes.
const MAX_REQUEST_HEAD: usize = 16 * 1024;

pub fn run(raw: &[String]) -> Result<(), CliError> {
    let spec = Spec {
        command: "serve",
        valued: &["dir", "host", "port"],
        switches: &["public"],
    };
    let args = Args::parse(raw, &spec)?;
    if let Some(extra) = args.positionals.first() {
        return Err(CliError::usage(
            "serve",
            format!("unexpected argument '{extra}'"),
        ));
    }
    let dir = args.value("dir").unwrap_or("www");
    let host: IpAddr = args
        .value("host")
        .unwrap_or("127.0.0.1")
        .parse()
        .map_err(|_| CliError::usage("serve", "--host must be an IP address such as 127.0.0.1"))?;
    let port: u16 = args.parsed("serve", "port", 8080)?;
    if !host.is_loopback() && !args.switch("public") {
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
    println!(
        "robocal {} serving {} at http://{shown}:{}/",
        robocal::VERSION,
        root.display(),
        local.port()
    );
    let _ = std::io::stdout().flush();
    for stream in listener.incoming() {
        let Ok(stream) = stream else { continue };
        let root = root.clone();
        std::thread::spawn(move || {
            let _ = handle(stream, &root);
        });
    }
    Ok(())
}

fn handle(stream: TcpStream, root: &Path) -> std::io::Result<()> {
    stream.set_read_timeout(Some(std::time::Duration::from_secs(10)))?;
    let mut reader = BufReader::new(stream.try_clone()?);
    let mut request_line = String::new();
    reader.read_line(&mut request_line)?;
    // Drain the headers (bounded); the server needs none of them.
    let mut total = request_line.len();
    loop {
        let mut line = String::new();
        let n = reader.read_line(&mut line)?;
        total += n;
        if n == 0 || line == "\r\n" || line == "\n" || total > MAX_REQUEST_HEAD {
            break;
        }
    }
    let mut parts = request_line.split_whitespace();
    let (method, target) = (parts.next().unwrap_or(""), parts.next().unwrap_or(""));
    let mut out = stream;
    if method != "GET" && method != "HEAD" {
        return respond(
            &mut out,
            405,
            "text/plain; charset=utf-8",
            b"method not allowed\n",
            method == "HEAD",
        );
    }
    match resolve(root, target) {
        Some(path) => match std::fs::read(&path) {
            Ok(body) => respond(&mut out, 200, mime_type(&path), &body, method == "HEAD"),
            Err(_) => not_found(&mut out, method == "HEAD"),
        },
        None => not_found(&mut out, method == "HEAD"),
    }
}

fn not_found(out: &mut TcpStream, head: bool) -> std::io::Result<()> {
    respond(out, 404, "text/plain; charset=utf-8", b"not found\n", head)
}

fn respond(
    out: &mut TcpStream,
    status: u16,
    mime: &str,
    body: &[u8],
    head_only: bool,
) -> std::io::Result<()> {
    let reason = match status {
        200 => "OK",
        404 => "Not Found",
        405 => "Method Not Allowed",
        _ => "Error",
    };
    let header = format!(
        "HTTP/1.1 {status} {reason}\r\nContent-Type: {mime}\r\nContent-Length: {}\r\n\
         Cache-Control: no-cache\r\nX-Content-Type-Options: nosniff\r\nConnection: close\r\n\r\n",
        body.len()
    );
    out.write_all(header.as_bytes())?;
    if !head_only {
        out.write_all(body)?;
    }
    out.flush()
}

/// Map a request target to a file inside `root`, or `None` (answered 404).
/// Rejects `..`, absolute components, NUL bytes, and anything whose real path
/// (after symlinks) leaves `root`.
pub fn resolve(root: &Path, target: &str) -> Option<PathBuf> {
    let path = target.split(['?', '#']).next().unwrap_or("");
    let decoded = percent_decode(path)?;
    if !decoded.starts_with('/') || decoded.contains('\0') || decoded.contains('\\') {
        return None;
    }
    let mut candidate = root.to_path_buf();
    for component in Path::new(&decoded[1..]).components() {
        match component {
            Component::Normal(part) => candidate.push(part),
            Component::CurDir => {}
            Component::ParentDir | Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    let mut real = std::fs::canonicalize(&candidate).ok()?;
    if real.is_dir() {
        real = std::fs::canonicalize(real.join("index.html")).ok()?;
    }
    (real.starts_with(root) && real.is_file()).then_some(real)
}

fn percent_decode(s: &str) -> Option<String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = s.get(i + 1..i + 3)?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// The Content-Type for a file, from its extension.
pub fn mime_type(path: &Path) -> &'static str {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "html" | "htm" => "text/html; charset=utf-8",
        "js" | "mjs" => "text/javascript; charset=utf-8",
        "css" => "text/css; charset=utf-8",
        "wasm" => "application/wasm",
        "json" | "map" => "application/json",
        "webmanifest" => "application/manifest+json",
        "svg" => "image/svg+xml",
        "png" => "image/png",
        "jpg" | "jpeg" => "image/jpeg",
        "gif" => "image/gif",
        "bmp" => "image/bmp",
        "tif" | "tiff" => "image/tiff",
        "ico" => "image/x-icon",
        "txt" | "md" | "csv" => "text/plain; charset=utf-8",
        "yml" | "yaml" => "text/yaml; charset=utf-8",
        _ => "application/octet-stream",
    }
}
