//! Unit tests of the request heads and answers of serve_http.rs.

use super::*;

fn get(target: &str) -> Request {
    Request {
        method: Method::Get,
        target: target.to_string(),
    }
}

#[test]
fn heads_parse_or_are_refused_with_their_status() {
    assert_eq!(
        parse_head(b"GET /a.js?v=1 HTTP/1.1\r\nHost: x\r\n\r\n"),
        Ok(Some(get("/a.js?v=1")))
    );
    assert_eq!(
        parse_head(b"HEAD / HTTP/1.0\r\n\r\n").map(|r| r.map(|r| r.method)),
        Ok(Some(Method::Head))
    );
    assert_eq!(
        parse_head(b"GET / HTTP/1.1\r\nHost: x\r\n"),
        Ok(None),
        "no blank line yet"
    );
    assert_eq!(parse_head(b""), Ok(None));
    assert_eq!(
        parse_head(b"POST / HTTP/1.1\r\n\r\n"),
        Err(Status::MethodNotAllowed)
    );
    assert_eq!(
        parse_head(b"GET / HTTP/9.9\r\n\r\n"),
        Err(Status::BadRequest)
    );
    assert_eq!(
        parse_head(b"\x16\x03\x01\x02\x00\x01\x00\x01\xfc\x03\x03"),
        Err(Status::BadRequest),
        "a TLS hello"
    );
    let mut many = b"GET / HTTP/1.1\r\n".to_vec();
    for i in 0..=MAX_HEADERS {
        many.extend_from_slice(format!("X-{i}: v\r\n").as_bytes());
    }
    many.extend_from_slice(b"\r\n");
    assert_eq!(parse_head(&many), Err(Status::HeadTooLarge));
}

#[test]
fn every_refusal_says_its_length_and_closes() {
    let page = String::from_utf8(status_page(Status::HeadTooLarge, false)).unwrap_or_default();
    assert!(
        page.starts_with("HTTP/1.1 431 Request Header Fields Too Large\r\n"),
        "{page}"
    );
    assert!(
        page.contains("Content-Length: 32\r\n") && page.contains("Connection: close\r\n"),
        "{page}"
    );
    assert!(
        page.ends_with("\r\n\r\nrequest header fields too large\n"),
        "{page}"
    );
    let head = String::from_utf8(status_page(Status::MethodNotAllowed, true)).unwrap_or_default();
    assert!(
        head.contains("Allow: GET, HEAD\r\n") && head.ends_with("\r\n\r\n"),
        "{head}"
    );
}
