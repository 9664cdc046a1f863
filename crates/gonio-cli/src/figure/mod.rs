//! The figures of `gonio plot`, drawn from the numbers of [`gonio::plot`]: one file per kind of figure,
//! the SVG writer and the PNG rasteriser beside them. Nothing here computes reflectance.

pub mod albedo;
pub mod lobe3d;
pub mod polar;
pub mod raster;
pub mod slice;
pub mod svg;

use svg::{Anchor, Svg};

/// Line colours of the overlaid models, in order (then repeated).
const PALETTE: [&str; 8] = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"];

/// The colour of the `i`-th model.
pub fn colour(i: usize) -> &'static str {
    PALETTE[i % PALETTE.len()]
}

/// Grey of grids and axes.
pub const GRID: &str = "#c8c8c8";
pub const AXIS: &str = "#404040";

/// Decades shown by a logarithmic scale below its top.
pub const LOG_DECADES: i32 = 4;

/// How a non-negative quantity maps to [0, 1] (a radius or a height).
#[derive(Clone, Copy, Debug)]
pub enum Scale {
    /// 0 → 0, `max` → 1.
    Linear { max: f64 },
    /// 10^lo → 0, 10^hi → 1 (decades); values below 10^lo map to 0.
    Log { lo: i32, hi: i32 },
}

impl Scale {
    /// A scale that holds every finite value of `values`; `None` when there is none above zero (nothing
    /// to show: a model made only of delta lobes, say).
    pub fn fit(values: impl IntoIterator<Item = f64>, log: bool) -> Option<Scale> {
        let max = values.into_iter().filter(|v| v.is_finite()).fold(0.0f64, f64::max);
        // max is finite and ≥ 0 (the fold starts at 0 and skips NaN).
        if max <= 0.0 {
            return None;
        }
        Some(if log {
            let hi = max.log10().ceil() as i32;
            Scale::Log { lo: hi - LOG_DECADES, hi }
        } else {
            Scale::Linear { max: nice_ceiling(max) }
        })
    }

    /// Like [`Scale::fit`], but topped at the `q`-quantile of the positive finite values rather than at
    /// their maximum, so that a few extreme values (f near grazing angles, where it grows without bound
    /// for microfacet models) do not leave the rest of an image black; larger values saturate.
    pub fn fit_quantile(values: impl IntoIterator<Item = f64>, log: bool, q: f64) -> Option<Scale> {
        let mut v: Vec<f64> = values.into_iter().filter(|v| v.is_finite() && *v > 0.0).collect();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        let k = ((v.len() - 1) as f64 * q.clamp(0.0, 1.0)).round() as usize;
        Scale::fit([v[k]], log)
    }

    /// The position of `v` in [0, 1] (clamped); NaN stays NaN.
    pub fn map(self, v: f64) -> f64 {
        match self {
            Scale::Linear { max } => (v / max).clamp(0.0, 1.0),
            Scale::Log { lo, hi } => {
                if v.is_nan() {
                    return f64::NAN;
                }
                if v <= 0.0 {
                    return 0.0;
                }
                ((v.log10() - f64::from(lo)) / f64::from(hi - lo)).clamp(0.0, 1.0)
            }
        }
    }

    /// Tick values with their labels, from the bottom to the top of the scale (zero / the lowest decade
    /// included).
    pub fn ticks(self) -> Vec<(f64, String)> {
        match self {
            Scale::Linear { max } => {
                let step = nice_step(max / 4.0);
                let count = (max / step + 1e-9).floor() as usize;
                (0..=count).map(|k| (k as f64 * step, format_tick(k as f64 * step, step))).collect()
            }
            Scale::Log { lo, hi } => (lo..=hi).map(|e| (10f64.powi(e), power_of_ten(e))).collect(),
        }
    }
}

/// The smallest of 1, 2, 2.5, 5 × 10^k at or above `x` (> 0).
pub fn nice_step(x: f64) -> f64 {
    let e = x.log10().floor();
    let base = 10f64.powf(e);
    let m = x / base;
    let nice = if m <= 1.0 + 1e-9 {
        1.0
    } else if m <= 2.0 + 1e-9 {
        2.0
    } else if m <= 2.5 + 1e-9 {
        2.5
    } else if m <= 5.0 + 1e-9 {
        5.0
    } else {
        10.0
    };
    nice * base
}

