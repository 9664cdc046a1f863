//! `measured` — a measured material of the RGL database, in the adaptive parameterisation of Dupuy &
//! Jakob 2018, "An Adaptive Parameterization for Efficient Material Acquisition and Rendering"
//! (ACM TOG 37(6)); Mitsuba 3's plugin of the same name reads the same files.
//!
//! | parameter  | type   | default | meaning                                                          |
//! |------------|--------|---------|------------------------------------------------------------------|
//! | `filename` | string | —       | an RGL `.bsdf` file (the `tensor_file` container, RGB variant `*_rgb.bsdf`) |
//!
//! # The tables (fields of the file)
//!
//! | field         | shape                      | meaning                                                  |
//! |---------------|----------------------------|----------------------------------------------------------|
//! | `theta_i`, `phi_i` | [nθ], [nφ]            | the incident directions measured (nφ ≤ 2: isotropic)      |
//! | `ndf`         | [2 or nφ', n]              | D(ωm), the microfacet normal distribution, over (u_θ, u_φ) |
//! | `sigma`       | [2 or nφ', n]              | σ(ωi), the projected microfacet area (§4, eq. 4)          |
//! | `vndf`        | [nφ, nθ, n, n]             | the visible-normal distribution D_ωi(ωm) per incident direction, as a density over the unit square (u_θ, u_φ) of ωm |
//! | `luminance`   | [nφ, nθ, m, m]             | the luminance of the reflectance in the square the VNDF warp maps from (§5.2) |
//! | `rgb`         | [nφ, nθ, 3, m, m]          | the RGB reflectance ρ in that square                       |
//! | `jacobian`    | [1] u8                     | whether f carries the D/(4σ) factor (all RGL files: 1)     |
//! | `description` | [k] u8                     | the material's name                                        |
//!
//! Angles map to the unit square by u_θ = √(2θ/π) (more resolution near the pole, §5.1) and
//! u_φ = (φ + π)/(2π); for isotropic files φm is taken relative to φi.
//!
//! # Evaluation (paper §5, eq. 8–11)
//! With θᵢ, φᵢ the angles of the viewer direction `wo` (Mitsuba's `si.wi`, the paper's ωi) and ωm the half
//! vector of `wo` and `wi`, the VNDF warp, conditioned on (φᵢ, θᵢ) and bilinearly interpolated between
//! the tabulated incident directions, is *inverted* at ωm's coordinates to find the point s of the
//! reflectance square, and
//!
//! f(wo, wi) · cos θ(wi) = ρ(s | φᵢ, θᵢ) · D(ωm) / (4 σ(wo)),
//!
//! which is exactly what Mitsuba's `eval` returns (it includes the cosine); gonio's `f` divides by
//! cos θ(wi). Sampling warps u through the luminance table and then the VNDF table to ωm and reflects
//! `wo` about it; its density is pdf_vndf · pdf_lum / (2π² u_θ sin θm · 4 (wo·ωm)), the Jacobian of
//! (u_θ, u_φ) → ωm (dωm = 2π² u_θ sin θm du_θ du_φ) times that of the reflection. The 2-D warps are
//! [`Marginal2D`], which reproduces Mitsuba's `Marginal2D` numerics, so `f` and `pdf` agree with
//! Mitsuba 3 (scalar_rgb) to float32 round-off (see crates/gonio-py/tests/test_measured_mitsuba.py).
//!
//! Anisotropic files (nφ > 2) cover a fraction 1/r of the azimuths (r = 2π / (φ_last − φ_first), 1, 2
//! or 4); directions are folded into the measured range by the mirror symmetries the file implies, as
//! Mitsuba does.
//!
//! # Differences from Mitsuba, on purpose
//! - RGB tables converted from spectra hold small negative entries (e.g. −0.007 in the blue channel of
//!   `cg_sunflower_rgb` where red is 0.22); Mitsuba returns them, gonio clamps each channel of f at 0,
//!   since a BSDF value is non-negative.
//! - A sample's `f` and `pdf` are evaluated at the returned direction through the inverse warp, like
//!   `f` and `pdf` themselves, so that sample, f and pdf agree to float32 round-off.
//! - Spectral files (`spectra` and `wavelengths` fields) are refused with an error: use the `_rgb` files.
//! - Bad files are errors naming the file and field (see [`crate::measured::tensor_file`]); Mitsuba
//!   trusts the header.
//!
//! Measured data are not reciprocal (each incident direction is a separate measurement): `gonio check`
//! runs the real files as expected *reciprocity* violations, every other check passing (see
//! [`Examples`](crate::bsdf::Examples) below).
//!
//! ```no_run
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::Vec3;
//! let paper = Bsdf::from_json(r#"{"type": "measured", "filename": "/work/shared/data/rgl/paper_white_rgb.bsdf"}"#).unwrap();
//! let f = paper.f(Vec3::new(0.0, 0.6, 0.8), Vec3::Z);
//! assert!(f.g() > 0.1);
//! ```

