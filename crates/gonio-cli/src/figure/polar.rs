//! Polar plots of f·cos θi ([`gonio::plot::lobe_data`]): the plane of incidence beside the perpendicular
//! plane, one curve per model. The radius is f·cos θi (sr⁻¹) on a linear or logarithmic scale; the
//! angle is the one of the data (up = the normal, resp. the mirror direction ωr; positive angles to the
//! right, towards the viewer in the plane of incidence).

use super::svg::{Anchor, Svg};
use super::{channel_name, colour, legend, Scale, AXIS, GRID};
use gonio::plot::{Channel, LobeData};

const R: f64 = 220.0;
const PANEL: f64 = 560.0;
const LEGEND_COLUMN: f64 = 240.0;

/// The figure for the lobes of several models seen from one θo.
pub fn draw(lobes: &[LobeData], labels: &[String], channel: Channel, log: bool, full_circle: bool) -> Svg {
    let theta_o = lobes.first().map_or(0.0, |l| l.theta_o);
    let values = |l: &LobeData| -> Vec<(Vec<f32>, Vec<f32>)> { vec![(channel.of_all(&l.incidence), channel.of_all(&l.perpendicular))] };
    let all: Vec<(Vec<f32>, Vec<f32>)> = lobes.iter().flat_map(values).collect();
    let in_domain = |a: f64| full_circle || a.abs() <= 90.0;
    let scale = Scale::fit(
        lobes.iter().zip(&all).flat_map(|(l, (a, b))| {
            l.angles.iter().zip(a.iter().zip(b)).filter(|(ang, _)| in_domain(**ang)).flat_map(|(_, (x, y))| [f64::from(*x), f64::from(*y)])
        }),
        log,
    );
    let top = 100.0;
    let cy = top + R;
    let height = if full_circle { cy + R + 60.0 } else { cy + 75.0 };
    let mut svg = Svg::new(2.0 * PANEL + LEGEND_COLUMN, height);
    let mut title = format!("f·cos θi at θo = {theta_o}°, {}", channel_name(channel));
    if log {
        title.push_str(", log scale");
    }
    svg.text(svg.width / 2.0, 34.0, &title, 22.0, Anchor::Middle, 0.0);
    if scale.is_none() {
        svg.text(
            svg.width / 2.0,
            58.0,
            "f·cos θi is 0 at every angle: the models have only delta lobes (mirrors, smooth glass)",
            14.0,
            Anchor::Middle,
            0.0,
        );
    }
    let scale = scale.unwrap_or(Scale::Linear { max: 1.0 });
    for (panel, name) in ["plane of incidence (angle = θi, signed)", "perpendicular plane (angle from ωr)"].iter().enumerate() {
        let cx = PANEL * (panel as f64 + 0.5);
        svg.text(cx, top - 42.0, name, 16.0, Anchor::Middle, 0.0);
        grid(&mut svg, cx, cy, scale, full_circle, panel == 0, theta_o);
        for (k, (lobe, (inc, perp))) in lobes.iter().zip(&all).enumerate() {
            let vals = if panel == 0 { inc } else { perp };
            curve(&mut svg, cx, cy, scale, &lobe.angles, vals, colour(k), &in_domain);
        }
    }
    let entries: Vec<(String, &str)> = labels.iter().enumerate().map(|(k, l)| (l.clone(), colour(k))).collect();
    let right = svg.width - 15.0;
    legend(&mut svg, right, top - 20.0, &entries);
    svg.text(svg.width - LEGEND_COLUMN / 2.0 - 10.0, cy + 20.0, "radius: f·cos θi (sr⁻¹)", 13.0, Anchor::Middle, 0.0);
    svg
}

/// Rings at the scale's ticks, spokes every 30°, the surface and the directions ωo, ωr.
fn grid(svg: &mut Svg, cx: f64, cy: f64, scale: Scale, full: bool, incidence: bool, theta_o: f64) {
    let span = if full { std::f64::consts::PI } else { std::f64::consts::FRAC_PI_2 };
    for (v, label) in scale.ticks() {
        let r = R * scale.map(v);
        if r <= 0.0 {
            continue;
        }
        svg.arc(cx, cy, r, -span, span, GRID, 1.0, None);
        svg.text(cx + r + 2.0, cy + 15.0, &label, 11.0, Anchor::Middle, 0.0);
    }
    let max_deg: i32 = if full { 180 } else { 90 };
    for a in (-max_deg..=max_deg).step_by(30) {
        let ar = f64::from(a).to_radians();
        svg.line(cx, cy, cx + R * ar.sin(), cy - R * ar.cos(), GRID, 1.0, None);
        // −180° and 180° are one spoke: label it once.
        if a != -180 {
            let (lx, ly) = (cx + (R + 20.0) * ar.sin(), cy - (R + 16.0) * ar.cos() + 4.0);
            // The horizon labels sit above the line.
            let ly = if a.abs() == 90 { ly - 8.0 } else { ly };
            svg.text(lx, ly, &format!("{a}°"), 11.0, Anchor::Middle, 0.0);
        }
    }
    if incidence {
        svg.line(cx - R - 12.0, cy, cx + R + 12.0, cy, AXIS, 2.0, None);
        svg.text(cx - R - 8.0, cy + 15.0, "surface", 11.0, Anchor::Start, 0.0);
        let t = theta_o.to_radians();
        let (ox, oy) = (cx + R * t.sin(), cy - R * t.cos());
        svg.line(cx, cy, ox, oy, AXIS, 1.5, Some("6 4"));
        let (lx, ly) = (cx + 0.9 * R * t.sin() + 8.0 * t.cos(), cy - 0.9 * R * t.cos() + 8.0 * t.sin());
        svg.text(lx + 4.0, ly + 4.0, "ωo", 15.0, Anchor::Start, 0.0);
        let (rx, ry) = (cx - R * t.sin(), cy - R * t.cos());
        svg.line(cx, cy, rx, ry, AXIS, 1.0, Some("2 3"));
        let (lx, ly) = (cx - 0.9 * R * t.sin() - 8.0 * t.cos(), cy - 0.9 * R * t.cos() + 8.0 * t.sin());
        svg.text(lx - 4.0, ly + 4.0, "ωr", 15.0, Anchor::End, 0.0);
    } else {
        svg.line(cx - R - 12.0, cy, cx + R + 12.0, cy, AXIS, 1.0, None);
        svg.text(cx + 8.0, cy - 0.9 * R, "ωr", 15.0, Anchor::Start, 0.0);
        svg.text(cx + R + 10.0, cy + 30.0, "+y", 11.0, Anchor::Middle, 0.0);
    }
}

/// One model's curve; NaN values (a model's bug) break the line rather than bend it.
#[allow(clippy::too_many_arguments)]
fn curve(svg: &mut Svg, cx: f64, cy: f64, scale: Scale, angles: &[f64], values: &[f32], stroke: &str, in_domain: &dyn Fn(f64) -> bool) {
    let mut run: Vec<(f64, f64)> = Vec::new();
    for (&a, &v) in angles.iter().zip(values) {
        let r = R * scale.map(f64::from(v));
        if !in_domain(a) || r.is_nan() {
            svg.polyline(&run, stroke, 2.2, None);
            run.clear();
            continue;
        }
        let ar = a.to_radians();
        run.push((cx + r * ar.sin(), cy - r * ar.cos()));
    }
    svg.polyline(&run, stroke, 2.2, None);
}
