//! The explorer's requests and answers — everything of `gonio explore` (the CLI's local web server) and
//! `gonio.explore` (the Jupyter widget) except the transport and the page. Both hand a path and a query
//! string to [`Explorer::handle`] and send back its [`Reply`]; the page (the repository's `web/` folder:
//! HTML, one JS module that is also the widget's, CSS — embedded in the binary and the extension by the
//! CLI and the Python crates) only draws the numbers it is given.
//!
//! | path | answer |
//! |---|---|
//! | `/api/models` | every plugin with its parameter table ([`params`]), the measured files offered, the initial models |
//! | `/api/plot?spec=…&kind=polar\|lobe\|slice\|albedo&theta_o=…&channel=…` | the numbers of [`crate::plot`] for one model |
//! | `/api/sphere?spec=…&light=env\|sky\|furnace\|dir&dir=x,y,z&size=…&spp=…&seed=…&client=…&seq=…` | the lit sphere of [`crate::preview`], PNG |
//! | `/api/verify?spec=…` | the verdict of [`crate::verify::check_named`] at [`CheckConfig::quick`] |
//! | `/api/export?spec=…&format=xml\|json` | the model as a Mitsuba `<bsdf>` or as JSON |
//! | `/api/fit?spec=…&model=…` | [`crate::fit`] of an analytic model to this one: the fitted spec |
//!
//! A bad request is answered `400` with the message the CLI prints for the same input (the model's own
//! error from `from_props`), as JSON `{"error", "at", "param"}`; a panic in a computation is caught and
//! answered `500`: the server never goes down with a request.
//!
//! `spec` is a model in Mitsuba's dictionary form (JSON). A `filename` in it is read only if it is one of
//! the measured files this explorer offers (those in its data folder, or given on the command line), so a
//! page cannot make it read other files.
//!
//! ```
//! use gonio::explore::Explorer;
//! let explorer = Explorer::new(None, Vec::new(), None, Vec::new());
//! let reply = explorer.handle("/api/plot", "spec=%7B%22type%22%3A%22diffuse%22%7D&kind=polar&theta_o=30");
//! assert_eq!(reply.status, 200);
//! let bad = explorer.handle("/api/plot", "spec={\"type\":\"roughconductor\",\"alpha\":20}&kind=polar");
//! assert_eq!(bad.status, 400);
//! assert!(String::from_utf8(bad.body).unwrap().contains("parameter `alpha` of `roughconductor` must be a number in [0.0001, 10], got 20"));
//! ```

pub mod params;
mod views;

use crate::bsdf::Bsdf;
use crate::error::{Error, Result};
use crate::image::{read_image, Image};
use crate::preview::Lighting;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

pub use views::{PlotKind, PlotRequest};

/// The answer to one request.
#[derive(Clone, Debug, PartialEq)]
pub struct Reply {
    /// HTTP status: 200, 400 (bad request, with the message), 404, 409 (a render superseded), 500.
    pub status: u16,
    pub content_type: &'static str,
    pub body: Vec<u8>,
}

impl Reply {
    fn json(status: u16, value: &Value) -> Reply {
        Reply { status, content_type: "application/json", body: value.to_string().into_bytes() }
    }

    fn text(status: u16, content_type: &'static str, body: &str) -> Reply {
        Reply { status, content_type, body: body.as_bytes().to_vec() }
    }

    /// A `400` carrying the error as the CLI prints it, where it was found, and the parameter it names.
    fn error(e: &Error) -> Reply {
        let (at, message) = match e {
            Error::Spec { at, message } | Error::Syntax { at, message } => (at.clone(), message.clone()),
            other => (String::new(), other.to_string()),
        };
        Reply::json(400, &json!({"error": e.to_string(), "at": at, "param": named_parameter(&at, &message)}))
    }
}

/// The parameter an error is about: the last key of its JSON path (`$.alpha`), else the first
/// "parameter `name`" of its message.
fn named_parameter(at: &str, message: &str) -> Option<String> {
    if let Some(key) = at.strip_prefix("$.").and_then(|k| k.rsplit('.').next()) {
        return Some(key.trim_end_matches(|c: char| c == ']' || c.is_ascii_digit() || c == '[').to_string());
    }
    let rest = message.split_once("parameter `")?.1;
    Some(rest.split_once('`')?.0.to_string())
}

