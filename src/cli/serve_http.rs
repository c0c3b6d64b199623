//! The HTTP side of `robocal serve`: a static file server with fixed bounds.
//!
//! Why a server of our own and not a crate: tiny_http 0.12, the small
//! maintained choice, starts a new thread whenever its pool is busy, reads a
//! header line until CRLF without a length limit and sets no socket timeouts,
//! so every slow or oversized client costs a thread and unbounded memory, and
//! none of that is configurable; hyper bounds all of it but brings the tokio
//! runtime for a server of a handful of files. So the untrusted bytes are
//! parsed by `httparse` (hyper's own request parser) and this file keeps only
//! the bounds, each a field of [`Limits`]:
//!
//! - a fixed pool of `workers` threads fed by an accept queue of `queue`
//!   connections; a connection beyond both is answered 503 and closed;
//! - the request line and headers within `max_head_bytes` and [`MAX_HEADERS`]
//!   headers, else 431;
//! - the whole request head within `head_deadline` of the accept, else 408,
//!   so a client that sends nothing, or a byte at a time (slowloris), holds a
//!   worker for at most that long, queued time included; a head that arrived
//!   in full while its connection was queued is still answered;
//! - a refusal (400, 405, 408, 431) is followed by a bounded linger (the
//!   sending side closed, what the client still sends read and dropped for
//!   at most [`LINGER_TIME`]), because closing a socket with unread input
//!   makes the kernel send a reset that can destroy the refusal unread;
//! - every write within `write_stall`, the whole response within
//!   `response_deadline`; files are streamed in [`CHUNK`]-sized pieces.
//!
//! - a slow-client budget: a connection gets `fast_wait` to send its whole
//!   head, and every write `fast_wait` to go out; a client slower than that
//!   needs one of `slow_slots` slots (fewer than the workers) to go on, up to
//!   the deadlines above, and is cut off (408, no linger) when all are taken.
//!   So however many slow clients there are, at least `workers - slow_slots`
//!   workers only ever wait `fast_wait` for a client, and a normal request
//!   queued behind slow ones is reached within about `queue * fast_wait /
//!   (workers - slow_slots)` (64 * 20 ms / 8 = 0.16 s with the defaults).
//!
//! Threads are `workers + 1`, memory about `workers * (max_head_bytes +
//! CHUNK)` plus the queued sockets, whatever the load. The price of blocking
//! workers: a flood of more than `workers + queue` connections at once is
//! answered 503 while it lasts (measured with benches/serve_load.py:
//! BENCHMARKS.md, "robocal serve under load").
//!
//! GET and HEAD only (405 otherwise), `Connection: close` on every response,
//! no directory listing, 404 for anything outside the served folder and for
//! dotfiles. Every response carries [`CONTENT_SECURITY_POLICY`] (the page's
//! own policy plus `frame-ancestors 'none'`, which a `<meta>` cannot set)
//! and `X-Content-Type-Options: nosniff`.

