//! `normalmap` — a nested model seen in a shading frame turned to a normal read from a texture (Mitsuba 3's
//! `normalmap`): normal mapping, detail without geometry. Also Mitsuba's `bumpmap` (parameters `scale`,
//! default 1, and one height texture): the same model, whose normal a scene's material computes at each
//! hit from the height field's gradient and the surface's ∂p/∂u, ∂p/∂v (`scene::material::bump_normal`);
//! without a surface (e.g. `gonio check`) a bump map leaves the shading normal as it is.
//!
//! | parameter                | type          | default   | meaning                                        |
//! |--------------------------|---------------|-----------|------------------------------------------------|
//! | `normalmap`              | rgb (texture) | (½, ½, 1) | the normal in the shading frame, each component x ↦ (x + 1)/2 (a `bitmap` with `raw` = true) |
//! | `flip_invalid_normals`   | boolean       | true      | turn a normal that faces away from ωo towards it |
//! | `use_shadowing_function` | boolean       | true      | attenuate by the bump-terminator shadowing term |
//! | (nested)                 | bsdf          | —         | the model the normal map turns                 |
//!
//! With n = 2c − 1 from the texture's colour c, as Mitsuba 3.9.1 builds the perturbed frame
//! (`src/bsdfs/perturbed_bsdf.h`):
//! - where ωo lies on the other side of n than of the shading normal (cos θo · (ωo · n) ≤ 0) and
//!   `flip_invalid_normals` is set, n is mirrored about the shading normal, (−nx, −ny, nz) (Schüssler et
//!   al. 2017 keep the shading normal on the side of the incident direction);
//! - n′ = n/|n| (+z where that is not finite); the frame F′ has n′, s′ = x̂ − n′x n′ normalised (ŷ where
//!   that fails), t′ = n′ × s′;
//! - the nested model sees ωo′ = F′ωo and ωi′ = F′ωi; where ωi lies on opposite sides of the two frames
//!   (cos θi · cos θi′ ≤ 0) nothing scatters;
//! - with `use_shadowing_function`, the value and a sample's weight are multiplied by the shadowing term of
//!   Estévez et al. 2019 ("A Microfacet-Based Shadowing Function to Solve the Bump Terminator Problem",
//!   Ray Tracing Gems ch. 12): G = 2 / (1 + √(1 + α² tan² θi)) with α² = min(tan² θn′ / 8, 1), θi the
//!   angle of ωi to the shading normal, θn′ that of n′.
//!
//! gonio's f excludes the cosine, which the integrator takes in the shading frame, so
//! f = f_nested(ωo′, ωi′) |cos θi′| / |cos θi| · G (Mitsuba's `eval` returns f_nested |cos θi′| G); the
//! density is the nested model's. Not reciprocal (a shading normal is not): its perturbed examples are
//! kept as `reciprocity` violations. `tests::matches_mitsuba` compares f·|cos θi| and pdf with Mitsuba 3.9.1's
//! (`tools/normalmap_reference.py`). One difference: a colour that encodes no direction (½, ½, ½) keeps the
//! shading normal in gonio; Mitsuba's value is 0 there.
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::Vec3;
//! let flat = Bsdf::from_json(r#"{"type": "normalmap", "normalmap": [0.5, 0.5, 1], "b": {"type": "diffuse", "reflectance": 0.5}}"#).unwrap();
//! let (wo, wi) = (Vec3::new(0.0, 0.6, 0.8), Vec3::new(0.48, 0.0, 0.877_496_4));
//! assert!((flat.f(wo, wi).r() - 0.5 / std::f32::consts::PI).abs() < 1e-6); // (½, ½, 1) is the normal +z
//! ```

use super::lanes::{f_one, pdf_one, sample_one, LaneSample};
use super::{Bsdf, BsdfFlags, BsdfModel, BsdfSample};
use crate::error::{Error, Result};
use crate::math::lanes::{channels, Real, V3};
use crate::math::{Frame, Vec2, Vec3};
use crate::props::Props;
use crate::spectrum::Rgb;

/// A nested model in the frame of a mapped normal.
#[derive(Clone, Debug, PartialEq)]
pub struct NormalMap {
    /// The texture's colour c (the normal is 2c − 1).
    pub normalmap: Rgb,
    flip_invalid_normals: bool,
    use_shadowing_function: bool,
    nested: Box<Bsdf>,
}