/// The explorer's state: what it may read, and the models it has built.
pub struct Explorer {
    data_dir: Option<PathBuf>,
    /// Measured files offered besides those in `data_dir` (given on the command line), canonical.
    extra_files: Vec<PathBuf>,
    /// The environment map of `light=env` (else the built-in sky), and its image once read.
    environment: Option<PathBuf>,
    environment_image: OnceLock<std::result::Result<Arc<Image>, String>>,
    /// The models shown first (JSON specs).
    initial: Vec<String>,
    /// Models built from recent specs (measured data takes long to read): (spec, model), newest last.
    cache: Mutex<Vec<(String, Arc<Bsdf>)>>,
    /// The lit spheres asked for, per client: a newer one stops the one being rendered.
    spheres: Mutex<Vec<SphereRequest>>,
}

/// The newest lit sphere a client (`client=…`, one per page) asked for: its number (`seq=…`, increasing) and
/// the flag that stops its render. Requests travel on several connections, so an older one can arrive after a
/// newer one; it is refused rather than allowed to stop the newer one (the page would be left with neither).
struct SphereRequest {
    client: String,
    seq: u64,
    cancel: Arc<AtomicBool>,
}

/// Clients whose newest lit sphere is remembered (the oldest are forgotten).
const SPHERE_CLIENTS: usize = 64;

/// Models kept built.
const CACHE_SIZE: usize = 16;

impl Explorer {
    /// An explorer offering the measured files in `data_dir` and `extra_files`, lighting `light=env` with
    /// `environment` (else the built-in sky), showing `initial` (JSON specs) first.
    #[must_use]
    pub fn new(data_dir: Option<PathBuf>, extra_files: Vec<PathBuf>, environment: Option<PathBuf>, initial: Vec<String>) -> Self {
        let extra_files = extra_files.iter().filter_map(|p| p.canonicalize().ok()).collect();
        Explorer {
            data_dir,
            extra_files,
            environment,
            environment_image: OnceLock::new(),
            initial,
            cache: Mutex::new(Vec::new()),
            spheres: Mutex::new(Vec::new()),
        }
    }