use super::files::{mime_type, resolve};
use super::slow::{SlowBudget, Slowness};
use std::fs::File;
use std::io::{self, ErrorKind, Read, Write};
use std::net::{Shutdown, TcpListener, TcpStream};
use std::panic::{self, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicUsize;
use std::sync::mpsc::{self, Receiver, SyncSender, TrySendError};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

/// The Content-Security-Policy header: the policy of www/index.html's
/// `<meta http-equiv="Content-Security-Policy">` (tests/cli_serve.rs checks
/// they agree) plus `frame-ancestors 'none'`, so no other site can frame
/// the page.
pub const CONTENT_SECURITY_POLICY: &str = "default-src 'self'; script-src 'self' 'wasm-unsafe-eval'; style-src 'self'; img-src 'self' blob: data:; media-src 'self' blob:; worker-src 'self'; connect-src 'self'; object-src 'none'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'";

/// Most headers one request may carry (431 beyond).
pub const MAX_HEADERS: usize = 64;
/// Bytes of a file read and written at a time, per worker.
pub const CHUNK: usize = 64 * 1024;
/// After refusing a request that was not read to its end, at most this many
/// more bytes are read and dropped, within [`LINGER_TIME`], before closing:
/// closing with unread input makes the kernel reset the connection, which
/// can destroy the refusal before the client reads it.
const LINGER_BYTES: usize = 64 * 1024;
/// See [`LINGER_BYTES`].
const LINGER_TIME: Duration = Duration::from_secs(1);
/// Past the head deadline, how long the one last read of what has already
/// arrived may wait (see [`read_head`]).
const LATE_READ: Duration = Duration::from_millis(1);
/// Pause after a failed accept (out of descriptors), so the loop never spins.
const ACCEPT_BACKOFF: Duration = Duration::from_millis(10);

/// The server's bounds. `Limits::default()` is what `robocal serve` uses.
#[derive(Debug, Clone)]
pub struct Limits {
    /// Worker threads answering requests (default 16). Each holds one
    /// connection at a time.
    pub workers: usize,
    /// Accepted connections waiting for a worker (default 64); beyond it the
    /// connection gets 503.
    pub queue: usize,
    /// Bytes of request line plus headers (default 8 KiB, like common
    /// servers' default); beyond it 431.
    pub max_head_bytes: usize,
    /// Time from accept to the end of the request head (default 5 s; a
    /// browser on the same network sends it in milliseconds); then 408.
    pub head_deadline: Duration,
    /// Longest a single write may wait for the client to read (default 10 s).
    pub write_stall: Duration,
    /// Longest one response may take in total (default 60 s: a 2 MB wasm
    /// file at 35 kB/s).
    pub response_deadline: Duration,
    /// Time a client gets to send its whole head, and each write to go out,
    /// before it counts as slow (default 20 ms; on loopback both take well
    /// under a millisecond, and a head sent in one piece has usually
    /// arrived before a worker takes the connection).
    pub fast_wait: Duration,
    /// Connections that may be slow at once (default 8, half the workers);
    /// a slow client beyond them is cut off with 408.
    pub slow_slots: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            workers: 16,
            queue: 64,
            max_head_bytes: 8 * 1024,
            head_deadline: Duration::from_secs(5),
            write_stall: Duration::from_secs(10),
            response_deadline: Duration::from_secs(60),
            fast_wait: Duration::from_millis(20),
            slow_slots: 8,
        }
    }
}

/// Serves the files under `root` (a canonical folder path) on `listener`
/// until accepting fails for good. Returns only on an error.
pub fn serve(listener: TcpListener, root: PathBuf, limits: Limits) -> io::Result<()> {
    let budget = Arc::new(SlowBudget {
        in_use: AtomicUsize::new(0),
        max: limits.slow_slots,
    });
    let limits = Arc::new(limits);
    let root = Arc::new(root);
    let (queue, jobs) = mpsc::sync_channel::<Accepted>(limits.queue);
    let jobs = Arc::new(Mutex::new(jobs));
    for i in 0..limits.workers {
        let (jobs, root, limits, budget) =
            (jobs.clone(), root.clone(), limits.clone(), budget.clone());
        std::thread::Builder::new()
            .name(format!("serve-worker-{i}"))
            .spawn(move || work(&jobs, &root, &limits, &budget))?;
    }
    for stream in listener.incoming() {
        match stream {
            Ok(stream) => admit(&queue, stream)?,
            Err(_) => std::thread::sleep(ACCEPT_BACKOFF),
        }
    }
    Ok(())
}

/// A connection and when it was accepted (its deadlines count from then).
struct Accepted {
    stream: TcpStream,
    at: Instant,
}

/// Queues a connection for the workers, or answers 503 when the queue is full.
fn admit(queue: &SyncSender<Accepted>, stream: TcpStream) -> io::Result<()> {
    let job = Accepted {
        stream,
        at: Instant::now(),
    };
    match queue.try_send(job) {
        Ok(()) => Ok(()),
        Err(TrySendError::Full(job)) => {
            // Non-blocking: a reply of a few hundred bytes fits the empty
            // send buffer of a new connection, and the accept loop never
            // waits. It cannot linger either, so it drops what has already
            // arrived and sends a FIN; a request still in flight when the
            // socket closes makes the kernel reset it, and that client sees
            // a reset instead of the 503 (both mean "retry").
            let mut stream = job.stream;
            drain_pending(&mut stream);
            let _ = stream.write_all(&status_page(Status::Busy, false));
            let _ = stream.shutdown(Shutdown::Write);
            drain_pending(&mut stream);
            Ok(())
        }
        Err(TrySendError::Disconnected(_)) => {
            Err(io::Error::other("every serve worker has stopped"))
        }
    }
}

