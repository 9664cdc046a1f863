//! `gonio explore [BSDF...] [--port 8000] [--host 127.0.0.1] [--open] [--data DIR]`: look at BSDFs in the
//! browser. Serves the page (`web/` of the repository, embedded with `include_str!`, no CDN) and answers its
//! requests with [`gonio::explore::Explorer`], which computes every number from the functions `gonio plot`
//! and `gonio preview` use.
//!
//! # The server
//! A few lines of `std::net`: one thread per connection, HTTP/1.1 `GET` with keep-alive, answers with a
//! `Content-Length`. The page is the only client (a person on this machine, a handful of connections at a
//! time, requests of a few kilobytes), so a server crate (`tiny_http` and its dependencies, or an async
//! stack) would add more code to the build than it saves here; gonio's dependency list stays as it is
//! (STYLE.md). It binds 127.0.0.1 unless `--host` says otherwise, and answers only requests whose `Host`
//! header names the address it was started on (a web page elsewhere cannot reach it by DNS rebinding).
//! A request line or header past 64 kB, a method other than `GET`/`HEAD`, or a malformed request is
//! answered 4xx; a panic in a computation is answered 500 by [`Explorer::handle`]: no request stops the
//! server.

use crate::spec::{in_json_file, load_props, measured_plugin};
use crate::stdout::outln;
use gonio::explore::{Explorer, Reply};
use gonio::Error;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// The page, served as is.
const INDEX_HTML: &str = include_str!("../../../../web/index.html");
const EXPLORER_JS: &str = include_str!("../../../../web/explorer.js");
const EXPLORER_CSS: &str = include_str!("../../../../web/explorer.css");

/// Longest request head (request line and headers) read.
const MAX_HEAD: usize = 64 * 1024;
/// Connections served at once; more are answered 503.
const MAX_CONNECTIONS: usize = 64;
/// An idle keep-alive connection is closed after this.
const IDLE: Duration = Duration::from_secs(30);

#[derive(clap::Args)]
pub struct Args {
    /// Models shown first, as every command takes them: JSON in Mitsuba's dictionary form, a `<bsdf>` (inline
    /// or an XML file), a JSON file, or a measured file (.binary MERL, .bsdf RGL). Without any, a rough
    /// conductor.
    #[arg(value_name = "BSDF")]
    bsdf: Vec<String>,
    /// Port to listen on (0: any free port; the address is printed).
    #[arg(long, default_value_t = 8000)]
    port: u16,
    /// Address to listen on. Anything but 127.0.0.1 or ::1 exposes the explorer (and the measured files it
    /// offers) to the network.
    #[arg(long, default_value = "127.0.0.1")]
    host: String,
    /// Open the page in the default browser.
    #[arg(long)]
    open: bool,
    /// A folder of measured files (.binary, .bsdf) the page may load.
    #[arg(long, value_name = "DIR")]
    data: Option<PathBuf>,
    /// Environment map of the lit sphere (default: the shipped venice_sunset_1k.hdr when present, else
    /// the built-in sky).
    #[arg(long, value_name = "FILE")]
    env: Option<PathBuf>,
}

/// A command-line model as a JSON spec, and the measured file it names (offered to the page). The page
/// edits JSON: a model given as XML (inline or in a file, as every command takes it) is converted.
fn initial_spec(arg: &str) -> Result<(String, Option<PathBuf>), Error> {
    let path = Path::new(arg);
    if let Some(plugin) = measured_plugin(path) {
        let absolute = path.canonicalize().map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
        let spec = serde_json::json!({"type": plugin, "filename": absolute.display().to_string()}).to_string();
        return Ok((spec, Some(absolute)));
    }
    let props = load_props(arg)?;
    gonio::Bsdf::from_props(&props).map_err(|e| in_json_file(arg, e))?;
    // JSON as the user wrote it; XML in the dictionary form.
    let json = |text: &str| text.trim_start().starts_with('{').then(|| text.trim().to_string());
    let given =
        if arg.trim_start().starts_with(['{', '<']) { json(arg) } else { std::fs::read_to_string(path).ok().and_then(|t| json(&t)) };
    Ok((given.unwrap_or_else(|| props.to_json().to_string()), None))
}

