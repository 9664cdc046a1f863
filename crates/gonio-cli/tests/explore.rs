//! `gonio explore` end to end: the server started as a subprocess on a free port, its page and JSON
//! answers over real HTTP, the numbers against `gonio plot`'s data functions (and its CSV), bad input
//! answered 400 with the CLI's own message, and the server still up after malformed requests.

mod common;

use common::{gonio, gonio_command, Scratch};
use gonio::plot::{
    albedo_data, lobe_data, slice_data, Channel, ALBEDO_ANGLES, ALBEDO_SAMPLES, GRID_PHI, GRID_THETA, POLAR_SAMPLES, SLICE_RES,
};
use gonio::Bsdf;
use serde_json::Value;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

const GGX: &str = r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.3, "material": "Au"}"#;

/// A running `gonio explore`, stopped when dropped.
struct Server {
    child: Child,
    /// `127.0.0.1:PORT`
    address: String,
}

impl Server {
    fn start(args: &[&str]) -> Server {
        let mut child = gonio_command()
            .arg("explore")
            .args(["--port", "0"])
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("start gonio explore");
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap()).read_line(&mut line).expect("read the address");
        let url = line.split_whitespace().find(|w| w.starts_with("http://")).unwrap_or_else(|| panic!("no address in {line:?}"));
        let address = url.trim_start_matches("http://").trim_end_matches('/').to_string();
        Server { child, address }
    }

    /// GET `target` with the `Host` header `host` (default: the address): (status, content type, body).
    fn get_as(&self, target: &str, host: &str) -> (u16, String, Vec<u8>) {
        let mut stream = TcpStream::connect(&self.address).expect("connect");
        stream.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
        write!(stream, "GET {target} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n").unwrap();
        read_response(&mut stream)
    }

    fn get(&self, target: &str) -> (u16, String, Vec<u8>) {
        self.get_as(target, &self.address.clone())
    }

    fn json(&self, path: &str, params: &[(&str, &str)]) -> (u16, Value) {
        let query: Vec<String> = params.iter().map(|(k, v)| format!("{k}={}", encode(v))).collect();
        let (status, kind, body) = self.get(&format!("{path}?{}", query.join("&")));
        assert!(kind.starts_with("application/json"), "{path}: {kind}");
        (status, serde_json::from_slice(&body).expect("JSON body"))
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn read_response(stream: &mut impl Read) -> (u16, String, Vec<u8>) {
    let mut raw = Vec::new();
    stream.read_to_end(&mut raw).expect("read the response");
    let split = raw.windows(4).position(|w| w == b"\r\n\r\n").expect("a response head");
    let head = String::from_utf8_lossy(&raw[..split]).into_owned();
    let status = head.split_whitespace().nth(1).and_then(|s| s.parse().ok()).expect("a status");
    let kind = head.lines().find_map(|l| l.strip_prefix("Content-Type: ")).unwrap_or_default().to_string();
    let body = raw[split + 4..].to_vec();
    let length: usize = head.lines().find_map(|l| l.strip_prefix("Content-Length: ")).and_then(|v| v.parse().ok()).expect("a length");
    assert_eq!(length, body.len(), "Content-Length");
    (status, kind, body)
}

/// URL encoding of a query value.
fn encode(text: &str) -> String {
    text.bytes()
        .map(|b| if b.is_ascii_alphanumeric() || b"-_.~".contains(&b) { (b as char).to_string() } else { format!("%{b:02X}") })
        .collect()
}

fn floats(v: &Value) -> Vec<f32> {
    v.as_array().expect("an array").iter().map(|x| x.as_f64().map_or(f32::NAN, |x| x as f32)).collect()
}

/// Equal as numbers, NaN (sent as null) equal to NaN.
fn assert_same(got: &[f32], want: &[f32], what: &str) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(g == w || (g.is_nan() && w.is_nan()), "{what}[{k}]: {g} from the server, {w} from gonio::plot");
    }
}

