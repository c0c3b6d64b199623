//! Which file a request names, and its Content-Type: the part of
//! `robocal serve` that decides what may be read from the served folder
//! (serve_http.rs holds the connection handling around it).

use std::path::{Component, Path, PathBuf};

/// Map a request target to a file inside `root`, or `None` (answered 404).
/// Rejects `..`, absolute components, NUL bytes, backslashes, malformed
/// percent escapes, any path component starting with `.` (`/.git/config`,
/// `/.env`: dotfiles are never served, also when a symlink leads to one),
/// and anything whose real path (after symlinks) leaves `root`. A folder
/// stands for its index.html.
pub fn resolve(root: &Path, target: &str) -> Option<PathBuf> {
    let path = target.split(['?', '#']).next().unwrap_or("");
    let decoded = percent_decode(path)?;
    if !decoded.starts_with('/') || decoded.contains('\0') || decoded.contains('\\') {
        return None;
    }
    let mut candidate = root.to_path_buf();
    for component in Path::new(&decoded[1..]).components() {
        match component {
            Component::Normal(part) if is_hidden(part) => return None,
            Component::Normal(part) => candidate.push(part),
            Component::CurDir => {}
            Component::ParentDir | Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    let mut real = std::fs::canonicalize(&candidate).ok()?;
    if real.is_dir() {
        real = std::fs::canonicalize(real.join("index.html")).ok()?;
    }
    let inside = real.strip_prefix(root).ok()?;
    let hidden = inside
        .components()
        .any(|c| matches!(c, Component::Normal(part) if is_hidden(part)));
    (!hidden && real.is_file()).then_some(real)
}

/// A dotfile or dot-folder name (`.git`, `.env`, `.DS_Store`).
fn is_hidden(part: &std::ffi::OsStr) -> bool {
    part.as_encoded_bytes().first() == Some(&b'.')
}

/// Strict `%XX` decoding of a URL path: a malformed escape or a result that
/// is not UTF-8 is `None` (the percent-encoding crate passes those through
/// unchanged, which would let `%zz` name a file).
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
        "webp" => "image/webp",
        "bmp" => "image/bmp",
        "tif" | "tiff" => "image/tiff",
        "ico" => "image/x-icon",
        "woff2" => "font/woff2",
        "txt" | "md" | "csv" => "text/plain; charset=utf-8",
        "yml" | "yaml" => "text/yaml; charset=utf-8",
        _ => "application/octet-stream",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_decoding_is_strict() {
        assert_eq!(percent_decode("/a%20b.css").as_deref(), Some("/a b.css"));
        assert_eq!(percent_decode("/%2e%2E/x").as_deref(), Some("/../x"));
        assert_eq!(percent_decode("/%zz"), None);
        assert_eq!(percent_decode("/%2"), None);
        assert_eq!(percent_decode("/%ff"), None, "not UTF-8");
    }

    #[test]
    fn dotfiles_are_never_resolved() {
        let root = std::env::temp_dir().join(format!("robocal-serve-dot-{}", std::process::id()));
        std::fs::create_dir_all(root.join(".git")).unwrap();
        std::fs::create_dir_all(root.join("sub")).unwrap();
        std::fs::write(root.join(".git/config"), "[core]").unwrap();
        std::fs::write(root.join(".env"), "KEY=1").unwrap();
        std::fs::write(root.join("sub/a.txt"), "a").unwrap();
        #[cfg(unix)]
        std::os::unix::fs::symlink(root.join(".env"), root.join("sub/env.txt")).unwrap();
        let root = std::fs::canonicalize(&root).unwrap();
        for target in [
            "/.git/config",
            "/.env",
            "/%2egit/config",
            "/sub/../.env",
            "/sub/env.txt",
        ] {
            assert_eq!(resolve(&root, target), None, "{target}");
        }
        assert_eq!(resolve(&root, "/sub/a.txt"), Some(root.join("sub/a.txt")));
        std::fs::remove_dir_all(root).unwrap();
    }

    #[test]
    fn mime_types_follow_the_web_platform() {
        for (name, mime) in [
            ("m.wasm", "application/wasm"),
            ("w.mjs", "text/javascript; charset=utf-8"),
            ("APP.JS", "text/javascript; charset=utf-8"),
            ("index.html", "text/html; charset=utf-8"),
            ("noext", "application/octet-stream"),
        ] {
            assert_eq!(mime_type(Path::new(name)), mime, "{name}");
        }
    }
}