pub fn run(args: Args) -> Result<ExitCode, Error> {
    let mut initial = Vec::new();
    let mut files = Vec::new();
    for arg in &args.bsdf {
        let (spec, file) = initial_spec(arg)?;
        initial.push(spec);
        files.extend(file);
    }
    if let Some(dir) = &args.data {
        if !dir.is_dir() {
            return Err(Error::Io {
                path: dir.clone(),
                source: std::io::Error::new(std::io::ErrorKind::NotFound, "--data: no such folder"),
            });
        }
    }
    let environment = match args.env {
        Some(p) if p.is_file() => Some(p),
        Some(p) => return Err(Error::Io { path: p, source: std::io::Error::new(std::io::ErrorKind::NotFound, "--env: no such file") }),
        None => Some(PathBuf::from(super::preview::DEFAULT_ENV)).filter(|p| p.is_file()),
    };
    let explorer = Arc::new(Explorer::new(args.data.clone(), files, environment, initial));
    let listener = TcpListener::bind((args.host.as_str(), args.port)).map_err(|source| Error::Spec {
        at: "--host/--port".into(),
        message: format!("cannot listen on {}:{}: {source}", args.host, args.port),
    })?;
    let address = listener.local_addr().map_err(|source| Error::Spec { at: "--port".into(), message: source.to_string() })?;
    let url = format!("http://{address}/");
    outln!("gonio explore: serving {url} (Ctrl-C to stop)");
    if args.open {
        // Best effort: a machine without a desktop has no opener; the address is printed above.
        let _ = std::process::Command::new("xdg-open").arg(&url).spawn();
    }
    let hosts = allowed_hosts(&args.host, address.port());
    let active = Arc::new(AtomicUsize::new(0));
    for stream in listener.incoming() {
        let Ok(mut stream) = stream else { continue };
        if active.load(Ordering::Relaxed) >= MAX_CONNECTIONS {
            let _ =
                write_reply(&mut stream, &Reply { status: 503, content_type: "text/plain", body: b"too many connections".to_vec() }, false);
            continue;
        }
        active.fetch_add(1, Ordering::Relaxed);
        let (explorer, hosts, active) = (explorer.clone(), hosts.clone(), active.clone());
        std::thread::spawn(move || {
            serve_connection(stream, &explorer, &hosts);
            active.fetch_sub(1, Ordering::Relaxed);
        });
    }
    Ok(ExitCode::SUCCESS)
}

/// The `Host` headers accepted: the address given and the loopback names, with the port.
fn allowed_hosts(host: &str, port: u16) -> Arc<Vec<String>> {
    let mut names = vec![host.to_string(), "localhost".into(), "127.0.0.1".into(), "[::1]".into()];
    if host.contains(':') && !host.starts_with('[') {
        names.push(format!("[{host}]"));
    }
    Arc::new(names.into_iter().map(|n| format!("{n}:{port}")).collect())
}

/// One request's line and the headers that matter.
struct Request {
    method: String,
    target: String,
    host: Option<String>,
    keep_alive: bool,
}

/// Read one request head; `Ok(None)` at the end of the connection.
fn read_request(reader: &mut BufReader<TcpStream>) -> Result<Option<Request>, u16> {
    let mut head = Vec::new();
    loop {
        let mut line = Vec::new();
        let n = reader.by_ref().take((MAX_HEAD - head.len()) as u64 + 1).read_until(b'\n', &mut line).map_err(|_| 408u16)?;
        if n == 0 {
            return if head.is_empty() { Ok(None) } else { Err(400) };
        }
        if head.len() + line.len() > MAX_HEAD {
            return Err(431);
        }
        let blank = line == b"\r\n" || line == b"\n";
        if blank && head.is_empty() {
            continue; // a stray newline between requests
        }
        head.extend_from_slice(&line);
        if blank {
            break;
        }
    }
    let text = String::from_utf8(head).map_err(|_| 400u16)?;
    let mut lines = text.lines();
    let mut parts = lines.next().unwrap_or_default().split_whitespace();
    let (method, target, version) = (parts.next().ok_or(400u16)?, parts.next().ok_or(400u16)?, parts.next().unwrap_or("HTTP/1.0"));
    let mut request = Request { method: method.into(), target: target.into(), host: None, keep_alive: version == "HTTP/1.1" };
    for line in lines {
        let Some((name, value)) = line.split_once(':') else { continue };
        let value = value.trim();
        match name.trim().to_ascii_lowercase().as_str() {
            "host" => request.host = Some(value.to_ascii_lowercase()),
            "connection" if value.eq_ignore_ascii_case("close") => request.keep_alive = false,
            "connection" if value.eq_ignore_ascii_case("keep-alive") => request.keep_alive = true,
            "content-length" if value != "0" => return Err(411), // GET only: no bodies
            "transfer-encoding" => return Err(411),
            _ => {}
        }
    }
    Ok(Some(request))
}