#[test]
fn binds_to_loopback_and_serves_the_page() {
    let server = Server::start(&[]);
    assert!(server.address.starts_with("127.0.0.1:"), "{}", server.address);
    let (status, kind, body) = server.get("/");
    assert_eq!((status, kind.as_str()), (200, "text/html; charset=utf-8"));
    assert!(String::from_utf8_lossy(&body).contains("import { mount, fetchTransport } from '/explorer.js'"));
    let (status, kind, js) = server.get("/explorer.js");
    assert_eq!(status, 200);
    assert!(kind.starts_with("text/javascript"));
    let js = String::from_utf8(js).unwrap();
    assert!(js.contains("export function mount") && js.contains("export default"), "the page's module and the widget's");
    // No CDN: nothing is fetched from elsewhere (the one URL is SVG's namespace name, never loaded).
    let js_without_namespace = js.replace("'http://www.w3.org/2000/svg'", "");
    assert!(!js_without_namespace.contains("http://") && !js_without_namespace.contains("https://"), "no CDN: the page works offline");
    assert_eq!(server.get("/explorer.css").0, 200);
    assert_eq!(server.get("/no/such/page").0, 404);
    // A request naming another host (DNS rebinding) is refused.
    assert_eq!(server.get_as("/", "evil.example:80").0, 421);
    // The form comes from the models' parameter tables.
    let (status, models) = server.json("/api/models", &[]);
    assert_eq!(status, 200);
    let rough = models["models"].as_array().unwrap().iter().find(|m| m["plugin"] == "roughconductor").expect("roughconductor");
    let alpha = rough["params"].as_array().unwrap().iter().find(|p| p["names"][0] == "alpha").expect("alpha");
    assert_eq!(
        (alpha["kind"].as_str(), alpha["range"]["min"].as_f64(), alpha["range"]["max"].as_f64()),
        (Some("float"), Some(1e-4), Some(10.0))
    );
    let distribution = rough["params"].as_array().unwrap().iter().find(|p| p["names"][0] == "distribution").unwrap();
    assert_eq!(distribution["choices"], serde_json::json!(["beckmann", "ggx"]));
    assert_eq!(models["models"].as_array().unwrap().len(), gonio::bsdf::PLUGINS.len());
}

#[test]
fn plot_numbers_are_gonio_plots() {
    let server = Server::start(&[GGX]);
    let (_, models) = server.json("/api/models", &[]);
    assert_eq!(models["initial"][0].as_str(), Some(GGX), "the command line's model is shown first");
    let bsdf = Bsdf::from_json(GGX).unwrap();
    let c = Channel::Lum;

    let (status, polar) = server.json("/api/plot", &[("spec", GGX), ("kind", "polar"), ("theta_o", "40")]);
    assert_eq!(status, 200, "{polar}");
    let lobe = lobe_data(&bsdf, 40.0, POLAR_SAMPLES, 0, 0).unwrap();
    assert_same(&floats(&polar["incidence"]), &c.of_all(&lobe.incidence), "incidence");
    assert_same(&floats(&polar["perpendicular"]), &c.of_all(&lobe.perpendicular), "perpendicular");
    // The lobe peaks at the mirror direction (−θo in the plane of incidence).
    let incidence = floats(&polar["incidence"]);
    let peak = (0..incidence.len()).max_by(|&i, &j| incidence[i].total_cmp(&incidence[j])).unwrap();
    assert!((polar["angles"][peak].as_f64().unwrap() + 40.0).abs() <= 1.0, "peak at {}", polar["angles"][peak]);

    // The same numbers as `gonio plot`'s CSV.
    let dir = Scratch::new("explore-plot");
    let csv = dir.path().join("polar.csv");
    common::ok(&gonio(&["plot", GGX, "--theta-o", "40", "--kind", "polar", "-o", csv.to_str().unwrap()]));
    let text = std::fs::read_to_string(&csv).unwrap();
    let column: Vec<f32> = text.lines().skip(1).map(|l| l.split(',').nth(1).unwrap().parse().unwrap()).collect();
    assert_same(&incidence, &column, "gonio plot CSV");

    let (_, grid) = server.json("/api/plot", &[("spec", GGX), ("kind", "lobe"), ("theta_o", "40")]);
    let lobe = lobe_data(&bsdf, 40.0, 2, GRID_THETA, GRID_PHI).unwrap();
    assert_same(&floats(&grid["values"]), &c.of_all(&lobe.grid.values), "3-D grid");

    let (_, slice) = server.json("/api/plot", &[("spec", GGX), ("kind", "slice"), ("channel", "r")]);
    let s = slice_data(&bsdf, 90.0, SLICE_RES, SLICE_RES).unwrap();
    assert_same(&floats(&slice["values"]), &Channel::R.of_all(&s.values), "slice");

    let (_, albedo) = server.json("/api/plot", &[("spec", GGX), ("kind", "albedo")]);
    let a = albedo_data(&bsdf, ALBEDO_ANGLES, ALBEDO_SAMPLES, 0).unwrap();
    assert_same(&floats(&albedo["albedo"]), &c.of_all(&a.albedo), "albedo");
    let furnace = albedo["furnace_channel"].as_f64().unwrap();
    assert!(furnace > 0.5 && furnace < 1.0, "white furnace {furnace}: a rough conductor without compensation loses energy");
}