impl NormalMap {
    /// The model it perturbs.
    pub(crate) fn nested_mut(&mut self) -> &mut Bsdf {
        &mut self.nested
    }

    /// Mitsuba's defaults: invalid normals flipped, the shadowing term applied.
    #[must_use]
    pub fn new(normalmap: Rgb, nested: Bsdf) -> Self {
        NormalMap { normalmap, flip_invalid_normals: true, use_shadowing_function: true, nested: Box::new(nested) }
    }

    /// A `normalmap`, or a `bumpmap`: the same model, whose `normalmap` colour the scene's material sets
    /// from the height texture at each hit (`scene::material::bump_normal`; the texture and its `scale`
    /// are the material's).
    pub fn from_props(p: &Props) -> Result<Self> {
        if p.plugin_type() == "bumpmap" {
            p.float_in("scale", 1.0, f32::MIN, f32::MAX)?;
        }
        let normalmap = p.rgb_in("normalmap", Rgb::new(0.5, 0.5, 1.0), f32::MIN, f32::MAX)?;
        let flip_invalid_normals = p.bool("flip_invalid_normals", true)?;
        let use_shadowing_function = p.bool("use_shadowing_function", true)?;
        let nested = p.nested();
        match nested.as_slice() {
            [one] => Ok(NormalMap { flip_invalid_normals, use_shadowing_function, ..NormalMap::new(normalmap, Bsdf::from_props(one)?) }),
            _ => Err(Error::spec(p.at(), format!("`{}` needs exactly one nested BSDF, got {}", p.plugin_type(), nested.len()))),
        }
    }

    /// The mapped normal n = 2c − 1, unnormalised.
    fn normal(&self) -> Vec3 {
        let [r, g, b] = self.normalmap.0;
        Vec3::new(2.0 * r - 1.0, 2.0 * g - 1.0, 2.0 * b - 1.0)
    }

    /// The frame F′ around the normal `n` (unnormalised), in the shading frame (module docs).
    fn frame_of(n: Vec3) -> Frame {
        let n = n.try_normalize().unwrap_or(Vec3::Z);
        let s = (Vec3::X - n * n.x).try_normalize().unwrap_or(Vec3::Y);
        Frame { s, t: n.cross(s), n }
    }

    /// The frame F′ of the mapped normal as it is (before any flip towards ωo).
    #[must_use]
    pub fn frame(&self) -> Frame {
        Self::frame_of(self.normal())
    }

    /// The two frames a lane may see — the mapped normal's, and the one flipped towards ωo — and which
    /// lanes of `wo` see the flipped one (module docs).
    #[inline(always)]
    fn frames<R: Real>(&self, wo: V3<R>) -> (Frame, Frame, R::Mask) {
        let n = self.normal();
        let flipped = Vec3::new(-n.x, -n.y, n.z);
        let invalid = (wo.z * wo.dot(V3::splat(n))).le(R::splat(0.0));
        let flip = if self.flip_invalid_normals { invalid } else { invalid & !invalid };
        (Self::frame_of(n), Self::frame_of(flipped), flip)
    }

    /// The shadowing term G for the light direction cosines `cos_i` (module docs; 1 without
    /// `use_shadowing_function`). Both frames of [`Self::frames`] have the same tan² θn′.
    #[inline(always)]
    fn shadowing<R: Real>(&self, frame: &Frame, cos_i: R) -> R {
        let one = R::splat(1.0);
        if !self.use_shadowing_function {
            return one;
        }
        let n = frame.n;
        let alpha2 = ((1.0 - n.z * n.z).max(0.0) / (n.z * n.z) * 0.125).min(1.0);
        let cos2 = cos_i * cos_i;
        let tan2 = (one - cos2).max(R::splat(0.0)) / cos2;
        let g = R::splat(2.0) / (one + (one + R::splat(alpha2) * tan2).sqrt());
        R::select(g.is_finite(), g, R::splat(0.0))
    }

    /// Itself: its lane code runs every configuration (the batch methods' `lane_batch_methods!`).
    #[inline(always)]
    fn lanes(&self) -> Option<&Self> {
        Some(self)
    }
}