/// One worker: takes connections off the queue, one at a time, forever.
fn work(jobs: &Mutex<Receiver<Accepted>>, root: &Path, limits: &Limits, budget: &SlowBudget) {
    let mut head = vec![0u8; limits.max_head_bytes];
    let mut chunk = vec![0u8; CHUNK];
    loop {
        // The lock is held only while waiting (the guard ends with this
        // statement), and nothing can panic while holding it.
        let next = jobs.lock().unwrap_or_else(PoisonError::into_inner).recv();
        let Ok(job) = next else { return };
        // A panic would lose one connection, never a worker: the pool stays
        // at its size.
        let _ = panic::catch_unwind(AssertUnwindSafe(|| {
            handle(job, root, limits, budget, &mut head, &mut chunk)
        }));
    }
}

/// The answers this server gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Status {
    Ok,
    BadRequest,
    NotFound,
    MethodNotAllowed,
    RequestTimeout,
    HeadTooLarge,
    Busy,
}

impl Status {
    fn code_and_reason(self) -> (u16, &'static str) {
        match self {
            Status::Ok => (200, "OK"),
            Status::BadRequest => (400, "Bad Request"),
            Status::NotFound => (404, "Not Found"),
            Status::MethodNotAllowed => (405, "Method Not Allowed"),
            Status::RequestTimeout => (408, "Request Timeout"),
            Status::HeadTooLarge => (431, "Request Header Fields Too Large"),
            Status::Busy => (503, "Service Unavailable"),
        }
    }

    /// The plain-text body of a refusal.
    fn body(self) -> &'static [u8] {
        match self {
            Status::Ok => b"",
            Status::BadRequest => b"bad request\n",
            Status::NotFound => b"not found\n",
            Status::MethodNotAllowed => b"method not allowed\n",
            Status::RequestTimeout => b"request timeout\n",
            Status::HeadTooLarge => b"request header fields too large\n",
            Status::Busy => b"busy, retry shortly\n",
        }
    }

    /// Extra header lines (each ending in CRLF).
    fn extra_headers(self) -> &'static str {
        match self {
            Status::MethodNotAllowed => "Allow: GET, HEAD\r\n",
            Status::Busy => "Retry-After: 1\r\n",
            Status::Ok
            | Status::BadRequest
            | Status::NotFound
            | Status::RequestTimeout
            | Status::HeadTooLarge => "",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Method {
    Get,
    Head,
}

/// A request head that passed every bound.
#[derive(Debug, PartialEq, Eq)]
struct Request {
    method: Method,
    target: String,
}

/// Why a connection yielded no request.
#[derive(Debug, PartialEq, Eq)]
enum NoRequest {
    /// The client closed or reset the connection: nobody to answer.
    Gone,
    /// The client is answered with this status, then the connection closed.
    Refused(Status),
    /// The client is slow and the slow-client budget is spent: 408 at once,
    /// without a linger.
    OverBudget,
}

fn handle(
    job: Accepted,
    root: &Path,
    limits: &Limits,
    budget: &SlowBudget,
    head: &mut [u8],
    chunk: &mut [u8],
) -> io::Result<()> {
    let Accepted { mut stream, at } = job;
    let mut slow = Slowness::new(budget);
    let deadlines = HeadDeadlines {
        fast: Instant::now() + limits.fast_wait,
        end: at + limits.head_deadline,
    };
    let request = read_head(&mut stream, &deadlines, &mut slow, head);
    let mut writer = Deadline::new(limits, slow);
    match request {
        Ok(request) => {
            let answered = answer(&mut stream, &request, root, &mut writer, chunk);
            // The head was read to its end; drop anything sent after it
            // that has already arrived, so closing does not reset.
            drain_pending(&mut stream);
            answered
        }
        Err(NoRequest::Gone) => Ok(()),
        Err(NoRequest::OverBudget) => {
            let written = writer.write(&mut stream, &status_page(Status::RequestTimeout, false));
            drain_pending(&mut stream);
            let _ = stream.shutdown(Shutdown::Both);
            written
        }
        Err(NoRequest::Refused(status)) => {
            let written = writer.write(&mut stream, &status_page(status, false));
            // The request was not read to its end (a 408 may not have read
            // a byte of it): close only once the client stops sending; a
            // client without a slow slot gets `fast_wait` for that.
            let time = if writer.slow.held {
                LINGER_TIME
            } else {
                limits.fast_wait
            };
            linger(&mut stream, time);
            written
        }
    }
}

/// When a request head must have arrived: `fast` without a slow slot,
/// `end` with one.
struct HeadDeadlines {
    fast: Instant,
    end: Instant,
}

/// Reads the request head into `buf` until it is complete, too large, late
/// (`deadline`) or malformed.
///
/// The deadline bounds how long a worker waits for the client, not how long
/// the connection waited in the queue: past the deadline whatever has
/// already arrived is still read once (waiting at most [`LATE_READ`]), so a
/// client whose whole head came while it was queued behind slow clients is
/// answered, not refused.
fn read_head(
    stream: &mut TcpStream,
    deadlines: &HeadDeadlines,
    slow: &mut Slowness,
    buf: &mut [u8],
) -> Result<Request, NoRequest> {
    let mut len = 0;
    loop {
        let now = Instant::now();
        if now >= deadlines.fast && now < deadlines.end && !slow.allow() {
            return Err(NoRequest::OverBudget);
        }
        let end = if slow.held {
            deadlines.end
        } else {
            deadlines.fast.min(deadlines.end)
        };
        let remaining = end.checked_duration_since(now).filter(|d| !d.is_zero());
        let late = now >= deadlines.end;
        stream
            .set_read_timeout(Some(remaining.unwrap_or(LATE_READ)))
            .map_err(|_| NoRequest::Gone)?;
        let n = match stream.read(&mut buf[len..]) {
            Ok(0) => return Err(NoRequest::Gone),
            Ok(n) => n,
            Err(e) if e.kind() == ErrorKind::Interrupted => continue,
            // Out of fast time: the loop's top takes a slow slot or gives up.
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) && !late => {
                continue
            }
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
                return Err(NoRequest::Refused(Status::RequestTimeout))
            }
            Err(_) => return Err(NoRequest::Gone),
        };
        len += n;
        match parse_head(&buf[..len]) {
            Ok(Some(request)) => return Ok(request),
            Ok(None) if len == buf.len() => return Err(NoRequest::Refused(Status::HeadTooLarge)),
            Ok(None) if late => return Err(NoRequest::Refused(Status::RequestTimeout)),
            Ok(None) => {}
            Err(status) => return Err(NoRequest::Refused(status)),
        }
    }
}

