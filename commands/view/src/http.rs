//! The HTTP side: tiny_http's server answered from a few worker threads,
//! the session's token, the limits on what a request may be, and replies.

use crate::ViewError;
use std::net::SocketAddr;
use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// The longest URL answered.
const MAX_URL: usize = 8 * 1024;
/// Requests answered at once: a slow one (a reference rendered for
/// grading) leaves the others to the rest.
const WORKERS: usize = 4;
/// How often a waiting worker looks at the stop flag.
const POLL: Duration = Duration::from_millis(100);

/// A request as the API sees it: its path and its query's pairs.
pub(crate) struct Request {
    pub path: String,
    pub query: Vec<(String, String)>,
}

/// An answer: status, content type, extra headers and body.
pub(crate) struct Reply {
    pub status: u16,
    pub content_type: &'static str,
    pub headers: Vec<(&'static str, String)>,
    pub body: Vec<u8>,
}

impl Reply {
    pub fn json(text: String) -> Reply {
        Reply::bytes("application/json", text.into_bytes())
    }

    pub fn bytes(content_type: &'static str, body: Vec<u8>) -> Reply {
        Reply {
            status: 200,
            content_type,
            headers: Vec::new(),
            body,
        }
    }

    /// A refusal: `{"error": message}` with a 4xx or 5xx status.
    pub fn error(status: u16, message: &str) -> Reply {
        let body = serde_json::json!({ "error": message }).to_string() + "\n";
        Reply {
            status,
            ..Reply::json(body)
        }
    }

    pub fn with_header(mut self, name: &'static str, value: String) -> Reply {
        self.headers.push((name, value));
        self
    }
}

/// A fresh random token: 128 bits from the operating system, in hex.
pub(crate) fn token() -> Result<String, String> {
    let mut bytes = [0u8; 16];
    getrandom::fill(&mut bytes).map_err(|e| e.to_string())?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

/// Listens on `address`, tells `ready` the page's URL, and answers requests
/// with `answer` on [`WORKERS`] threads until `stop` is set.
pub(crate) fn run(
    address: SocketAddr,
    token: &str,
    stop: &AtomicBool,
    ready: &mut dyn FnMut(&str),
    answer: &(dyn Fn(&Request) -> Reply + Sync),
) -> Result<(), ViewError> {
    let server = tiny_http::Server::http(address).map_err(|e| ViewError::Listen {
        address,
        message: e.to_string(),
    })?;
    let bound = server.server_addr().to_ip().unwrap_or(address);
    ready(&format!("http://{bound}/?token={token}"));
    std::thread::scope(|s| {
        for _ in 0..WORKERS {
            s.spawn(|| {
                while !stop.load(Ordering::Relaxed) {
                    if let Ok(Some(request)) = server.recv_timeout(POLL) {
                        respond(request, token, answer);
                    }
                }
            });
        }
    });
    Ok(())
}

/// Answers one request: refused if it breaks a limit or lacks the token,
/// else by `answer` (a panic in which is a 500, never a dead worker).
fn respond(request: tiny_http::Request, token: &str, answer: &(dyn Fn(&Request) -> Reply + Sync)) {
    let refused = refusal(&request, token);
    let close = refused.is_some();
    let reply = refused.unwrap_or_else(|| {
        let parsed = parse(request.url());
        std::panic::catch_unwind(AssertUnwindSafe(|| answer(&parsed)))
            .unwrap_or_else(|_| Reply::error(500, "the server failed on this request"))
    });
    // Every answer says its length: the simplest client can read it.
    let mut response = tiny_http::Response::from_data(reply.body)
        .with_status_code(reply.status)
        .with_chunked_threshold(usize::MAX);
    let mut headers = vec![
        ("Content-Type", reply.content_type.to_owned()),
        ("Cache-Control", "no-store".to_owned()),
        ("X-Content-Type-Options", "nosniff".to_owned()),
    ];
    if close {
        headers.push(("Connection", "close".to_owned()));
    }
    headers.extend(reply.headers);
    for (name, value) in headers {
        if let Ok(header) = tiny_http::Header::from_bytes(name.as_bytes(), value.as_bytes()) {
            response.add_header(header);
        }
    }
    let _ = request.respond(response);
}

/// Why a request is not answered, if it is not: too long a URL, another
/// method than GET, a body, or no token or a wrong one.
fn refusal(request: &tiny_http::Request, token: &str) -> Option<Reply> {
    if request.url().len() > MAX_URL {
        return Some(Reply::error(414, "the URL is longer than 8 KiB"));
    }
    if *request.method() != tiny_http::Method::Get {
        let method = request.method().as_str();
        return Some(Reply::error(
            405,
            &format!("{method}: only GET is answered"),
        ));
    }
    if request.body_length().unwrap_or(0) > 0 || chunked(request) {
        return Some(Reply::error(413, "requests carry no body"));
    }
    let given = header(request, "X-Glint-Token").or_else(|| {
        parse(request.url())
            .query
            .into_iter()
            .find(|(k, _)| k == "token")
            .map(|(_, v)| v)
    });
    match given {
        Some(given) if same(&given, token) => None,
        Some(_) => Some(Reply::error(
            403,
            "wrong token: use the URL glint view printed",
        )),
        None => Some(Reply::error(
            403,
            "no token: use the URL glint view printed",
        )),
    }
}

fn chunked(request: &tiny_http::Request) -> bool {
    header(request, "Transfer-Encoding").is_some()
}

fn header(request: &tiny_http::Request, name: &'static str) -> Option<String> {
    request
        .headers()
        .iter()
        .find(|h| h.field.equiv(name))
        .map(|h| h.value.as_str().to_owned())
}

/// Equal strings, compared in time that does not depend on where they
/// differ (the token is a secret).
fn same(a: &str, b: &str) -> bool {
    a.len() == b.len() && a.bytes().zip(b.bytes()).fold(0u8, |d, (x, y)| d | (x ^ y)) == 0
}

/// The URL's path and its query's pairs, percent-decoded.
fn parse(url: &str) -> Request {
    let (path, query) = url.split_once('?').unwrap_or((url, ""));
    Request {
        path: path.to_owned(),
        query: form_urlencoded::parse(query.as_bytes())
            .map(|(k, v)| (k.into_owned(), v.into_owned()))
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_are_fresh_and_compared_whole() {
        let (a, b) = (token().unwrap(), token().unwrap());
        assert_eq!(a.len(), 32);
        assert_ne!(a, b);
        assert!(same(&a, &a.clone()));
        assert!(!same(&a, &b) && !same(&a, &a[..31]));
    }

    #[test]
    fn a_query_is_percent_decoded() {
        let r = parse("/api/explain?pixel=3%2C4&token=ab&all-samples");
        assert_eq!(r.path, "/api/explain");
        let pairs: Vec<(&str, &str)> = r.query.iter().map(|(k, v)| (&k[..], &v[..])).collect();
        assert_eq!(
            pairs,
            [("pixel", "3,4"), ("token", "ab"), ("all-samples", "")]
        );
    }
}
