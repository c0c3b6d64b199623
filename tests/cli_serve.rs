//! `robocal serve`: MIME types, index.html, 404 for traversal, unknown paths
//! and folders without index, loopback-only binding.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};

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

fn site() -> PathBuf {
    let base = std::env::temp_dir().join(format!("robocal-serve-{}", std::process::id()));
    let root = base.join("www");
    std::fs::create_dir_all(root.join("sub")).unwrap();
    std::fs::create_dir_all(root.join("app")).unwrap();
    std::fs::write(root.join("index.html"), "<!doctype html><title>t</title>").unwrap();
    std::fs::write(root.join("app/index.html"), "app").unwrap();
    std::fs::write(root.join("m.wasm"), b"\0asm\x01\0\0\0").unwrap();
    std::fs::write(root.join("x.js"), "export {}").unwrap();
    std::fs::write(root.join("a b.css"), "body{}").unwrap();
    std::fs::write(base.join("secret.txt"), "outside the served folder").unwrap();
    #[cfg(unix)]
    {
        let _ = std::os::unix::fs::symlink(base.join("secret.txt"), root.join("link.txt"));
    }
    root
}

fn start(root: &PathBuf) -> Server {
    let mut child = Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(["serve", "--port", "0", "--dir"])
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

/// Sends a raw request line; returns (status, content-type, body).
fn request(server: &Server, method: &str, target: &str) -> (u16, String, Vec<u8>) {
    let mut s = TcpStream::connect(&server.addr).unwrap();
    write!(s, "{method} {target} HTTP/1.1\r\nHost: x\r\n\r\n").unwrap();
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).unwrap();
    let split = raw.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
    let head = String::from_utf8_lossy(&raw[..split]).to_string();
    let status = head.split_whitespace().nth(1).unwrap().parse().unwrap();
    let ctype = head
        .lines()
        .find_map(|l| l.strip_prefix("Content-Type: "))
        .unwrap_or("")
        .to_string();
    (status, ctype, raw[split + 4..].to_vec())
}

#[test]
fn serves_files_with_mime_types_and_refuses_escapes() {
    let root = site();
    let server = start(&root);
    let (status, ctype, body) = request(&server, "GET", "/");
    assert_eq!((status, ctype.as_str()), (200, "text/html; charset=utf-8"));
    assert_eq!(body, b"<!doctype html><title>t</title>");
    assert_eq!(request(&server, "GET", "/m.wasm").1, "application/wasm");
    assert_eq!(
        request(&server, "GET", "/x.js?v=1").1,
        "text/javascript; charset=utf-8"
    );
    assert_eq!(request(&server, "GET", "/a%20b.css").0, 200);
    assert_eq!(request(&server, "GET", "/app/").2, b"app");
    // HEAD: headers only.
    let (status, _, body) = request(&server, "HEAD", "/index.html");
    assert_eq!((status, body.len()), (200, 0));
    // Unknown paths, folders without index.html (no listing), traversal in
    // every spelling, and a symlink out of the folder: all 404.
    for target in [
        "/missing.html",
        "/sub/",
        "/sub",
        "/../secret.txt",
        "/%2e%2e/secret.txt",
        "/sub/../../secret.txt",
        "/..%2fsecret.txt",
        "/%2e%2e%2fsecret.txt",
        "//etc/passwd",
        "/link.txt",
        "/%00",
        "/%zz",
        "relative",
    ] {
        let (status, _, body) = request(&server, "GET", target);
        assert_eq!(status, 404, "{target} must be 404");
        assert_eq!(body, b"not found\n", "{target}");
    }
    assert_eq!(request(&server, "POST", "/").0, 405);
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
    assert!(String::from_utf8_lossy(&out.stderr)
        .contains("unknown option --bogus (known: --dir, --host, --port, --public)"));
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
