//! `robocal serve`: MIME types, index.html, HEAD, 404 for traversal, unknown
//! paths and folders without index, loopback-only binding; and the bounds
//! (src/cli/serve_http.rs): 431 for an oversized head, 408 for a client that
//! sends nothing while others are still served, 503 beyond the worker pool
//! and its queue. Correctness only: the load test is benches/serve_load.py.
//!
//! A test binary of its own (the others are one per capability): its tests
//! time a server's answers, so they do not share the process with the
//! CPU-heavy calibration tests.
//!
//! Times: the server gives a request head 5 s from accept (its default
//! `head_deadline`); every client read here times out after `HANG_GUARD`, so a
//! server that stops answering fails the test instead of hanging it.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

/// The server's defaults (serve_http.rs `Limits::default()`).
const WORKERS: usize = 16;
const QUEUE: usize = 64;
const MAX_HEAD_BYTES: usize = 8 * 1024;
/// Far above the 5 s head deadline.
const HANG_GUARD: Duration = Duration::from_secs(30);

struct Server {
    child: Child,
    addr: String,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A served folder per test (tests run in parallel), with a secret beside it.
fn site(test: &str) -> PathBuf {
    let base = std::env::temp_dir().join(format!("robocal-serve-{}-{test}", std::process::id()));
    let root = base.join("www");
    std::fs::create_dir_all(root.join("sub")).unwrap();
    std::fs::create_dir_all(root.join("app")).unwrap();
    std::fs::write(root.join("index.html"), "<!doctype html><title>t</title>").unwrap();
    std::fs::write(root.join("app/index.html"), "app").unwrap();
    std::fs::write(root.join("m.wasm"), b"\0asm\x01\0\0\0").unwrap();
    std::fs::write(root.join("x.js"), "export {}").unwrap();
    std::fs::write(root.join("w.mjs"), "export {}").unwrap();
    std::fs::write(root.join("a b.css"), "body{}").unwrap();
    std::fs::write(base.join("secret.txt"), "outside the served folder").unwrap();
    std::fs::write(base.join("Cargo.toml"), "[package]").unwrap();
    #[cfg(unix)]
    {
        let _ = std::os::unix::fs::symlink(base.join("secret.txt"), root.join("link.txt"));
    }
    root
}

fn start(root: &PathBuf) -> Server {
    start_with(root, "--dir")
}

/// `flag` is "--dir", or "" for the positional folder (`robocal serve DIR`).
fn start_with(root: &PathBuf, flag: &str) -> Server {
    let mut child = Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(["serve", "--port", "0"])
        .args((!flag.is_empty()).then_some(flag))
        .arg(root)
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let url = line.split(" at ").nth(1).unwrap().trim().to_string();
    let addr = url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_string();
    Server { child, addr }
}

fn connect(server: &Server) -> TcpStream {
    let s = TcpStream::connect(&server.addr).unwrap();
    s.set_read_timeout(Some(HANG_GUARD)).unwrap();
    s
}

/// A response: status, the head's lines, body.
struct Response {
    status: u16,
    head: String,
    body: Vec<u8>,
}

impl Response {
    fn header(&self, name: &str) -> &str {
        self.head
            .lines()
            .find_map(|l| l.strip_prefix(name)?.strip_prefix(": "))
            .unwrap_or("")
    }
}

/// Reads a whole response (the server closes every connection).
fn read_response(mut s: TcpStream) -> Response {
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).unwrap();
    let split = raw
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .unwrap_or_else(|| panic!("no response head in {:?}", String::from_utf8_lossy(&raw)));
    let head = String::from_utf8_lossy(&raw[..split]).to_string();
    let status = head.split_whitespace().nth(1).unwrap().parse().unwrap();
    Response {
        status,
        head,
        body: raw[split + 4..].to_vec(),
    }
}

/// Sends raw bytes as the request; returns the response.
fn send(server: &Server, raw: &[u8]) -> Response {
    let mut s = connect(server);
    s.write_all(raw).unwrap();
    read_response(s)
}

fn request(server: &Server, method: &str, target: &str) -> Response {
    send(
        server,
        format!("{method} {target} HTTP/1.1\r\nHost: x\r\n\r\n").as_bytes(),
    )
}