/// A round number at or above `x` (> 0) that is a multiple of a nice step: the top of a linear axis.
pub fn nice_ceiling(x: f64) -> f64 {
    let step = nice_step(x / 5.0);
    (x / step - 1e-9).ceil().max(1.0) * step
}

/// A tick label with as many decimals as the step needs.
pub fn format_tick(v: f64, step: f64) -> String {
    let decimals =
        (-(step.log10().floor()) + if (step / 10f64.powf(step.log10().floor()) - 2.5).abs() < 1e-9 { 1.0 } else { 0.0 }).max(0.0) as usize;
    format!("{v:.decimals$}")
}

/// 10^e with superscript digits: "10⁻³", "1" for e = 0, "10" for e = 1.
pub fn power_of_ten(e: i32) -> String {
    match e {
        0 => "1".into(),
        1 => "10".into(),
        _ => {
            const SUP: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
            let digits: String = e.unsigned_abs().to_string().chars().map(|c| SUP[c.to_digit(10).unwrap() as usize]).collect();
            format!("10{}{digits}", if e < 0 { "⁻" } else { "" })
        }
    }
}

/// A legend box whose top-right corner is at (x, y): one line of colour and the label per model.
pub fn legend(svg: &mut Svg, x: f64, y: f64, entries: &[(String, &str)]) {
    if entries.is_empty() {
        return;
    }
    let widest = entries.iter().map(|(l, _)| l.chars().count()).max().unwrap_or(0) as f64;
    let (w, h) = (44.0 + 8.0 * widest, 10.0 + 22.0 * entries.len() as f64);
    svg.rect(x - w, y, w, h, "white", Some(GRID));
    for (k, (label, c)) in entries.iter().enumerate() {
        let ly = y + 20.0 + 22.0 * k as f64;
        svg.line(x - w + 8.0, ly - 5.0, x - w + 32.0, ly - 5.0, c, 3.0, None);
        svg.text(x - w + 38.0, ly, label, 14.0, Anchor::Start, 0.0);
    }
}

/// The label of a channel in titles.
pub fn channel_name(channel: gonio::plot::Channel) -> &'static str {
    use gonio::plot::Channel;
    match channel {
        Channel::R => "red channel",
        Channel::G => "green channel",
        Channel::B => "blue channel",
        Channel::Lum => "luminance",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_numbers() {
        assert_eq!(nice_step(0.03), 0.05);
        assert_eq!(nice_step(0.2), 0.2);
        assert_eq!(nice_step(7.0), 10.0);
        assert_eq!(nice_ceiling(0.159), 0.2);
        assert_eq!(nice_ceiling(1.7), 2.0);
        assert_eq!(nice_ceiling(1.0), 1.0);
        assert_eq!(format_tick(0.25, 0.25), "0.25");
        assert_eq!(format_tick(2.0, 1.0), "2");
        assert_eq!(format_tick(0.1, 0.05), "0.10");
        assert_eq!(power_of_ten(-3), "10⁻³");
        assert_eq!(power_of_ten(12), "10¹²");
    }

    #[test]
    fn scales_map_and_tick() {
        let lin = Scale::fit([0.0, 0.3, f64::NAN, 0.15], false).unwrap();
        assert!(matches!(lin, Scale::Linear { max } if (max - 0.3).abs() < 1e-12));
        assert!((lin.map(0.15) - 0.5).abs() < 1e-12);
        assert_eq!(lin.ticks().iter().map(|t| t.1.as_str()).collect::<Vec<_>>(), ["0.0", "0.1", "0.2", "0.3"]);
        let log = Scale::fit([5.0, 0.01], true).unwrap();
        assert!(matches!(log, Scale::Log { lo: -3, hi: 1 }));
        assert_eq!(log.map(10.0), 1.0);
        assert_eq!(log.map(1e-9), 0.0);
        assert_eq!(log.ticks().len(), 5);
        assert!(Scale::fit([0.0, f64::NAN], false).is_none());
        let values: Vec<f64> = (1..=1000).map(f64::from).chain([1e9]).collect();
        assert!(matches!(Scale::fit_quantile(values, false, 0.99), Some(Scale::Linear { max }) if max == 1000.0));
    }
}