use super::{BsdfFlags, BsdfModel, BsdfSample};
use crate::error::{Error, Result};
use crate::math::{Vec2, Vec3};
use crate::measured::tensor_file::{F32Array, TensorFile};
use crate::props::Props;
use crate::sampling::marginal2d::Marginal2D;
use crate::spectrum::Rgb;
use std::f32::consts::{FRAC_PI_2, PI};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The tables of one RGL material, shared by every copy of the BSDF.
pub struct RglTables {
    path: PathBuf,
    description: String,
    ndf: Marginal2D<0>,
    sigma: Marginal2D<0>,
    vndf: Marginal2D<2>,
    luminance: Marginal2D<2>,
    rgb: Marginal2D<3>,
    isotropic: bool,
    jacobian: bool,
    /// Azimuthal symmetry of an anisotropic file: 2 (180°) or 4 (90°) fold; 0 or 1 otherwise.
    reduction: i32,
}

/// A measured RGL material.
#[derive(Clone)]
pub struct Measured {
    tables: Arc<RglTables>,
}

impl std::fmt::Debug for Measured {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Measured")
            .field("filename", &self.tables.path)
            .field("description", &self.tables.description)
            .field("isotropic", &self.tables.isotropic)
            .finish()
    }
}

impl PartialEq for Measured {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.tables, &other.tables) || self.tables.path == other.tables.path
    }
}

/// Where a pair of directions lands in the tables: everything `f` and `pdf` share.
struct Located {
    /// (φᵢ, θᵢ) of the (folded) viewer direction: the tables' conditioning parameters.
    params: [f32; 2],
    /// ωi (the viewer) and ωm in unit-square coordinates.
    u_wi: Vec2,
    u_m: Vec2,
    /// The folded viewer direction and the half vector.
    wo: Vec3,
    wm: Vec3,
    /// The point of the reflectance square that maps to ωm, and the VNDF density there.
    sample: Vec2,
    vndf_pdf: f32,
}

/// θ → u_θ = √(2θ/π) (Dupuy & Jakob 2018 §5.1: the square root spends resolution near the pole).
#[inline]
fn theta_to_u(theta: f32) -> f32 {
    (theta * (2.0 / PI)).sqrt()
}

#[inline]
fn u_to_theta(u: f32) -> f32 {
    u * u * FRAC_PI_2
}

#[inline]
fn phi_to_u(phi: f32) -> f32 {
    (phi + PI) * (0.5 / PI)
}

#[inline]
fn u_to_phi(u: f32) -> f32 {
    (2.0 * u - 1.0) * PI
}

/// The polar angle of a unit vector, accurate near the pole: 2 asin(|d − ẑ| / 2).
#[inline]
fn elevation(d: Vec3) -> f32 {
    let dist = (d.x * d.x + d.y * d.y + (d.z - 1.0) * (d.z - 1.0)).sqrt();
    2.0 * (0.5 * dist).clamp(-1.0, 1.0).asin()
}