    /// Answer `path` with the URL-encoded `query` (`a=1&b=2`, without the `?`). Never panics.
    #[must_use]
    pub fn handle(&self, path: &str, query: &str) -> Reply {
        match catch_unwind(AssertUnwindSafe(|| self.route(path, &parse_query(query)))) {
            Ok(Ok(reply)) => reply,
            Ok(Err(e)) => Reply::error(&e),
            Err(panic) => {
                let what = panic.downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| panic.downcast_ref::<String>().cloned());
                Reply::json(500, &json!({"error": format!("internal error: {}", what.unwrap_or_default())}))
            }
        }
    }

    fn route(&self, path: &str, q: &HashMap<String, String>) -> Result<Reply> {
        Ok(match path {
            "/api/models" => Reply::json(
                200,
                &json!({
                    "models": params::models_json(),
                    "files": self.files(),
                    "initial": self.initial,
                    "environment": self.environment.as_ref().map(|p| p.display().to_string()),
                    "fit_models": crate::fit::MODELS.iter().map(|m| json!({"name": m.name, "about": m.about})).collect::<Vec<_>>(),
                }),
            ),
            "/api/plot" => {
                let bsdf = self.bsdf(q)?;
                Reply::json(200, &views::plot(&bsdf, &PlotRequest::from_query(q)?)?)
            }
            "/api/sphere" => {
                let bsdf = self.bsdf(q)?;
                let Some(cancel) = self.start_sphere(q)? else {
                    return Ok(Reply::json(409, &json!({"error": "superseded by a newer render"})));
                };
                let env = if q.get("light").map_or(true, |l| l == "env") { self.environment_lighting()? } else { Lighting::GradientSky };
                let png = views::sphere(&bsdf, q, env, &cancel)?;
                if cancel.load(Ordering::Relaxed) {
                    return Ok(Reply::json(409, &json!({"error": "superseded by a newer render"})));
                }
                Reply { status: 200, content_type: "image/png", body: png }
            }
            "/api/verify" => {
                let bsdf = self.bsdf(q)?;
                let report = crate::verify::check_named(&*bsdf, "explorer", &crate::verify::CheckConfig::quick());
                Reply::json(200, &report.to_json())
            }
            "/api/export" => {
                let spec = self.spec(q)?;
                self.build(&spec)?;
                match q.get("format").map(String::as_str) {
                    Some("json") | None => Reply::text(200, "application/json", &serde_json::to_string_pretty(&spec).unwrap_or_default()),
                    Some("xml") => Reply::text(200, "application/xml", &crate::fit::spec_to_xml(&spec, None, 0)),
                    Some(other) => return Err(Error::spec("format", format!("unknown export format `{other}`; expected json or xml"))),
                }
            }
            "/api/fit" => {
                let bsdf = self.bsdf(q)?;
                let model = crate::fit::model(q.get("model").map_or("ggx", String::as_str))?;
                let strata = number(q, "strata", 6.0)?;
                if !(2.0..=16.0).contains(&strata) {
                    return Err(Error::spec("strata", format!("must be in [2, 16], got {strata}")));
                }
                let fit = crate::fit::fit(model, &crate::fit::pairs(&bsdf, strata as usize))?;
                Reply::json(200, &json!({"model": fit.model, "spec": fit.spec, "relative_error": fit.relative_error}))
            }
            _ => Reply::json(404, &json!({"error": format!("no such page: {path}")})),
        })
    }

    /// Register the lit sphere `q` asks for as its client's newest, stopping the client's render under way;
    /// `None` if the client has already asked for a newer one. Without `client` every request is one
    /// client's; without `seq` a request is the newest.
    fn start_sphere(&self, q: &HashMap<String, String>) -> Result<Option<Arc<AtomicBool>>> {
        let client = q.get("client").cloned().unwrap_or_default();
        let seq = match q.get("seq") {
            None => None,
            Some(text) => {
                Some(text.trim().parse::<u64>().map_err(|_| Error::spec("seq", format!("must be a whole number ≥ 0, got `{text}`")))?)
            }
        };
        let mut spheres = self.spheres.lock().unwrap_or_else(|e| e.into_inner());
        let cancel = Arc::new(AtomicBool::new(false));
        let request = |seq| SphereRequest { client: client.clone(), seq, cancel: cancel.clone() };
        match spheres.iter().position(|r| r.client == client) {
            Some(i) => {
                let newest = spheres[i].seq;
                let seq = seq.unwrap_or(newest);
                if seq < newest {
                    return Ok(None);
                }
                spheres.remove(i).cancel.store(true, Ordering::Relaxed);
                spheres.push(request(seq));
            }
            None => {
                spheres.push(request(seq.unwrap_or(0)));
                if spheres.len() > SPHERE_CLIENTS {
                    spheres.remove(0);
                }
            }
        }
        Ok(Some(cancel))
    }

    /// The lighting of `light=env`: the environment map, read once (else the built-in sky).
    fn environment_lighting(&self) -> Result<Lighting> {
        let Some(path) = &self.environment else { return Ok(Lighting::GradientSky) };
        let image = self.environment_image.get_or_init(|| read_image(path).map(Arc::new).map_err(|e| e.to_string()));
        match image {
            Ok(image) => Ok(Lighting::EnvironmentImage { image: image.clone(), name: path.display().to_string() }),
            Err(message) => Err(Error::spec("light", message.clone())),
        }
    }

    /// The measured files offered: those in the data folder (by name), then those given (by path).
    #[must_use]
    pub fn files(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        if let Some(dir) = &self.data_dir {
            if let Ok(entries) = std::fs::read_dir(dir) {
                out = entries
                    .filter_map(|e| e.ok())
                    .map(|e| e.path())
                    .filter(|p| p.is_file() && is_measured(p))
                    .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
                    .collect();
                out.sort();
            }
        }
        out.extend(self.extra_files.iter().map(|p| p.display().to_string()));
        out
    }

    /// The `spec` parameter as JSON, its `filename`s resolved to the files offered.
    fn spec(&self, q: &HashMap<String, String>) -> Result<Value> {
        let text = q.get("spec").ok_or_else(|| Error::spec("spec", "missing: the model as JSON in Mitsuba's dictionary form"))?;
        let mut spec: Value = serde_json::from_str(text).map_err(|e| Error::Syntax { at: "JSON spec".into(), message: e.to_string() })?;
        self.resolve_files(&mut spec, "$")?;
        Ok(spec)
    }

    fn resolve_files(&self, value: &mut Value, at: &str) -> Result<()> {
        if let Value::Object(map) = value {
            for (key, v) in map.iter_mut() {
                let here = format!("{at}.{key}");
                match v {
                    Value::String(name) if key == "filename" => *name = self.offered(name, &here)?.display().to_string(),
                    _ => self.resolve_files(v, &here)?,
                }
            }
        }
        Ok(())
    }

    /// The path of an offered measured file named `name` (a name in the data folder, or a given path).
    fn offered(&self, name: &str, at: &str) -> Result<PathBuf> {
        let candidate = match &self.data_dir {
            Some(dir) if Path::new(name).is_relative() => dir.join(name),
            _ => PathBuf::from(name),
        };
        let canonical = candidate.canonicalize().ok();
        let in_dir = |c: &PathBuf| {
            self.data_dir.as_ref().and_then(|d| d.canonicalize().ok()).is_some_and(|d| c.parent() == Some(d.as_path()) && is_measured(c))
        };
        match canonical {
            Some(c) if in_dir(&c) || self.extra_files.contains(&c) => Ok(c),
            _ => Err(Error::spec(
                at,
                format!("`{name}` is not a measured file this explorer offers (give its folder with --data DIR, or the file on the command line)"),
            )),
        }
    }

    fn build(&self, spec: &Value) -> Result<Arc<Bsdf>> {
        let key = spec.to_string();
        let mut cache = self.cache.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(k) = cache.iter().position(|(s, _)| *s == key) {
            let entry = cache.remove(k);
            let bsdf = entry.1.clone();
            cache.push(entry);
            return Ok(bsdf);
        }
        drop(cache);
        let bsdf = Arc::new(Bsdf::from_json(&key)?);
        let mut cache = self.cache.lock().unwrap_or_else(|e| e.into_inner());
        cache.push((key, bsdf.clone()));
        if cache.len() > CACHE_SIZE {
            cache.remove(0);
        }
        Ok(bsdf)
    }

    fn bsdf(&self, q: &HashMap<String, String>) -> Result<Arc<Bsdf>> {
        self.build(&self.spec(q)?)
    }
}