#[test]
fn serves_files_with_mime_types_and_refuses_escapes() {
    let root = site("files");
    let server = start(&root);
    let index = request(&server, "GET", "/");
    assert_eq!(
        (index.status, index.header("Content-Type")),
        (200, "text/html; charset=utf-8")
    );
    assert_eq!(index.body, b"<!doctype html><title>t</title>");
    assert_eq!(index.header("Connection"), "close");
    for (target, mime) in [
        ("/m.wasm", "application/wasm"),
        ("/x.js?v=1", "text/javascript; charset=utf-8"),
        ("/w.mjs", "text/javascript; charset=utf-8"),
        ("/a%20b.css", "text/css; charset=utf-8"),
    ] {
        let r = request(&server, "GET", target);
        assert_eq!(
            (r.status, r.header("Content-Type")),
            (200, mime),
            "{target}"
        );
    }
    assert_eq!(request(&server, "GET", "/m.wasm").body, b"\0asm\x01\0\0\0");
    assert_eq!(request(&server, "GET", "/app/").body, b"app");
    // HEAD: the GET's headers, no body.
    let head = request(&server, "HEAD", "/index.html");
    assert_eq!((head.status, head.body.len()), (200, 0));
    assert_eq!(head.header("Content-Length"), "31");
    let head = request(&server, "HEAD", "/missing");
    assert_eq!((head.status, head.body.len()), (404, 0));
    // Unknown paths, folders without index.html (no listing), traversal in
    // every spelling, and a symlink out of the folder: all 404.
    for target in [
        "/missing.html",
        "/sub/",
        "/sub",
        "/../Cargo.toml",
        "/../secret.txt",
        "/%2e%2e/Cargo.toml",
        "/%2E%2E/secret.txt",
        "/sub/../../secret.txt",
        "/sub/%2e%2e/%2e%2e/Cargo.toml",
        "/..%2fsecret.txt",
        "/%2e%2e%2fsecret.txt",
        "/..%5csecret.txt",
        "//etc/passwd",
        "/link.txt",
        "/%00",
        "/%zz",
        "relative",
        "http://x/../secret.txt",
    ] {
        let r = request(&server, "GET", target);
        assert_eq!(r.status, 404, "{target} must be 404");
        assert_eq!(r.body, b"not found\n", "{target}");
    }
    for method in ["POST", "PUT", "DELETE", "OPTIONS"] {
        let r = request(&server, method, "/");
        assert_eq!(
            (r.status, r.header("Allow")),
            (405, "GET, HEAD"),
            "{method}"
        );
    }
    assert_eq!(send(&server, b"GET / HTTP/9.9\r\n\r\n").status, 400);
    assert_eq!(
        send(&server, b"\x16\x03\x01\x00\xa5\x01\x00\x00\xa1\x03\x03").status,
        400,
        "a TLS hello"
    );
}

#[test]
fn the_folder_may_be_given_positionally() {
    let root = site("positional");
    let server = start_with(&root, "");
    let index = request(&server, "GET", "/");
    assert_eq!(
        (index.status, index.body.as_slice()),
        (200, &b"<!doctype html><title>t</title>"[..])
    );
    assert_eq!(request(&server, "GET", "/../secret.txt").status, 404);
}

#[test]
fn oversized_heads_get_431_and_the_server_goes_on() {
    let root = site("431");
    let server = start(&root);
    let long = format!(
        "GET / HTTP/1.1\r\nHost: x\r\nX-Big: {}\r\n\r\n",
        "a".repeat(2 * MAX_HEAD_BYTES)
    );
    let many: String = (0..100).map(|i| format!("X-{i}: v\r\n")).collect();
    let many = format!("GET / HTTP/1.1\r\n{many}\r\n");
    let endless_line = "G".repeat(4 * MAX_HEAD_BYTES);
    for (what, raw) in [
        ("a long header", long),
        ("100 headers", many),
        ("a line without end", endless_line),
    ] {
        let r = send(&server, raw.as_bytes());
        assert_eq!(r.status, 431, "{what}");
        assert_eq!(r.body, b"request header fields too large\n", "{what}");
        assert_eq!(
            request(&server, "GET", "/x.js").status,
            200,
            "the request after {what}"
        );
    }
    // Just under the cap is still a request.
    let filler = "a".repeat(MAX_HEAD_BYTES - 100);
    let fits = format!("GET /x.js HTTP/1.1\r\nX-Fill: {filler}\r\n\r\n");
    assert_eq!(send(&server, fits.as_bytes()).status, 200);
}

#[test]
fn idle_clients_are_cut_off_while_others_are_served() {
    let root = site("idle");
    let server = start(&root);
    // More idle clients than workers (all under the queue's bound): silent
    // ones, and slow ones stuck half-way through a request line.
    let mut idle: Vec<TcpStream> = (0..WORKERS + 8).map(|_| connect(&server)).collect();
    for s in idle.iter_mut().step_by(2) {
        s.write_all(b"GET /index.ht").unwrap();
    }
    let r = request(&server, "GET", "/index.html");
    assert_eq!(
        r.status,
        200,
        "a normal GET behind {} idle clients",
        idle.len()
    );
    assert_eq!(r.body, b"<!doctype html><title>t</title>");
    for (i, s) in idle.into_iter().enumerate() {
        let r = read_response(s);
        assert_eq!(
            (r.status, r.body.as_slice()),
            (408, &b"request timeout\n"[..]),
            "idle client {i}"
        );
    }
}

