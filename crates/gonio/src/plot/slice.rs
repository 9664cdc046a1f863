//! Slice data: f on a θh × θd grid at one φd — the image slices of the MERL papers (Matusik et al. 2003)
//! and of Disney's BRDF Explorer, in Rusinkiewicz's half/difference angles (1998).
//!
//! θh is the angle of the half vector ωh from the normal, θd the angle between ωi (or ωo) and ωh, φd the
//! azimuth of ωi about ωh (see [`crate::measured::merl_file`]). The grid is MERL's:
//!
//! - column `i` of `n_h`: θh = 90° · ((i + ½)/n_h)² — the square-root spacing that spends columns near the
//!   specular peak; at n_h = 90 these are exactly the centres of the cells of a MERL table;
//! - row `j` of `n_d`: θd = 90° · (j + ½)/n_d (MERL's cell centres at n_d = 90);
//! - φd in degrees; MERL tables store φd ∈ [0°, 180°) (reciprocity folds φd + 180° onto φd), and their
//!   cell centres lie at φd = k + ½ degrees. The classic slice is φd = 90°.
//!
//! Each value is f(ωo, ωi) in sr⁻¹ with the directions built exactly as the virtual gonioreflectometer
//! builds them ([`configuration`], φh = 0), so the slice of a MERL table at its cell centres reads the
//! table's own entries. Configurations where ωo or ωi is at or below the horizon cannot be measured and
//! are NaN (the black corner of the MERL slices).

use crate::bsdf::BsdfModel;
use crate::error::{Error, Result};
use crate::measured::gonioreflectometer::configuration;
use crate::measured::merl_file::{RES_PHI_D, RES_THETA_D, RES_THETA_H};
use crate::spectrum::Rgb;
use rayon::prelude::*;

/// f on a θh × θd grid (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct SliceData {
    /// φd in degrees.
    pub phi_d: f64,
    /// θh of each column, in degrees (square-root spacing).
    pub theta_h: Vec<f64>,
    /// θd of each row, in degrees.
    pub theta_d: Vec<f64>,
    /// f (sr⁻¹) at (θh[i], θd[j]) at index `j · theta_h.len() + i` (rows of θd); NaN below the horizon.
    pub values: Vec<Rgb>,
}

/// The slice of `bsdf` at φd = `phi_d` degrees (in [0°, 360°)) on `n_h` × `n_d` points (each ≥ 1;
/// 90 × 90 is MERL's resolution).
pub fn slice_data<M: BsdfModel + Sync + ?Sized>(bsdf: &M, phi_d: f64, n_h: usize, n_d: usize) -> Result<SliceData> {
    if !(0.0..360.0).contains(&phi_d) {
        return Err(Error::spec("phi_d", format!("φd = {phi_d}° is outside [0°, 360°)")));
    }
    if n_h == 0 || n_d == 0 {
        return Err(Error::spec("resolution", format!("need at least one θh and one θd, got {n_h} × {n_d}")));
    }
    // Index coordinates of MERL's table (cell i spans [i, i + 1)); the scales are exactly 1 at 90 × 90.
    let (scale_h, scale_d) = (RES_THETA_H as f64 / n_h as f64, RES_THETA_D as f64 / n_d as f64);
    let x_p = phi_d / 180.0 * RES_PHI_D as f64;
    let theta_h = (0..n_h).map(|i| 90.0 * ((i as f64 + 0.5) / n_h as f64).powi(2)).collect();
    let theta_d = (0..n_d).map(|j| 90.0 * (j as f64 + 0.5) / n_d as f64).collect();
    let values = (0..n_d)
        .into_par_iter()
        .flat_map_iter(|j| {
            (0..n_h).map(move |i| match configuration((i as f64 + 0.5) * scale_h, (j as f64 + 0.5) * scale_d, x_p) {
                Some((wo, wi)) => bsdf.f(wo, wi),
                None => Rgb::new(f32::NAN, f32::NAN, f32::NAN),
            })
        })
        .collect();
    Ok(SliceData { phi_d, theta_h, theta_d, values })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::merl::Merl;
    use crate::bsdf::Bsdf;
    use crate::measured::{fixtures, Interpolation};

    #[test]
    fn slice_of_a_merl_table_reads_its_cells() {
        // A table made by the virtual gonioreflectometer, written by gonio's writer and read back.
        let (_, _, table) = fixtures::smooth();
        let nearest = Merl::new(table.clone(), Interpolation::Nearest);
        let trilinear = Merl::new(table.clone(), Interpolation::Trilinear);
        // φd = 90.5° is the centre of cell 90.
        let a = slice_data(&nearest, 90.5, 90, 90).unwrap();
        let b = slice_data(&trilinear, 90.5, 90, 90).unwrap();
        let (mut measured, mut worst) = (0, 0f32);
        for j in 0..90 {
            for i in 0..90 {
                let (va, vb, cell) = (a.values[j * 90 + i], b.values[j * 90 + i], table.cell(i, j, 90));
                if va.r().is_nan() {
                    assert!(vb.r().is_nan());
                    continue;
                }
                measured += 1;
                assert_eq!(va, cell, "nearest at (θh {i}, θd {j})");
                for c in 0..3 {
                    worst = worst.max((vb.0[c] - cell.0[c]).abs() / cell.0[c].max(1e-3));
                }
            }
        }
        println!("{measured} measured cells; trilinear at the cell centres within {worst:e} (relative)");
        assert!(measured > 4000, "{measured}");
        assert!(worst < 1e-3, "{worst}");
        // Below the horizon: θd → 90° with θh > 0 puts ωo under the surface.
        assert!(a.values[89 * 90 + 89].r().is_nan());
        // φd = 90° is the border of cells 89 and 90: trilinear reads their mean.
        let c = slice_data(&trilinear, 90.0, 90, 90).unwrap();
        let (i, j) = (30, 40);
        let mean = (table.cell(i, j, 89) + table.cell(i, j, 90)) * 0.5;
        let got = c.values[j * 90 + i];
        assert!((0..3).all(|k| (got.0[k] - mean.0[k]).abs() <= 1e-3 * mean.0[k]), "{got} vs {mean}");
    }

    #[test]
    fn slice_axes_and_analytic_model() {
        let rho = 0.4f32;
        let b = Bsdf::from_json(r#"{"type": "diffuse", "reflectance": 0.4}"#).unwrap();
        // At φd = 0 the two directions lie in one plane and ωi sinks below the horizon when θh + θd > 90°.
        let s = slice_data(&b, 0.0, 30, 20).unwrap();
        assert_eq!((s.theta_h.len(), s.theta_d.len(), s.values.len()), (30, 20, 600));
        assert_eq!((s.theta_h[0], s.theta_d[0]), (90.0 * (0.5f64 / 30.0).powi(2), 90.0 * 0.5 / 20.0));
        // Lambertian: ρ/π wherever both directions are above the surface; NaN elsewhere.
        let mut nan = 0;
        for v in &s.values {
            if v.r().is_nan() {
                nan += 1;
            } else {
                assert!((v.g() - rho / std::f32::consts::PI).abs() < 1e-7);
            }
        }
        assert!(nan > 0 && nan < 300, "{nan}");
    }

    #[test]
    fn bad_arguments_are_errors() {
        let b = Bsdf::from_json(r#"{"type": "diffuse"}"#).unwrap();
        assert!(slice_data(&b, -1.0, 4, 4).unwrap_err().to_string().starts_with("phi_d:"));
        assert!(slice_data(&b, f64::NAN, 4, 4).is_err());
        assert!(slice_data(&b, 90.0, 0, 4).unwrap_err().to_string().contains("resolution"));
    }
}
