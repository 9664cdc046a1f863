//! Helpers shared by the spectrum tests (`mod common;` in each; each test file uses some of them).
#![allow(dead_code)]

use gonio::render::RenderOutput;
use gonio::spectrum::cie::{cie1931_xyz, CIE_MAX, CIE_MIN, CIE_Y_NORMALIZATION};

/// XYZ of a spectrum: composite 3-point Gauss–Legendre on 0.5 nm steps over [360, 830] nm (2820 nodes;
/// exact for D65 × x̄ȳz̄, quadratic on each step), times `CIE_Y_NORMALIZATION` — a reduction independent of
/// the upsampling solver's own rule.
pub fn xyz_of(s: impl Fn(f64) -> f64) -> [f64; 3] {
    let steps = 940;
    let h = (CIE_MAX - CIE_MIN) / f64::from(steps);
    let gl = [(-(0.6_f64.sqrt()), 5.0 / 9.0), (0.0, 8.0 / 9.0), (0.6_f64.sqrt(), 5.0 / 9.0)];
    let mut xyz = [0.0; 3];
    for i in 0..steps {
        let mid = CIE_MIN + h * (f64::from(i) + 0.5);
        for (node, weight) in gl {
            let lambda = mid + 0.5 * h * node;
            let w = 0.5 * h * weight * s(lambda) * CIE_Y_NORMALIZATION;
            let cmf = cie1931_xyz(lambda);
            for c in 0..3 {
                xyz[c] += w * cmf[c];
            }
        }
    }
    xyz
}

/// Each channel's mean over an image's pixels and its standard error.
pub fn mean_and_se(img: &RenderOutput) -> [(f64, f64); 3] {
    std::array::from_fn(|c| {
        let v: Vec<f64> = img.data.chunks(3).map(|p| f64::from(p[c])).collect();
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        (mean, (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt())
    })
}