#[test]
fn refuses_non_loopback_bind_without_public() {
    let out = Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(["serve", "--host", "0.0.0.0", "--port", "0"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr),
        "robocal: serve: refusing to bind to 0.0.0.0: it is not a loopback address; add --public to serve to the network (see 'robocal serve --help')\n"
    );
    let out = Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(["serve", "--bogus"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("error: unexpected argument '--bogus' found")
    );
}

#[test]
fn info_reports_each_file() {
    let dir = std::env::temp_dir().join(format!("robocal-info-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let pgm = dir.join("a.pgm");
    std::fs::write(&pgm, b"P5\n3 2\n255\n\x00\x01\x02\x03\x04\x05").unwrap();
    let bad = dir.join("b.png");
    std::fs::write(&bad, b"nope").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_robocal"))
        .arg("info")
        .arg(&pgm)
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<serde_json::Value> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines[0]["format"], "pnm");
    assert_eq!(
        (lines[0]["width"].as_u64(), lines[0]["height"].as_u64()),
        (Some(3), Some(2))
    );
    assert_eq!(
        lines[1]["error"],
        "not an image: the bytes match none of PNG, JPEG, TIFF, BMP, PGM/PPM, GIF, WebP"
    );
}

/// The policy of www/index.html's `<meta http-equiv="Content-Security-Policy">`.
fn page_policy() -> String {
    let page = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/www/index.html"))
        .expect("read www/index.html");
    let meta = page
        .lines()
        .find(|l| l.contains("http-equiv=\"Content-Security-Policy\""))
        .expect("the page's CSP meta");
    let content = meta.split("content=\"").nth(1).expect("content=");
    content
        .split('"')
        .next()
        .expect("closing quote")
        .to_string()
}

#[test]
fn dotfiles_are_404_and_every_response_carries_the_page_policy() {
    let root = site("dotfiles");
    std::fs::create_dir_all(root.join(".git")).unwrap();
    std::fs::write(root.join(".git/config"), "[remote \"origin\"]").unwrap();
    std::fs::write(root.join(".env"), "TOKEN=1").unwrap();
    std::fs::write(root.join("sub/.hidden.js"), "x").unwrap();
    let server = start(&root);
    for target in [
        "/.git/config",
        "/.git/",
        "/.env",
        "/%2eenv",
        "/sub/.hidden.js",
    ] {
        let r = request(&server, "GET", target);
        assert_eq!(
            (r.status, r.body.as_slice()),
            (404, &b"not found\n"[..]),
            "{target}"
        );
    }
    let want = format!("{}; frame-ancestors 'none'", page_policy());
    for target in ["/", "/m.wasm", "/missing", "/.env"] {
        let r = request(&server, "GET", target);
        assert_eq!(r.header("Content-Security-Policy"), want, "{target}");
        assert_eq!(r.header("X-Content-Type-Options"), "nosniff", "{target}");
    }
    let refused = request(&server, "POST", "/");
    assert_eq!(refused.header("Content-Security-Policy"), want);
}

/// Connections that send half a request line and then nothing (slowloris).
fn slow_clients(server: &Server, n: usize) -> Vec<TcpStream> {
    (0..n)
        .map(|_| {
            let mut s = connect(server);
            s.write_all(b"GET /index.ht").unwrap();
            s
        })
        .collect()
}

/// The contract of the slow-client budget: whatever the slow clients do, a
/// normal request is reached within about a second (the design figure is
/// 0.16 s; 2 s leaves room for a loaded 2-core machine).
const NORMAL_WITHIN: Duration = Duration::from_secs(2);

#[test]
fn a_normal_request_is_answered_while_slow_clients_hold_connections() {
    let root = site("slowloris");
    let server = start(&root);
    // Fewer than the queue holds, so none of them (nor the normal request)
    // is refused with 503 at accept even before a worker takes one, and
    // every one of them waits in front of the normal request.
    let slow = slow_clients(&server, QUEUE - 8);
    let started = std::time::Instant::now();
    let r = request(&server, "GET", "/index.html");
    let took = started.elapsed();
    assert_eq!(
        (r.status, r.body.as_slice()),
        (200, &b"<!doctype html><title>t</title>"[..])
    );
    assert!(
        took < NORMAL_WITHIN,
        "answered after {took:?} behind {} slow clients",
        slow.len()
    );
    // Every slow client is still answered, 408, in time.
    for (i, s) in slow.into_iter().enumerate() {
        assert_eq!(read_response(s).status, 408, "slow client {i}");
    }
}

#[test]
fn clients_that_never_read_a_large_file_do_not_block_the_next_request() {
    let root = site("nonreading");
    // Larger than the socket buffers, so a client that never reads stalls
    // the write.
    std::fs::write(root.join("big.wasm"), vec![0u8; 16 << 20]).unwrap();
    let server = start(&root);
    let stalled: Vec<TcpStream> = (0..20)
        .map(|_| {
            let mut s = connect(&server);
            s.write_all(b"GET /big.wasm HTTP/1.1\r\nHost: x\r\n\r\n")
                .unwrap();
            s
        })
        .collect();
    // Let the workers take them and stall.
    std::thread::sleep(Duration::from_millis(300));
    let started = std::time::Instant::now();
    let r = request(&server, "GET", "/index.html");
    let took = started.elapsed();
    assert_eq!(r.status, 200);
    assert!(
        took < NORMAL_WITHIN,
        "answered after {took:?} behind {} stalled downloads",
        stalled.len()
    );
}
