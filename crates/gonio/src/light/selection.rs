//! Which light next-event estimation samples: each light chosen with a probability that follows an estimate
//! of the irradiance it brings to the shading point, mixed with the uniform choice.
//!
//! Mitsuba 3's `path` integrator chooses among the emitters uniformly (`Scene::sample_emitter`, weighted by
//! each emitter's `sampling_weight`, 1 by default): a scene lit by a bright point light and a dim sky spends
//! half its light samples on the sky, and the point light's contribution is a coin toss per sample. gonio
//! weighs each light by its unoccluded irradiance on a surface facing it, estimated at the shading point x
//! (pbrt-v4's `ExhaustiveLightSampler`, §12.6.3, with these simpler bounds; Conty Estevez & Kulla 2018,
//! "Importance Sampling of Many Lights with Adaptive Tree Splitting", for the idea):
//!
//! | light         | importance at x (luminance of the light's colour)                                    |
//! |---------------|--------------------------------------------------------------------------------------|
//! | `point`       | I / d²                                                                               |
//! | `spot`        | I · falloff(x) / d² (0 outside the cone, where the light brings nothing)              |
//! | `directional` | E                                                                                    |
//! | `constant`    | π L                                                                                  |
//! | `envmap`      | π L̄, L̄ the map's mean radiance over the sphere                                       |
//! | `area`        | L · max(A/4, a·ŵ) / (d² + A/4): a the shape's vector area (Σ of its triangles' n dA), ŵ the unit direction from its centre to x; A/4 is the mean projected area of a convex shape (Cauchy), the exact far field of a sphere, a·ŵ that of a flat emitter facing x |
//!
//! (d the distance from the light's position, or its bounding box's centre, to x.) Occlusion, the BSDF and
//! the surface's orientation are not known to the estimate, so a share [`UNIFORM_SHARE`] of the choice stays
//! uniform: no light is sampled less than that share of Mitsuba's rate (a light the estimate misjudges costs
//! at most 1/[`UNIFORM_SHARE`] of its samples), and the estimator stays unbiased wherever a light can
//! contribute. With more than [`MAX_LIGHTS`] lights the choice is uniform (Mitsuba's), not to spend O(n)
//! per sample.

use super::Light;
use crate::geometry::Shape;
use glam::Vec3;
use std::f32::consts::PI;

/// The share of the choice that stays uniform.
pub const UNIFORM_SHARE: f32 = 0.2;

/// Above this many lights the choice is uniform.
pub const MAX_LIGHTS: usize = 16;

/// How a light's importance at a point is estimated (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Estimate {
    /// The same everywhere (directional, constant, envmap).
    Distant(f32),
    /// I / d² at a point light's position, times the spot's falloff for a spot (its index into the lights).
    Point { position: Vec3, intensity: f32, spot: Option<usize> },
    /// An emitting shape: radiance, centre, A/4 and its vector area.
    Area { radiance: f32, center: Vec3, quarter_area: f32, vector_area: Vec3 },
}

/// The light choice of a scene (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct LightSelection {
    estimates: Vec<Estimate>,
}

impl LightSelection {
    /// The choice among `lights` (area lights on `shapes`).
    #[must_use]
    pub fn new(lights: &[Light], shapes: &[Shape]) -> Self {
        if lights.len() > MAX_LIGHTS || lights.len() < 2 {
            return LightSelection { estimates: Vec::new() };
        }
        let estimates = lights
            .iter()
            .enumerate()
            .map(|(index, light)| match light {
                Light::Point(p) => Estimate::Point { position: p.position, intensity: p.intensity.luminance(), spot: None },
                Light::Spot(s) => Estimate::Point { position: s.position, intensity: s.intensity.luminance(), spot: Some(index) },
                Light::Directional(d) => Estimate::Distant(d.irradiance.luminance()),
                Light::Constant(c) => Estimate::Distant(PI * c.radiance.luminance()),
                Light::EnvMap(e) => Estimate::Distant(PI * e.mean_luminance()),
                Light::Area(a) => {
                    let shape = &shapes[a.shape as usize];
                    let center = (0..shape.primitive_count() as u32)
                        .fold(crate::geometry::bounds::Bounds3::EMPTY, |b, p| b.union(shape.primitive_bounds(p)))
                        .centroid();
                    Estimate::Area {
                        radiance: a.radiance.luminance(),
                        center,
                        quarter_area: 0.25 * shape.area(),
                        vector_area: vector_area(shape),
                    }
                }
            })
            .collect();
        LightSelection { estimates }
    }

