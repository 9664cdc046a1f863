//! Directional albedo against θo ([`gonio::plot::albedo_data`]): one curve per model, θo from 0° to 90°,
//! the albedo (dimensionless) on a linear or logarithmic axis, and the line at 1 that an
//! energy-conserving model stays under.

use super::svg::{Anchor, Svg};
use super::{channel_name, colour, legend, Scale, AXIS, GRID};
use gonio::plot::{AlbedoData, Channel};

const WIDTH: f64 = 1000.0;
const HEIGHT: f64 = 580.0;
/// The plot box.
const LEFT: f64 = 90.0;
const RIGHT: f64 = 760.0;
const TOP: f64 = 70.0;
const BOTTOM: f64 = 500.0;

/// The figure; `theta_o` (degrees) is marked when given.
pub fn draw(curves: &[AlbedoData], labels: &[String], channel: Channel, log: bool, theta_o: Option<f64>) -> Svg {
    let mut svg = Svg::new(WIDTH, HEIGHT);
    let mut title = format!("directional albedo ∫ f cos θi dωi against θo, {}", channel_name(channel));
    if log {
        title.push_str(", log scale");
    }
    svg.text(WIDTH / 2.0, 34.0, &title, 20.0, Anchor::Middle, 0.0);
    // The axis always shows 1, the bound of energy conservation.
    let values = curves.iter().flat_map(|c| c.albedo.iter().map(move |&a| f64::from(channel.of(a))));
    let scale = Scale::fit(values.chain([1.0]), log).unwrap_or(Scale::Linear { max: 1.0 });
    let x_of = |t: f64| LEFT + (RIGHT - LEFT) * t / 90.0;
    let y_of = |v: f64| BOTTOM - (BOTTOM - TOP) * scale.map(v);
    for (v, label) in scale.ticks() {
        let y = y_of(v);
        svg.line(LEFT, y, RIGHT, y, GRID, 1.0, None);
        svg.text(LEFT - 8.0, y + 4.0, &label, 12.0, Anchor::End, 0.0);
    }
    for t in (0..=90).step_by(15) {
        let x = x_of(f64::from(t));
        svg.line(x, TOP, x, BOTTOM, GRID, 1.0, None);
        svg.text(x, BOTTOM + 20.0, &format!("{t}°"), 12.0, Anchor::Middle, 0.0);
    }
    svg.rect(LEFT, TOP, RIGHT - LEFT, BOTTOM - TOP, "none", Some(AXIS));
    svg.line(LEFT, y_of(1.0), RIGHT, y_of(1.0), AXIS, 1.2, Some("6 4"));
    svg.text(RIGHT - 6.0, y_of(1.0) - 6.0, "1: all energy reflected", 12.0, Anchor::End, 0.0);
    if let Some(t) = theta_o {
        svg.line(x_of(t), TOP, x_of(t), BOTTOM, AXIS, 1.0, Some("2 3"));
        svg.text(x_of(t) + 4.0, TOP + 14.0, &format!("θo = {t}°"), 12.0, Anchor::Start, 0.0);
    }
    svg.text((LEFT + RIGHT) / 2.0, BOTTOM + 46.0, "θo (viewing angle from the normal)", 14.0, Anchor::Middle, 0.0);
    svg.text(LEFT - 58.0, (TOP + BOTTOM) / 2.0, "albedo", 14.0, Anchor::Middle, -90.0);
    for (k, c) in curves.iter().enumerate() {
        let pts: Vec<(f64, f64)> =
            c.theta_o.iter().zip(&c.albedo).map(|(&t, &a)| (x_of(t), y_of(f64::from(channel.of(a))))).filter(|p| p.1.is_finite()).collect();
        svg.polyline(&pts, colour(k), 2.2, None);
        for &(x, y) in &pts {
            svg.circle(x, y, 3.0, colour(k));
        }
    }
    let entries: Vec<(String, &str)> = labels.iter().enumerate().map(|(k, l)| (l.clone(), colour(k))).collect();
    legend(&mut svg, WIDTH - 15.0, TOP, &entries);
    svg
}