fn is_measured(path: &Path) -> bool {
    matches!(path.extension().and_then(|e| e.to_str()), Some("binary" | "bsdf"))
}

/// A number from the query, `default` when absent; an error naming it when it is not a finite number.
fn number(q: &HashMap<String, String>, name: &str, default: f64) -> Result<f64> {
    match q.get(name) {
        None => Ok(default),
        Some(text) => text
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| Error::spec(name, format!("expected a number, got `{text}`"))),
    }
}

/// `a=1&b=x%20y` → {a: "1", b: "x y"} (`+` is a space; a key given twice keeps its last value).
#[must_use]
pub fn parse_query(query: &str) -> HashMap<String, String> {
    query
        .split('&')
        .filter(|p| !p.is_empty())
        .map(|pair| {
            let (k, v) = pair.split_once('=').unwrap_or((pair, ""));
            (percent_decode(k), percent_decode(v))
        })
        .collect()
}

/// Undo URL encoding (`%XX` bytes, `+` for space); invalid escapes are kept as written.
#[must_use]
pub fn percent_decode(text: &str) -> String {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'+' => out.push(b' '),
            b'%' if i + 2 < bytes.len() => {
                match std::str::from_utf8(&bytes[i + 1..i + 3]).ok().and_then(|h| u8::from_str_radix(h, 16).ok()) {
                    Some(b) => {
                        out.push(b);
                        i += 3;
                        continue;
                    }
                    None => out.push(b'%'),
                }
            }
            b => out.push(b),
        }
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn queries_decode() {
        let q = parse_query("spec=%7B%22type%22%3A+%22diffuse%22%7D&x=1&bad=%zz&end=%4");
        assert_eq!(q["spec"], r#"{"type": "diffuse"}"#);
        assert_eq!(q["x"], "1");
        assert_eq!(q["bad"], "%zz");
        assert_eq!(q["end"], "%4");
        assert_eq!(percent_decode("%C3%A9"), "é");
    }

    #[test]
    fn errors_name_their_parameter() {
        assert_eq!(named_parameter("$.alpha", "x").as_deref(), Some("alpha"));
        assert_eq!(named_parameter("$", "parameter `distribution` of `roughconductor` must be").as_deref(), Some("distribution"));
        assert_eq!(named_parameter("$.bsdf.reflectance", "x").as_deref(), Some("reflectance"));
    }

    #[test]
    fn files_outside_the_data_folder_are_refused() {
        let e = Explorer::new(None, Vec::new(), None, Vec::new());
        let reply = e.handle("/api/plot", "spec={\"type\":\"merl\",\"filename\":\"/etc/passwd\"}&kind=polar");
        assert_eq!(reply.status, 400);
        assert!(String::from_utf8(reply.body).unwrap().contains("not a measured file this explorer offers"));
    }

    #[test]
    fn an_older_lit_sphere_arriving_late_is_refused_and_stops_nothing() {
        // The page's requests travel on several connections: its sphere number 3 can reach the server after
        // its number 4. Before, whichever arrived last stopped the other, and the page was left with no image.
        let e = Explorer::new(None, Vec::new(), None, Vec::new());
        let q = |client: &str, seq: &str| parse_query(&format!("client={client}&seq={seq}"));
        let four = e.start_sphere(&q("a", "4")).unwrap().expect("the newest is rendered");
        assert!(e.start_sphere(&q("a", "3")).unwrap().is_none(), "an older request is refused");
        assert!(!four.load(Ordering::Relaxed), "and does not stop the newer render");
        // Another page's requests are its own; the same number (the next pass of one image) and a newer one
        // stop the render under way.
        let other = e.start_sphere(&q("b", "1")).unwrap().expect("another client");
        let four_again = e.start_sphere(&q("a", "4")).unwrap().expect("the next pass of the same image");
        assert!(four.load(Ordering::Relaxed) && !other.load(Ordering::Relaxed));
        e.start_sphere(&q("a", "5")).unwrap().expect("a newer image");
        assert!(four_again.load(Ordering::Relaxed));
        // Without `client` and `seq` (a user's own request), the newest arrival wins, as before.
        let first = e.start_sphere(&HashMap::new()).unwrap().unwrap();
        e.start_sphere(&HashMap::new()).unwrap().unwrap();
        assert!(first.load(Ordering::Relaxed));
        // Over HTTP: the stale request is answered 409, a bad number 400 naming `seq`.
        let spec = "spec=%7B%22type%22%3A%22diffuse%22%7D&light=sky&size=8&spp=1";
        assert_eq!(e.handle("/api/sphere", &format!("{spec}&client=a&seq=2")).status, 409);
        assert_eq!(e.handle("/api/sphere", &format!("{spec}&client=a&seq=5")).status, 200);
        let bad = e.handle("/api/sphere", &format!("{spec}&client=a&seq=-1"));
        assert_eq!(bad.status, 400);
        assert!(String::from_utf8(bad.body).unwrap().contains("seq"));
    }

    #[test]
    fn unknown_paths_and_bad_numbers() {
        let e = Explorer::new(None, Vec::new(), None, Vec::new());
        assert_eq!(e.handle("/nothing", "").status, 404);
        let r = e.handle("/api/plot", "spec={\"type\":\"diffuse\"}&kind=polar&theta_o=abc");
        assert_eq!(r.status, 400);
        assert_eq!(e.handle("/api/plot", "spec={nope").status, 400);
        assert_eq!(e.handle("/api/export", "spec={\"type\":\"diffuse\"}&format=obj").status, 400);
    }
}