/// `a` with its sign flipped when `b` has a positive sign bit (Dr.Jit's `mulsign_neg`).
#[inline]
fn mulsign_neg(a: f32, b: f32) -> f32 {
    if b.is_sign_positive() {
        -a
    } else {
        a
    }
}

impl Measured {
    /// Load the RGL file at `path`.
    pub fn load(path: &Path) -> Result<Measured> {
        Measured::from_file(TensorFile::open(path)?)
    }

    /// The material held by a parsed tensor file (checks every field as [`Measured::load`] does).
    pub fn from_file(file: TensorFile) -> Result<Measured> {
        Ok(Measured { tables: Arc::new(RglTables::from_file(file)?) })
    }

    pub fn from_props(p: &Props) -> Result<Self> {
        let filename = p.string("filename")?.ok_or_else(|| Error::spec(p.at(), "`measured` needs a `filename` (an RGL .bsdf file)"))?;
        Measured::load(Path::new(&filename))
    }

    /// The material's name as stored in the file.
    #[must_use]
    pub fn description(&self) -> &str {
        &self.tables.description
    }

    /// Whether the file is isotropic (φᵢ tabulated at ≤ 2 values).
    #[must_use]
    pub fn is_isotropic(&self) -> bool {
        self.tables.isotropic
    }

    /// Map both directions into the tables; `None` below the horizon or for non-finite input.
    fn locate(&self, wo: Vec3, wi: Vec3) -> Option<Located> {
        let t = &*self.tables;
        if !(wo.z > 0.0 && wi.z > 0.0 && wo.is_finite() && wi.is_finite()) {
            return None;
        }
        let (wo, wi) = t.fold(wo, wi);
        let wm = (wo + wi).normalize();
        let theta_i = elevation(wo);
        let phi_i = wo.y.atan2(wo.x);
        let theta_m = elevation(wm);
        let phi_m = wm.y.atan2(wm.x);
        let u_wi = Vec2::new(theta_to_u(theta_i), phi_to_u(phi_i));
        let mut u_m = Vec2::new(theta_to_u(theta_m), phi_to_u(if t.isotropic { phi_m - phi_i } else { phi_m }));
        u_m.y -= u_m.y.floor();
        if !u_m.is_finite() || !u_wi.is_finite() {
            return None;
        }
        let params = [phi_i, theta_i];
        let (sample, vndf_pdf) = t.vndf.invert(u_m, params);
        Some(Located { params, u_wi, u_m, wo, wm, sample, vndf_pdf })
    }

    /// f · cos θ(wi), Mitsuba's `eval` (before clamping negative channels).
    fn eval_cos(&self, q: &Located) -> [f32; 3] {
        let t = &*self.tables;
        let [phi_i, theta_i] = q.params;
        let mut rho = [0, 1, 2].map(|c| t.rgb.eval(q.sample, [phi_i, theta_i, c as f32]));
        if t.jacobian {
            // D(ωm) / (4 σ(ωi)): the microfacet factor of eq. 8.
            let scale = t.ndf.eval(q.u_m, []) / (4.0 * t.sigma.eval(q.u_wi, []));
            rho = rho.map(|v| v * scale);
        }
        rho
    }

    /// The sampling density of `wi` at a located pair (Mitsuba's `pdf`).
    fn pdf_located(&self, q: &Located) -> f32 {
        let t = &*self.tables;
        let lum = t.luminance.eval(q.sample, q.params);
        // dωm = 2π² u_θ sin θm du_θ du_φ, and dωi = 4 (ωo·ωm) dωm; floored as Mitsuba does (1e-6) so that
        // the pole, where the table's density in u vanishes with the Jacobian, gives 0 rather than NaN.
        // sin θm = |(x, y)| of the unit ωm: a float32 √(1 − z²) cancels near the pole (2026-11: it put the
        // pdf 1.6 % off at θm = 1.9e-3, enough to fail the chi-square test at the specular peak of glossy
        // files; this form is exact to a few ulps and agrees with Mitsuba 3.9.1 to 6e-5 there).
        let sin_theta_m = (q.wm.x * q.wm.x + q.wm.y * q.wm.y).sqrt();
        let jacobian = (2.0 * PI * PI * q.u_m.x * sin_theta_m).max(1e-6) * 4.0 * q.wo.dot(q.wm);
        let pdf = q.vndf_pdf * lum / jacobian;
        if pdf.is_finite() && pdf > 0.0 {
            pdf
        } else {
            0.0
        }
    }
}