/// Parses a request head: `Ok(None)` while it is incomplete.
fn parse_head(bytes: &[u8]) -> Result<Option<Request>, Status> {
    let mut headers = [httparse::EMPTY_HEADER; MAX_HEADERS];
    let mut parsed = httparse::Request::new(&mut headers);
    match parsed.parse(bytes) {
        Ok(httparse::Status::Partial) => Ok(None),
        Ok(httparse::Status::Complete(_)) => {
            let method = match parsed.method {
                Some("GET") => Method::Get,
                Some("HEAD") => Method::Head,
                _ => return Err(Status::MethodNotAllowed),
            };
            let target = parsed.path.ok_or(Status::BadRequest)?.to_string();
            Ok(Some(Request { method, target }))
        }
        Err(httparse::Error::TooManyHeaders) => Err(Status::HeadTooLarge),
        Err(_) => Err(Status::BadRequest),
    }
}

/// Answers a request with the file it names, or 404.
fn answer(
    stream: &mut TcpStream,
    request: &Request,
    root: &Path,
    writer: &mut Deadline,
    chunk: &mut [u8],
) -> io::Result<()> {
    let head_only = request.method == Method::Head;
    let found = resolve(root, &request.target)
        .and_then(|path| File::open(&path).ok().map(|file| (path, file)))
        .and_then(|(path, file)| Some((file.metadata().ok()?.len(), path, file)));
    let Some((len, path, file)) = found else {
        return writer.write(stream, &status_page(Status::NotFound, head_only));
    };
    writer.write(
        stream,
        head_lines(Status::Ok, mime_type(&path), len).as_bytes(),
    )?;
    if head_only {
        return Ok(());
    }
    // `take`: a file that grows while being sent never overruns its
    // Content-Length.
    let mut file = file.take(len);
    loop {
        let n = file.read(chunk)?;
        if n == 0 {
            return Ok(());
        }
        writer.write(stream, &chunk[..n])?;
    }
}

