//! The virtual gonioreflectometer: tabulate any [`BsdfModel`] into a MERL table (`gonio measure`).
//!
//! Each cell of the 90 × 90 × 180 half/difference grid (see [`super::merl_file`]) gets the average of f
//! over `k × k × k` stratified points of the cell in index coordinates (the centre of each stratum;
//! `k = 1` samples the cell centre). Points whose ωo or ωi lies at or below the horizon are left out of
//! the average, as a real gonioreflectometer cannot measure them; a cell with no such point is written
//! as "not measured", which the reader fills from its neighbours. The value stored is therefore what the
//! trilinear lookup reads at the cell centre, up to the second-order difference between a cell's
//! average and its centre value (1/24 of the second derivative along each axis, in index units).
//!
//! Cost: 1,458,000 · k³ evaluations of f, over threads. A stochastic model becomes a fast table.
//!
//! ```no_run
//! use gonio::bsdf::Bsdf;
//! use gonio::measured::gonioreflectometer::measure;
//! let ggx = Bsdf::from_json(r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.2}"#).unwrap();
//! let table = measure(&ggx, 2, "ggx").unwrap();
//! table.write(std::path::Path::new("ggx.binary")).unwrap();
//! ```

use super::merl_file::{directions_at, MerlTable, CELLS, RES_PHI_D, RES_THETA_D};
use crate::bsdf::BsdfModel;
use crate::error::Result;
use crate::math::Vec3;
use rayon::prelude::*;

/// The `f32` directions (ωo, ωi) a gonioreflectometer can measure at index coordinates (xθh, xθd, xφd)
/// (see [`directions_at`]); `None` when either is at or below the horizon.
#[must_use]
pub fn configuration(x_h: f64, x_d: f64, x_p: f64) -> Option<(Vec3, Vec3)> {
    let (wo, wi) = directions_at(x_h, x_d, x_p);
    // 2026-11: 1e-7 keeps f32 directions strictly above the horizon.
    if wo.z <= 1e-7 || wi.z <= 1e-7 {
        return None;
    }
    Some((wo.normalize().as_vec3(), wi.normalize().as_vec3()))
}

/// Tabulate `bsdf` with `k³` points per cell (`k ≥ 1`); `name` names the table in messages.
pub fn measure<M: BsdfModel + Sync + ?Sized>(bsdf: &M, k: usize, name: &str) -> Result<MerlTable> {
    let k = k.max(1);
    let mut values = vec![0f32; 3 * CELLS];
    let per_row = 3 * RES_THETA_D * RES_PHI_D;
    values.par_chunks_mut(per_row).enumerate().for_each(|(ih, row)| {
        for id in 0..RES_THETA_D {
            for ip in 0..RES_PHI_D {
                let mut sum = [0f64; 3];
                let mut count = 0usize;
                for a in 0..k {
                    for b in 0..k {
                        for c in 0..k {
                            let at = |i: usize, s: usize| i as f64 + (s as f64 + 0.5) / k as f64;
                            let Some((wo, wi)) = configuration(at(ih, a), at(id, b), at(ip, c)) else { continue };
                            let f = bsdf.f(wo, wi);
                            for (s, v) in sum.iter_mut().zip(f.0) {
                                *s += f64::from(v);
                            }
                            count += 1;
                        }
                    }
                }
                let i = 3 * (ip + RES_PHI_D * id);
                let cell = &mut row[i..i + 3];
                if count == 0 {
                    cell.fill(-1.0);
                } else {
                    for (v, s) in cell.iter_mut().zip(sum) {
                        *v = (s / count as f64) as f32;
                    }
                }
            }
        }
    });
    MerlTable::from_values(values, name)
}