impl RglTables {
    fn from_file(file: TensorFile) -> Result<RglTables> {
        if !file.has_field("rgb") && file.has_field("spectra") {
            return Err(file.error(
                "rgb",
                "this is a spectral RGL file (fields `spectra`, `wavelengths`); gonio reads the RGB variant of each material (`*_rgb.bsdf`)",
            ));
        }
        let description = String::from_utf8_lossy(file.u8_field("description", 1)?).trim_end_matches('\0').to_string();
        let theta_i = file.f32_field("theta_i", 1)?;
        let phi_i = file.f32_field("phi_i", 1)?;
        let ndf = file.f32_field("ndf", 2)?;
        let sigma = file.f32_field("sigma", 2)?;
        let vndf = file.f32_field("vndf", 4)?;
        let luminance = file.f32_field("luminance", 4)?;
        let rgb = file.f32_field("rgb", 5)?;
        let jacobian = file.u8_field("jacobian", 1)?;
        if jacobian.len() != 1 {
            return Err(file.error("jacobian", format!("expected a single u8 flag, found {} values", jacobian.len())));
        }
        let (n_phi, n_theta) = (phi_i.data.len(), theta_i.data.len());
        if n_phi == 0 || n_theta == 0 {
            return Err(file.error(if n_phi == 0 { "phi_i" } else { "theta_i" }, "no incident directions tabulated"));
        }
        let expect_shape = |name: &str, a: &F32Array, lead: &[usize]| -> Result<()> {
            let ok = a.shape.len() == lead.len() + 2 && a.shape[..lead.len()] == *lead && a.shape[lead.len()..].iter().all(|&n| n >= 2);
            if ok {
                Ok(())
            } else {
                let lead_text: Vec<String> = lead.iter().map(ToString::to_string).collect();
                Err(file.error(
                    name,
                    format!(
                        "expected shape [{}{}≥2, ≥2] (φᵢ × θᵢ = {n_phi} × {n_theta} incident directions), found {:?}",
                        lead_text.join(", "),
                        if lead.is_empty() { "" } else { ", " },
                        a.shape
                    ),
                ))
            }
        };
        expect_shape("ndf", &ndf, &[])?;
        expect_shape("sigma", &sigma, &[])?;
        expect_shape("vndf", &vndf, &[n_phi, n_theta])?;
        expect_shape("luminance", &luminance, &[n_phi, n_theta])?;
        expect_shape("rgb", &rgb, &[n_phi, n_theta, 3])?;
        if luminance.shape[2..] != rgb.shape[3..] {
            return Err(file.error(
                "rgb",
                format!("the reflectance grid {:?} must match the luminance grid {:?}", &rgb.shape[3..], &luminance.shape[2..]),
            ));
        }
        for (name, a) in [("ndf", &ndf), ("sigma", &sigma), ("vndf", &vndf), ("luminance", &luminance)] {
            if let Some(v) = a.data.iter().find(|v| **v < 0.0) {
                return Err(file.error(name, format!("holds a negative value ({v}); it is a density and must be ≥ 0")));
            }
        }
        if sigma.data.iter().any(|v| *v <= 0.0) {
            return Err(file.error("sigma", "the projected area σ must be positive everywhere (f divides by it)"));
        }
        for (name, a) in [("ndf", &ndf), ("vndf", &vndf), ("luminance", &luminance)] {
            if a.data.iter().all(|v| *v == 0.0) {
                return Err(file.error(name, "is zero everywhere: the material would be black"));
            }
        }
        if !rgb.data.iter().any(|v| *v > 0.0) {
            return Err(file.error("rgb", "has no positive value: the material would be black"));
        }
        let file = &file;
        let table_error = |name: &'static str| move |m: String| file.error(name, m);
        let grid = |a: &F32Array| {
            let r = a.shape.len();
            [a.shape[r - 1], a.shape[r - 2]]
        };
        let params2 = || [phi_i.data.clone(), theta_i.data.clone()];
        let ndf_t = Marginal2D::new(&ndf.data, grid(&ndf), [], false, false).map_err(table_error("ndf"))?;
        let sigma_t = Marginal2D::new(&sigma.data, grid(&sigma), [], false, false).map_err(table_error("sigma"))?;
        let vndf_t = Marginal2D::new(&vndf.data, grid(&vndf), params2(), true, true).map_err(table_error("vndf"))?;
        let lum_t = Marginal2D::new(&luminance.data, grid(&luminance), params2(), true, true).map_err(table_error("luminance"))?;
        let rgb_t = Marginal2D::new(&rgb.data, grid(&rgb), [phi_i.data.clone(), theta_i.data.clone(), vec![0.0, 1.0, 2.0]], false, false)
            .map_err(table_error("rgb"))?;
        let isotropic = n_phi <= 2;
        let reduction = if isotropic {
            0
        } else {
            let span = phi_i.data[n_phi - 1] - phi_i.data[0];
            let r = (2.0 * PI / span).round() as i32;
            if ![1, 2, 4].contains(&r) {
                return Err(file.error("phi_i", format!("spans {span} rad; expected 2π, π or π/2 (a full, half or quarter turn)")));
            }
            r
        };
        Ok(RglTables {
            path: file.path().to_path_buf(),
            description,
            ndf: ndf_t,
            sigma: sigma_t,
            vndf: vndf_t,
            luminance: lum_t,
            rgb: rgb_t,
            isotropic,
            jacobian: jacobian[0] != 0,
            reduction,
        })
    }