/// Each lane's frame axes (s, t, n): `a`'s where `pick` is false, `b`'s where it is true.
#[inline(always)]
fn lane_axes<R: Real>(a: &Frame, b: &Frame, pick: R::Mask) -> [V3<R>; 3] {
    [(a.s, b.s), (a.t, b.t), (a.n, b.n)].map(|(x, y)| V3::select(pick, V3::splat(y), V3::splat(x)))
}

/// `v` in the frame of each lane ([`lane_axes`]).
#[inline(always)]
fn to_frame<R: Real>(a: &Frame, b: &Frame, pick: R::Mask, v: V3<R>) -> V3<R> {
    let [s, t, n] = lane_axes(a, b, pick);
    V3::new(v.dot(s), v.dot(t), v.dot(n))
}

/// `v`, given in the frame of each lane ([`lane_axes`]), in the shading frame.
#[inline(always)]
fn from_frame<R: Real>(a: &Frame, b: &Frame, pick: R::Mask, v: V3<R>) -> V3<R> {
    let [s, t, n] = lane_axes(a, b, pick);
    s.scale(v.x).add(t.scale(v.y)).add(n.scale(v.z))
}

/// |cos θi′| / |cos θi| where ωi is on the same side of both frames, else 0 (nothing scatters there).
#[inline(always)]
fn cosine_ratio<R: Real>(cos: R, cos_mapped: R) -> R {
    let zero = R::splat(0.0);
    R::select((cos * cos_mapped).gt(zero), cos_mapped.abs() / cos.abs(), zero)
}

/// The nested f times the cosine ratio; 0 where that overflows (ωi within ~10⁻³⁸ of the horizon, where
/// f · cos θi, what counts, is bounded).
#[inline(always)]
fn scaled<R: Real>(f: [R; 3], ratio: R) -> [R; 3] {
    channels!(|c| {
        let v = f[c] * ratio;
        R::select(v.is_finite(), v, R::splat(0.0))
    })
}

impl NormalMap {
    /// [`Bsdf::f_lanes_where`] of `normalmap`: the nested f in the mapped frame times the cosine ratio and
    /// the shadowing term.
    #[inline(always)]
    pub(crate) fn f_lanes_where<R: Real>(&self, wo: V3<R>, wi: V3<R>, active: R::Mask) -> [R; 3] {
        let (a, b, flip) = self.frames(wo);
        let mapped = to_frame(&a, &b, flip, wi);
        let ratio = cosine_ratio(wi.z, mapped.z) * self.shadowing(&a, wi.z);
        scaled(self.nested.leaf_f(to_frame(&a, &b, flip, wo), mapped, active & ratio.gt(R::splat(0.0))), ratio)
    }

    /// [`Bsdf::pdf_lanes_where`] of `normalmap`: the nested density (solid angle does not depend on the
    /// frame), 0 where ωi is on opposite sides of the two frames.
    #[inline(always)]
    pub(crate) fn pdf_lanes_where<R: Real>(&self, wo: V3<R>, wi: V3<R>, active: R::Mask) -> R {
        let (a, b, flip) = self.frames(wo);
        let mapped = to_frame(&a, &b, flip, wi);
        let kept = (wi.z * mapped.z).gt(R::splat(0.0));
        R::select(kept, self.nested.leaf_pdf(to_frame(&a, &b, flip, wo), mapped, active & kept), R::splat(0.0))
    }

    /// [`Bsdf::sample_lanes_where`] of `normalmap`: the nested model's sample in the mapped frame, turned
    /// back; its density as it is, its weight times the shadowing term, f times the cosine ratio and the
    /// shadowing term (as [`Self::f_lanes_where`] computes them); none where ωi lands on opposite sides of
    /// the two frames.
    #[inline(always)]
    pub(crate) fn sample_lanes_where<R: Real>(&self, wo: V3<R>, uc: R, ux: R, uy: R, active: R::Mask) -> LaneSample<R> {
        let (a, b, flip) = self.frames(wo);
        let s = self.nested.leaf_sample(to_frame(&a, &b, flip, wo), uc, ux, uy, active);
        let wi = from_frame(&a, &b, flip, s.wi);
        let g = self.shadowing(&a, wi.z);
        // cos θi′ as `f` computes it from ωi (the nested model's own cos θi′ differs in the last bits, which
        // matters where it is tiny), and the weight rescaled to it.
        let mapped = to_frame(&a, &b, flip, wi).z;
        let ratio = cosine_ratio(wi.z, mapped);
        let rescaled = R::select((mapped * s.wi.z).gt(R::splat(0.0)), g * mapped.abs() / s.wi.z.abs(), R::splat(0.0));
        let valid = s.valid & (ratio * g).gt(R::splat(0.0));
        LaneSample { wi, f: scaled(s.f, ratio * g), weight: scaled(s.weight, rescaled), valid, ..s }
    }
}

