//! θh × θd images of f ([`gonio::plot::slice_data`]), one panel per model, as in the MERL papers and
//! Disney's BRDF Explorer: θh across (MERL's square-root spacing, so the specular peak gets room), θd up,
//! f in sr⁻¹ through a black-body colour map on a linear or logarithmic scale shared by the panels, topped
//! at the 99.5th percentile of the values (f grows without bound towards grazing angles).
//! Configurations below the horizon (NaN in the data) are light grey.

use super::raster::rgb_to_png;
use super::svg::{Anchor, Svg};
use super::{channel_name, Scale, AXIS};
use gonio::plot::{Channel, SliceData};

const SIDE: f64 = 360.0;
const GAP: f64 = 80.0;
const LEFT: f64 = 80.0;
const TOP: f64 = 90.0;
/// Anchors of the colour map, evenly spaced over [0, 1] (black → purple → red → orange → yellow → white).
const MAP: [[f64; 3]; 6] =
    [[0.0, 0.0, 0.0], [60.0, 15.0, 110.0], [180.0, 40.0, 80.0], [240.0, 120.0, 30.0], [250.0, 220.0, 80.0], [255.0, 255.0, 235.0]];
const BELOW_HORIZON: [u8; 3] = [217, 217, 217];
/// The top of the colour scale: this quantile of the values (see [`Scale::fit_quantile`]).
const QUANTILE: f64 = 0.995;

/// The colour of `t` ∈ [0, 1].
pub fn colour_map(t: f64) -> [u8; 3] {
    let x = t.clamp(0.0, 1.0) * (MAP.len() - 1) as f64;
    let i = (x.floor() as usize).min(MAP.len() - 2);
    let w = x - i as f64;
    let c = |k: usize| (MAP[i][k] * (1.0 - w) + MAP[i + 1][k] * w).round() as u8;
    [c(0), c(1), c(2)]
}

/// The figure; errors only if PNG encoding of a panel fails.
pub fn draw(slices: &[SliceData], labels: &[String], channel: Channel, log: bool) -> Result<Svg, String> {
    let n = slices.len().max(1) as f64;
    let width = LEFT + n * SIDE + (n - 1.0) * GAP + 150.0;
    let mut svg = Svg::new(width, TOP + SIDE + 80.0);
    let phi_d = slices.first().map_or(90.0, |s| s.phi_d);
    let mut title = format!("f (sr⁻¹) at φd = {phi_d}°, {}", channel_name(channel));
    if log {
        title.push_str(", log scale");
    }
    svg.text(width / 2.0, 34.0, &title, 22.0, Anchor::Middle, 0.0);
    let scale = Scale::fit_quantile(slices.iter().flat_map(|s| s.values.iter().map(move |&v| f64::from(channel.of(v)))), log, QUANTILE)
        .unwrap_or(Scale::Linear { max: 1.0 });
    svg.text(
        width / 2.0,
        56.0,
        "colours top out at the 99.5th percentile of f; brighter cells (near grazing angles) saturate",
        12.0,
        Anchor::Middle,
        0.0,
    );
    for (k, (s, label)) in slices.iter().zip(labels).enumerate() {
        let x0 = LEFT + k as f64 * (SIDE + GAP);
        let (nh, nd) = (s.theta_h.len(), s.theta_d.len());
        // Rows of the image top first: the largest θd at the top.
        let pixels: Vec<[u8; 3]> = (0..nd)
            .rev()
            .flat_map(|j| (0..nh).map(move |i| (j, i)))
            .map(|(j, i)| {
                let v = f64::from(channel.of(s.values[j * nh + i]));
                if v.is_nan() {
                    BELOW_HORIZON
                } else {
                    colour_map(scale.map(v))
                }
            })
            .collect();
        let png = rgb_to_png(nh as u32, nd as u32, &pixels)?;
        svg.png_image(x0, TOP, SIDE, SIDE, &png);
        svg.rect(x0, TOP, SIDE, SIDE, "none", Some(AXIS));
        svg.text(x0 + SIDE / 2.0, TOP - 12.0, label, 16.0, Anchor::Middle, 0.0);
        // θh ticks at their square-root positions.
        for t in [0.0f64, 2.0, 10.0, 20.0, 45.0, 90.0] {
            let x = x0 + SIDE * (t / 90.0).sqrt();
            svg.line(x, TOP + SIDE, x, TOP + SIDE + 5.0, AXIS, 1.0, None);
            svg.text(x, TOP + SIDE + 19.0, &format!("{t}°"), 11.0, Anchor::Middle, 0.0);
        }
        svg.text(x0 + SIDE / 2.0, TOP + SIDE + 40.0, "θh (square-root axis)", 13.0, Anchor::Middle, 0.0);
        for t in (0..=90).step_by(15) {
            let y = TOP + SIDE * (1.0 - f64::from(t) / 90.0);
            svg.line(x0 - 5.0, y, x0, y, AXIS, 1.0, None);
            svg.text(x0 - 8.0, y + 4.0, &format!("{t}°"), 11.0, Anchor::End, 0.0);
        }
        svg.text(x0 - 44.0, TOP + SIDE / 2.0, "θd", 13.0, Anchor::Middle, -90.0);
    }
    // The colour bar.
    let bx = width - 110.0;
    let bar: Vec<[u8; 3]> = (0..256).rev().map(|k| colour_map(f64::from(k) / 255.0)).collect();
    svg.png_image(bx, TOP, 20.0, SIDE, &rgb_to_png(1, 256, &bar)?);
    svg.rect(bx, TOP, 20.0, SIDE, "none", Some(AXIS));
    for (v, label) in scale.ticks() {
        let y = TOP + SIDE * (1.0 - scale.map(v));
        svg.line(bx + 20.0, y, bx + 25.0, y, AXIS, 1.0, None);
        svg.text(bx + 28.0, y + 4.0, &label, 11.0, Anchor::Start, 0.0);
    }
    svg.rect(bx, TOP + SIDE + 22.0, 20.0, 12.0, "#d9d9d9", Some(AXIS));
    svg.text(bx + 26.0, TOP + SIDE + 32.0, "below horizon", 11.0, Anchor::Start, 0.0);
    Ok(svg)
}
