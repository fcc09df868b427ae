//! The little HTTP/1.1 that `fvr view` speaks: one request per connection
//! (`Connection: close`), a bounded head, a body only with a
//! `Content-Length`. Enough for a browser on the same machine; not a
//! general server.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;

/// The longest request head read (request line and headers).
const MAX_HEAD: usize = 16 * 1024;

/// A request: method, path, query (undecoded) and body.
pub(crate) struct Request {
    pub(crate) method: String,
    pub(crate) path: String,
    pub(crate) query: String,
    pub(crate) body: Vec<u8>,
}

/// A response: status, content type and body.
pub(crate) struct Response {
    pub(crate) status: u16,
    pub(crate) content_type: &'static str,
    pub(crate) body: Vec<u8>,
}

impl Response {
    /// 200 with `body`.
    pub(crate) fn ok(content_type: &'static str, body: Vec<u8>) -> Self {
        Self {
            status: 200,
            content_type,
            body,
        }
    }

    /// An error status with a one-line text message.
    pub(crate) fn error(status: u16, message: &str) -> Self {
        Self {
            status,
            content_type: "text/plain; charset=utf-8",
            body: message.replace('\n', " ").into_bytes(),
        }
    }
}

/// Read one request, refusing a body longer than `max_body` bytes.
///
/// # Errors
/// A malformed or oversized request, as the response to send.
pub(crate) fn read_request(stream: &TcpStream, max_body: u64) -> Result<Request, Response> {
    let bad = |m: &str| Response::error(400, m);
    let mut reader = BufReader::new(stream);
    let mut head = Vec::new();
    loop {
        let before = head.len();
        let n = (&mut reader)
            .take((MAX_HEAD - before) as u64)
            .read_until(b'\n', &mut head)
            .map_err(|e| bad(&format!("cannot read the request: {e}")))?;
        if n == 0 || head.len() >= MAX_HEAD {
            return Err(bad("incomplete or oversized request head"));
        }
        if head.ends_with(b"\r\n\r\n") || head.ends_with(b"\n\n") {
            break;
        }
    }
    let head = String::from_utf8_lossy(&head);
    let mut lines = head.lines();
    let mut first = lines.next().unwrap_or("").split_whitespace();
    let (method, target) = match (first.next(), first.next()) {
        (Some(m), Some(t)) => (m.to_string(), t),
        _ => return Err(bad("malformed request line")),
    };
    let (path, query) = target.split_once('?').unwrap_or((target, ""));
    let mut length = 0u64;
    for line in lines {
        if let Some((k, v)) = line.split_once(':') {
            if k.trim().eq_ignore_ascii_case("content-length") {
                length = v.trim().parse().map_err(|_| bad("bad Content-Length"))?;
            }
        }
    }
    if length > max_body {
        return Err(Response::error(
            413,
            &format!("a {length}-byte upload is more than fvr view accepts ({max_body} bytes)"),
        ));
    }
    let mut body = Vec::new();
    (&mut reader)
        .take(length)
        .read_to_end(&mut body)
        .map_err(|e| bad(&format!("cannot read the upload: {e}")))?;
    if body.len() as u64 != length {
        return Err(bad("the upload ended early"));
    }
    Ok(Request {
        method,
        path: path.to_string(),
        query: query.to_string(),
        body,
    })
}

/// Send `response` and close.
pub(crate) fn write_response(mut stream: &TcpStream, response: &Response) {
    let reason = match response.status {
        200 => "OK",
        400 => "Bad Request",
        404 => "Not Found",
        405 => "Method Not Allowed",
        413 => "Payload Too Large",
        _ => "Unprocessable Content",
    };
    let head = format!(
        "HTTP/1.1 {} {reason}\r\nContent-Type: {}\r\nContent-Length: {}\r\n\
         Cache-Control: no-store\r\nConnection: close\r\n\r\n",
        response.status,
        response.content_type,
        response.body.len()
    );
    // A browser that went away is no error of ours.
    let _ = stream
        .write_all(head.as_bytes())
        .and_then(|()| stream.write_all(&response.body));
}

/// The value of `key` in a query string, percent-decoded.
pub(crate) fn query_value(query: &str, key: &str) -> Option<String> {
    query.split('&').find_map(|pair| {
        let (k, v) = pair.split_once('=')?;
        (k == key).then(|| decode(v))
    })
}

fn decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        match b[i] {
            b'%' if i + 2 < b.len() => match (hex(b[i + 1]), hex(b[i + 2])) {
                (Some(h), Some(l)) => {
                    out.push((h * 16 + l) as u8);
                    i += 3;
                    continue;
                }
                _ => out.push(b'%'),
            },
            b'+' => out.push(b' '),
            c => out.push(c),
        }
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}