    /// Whether the choice is uniform (one light, or more than [`MAX_LIGHTS`]).
    #[must_use]
    pub fn is_uniform(&self) -> bool {
        self.estimates.is_empty()
    }

    /// The estimated importance of light `index` at `x` (module docs), ≥ 0 and finite.
    fn importance(&self, lights: &[Light], index: usize, x: Vec3) -> f32 {
        let value = match self.estimates[index] {
            Estimate::Distant(e) => e,
            Estimate::Point { position, intensity, spot } => {
                let falloff = match spot.map(|s| &lights[s]) {
                    Some(Light::Spot(s)) => s.falloff_at(x),
                    _ => 1.0,
                };
                intensity * falloff / (x - position).length_squared()
            }
            Estimate::Area { radiance, center, quarter_area, vector_area } => {
                let d = x - center;
                let d2 = d.length_squared();
                let facing = if d2 > 0.0 { vector_area.dot(d) / d2.sqrt() } else { 0.0 };
                radiance * quarter_area.max(facing) / (d2 + quarter_area)
            }
        };
        if value.is_finite() && value > 0.0 {
            value
        } else if value.is_infinite() {
            f32::MAX / (MAX_LIGHTS as f32 * 2.0)
        } else {
            0.0
        }
    }

    /// Choose one of the `lights` (the scene's, which this choice was made for) for the shading point `x` with
    /// the uniform number `u`: its index and the probability of having chosen it.
    #[must_use]
    pub fn sample(&self, lights: &[Light], x: Vec3, u: f32) -> (usize, f32) {
        let n = lights.len();
        if self.is_uniform() {
            // `(u · n) as usize`, at most n − 1.
            return (((u * n as f32) as usize).min(n - 1), 1.0 / n as f32);
        }
        let mut weights = [0.0f32; MAX_LIGHTS];
        let total = self.weights(lights, x, &mut weights);
        let target = u * total;
        let mut sum = 0.0;
        for (i, w) in weights[..n].iter().enumerate() {
            sum += w;
            if target < sum {
                return (i, w / total);
            }
        }
        // Rounding in the sum: the last light with a positive weight.
        let last = weights[..n].iter().rposition(|w| *w > 0.0).unwrap_or(n - 1);
        (last, weights[last] / total)
    }

    /// The probability that [`Self::sample`] chooses light `index` for the shading point `x`.
    #[must_use]
    pub fn pmf(&self, lights: &[Light], x: Vec3, index: usize) -> f32 {
        if self.is_uniform() {
            return 1.0 / lights.len() as f32;
        }
        let mut weights = [0.0f32; MAX_LIGHTS];
        let total = self.weights(lights, x, &mut weights);
        weights[index] / total
    }

    /// Each light's weight at `x` (into `weights`), (1 − s) imp/Σimp + s/n with s = [`UNIFORM_SHARE`] (all
    /// uniform where every importance is 0), and their sum (1 up to rounding).
    fn weights(&self, lights: &[Light], x: Vec3, weights: &mut [f32; MAX_LIGHTS]) -> f32 {
        let n = self.estimates.len();
        let mut sum = 0.0f32;
        for (i, w) in weights[..n].iter_mut().enumerate() {
            *w = self.importance(lights, i, x);
            sum += *w;
        }
        let uniform = 1.0 / n as f32;
        let (share, scale) = if sum > 0.0 && sum.is_finite() { (UNIFORM_SHARE, (1.0 - UNIFORM_SHARE) / sum) } else { (1.0, 0.0) };
        let mut total = 0.0;
        for w in &mut weights[..n] {
            *w = *w * scale + share * uniform;
            total += *w;
        }
        total
    }
}

/// The vector area ∫ n dA of an emitting shape: its area times its normal for a disk or a flat mesh, 0 for
/// a sphere, a cylinder or a closed mesh (Mitsuba's meshes emit on the side of their triangles' normal,
/// p₁ − p₀ × p₂ − p₀).
fn vector_area(shape: &Shape) -> Vec3 {
    match shape {
        // An open cylinder's normals cancel round its circumference.
        Shape::Sphere(_) | Shape::Cylinder(_) => Vec3::ZERO,
        Shape::Disk(d) => d.normal() * d.area(),
        Shape::Mesh(m) => (0..m.triangle_count() as u32).fold(Vec3::ZERO, |a, t| {
            let [_, e1, e2] = m.triangle_edges(t);
            a + 0.5 * e1.cross(e2)
        }),
    }
}