lane_model_where!(NormalMap);

impl crate::bsdf::Examples for NormalMap {
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "normalmap", "b": {"type": "diffuse"}}"#,
        r#"{"type": "normalmap", "normalmap": [0.5, 0.5, 1], "b": {"type": "roughconductor", "alpha": 0.3}}"#,
    ];
    /// A turned normal makes f(ωo, ωi) ≠ f(ωi, ωo): the cosine ratio differs (module docs).
    const VIOLATIONS: &'static [(&'static str, &'static str)] = &[
        (r#"{"type": "normalmap", "normalmap": [0.7, 0.4, 0.9], "b": {"type": "diffuse", "reflectance": 0.8}}"#, "reciprocity"),
        (r#"{"type": "normalmap", "normalmap": [0.3, 0.6, 0.95], "b": {"type": "roughplastic", "alpha": 0.2}}"#, "reciprocity"),
    ];
}

impl BsdfModel for NormalMap {
    fn flags(&self) -> BsdfFlags {
        self.nested.flags()
    }

    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        f_one(self, wo, wi)
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        sample_one(self, wo, uc, u)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        pdf_one(self, wo, wi)
    }

    lane_batch_methods!(lanes);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Examples;
    use crate::verify::{check, expect_violation, CheckConfig};

    #[test]
    fn examples_pass_every_check_and_turned_normals_break_only_reciprocity() {
        for spec in NormalMap::EXAMPLES {
            let report = check(&Bsdf::from_json(spec).unwrap(), &CheckConfig::quick());
            assert!(report.passed(), "{spec}\n{}", report.to_table());
        }
        for (spec, kind) in NormalMap::VIOLATIONS {
            let report = check(&Bsdf::from_json(spec).unwrap(), &CheckConfig::quick());
            expect_violation(&report, kind).unwrap_or_else(|e| panic!("{spec}: {e}"));
        }
    }

    /// G of the module docs for a unit normal `n` and the light cosine `cos_i`, in f64.
    fn shadowing(n: Vec3, cos_i: f32) -> f32 {
        let (nz, c) = (f64::from(n.z), f64::from(cos_i));
        let alpha2 = ((1.0 - nz * nz) / (nz * nz) / 8.0).min(1.0);
        (2.0 / (1.0 + (1.0 + alpha2 * (1.0 - c * c) / (c * c)).sqrt())) as f32
    }

    /// A diffuse model under a turned normal: f = ρ/π |cos θi′| / |cos θi| · G on the side both frames
    /// share, 0 beyond; samples come back in the shading frame with the nested weight times G.
    #[test]
    fn a_turned_normal_is_seen_by_the_nested_model() {
        let m = NormalMap::new(Rgb::new(0.8, 0.5, 0.9), Bsdf::from_json(r#"{"type": "diffuse", "reflectance": 0.6}"#).unwrap());
        let n = Vec3::new(0.6, 0.0, 0.8).normalize();
        assert!((m.frame().n - n).length() < 1e-6);
        let wo = Vec3::new(0.0, 0.6, 0.8);
        for wi in [Vec3::new(0.48, 0.0, 0.877_496_4), Vec3::new(-0.9, 0.1, 0.424_264)] {
            let wi = wi.normalize();
            let cos_mapped = wi.dot(n);
            let want = if cos_mapped > 0.0 { 0.6 / std::f32::consts::PI * cos_mapped / wi.z * shadowing(n, wi.z) } else { 0.0 };
            assert!((m.f(wo, wi).r() - want).abs() < 1e-6, "{wi}: {} against {want}", m.f(wo, wi).r());
        }
        let s = m.sample(wo, 0.5, Vec2::new(0.3, 0.7)).unwrap();
        assert!(s.wi.z > 0.0 && s.wi.dot(n) > 0.0 && (s.weight.r() - 0.6 * shadowing(n, s.wi.z)).abs() < 1e-5);
        assert!((s.pdf - m.pdf(wo, s.wi)).abs() < 1e-5 && (s.pdf - s.wi.dot(n) / std::f32::consts::PI).abs() < 1e-5);
    }

    /// A normal that faces away from ωo is mirrored about the shading normal (`flip_invalid_normals`), or
    /// kept, and then nothing reaches the side of ωo that it turns away from.
    #[test]
    fn normals_facing_away_from_wo_are_flipped() {
        let diffuse = Bsdf::from_json(r#"{"type": "diffuse", "reflectance": 0.5}"#).unwrap();
        let m = NormalMap::new(Rgb::new(0.8, 0.5, 0.9), diffuse);
        let wo = Vec3::new(-0.95, 0.0, 0.1).normalize(); // ωo · n < 0 for n = (0.6, 0, 0.8)
        let flipped = Vec3::new(-0.6, 0.0, 0.8);
        let wi = Vec3::new(-0.6, 0.0, 0.8);
        let want = 0.5 / std::f32::consts::PI / wi.z * shadowing(flipped, wi.z);
        assert!((m.f(wo, wi).r() - want).abs() < 1e-6, "{} against {want}", m.f(wo, wi).r());
        // Kept, the normal puts ωo below the nested model's horizon: nothing scatters.
        let kept = NormalMap { flip_invalid_normals: false, ..m.clone() };
        assert_eq!(kept.f(wo, wi), Rgb::ZERO);
        assert!(kept.sample(wo, 0.5, Vec2::new(0.3, 0.7)).is_none());
    }

    /// f·|cos θi| and pdf against Mitsuba 3.9.1's `eval` and `pdf` of `normalmap` (constant colours, three
    /// nested models among them an anisotropic one, both flags on and off; `tools/normalmap_reference.py`):
    /// within 2e-4 relative (floor 1e-5 of a case's largest value). GGX, not Beckmann, as the nested
    /// microfacet model: Mitsuba's Beckmann uses a rational approximation of its shadowing (0.3 % apart).
    #[test]
    fn matches_mitsuba() {
        let data: serde_json::Value = serde_json::from_str(include_str!("../../tests/data/normalmap_mitsuba.json")).unwrap();
        let mut worst = (0.0f64, String::new());
        for case in data["cases"].as_array().unwrap() {
            let nested =
                Bsdf::from_props(&Props::from_json_value(&data["nested"][case["nested"].as_str().unwrap()], "test").unwrap()).unwrap();
            let c: Vec<f32> = case["normalmap"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap() as f32).collect();
            let m = NormalMap {
                flip_invalid_normals: case["flip_invalid_normals"].as_bool().unwrap(),
                use_shadowing_function: case["use_shadowing_function"].as_bool().unwrap(),
                ..NormalMap::new(Rgb::new(c[0], c[1], c[2]), nested)
            };
            let rows: Vec<Vec<f32>> = case["rows"]
                .as_array()
                .unwrap()
                .iter()
                .map(|r| r.as_array().unwrap().iter().map(|x| x.as_f64().unwrap() as f32).collect())
                .collect();
            let scale = rows.iter().flat_map(|v| v[6..].iter().map(|x| f64::from(x.abs()))).fold(0.0, f64::max);
            for v in &rows {
                let (wo, wi) = (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]));
                let ours = m.f(wo, wi) * wi.z.abs();
                for (g, want) in [(ours.r(), v[6]), (ours.g(), v[7]), (ours.b(), v[8]), (m.pdf(wo, wi), v[9])] {
                    let err = (f64::from(g) - f64::from(want)).abs() / f64::from(want.abs()).max(1e-5 * scale);
                    if err > worst.0 {
                        worst = (err, format!("{c:?} over {} at {wo} {wi}: {g} against {want}", case["nested"]));
                    }
                }
            }
        }
        assert!(worst.0 < 2e-4, "worst {:.2e}: {}", worst.0, worst.1);
    }
}