    /// The signs that fold the viewer direction into the measured azimuth range (anisotropic files with
    /// a 2- or 4-fold symmetry); `(-1, -1)` leaves directions unchanged.
    #[inline]
    fn fold_signs(&self, wo: Vec3) -> (f32, f32) {
        if self.reduction >= 2 {
            let sy = wo.y;
            let sx = if self.reduction == 4 { wo.x } else { sy };
            (sx, sy)
        } else {
            (-1.0, -1.0)
        }
    }

    #[inline]
    fn fold(&self, wo: Vec3, wi: Vec3) -> (Vec3, Vec3) {
        let (sx, sy) = self.fold_signs(wo);
        let f = |w: Vec3| Vec3::new(mulsign_neg(w.x, sx), mulsign_neg(w.y, sy), w.z);
        (f(wo), f(wi))
    }
}

impl crate::bsdf::Examples for Measured {
    /// None: every real file fails the reciprocity row (see `VIOLATIONS`).
    const EXAMPLES: &'static [&'static str] = &[];

    /// Measured data are not reciprocal: each incident direction is a separate measurement, fitted and
    /// converted to RGB on its own, so f(ωo, ωi) and f(ωi, ωo) come from different tables (the worst pairs,
    /// at grazing angles, differ by 100 %: one side is 0 where a clamped RGB channel meets a positive one).
    /// For `paper_white` and the glossy `cc_ibiza_sunset` every other row of the harness passes:
    /// chi-square, sample weights, energy and the NaN sweep. (Some files also gain energy at grazing view:
    /// `satin_rosaline`'s albedo reaches 1.155 at cos θo = 0.08, as measured; they are not listed.) The
    /// files are the project's test data (absolute paths; see `/work/shared/data/SOURCES.md`).
    const VIOLATIONS: &'static [(&'static str, &'static str)] = &[
        (r#"{"type": "measured", "filename": "/work/shared/data/rgl/paper_white_rgb.bsdf"}"#, "reciprocity"),
        (r#"{"type": "measured", "filename": "/work/shared/data/rgl/cc_ibiza_sunset_rgb.bsdf"}"#, "reciprocity"),
    ];
}