#[test]
fn bad_input_is_400_with_the_clis_message_and_the_server_lives_on() {
    let server = Server::start(&[]);
    let bad = r#"{"type": "roughconductor", "alpha": 20}"#;
    let (status, e) = server.json("/api/plot", &[("spec", bad), ("kind", "polar")]);
    assert_eq!(status, 400);
    let cli = String::from_utf8(gonio(&["check", bad]).stderr).unwrap();
    assert_eq!(format!("gonio: error: {}\n", e["error"].as_str().unwrap()), cli, "the CLI's message");
    assert_eq!(e["param"], "alpha", "shown next to the field");
    let (status, e) = server.json("/api/plot", &[("spec", r#"{"type": "roughconductor", "distribution": "foo"}"#)]);
    assert_eq!((status, e["param"].as_str()), (400, Some("distribution")));
    for (params, expect) in [
        (vec![("spec", "{nope")], "JSON spec"),
        (vec![("kind", "polar")], "spec: missing"),
        (vec![("spec", GGX), ("theta_o", "95")], "outside [0°, 90°)"),
        (vec![("spec", GGX), ("kind", "pie")], "unknown plot `pie`"),
        (vec![("spec", r#"{"type": "merl", "filename": "/etc/passwd"}"#)], "not a measured file this explorer offers"),
    ] {
        let (status, e) = server.json("/api/plot", &params);
        assert_eq!(status, 400, "{params:?}");
        assert!(e["error"].as_str().unwrap().contains(expect), "{params:?}: {e}");
    }
    let (status, e) = server.json("/api/sphere", &[("spec", GGX), ("size", "100000")]);
    assert_eq!(status, 400);
    assert!(e["error"].as_str().unwrap().starts_with("size:"), "{e}");
    // Malformed requests: answered, and the server goes on.
    for raw in ["BLAH\r\n\r\n", "POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 3\r\n\r\nabc", "\u{1}\u{2}\r\n\r\n"] {
        let mut stream = TcpStream::connect(&server.address).unwrap();
        stream.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
        stream.write_all(raw.as_bytes()).unwrap();
        let (status, _, _) = read_response(&mut stream);
        assert!((400..500).contains(&status), "{raw:?}: {status}");
    }
    let long = format!("/api/plot?spec={}", "x".repeat(70_000));
    let mut stream = TcpStream::connect(&server.address).unwrap();
    let _ = write!(stream, "GET {long} HTTP/1.1\r\nHost: {}\r\n\r\n", server.address);
    assert_eq!(read_response(&mut stream).0, 431);
    assert_eq!(server.get("/").0, 200, "still serving");
}

#[test]
fn lit_sphere_verdict_and_export() {
    let server = Server::start(&[]);
    // A white Lambertian sphere in the white furnace is white (1 within noise); the first image is fast.
    let start = Instant::now();
    let query = format!("/api/sphere?spec={}&light=furnace&size=64&spp=64", encode(r#"{"type": "diffuse", "reflectance": 1}"#));
    let (status, kind, png) = server.get(&query);
    let seconds = start.elapsed().as_secs_f64();
    assert_eq!((status, kind.as_str()), (200, "image/png"));
    let image = gonio::image::decode_image(std::path::Path::new("sphere.png"), &png).unwrap();
    assert_eq!((image.width, image.height), (64, 64));
    // The central half of the frame lies on the sphere: its mean is 1 within the noise of 1024 px × 64 spp
    // (a PNG clips values above 1, so the noise biases it low, by ~1 % at 64 spp).
    let mut mean = 0.0;
    for y in 16..48 {
        for x in 16..48 {
            mean += image.get(x, y).g() / 1024.0;
        }
    }
    assert!(mean > 0.97 && mean <= 1.0, "furnace sphere centre averages {mean}");
    println!("64² px 64 spp furnace sphere over HTTP in {seconds:.3} s");
    assert!(seconds < 5.0, "{seconds} s");
    let (status, _, png) = server.get(&format!("/api/sphere?spec={}&light=dir&dir=1,0,0&size=32", encode(GGX)));
    assert_eq!(status, 200);
    assert!(png.starts_with(&[0x89, b'P', b'N', b'G']));

    // The Phong counter-example of the lecture is a violation; a Lambertian surface passes.
    let (_, diffuse) = server.json("/api/verify", &[("spec", r#"{"type": "diffuse"}"#)]);
    assert_eq!(diffuse["passed"], true, "{diffuse}");
    let phong = gonio::Bsdf::violations().into_iter().find(|(s, _)| s.contains("phong")).expect("a Phong violation").0;
    let (status, verdict) = server.json("/api/verify", &[("spec", phong)]);
    assert_eq!(status, 200);
    assert_eq!(verdict["passed"], false, "{verdict}");
    assert!(
        verdict["checks"].as_array().unwrap().iter().any(|r| r["passed"] == false && r["check"].as_str().unwrap().contains("albedo")),
        "{verdict}"
    );

    let (status, kind, xml) = server.get(&format!("/api/export?format=xml&spec={}", encode(GGX)));
    assert_eq!((status, kind.as_str()), (200, "application/xml"));
    let xml = String::from_utf8(xml).unwrap();
    assert!(xml.contains(r#"<bsdf type="roughconductor">"#) && xml.contains(r#"<float name="alpha" value="0.3"/>"#), "{xml}");
    assert_eq!(Bsdf::from_xml(&xml, "export").unwrap(), Bsdf::from_json(GGX).unwrap(), "the export reads back as the same model");
    let (status, json) = server.json("/api/export", &[("format", "json"), ("spec", GGX)]);
    assert_eq!((status, json["alpha"].as_f64()), (200, Some(0.3)));
}

#[test]
fn models_on_the_command_line_in_xml_are_shown_as_json() {
    let dir = Scratch::new("explore-xml");
    let file = dir.join("coat.xml");
    std::fs::write(
        &file,
        r#"<bsdf type="roughplastic"><float name="alpha" value="0.25"/><rgb name="diffuse_reflectance" value="0.1, 0.2, 0.3"/></bsdf>"#,
    )
    .unwrap();
    let inline = r#"<bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>"#;
    let server = Server::start(&[&dir.arg("coat.xml"), inline]);
    let (status, models) = server.json("/api/models", &[]);
    assert_eq!(status, 200);
    let initial: Vec<Value> =
        models["initial"].as_array().unwrap().iter().map(|s| serde_json::from_str(s.as_str().unwrap()).unwrap()).collect();
    assert_eq!(initial[0], serde_json::json!({"type": "roughplastic", "alpha": 0.25, "diffuse_reflectance": [0.1, 0.2, 0.3]}));
    assert_eq!(initial[1], serde_json::json!({"type": "diffuse", "reflectance": 0.5}));
    // The page's numbers for it are those of the model read from the XML file.
    let (_, polar) = server.json("/api/plot", &[("spec", &initial[0].to_string()), ("kind", "polar")]);
    let bsdf = gonio::Bsdf::from_props(&gonio::props::Props::from_xml_bsdf(&std::fs::read_to_string(&file).unwrap(), "coat.xml").unwrap())
        .unwrap();
    let lobe = lobe_data(&bsdf, 30.0, POLAR_SAMPLES, 0, 0).unwrap();
    assert_same(&floats(&polar["incidence"]), &Channel::Lum.of_all(&lobe.incidence), "polar of the XML model");
    // A broken XML file stops the server before it listens, naming the file and place.
    let bad = dir.join("bad.xml");
    std::fs::write(&bad, r#"<bsdf type="roughplastic"><float name="alpha" value="-1"/></bsdf>"#).unwrap();
    let out = gonio_command().args(["explore", "--port", "0", &dir.arg("bad.xml")]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("bad.xml") && err.contains("alpha"), "{err}");
}
