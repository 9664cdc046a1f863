//! The 3-D lobe: the surface r(ωi) = f·cos θi · ωi over the grid of [`gonio::plot::LobeGrid`], projected
//! orthographically and shaded (quads sorted back to front), one colour per model. The radius is
//! f·cos θi on a linear or logarithmic scale; the grey disk is the surface (radius 1 = the top of the scale).

use super::svg::{Anchor, Svg};
use super::{channel_name, colour, legend, Scale, AXIS};
use gonio::math::DVec3;
use gonio::plot::{Channel, LobeData};

const WIDTH: f64 = 960.0;
const HEIGHT: f64 = 760.0;
/// Pixels per unit radius.
const S: f64 = 300.0;
/// The camera: azimuth and elevation (degrees) of the direction it looks from.
const AZIMUTH: f64 = -60.0;
const ELEVATION: f64 = 25.0;

struct Camera {
    right: DVec3,
    up: DVec3,
    towards: DVec3,
    cx: f64,
    cy: f64,
}

impl Camera {
    fn new() -> Self {
        let (az, el) = (AZIMUTH.to_radians(), ELEVATION.to_radians());
        let towards = DVec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
        let right = DVec3::new(-az.sin(), az.cos(), 0.0);
        let up = towards.cross(right);
        Camera { right, up, towards, cx: WIDTH * 0.45, cy: HEIGHT * 0.66 }
    }

    fn project(&self, p: DVec3) -> (f64, f64) {
        (self.cx + S * p.dot(self.right), self.cy - S * p.dot(self.up))
    }
}

/// One shaded quad of a lobe, in screen coordinates, with its depth along the view direction.
struct Quad {
    depth: f64,
    corners: [(f64, f64); 4],
    fill: String,
    opacity: f64,
}

fn hex(c: &str) -> DVec3 {
    let v = u32::from_str_radix(c.trim_start_matches('#'), 16).unwrap_or(0);
    DVec3::new(f64::from((v >> 16) & 255), f64::from((v >> 8) & 255), f64::from(v & 255))
}

/// The figure for the 3-D lobes of several models seen from one θo.
pub fn draw(lobes: &[LobeData], labels: &[String], channel: Channel, log: bool) -> Svg {
    let theta_o = lobes.first().map_or(0.0, |l| l.theta_o);
    let mut svg = Svg::new(WIDTH, HEIGHT);
    let mut title = format!("f·cos θi at θo = {theta_o}°, {}: the lobe in 3-D", channel_name(channel));
    if log {
        title.push_str(", log scale");
    }
    svg.text(WIDTH / 2.0, 34.0, &title, 22.0, Anchor::Middle, 0.0);
    let scale = Scale::fit(lobes.iter().flat_map(|l| l.grid.values.iter().map(move |&v| f64::from(channel.of(v)))), log);
    if scale.is_none() {
        svg.text(WIDTH / 2.0, 58.0, "f·cos θi is 0 everywhere: the models have only delta lobes", 14.0, Anchor::Middle, 0.0);
    }
    let scale = scale.unwrap_or(Scale::Linear { max: 1.0 });
    let cam = Camera::new();
    // The surface: a disk of radius 1 and the x and y axes.
    let disk: Vec<(f64, f64)> = (0..=96)
        .map(|k| {
            let p = std::f64::consts::TAU * f64::from(k) / 96.0;
            cam.project(DVec3::new(p.cos(), p.sin(), 0.0))
        })
        .collect();
    svg.polygon(&disk, "#e4e4e4", 1.0, Some(("#a0a0a0", 1.0)));
    for (axis, name) in [(DVec3::X, "x"), (DVec3::Y, "y")] {
        let (a, b) = (cam.project(-axis), cam.project(axis * 1.08));
        svg.line(a.0, a.1, b.0, b.1, "#a0a0a0", 1.0, None);
        svg.text(b.0, b.1 + 14.0, name, 12.0, Anchor::Middle, 0.0);
    }
    // Quads of every model, far ones first.
    let mut quads: Vec<Quad> = Vec::new();
    let light = (cam.towards + DVec3::new(0.0, 0.0, 0.6)).normalize();
    for (k, lobe) in lobes.iter().enumerate() {
        let g = &lobe.grid;
        let (nt, np) = (g.theta.len(), g.phi.len());
        let point = |i: usize, j: usize| -> DVec3 {
            let j = j % np;
            let r = scale.map(f64::from(channel.of(g.values[i * np + j])));
            let r = if r.is_nan() { 0.0 } else { r };
            let (t, p) = (g.theta[i].to_radians(), g.phi[j].to_radians());
            r * DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
        };
        let base = hex(colour(k));
        for i in 0..nt.saturating_sub(1) {
            for j in 0..np {
                let c = [point(i, j), point(i, j + 1), point(i + 1, j + 1), point(i + 1, j)];
                if c.iter().all(|p| p.length_squared() < 1e-12) {
                    continue;
                }
                let normal = (c[2] - c[0]).cross(c[3] - c[1]);
                let shade = if normal.length_squared() > 0.0 { 0.35 + 0.65 * normal.normalize().dot(light).abs() } else { 0.6 };
                let rgb = base * shade + DVec3::splat(255.0) * (1.0 - shade) * 0.25;
                let fill = format!("#{:02x}{:02x}{:02x}", rgb.x.min(255.0) as u8, rgb.y.min(255.0) as u8, rgb.z.min(255.0) as u8);
                let depth = c.iter().map(|p| p.dot(cam.towards)).sum::<f64>() / 4.0;
                quads.push(Quad { depth, corners: c.map(|p| cam.project(p)), fill, opacity: if lobes.len() > 1 { 0.7 } else { 0.95 } });
            }
        }
    }
    quads.sort_by(|a, b| a.depth.total_cmp(&b.depth));
    for q in &quads {
        svg.polygon(&q.corners, &q.fill, q.opacity, Some((&q.fill, 0.4)));
    }
    // The normal and the viewing direction, on top.
    let t = theta_o.to_radians();
    let (o, n, v) = (cam.project(DVec3::ZERO), cam.project(DVec3::Z * 1.1), cam.project(DVec3::new(t.sin(), 0.0, t.cos()) * 1.15));
    svg.line(o.0, o.1, n.0, n.1, AXIS, 1.0, Some("2 3"));
    svg.text(n.0, n.1 - 6.0, "n", 13.0, Anchor::Middle, 0.0);
    svg.line(o.0, o.1, v.0, v.1, AXIS, 1.5, Some("6 4"));
    svg.text(v.0 + 6.0, v.1 - 6.0, "ωo", 14.0, Anchor::Start, 0.0);
    let ticks = scale.ticks();
    let top = ticks.last().map_or(String::new(), |(_, l)| l.clone());
    let note = match scale {
        Scale::Linear { .. } => format!("radius: f·cos θi, disk radius = {top} sr⁻¹"),
        Scale::Log { .. } => format!("radius: log f·cos θi from {} (centre) to {top} sr⁻¹ (disk edge)", ticks[0].1),
    };
    svg.text(WIDTH / 2.0, HEIGHT - 18.0, &note, 13.0, Anchor::Middle, 0.0);
    let entries: Vec<(String, &str)> = labels.iter().enumerate().map(|(k, l)| (l.clone(), colour(k))).collect();
    legend(&mut svg, WIDTH - 15.0, 60.0, &entries);
    svg
}