/// Writes bounded by the response's deadline and the per-write stall: a
/// write that waits more than `fast` makes the client slow, which needs a
/// slot of the slow-client budget (else the write fails with TimedOut).
struct Deadline<'a> {
    stall: Duration,
    fast: Duration,
    end: Instant,
    slow: Slowness<'a>,
}

impl<'a> Deadline<'a> {
    fn new(limits: &Limits, slow: Slowness<'a>) -> Self {
        Deadline {
            stall: limits.write_stall,
            fast: limits.fast_wait,
            end: Instant::now() + limits.response_deadline,
            slow,
        }
    }

    fn write(&mut self, stream: &mut TcpStream, mut bytes: &[u8]) -> io::Result<()> {
        while !bytes.is_empty() {
            let remaining = self
                .end
                .checked_duration_since(Instant::now())
                .filter(|d| !d.is_zero())
                .ok_or_else(|| io::Error::from(ErrorKind::TimedOut))?;
            let patience = if self.slow.held {
                self.stall
            } else {
                self.fast
            };
            stream.set_write_timeout(Some(remaining.min(patience)))?;
            match stream.write(bytes) {
                Ok(0) => return Err(ErrorKind::WriteZero.into()),
                Ok(n) => bytes = &bytes[n..],
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e)
                    if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut)
                        && !self.slow.held =>
                {
                    if !self.slow.allow() {
                        return Err(ErrorKind::TimedOut.into());
                    }
                }
                Err(e) => return Err(e),
            }
        }
        Ok(())
    }
}

/// Closes the sending side, then reads and drops what the client still sends
/// (bounded by [`LINGER_BYTES`] and [`LINGER_TIME`]), so the refusal arrives:
/// closing a socket with unread input, or input arriving after the close,
/// makes the kernel answer with a reset, and a reset can destroy a response
/// the client has not read yet. A client that closes on our FIN ends the
/// linger at once.
fn linger(stream: &mut TcpStream, time: Duration) {
    let _ = stream.shutdown(Shutdown::Write);
    let end = Instant::now() + time;
    let mut sink = [0u8; 4096];
    let mut drained = 0;
    while drained < LINGER_BYTES {
        let Some(remaining) = end
            .checked_duration_since(Instant::now())
            .filter(|d| !d.is_zero())
        else {
            break;
        };
        if stream.set_read_timeout(Some(remaining)).is_err() {
            return;
        }
        match stream.read(&mut sink) {
            Ok(0) => return,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(_) => return,
            Ok(n) => drained += n,
        }
    }
    // Out of time or bytes: what is still buffered goes now, so that the
    // close itself sends a FIN, not a reset, unless the client keeps sending.
    drain_pending(stream);
}

/// Reads and drops, without waiting, the input that has already arrived (at
/// most [`LINGER_BYTES`]).
fn drain_pending(stream: &mut TcpStream) {
    if stream.set_nonblocking(true).is_err() {
        return;
    }
    let mut sink = [0u8; 4096];
    let mut drained = 0;
    while drained < LINGER_BYTES {
        match stream.read(&mut sink) {
            Ok(0) => return,
            Ok(n) => drained += n,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(_) => return,
        }
    }
}

/// The status line and headers of a response whose body is `len` bytes.
fn head_lines(status: Status, mime: &str, len: u64) -> String {
    let (code, reason) = status.code_and_reason();
    format!(
        "HTTP/1.1 {code} {reason}\r\nContent-Type: {mime}\r\nContent-Length: {len}\r\n{}\
         Cache-Control: no-cache\r\nX-Content-Type-Options: nosniff\r\n\
         Content-Security-Policy: {CONTENT_SECURITY_POLICY}\r\nConnection: close\r\n\r\n",
        status.extra_headers()
    )
}

/// A whole refusal (head and, unless `head_only`, its text body).
fn status_page(status: Status, head_only: bool) -> Vec<u8> {
    let body = status.body();
    let mut page = head_lines(status, "text/plain; charset=utf-8", body.len() as u64).into_bytes();
    if !head_only {
        page.extend_from_slice(body);
    }
    page
}

#[cfg(test)]
#[path = "serve_http_tests.rs"]
mod tests;
