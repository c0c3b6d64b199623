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

/// Reads one whole answer and returns its status (0 when there is none, as
/// after a reset).
fn status_of(mut s: TcpStream) -> u16 {
    let mut raw = Vec::new();
    let _ = s.read_to_end(&mut raw);
    String::from_utf8_lossy(&raw)
        .split_whitespace()
        .nth(1)
        .and_then(|code| code.parse().ok())
        .unwrap_or(0)
}

#[test]
fn clients_beyond_the_pool_and_queue_get_503() {
    // A small pool where every idle client may hold its worker until the
    // head deadline (as many slow slots as workers, a long fast wait), so
    // the count of refusals depends on the bounds alone, never on how fast
    // this machine opens connections.
    let limits = Limits {
        workers: 2,
        queue: 3,
        slow_slots: 2,
        fast_wait: Duration::from_secs(30),
        head_deadline: Duration::from_secs(3),
        ..Limits::default()
    };
    let root = std::env::temp_dir().join(format!("robocal-serve-503-{}", std::process::id()));
    std::fs::create_dir_all(&root).unwrap();
    std::fs::write(root.join("index.html"), "<title>t</title>").unwrap();
    let root = root.canonicalize().unwrap();
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    let (workers, queue) = (limits.workers, limits.queue);
    std::thread::spawn(move || serve(listener, root, limits));
    let over = 5;
    let clients: Vec<TcpStream> = (0..workers + queue + over)
        .map(|_| {
            let s = TcpStream::connect(addr).unwrap();
            s.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
            s
        })
        .collect();
    let statuses: Vec<u16> = clients.into_iter().map(status_of).collect();
    // `queue` connections wait, and the workers hold up to one each (a
    // worker thread that has not reached the queue yet when the connections
    // come holds none); every other one is refused at once, and the held
    // ones time out.
    let count = |code: u16| statuses.iter().filter(|&&s| s == code).count();
    let held = count(408);
    assert!((queue..=workers + queue).contains(&held), "{statuses:?}");
    assert_eq!(count(503), statuses.len() - held, "{statuses:?}");
    // Once the idle clients are gone, service is back.
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
    s.write_all(b"GET /index.html HTTP/1.1\r\nHost: x\r\n\r\n")
        .unwrap();
    assert_eq!(status_of(s), 200);
}