fn serve_connection(stream: TcpStream, explorer: &Explorer, hosts: &[String]) {
    let _ = stream.set_read_timeout(Some(IDLE));
    let _ = stream.set_nodelay(true);
    let Ok(mut writer) = stream.try_clone() else { return };
    let mut reader = BufReader::new(stream);
    loop {
        let (reply, keep_alive, head_only) = match read_request(&mut reader) {
            Ok(None) => return,
            Err(status) => (plain(status, "bad request"), false, false),
            Ok(Some(r)) => {
                let reply = if r.method != "GET" && r.method != "HEAD" {
                    plain(405, "only GET and HEAD")
                } else if !r.host.as_ref().is_some_and(|h| hosts.iter().any(|a| a == h)) {
                    plain(421, "unexpected Host header: open the address gonio explore printed")
                } else {
                    answer(explorer, &r.target)
                };
                (reply, r.keep_alive, r.method == "HEAD")
            }
        };
        let mut reply = reply;
        if head_only {
            reply.body.clear();
        }
        if write_reply(&mut writer, &reply, keep_alive).is_err() || !keep_alive {
            drain(reader.get_mut());
            return;
        }
    }
}

/// Read what the client still sends (a refused body, the rest of a long line) for a moment before the
/// connection closes: closing a socket with unread data resets it, and the client may lose the answer.
fn drain(stream: &mut TcpStream) {
    let _ = stream.shutdown(std::net::Shutdown::Write);
    let _ = stream.set_read_timeout(Some(Duration::from_millis(200)));
    let mut sink = [0u8; 16 * 1024];
    let mut total = 0;
    while let Ok(n) = stream.read(&mut sink) {
        total += n;
        if n == 0 || total > 1 << 20 {
            break;
        }
    }
}

fn plain(status: u16, text: &str) -> Reply {
    Reply { status, content_type: "text/plain; charset=utf-8", body: text.as_bytes().to_vec() }
}

/// The page's files, or the explorer's answer.
fn answer(explorer: &Explorer, target: &str) -> Reply {
    let (path, query) = target.split_once('?').unwrap_or((target, ""));
    let page = |content_type, text: &str| Reply { status: 200, content_type, body: text.as_bytes().to_vec() };
    match path {
        "/" | "/index.html" => page("text/html; charset=utf-8", INDEX_HTML),
        "/explorer.js" => page("text/javascript; charset=utf-8", EXPLORER_JS),
        "/explorer.css" => page("text/css; charset=utf-8", EXPLORER_CSS),
        "/favicon.ico" => Reply { status: 204, content_type: "image/x-icon", body: Vec::new() },
        _ => explorer.handle(path, query),
    }
}

fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        204 => "No Content",
        400 => "Bad Request",
        404 => "Not Found",
        405 => "Method Not Allowed",
        408 => "Request Timeout",
        409 => "Conflict",
        411 => "Length Required",
        421 => "Misdirected Request",
        431 => "Request Header Fields Too Large",
        503 => "Service Unavailable",
        _ => "Internal Server Error",
    }
}

fn write_reply(stream: &mut TcpStream, reply: &Reply, keep_alive: bool) -> std::io::Result<()> {
    let head = format!(
        "HTTP/1.1 {} {}\r\nContent-Type: {}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nConnection: {}\r\n\r\n",
        reply.status,
        reason(reply.status),
        reply.content_type,
        reply.body.len(),
        if keep_alive { "keep-alive" } else { "close" }
    );
    stream.write_all(head.as_bytes())?;
    stream.write_all(&reply.body)?;
    stream.flush()
}