impl BsdfModel for Measured {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::GLOSSY_REFLECTION
    }

    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let Some(q) = self.locate(wo, wi) else { return Rgb::ZERO };
        let v = self.eval_cos(&q);
        let f = Rgb::new(v[0], v[1], v[2]).map(|c| c.max(0.0) / wi.z);
        if f.is_finite() {
            f
        } else {
            Rgb::ZERO
        }
    }

    fn sample(&self, wo: Vec3, _uc: f32, u: Vec2) -> Option<BsdfSample> {
        let t = &*self.tables;
        if !(wo.z > 0.0) || !wo.is_finite() {
            return None;
        }
        let (sx, sy) = t.fold_signs(wo);
        let wo_f = Vec3::new(mulsign_neg(wo.x, sx), mulsign_neg(wo.y, sy), wo.z);
        let theta_i = elevation(wo_f);
        let phi_i = wo_f.y.atan2(wo_f.x);
        let params = [phi_i, theta_i];
        // The luminance warp first (the reflectance square), then the VNDF warp to ωm (§5.2).
        let (s, _) = t.luminance.sample(Vec2::new(u.y, u.x), params);
        let (u_m, _) = t.vndf.sample(s, params);
        let theta_m = u_to_theta(u_m.x);
        let phi_m = u_to_phi(u_m.y) + if t.isotropic { phi_i } else { 0.0 };
        let (sin_theta_m, cos_theta_m) = theta_m.sin_cos();
        let (sin_phi_m, cos_phi_m) = phi_m.sin_cos();
        let wm = Vec3::new(cos_phi_m * sin_theta_m, sin_phi_m * sin_theta_m, cos_theta_m);
        let wi_f = wm * (2.0 * wm.dot(wo_f)) - wo_f;
        let wi = Vec3::new(mulsign_neg(wi_f.x, sx), mulsign_neg(wi_f.y, sy), wi_f.z).normalize();
        if !(wi.z > 0.0) {
            return None;
        }
        // f and pdf of the returned direction through the inverse warp, as `f` and `pdf` compute them.
        let q = self.locate(wo, wi)?;
        let v = self.eval_cos(&q);
        let f = Rgb::new(v[0], v[1], v[2]).map(|c| c.max(0.0) / wi.z);
        if !f.is_finite() {
            return None;
        }
        BsdfSample::smooth(wi, f, self.pdf_located(&q), BsdfFlags::GLOSSY_REFLECTION, 1.0)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.locate(wo, wi).map_or(0.0, |q| self.pdf_located(&q))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;
    use crate::verify::chi2::{chi2_bsdf, Chi2Config};
    use crate::verify::energy::direction;

    const DATA: &str = "/work/shared/data/rgl";

    fn load(name: &str) -> Measured {
        let path = Path::new(DATA).join(name);
        Measured::load(&path).unwrap_or_else(|e| panic!("the shared RGL data must be present: {e}"))
    }

    #[test]
    fn reads_the_real_files() {
        let m = load("cg_sunflower_rgb.bsdf");
        assert!(m.is_isotropic());
        assert!(m.description().contains("Sunflower"), "{}", m.description());
        // Mitsuba 3.9.1 scalar_rgb, eval(si.wi = wo, wo = wi) and pdf, recorded by hand. The first pair's
        // blue channel is negative in the table: gonio clamps it to 0.
        let wo = Vec3::new(0.3, 0.1, 0.948_683_3);
        let cases = [
            (Vec3::new(-0.5, 0.2, 0.842_614_97), [0.225_727f32, 0.106_305, 0.0], 0.265_320_9f32),
            (Vec3::new(-0.25, -0.1, 0.963_068), [0.321_207, 0.175_305, 0.038_606_7], 0.422_338_1),
        ];
        for (wi, want, pdf) in cases {
            let got = m.f(wo, wi) * wi.z;
            for (g, w) in got.0.iter().zip(want) {
                assert!((g - w).abs() <= 1e-4 * w.max(1e-3), "{got:?} vs {want:?}");
            }
            assert!((m.pdf(wo, wi) - pdf).abs() < 1e-4 * pdf);
        }
    }

    fn chi2_files(names: &[&str], cosines: &[f32]) {
        let cfg = Chi2Config { samples: 1_000_000, tests: names.len() * cosines.len(), ..Chi2Config::default() };
        for name in names {
            let m = load(name);
            for &mu in cosines {
                let wo = direction(mu, 0.3);
                let r = chi2_bsdf(&m, wo, &cfg);
                eprintln!("{name} cosθo={mu:.2}: p = {:.3e} (α = {:.1e})", r.p_value, r.alpha);
                assert!(r.passed, "{name} at {wo}: {}", r.message);
            }
        }
    }

    /// Sampling draws what `pdf` says: the 64² file at 70° (the glossy cc_ibiza_sunset and paper_white run
    /// through the whole harness in `gonio check --all`, as expected reciprocity violations).
    #[test]
    fn chi2_fine_file() {
        chi2_files(&["cg_sunflower_rgb.bsdf"], &[0.35]);
    }

    /// Every file at two directions (7 × 2 tests of 10⁶ samples; minutes, so run by hand:
    /// `cargo test --release -p gonio chi2_of_every_file -- --ignored`).
    #[test]
    #[ignore]
    fn chi2_of_every_file() {
        let Ok(dir) = std::fs::read_dir(DATA) else { return };
        let mut names: Vec<String> = dir.filter_map(|e| e.ok()?.file_name().into_string().ok()).filter(|n| n.ends_with(".bsdf")).collect();
        names.sort();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        chi2_files(&names, &[0.9, 0.35]);
    }

    #[test]
    fn sample_f_and_pdf_agree() {
        let m = load("satin_rosaline_rgb.bsdf");
        let mut rng = Pcg32::new(5, 1);
        let mut n = 0;
        for _ in 0..20_000 {
            let wo = direction(rng.next_f32().max(0.02), rng.next_f32() * std::f32::consts::TAU);
            let Some(s) = m.sample(wo, 0.5, rng.next_vec2()) else { continue };
            n += 1;
            assert!(s.wi.z > 0.0 && s.pdf > 0.0 && s.weight.is_finite());
            assert_eq!(s.pdf, m.pdf(wo, s.wi));
            assert_eq!(s.f, m.f(wo, s.wi));
        }
        assert!(n > 19_000, "{n} samples of 20000");
    }

    #[test]
    fn below_the_horizon_is_black() {
        let m = load("paper_white_rgb.bsdf");
        let (up, down) = (Vec3::new(0.0, 0.6, 0.8), Vec3::new(0.0, 0.6, -0.8));
        assert!(m.f(up, down).is_black() && m.f(down, up).is_black());
        assert_eq!(m.pdf(down, up), 0.0);
        assert!(m.sample(down, 0.5, Vec2::new(0.3, 0.3)).is_none());
        assert!(m.f(up, up).g() > 0.0);
    }

    #[test]
    fn bad_spec_errors() {
        let e = Measured::from_props(&Props::from_json(r#"{"type": "measured"}"#).unwrap()).unwrap_err().to_string();
        assert!(e.contains("needs a `filename`"), "{e}");
        let e = Measured::load(Path::new("/nonexistent/x.bsdf")).unwrap_err().to_string();
        assert!(e.contains("/nonexistent/x.bsdf"), "{e}");
    }
}
