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
use crate::math::lanes::Real;
use crate::math::simd::Float8;
use glam::Vec3;
use std::f32::consts::PI;

/// The share of the choice that stays uniform.
pub const UNIFORM_SHARE: f32 = 0.2;

/// Above this many lights the choice is uniform.
pub const MAX_LIGHTS: usize = 16;

/// The lights' estimates in one form, importance = L · max(m, a·ŵ) / (k d² + q), d the distance from the
/// centre c to x and ŵ their unit direction, as columns of [`MAX_LIGHTS`] numbers, so that [`Float8`] lanes
/// estimate eight lights at once (2026-12-05: one light at a time, the estimates were 14 % of a render
/// lit by four area lights):
/// - `point`, `spot`: L = I, m = 1, a = 0, k = 1, q = 0 (I / d²; a spot's falloff multiplied in after);
/// - `directional`, `constant`, `envmap`: L = E, m = 1, a = 0, k = 0, q = 1 (E);
/// - `area`: L the radiance, m = q = A/4, a the vector area, k = 1;
/// - the columns past the last light: L = 0, k = 0, q = 1 (0).
#[derive(Clone, Debug, PartialEq)]
struct Estimates {
    center: [[f32; MAX_LIGHTS]; 3],
    vector_area: [[f32; MAX_LIGHTS]; 3],
    l: [f32; MAX_LIGHTS],
    m: [f32; MAX_LIGHTS],
    k: [f32; MAX_LIGHTS],
    q: [f32; MAX_LIGHTS],
    /// The lights that are spots: their falloff towards x multiplies their estimate.
    spots: Vec<usize>,
}

/// One light's row of [`Estimates`]: (L, m, k, q, centre, vector area).
type Row = (f32, f32, f32, f32, Vec3, Vec3);

/// The light choice of a scene (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct LightSelection {
    /// The number of lights, 0 for the uniform choice.
    n: usize,
    estimates: Box<Estimates>,
}

impl LightSelection {
    /// The choice among `lights` (area lights on `shapes`).
    #[must_use]
    pub fn new(lights: &[Light], shapes: &[Shape]) -> Self {
        let mut e = Estimates {
            center: [[0.0; MAX_LIGHTS]; 3],
            vector_area: [[0.0; MAX_LIGHTS]; 3],
            l: [0.0; MAX_LIGHTS],
            m: [0.0; MAX_LIGHTS],
            k: [0.0; MAX_LIGHTS],
            q: [1.0; MAX_LIGHTS],
            spots: Vec::new(),
        };
        if lights.len() > MAX_LIGHTS || lights.len() < 2 {
            return LightSelection { n: 0, estimates: Box::new(e) };
        }
        for (index, light) in lights.iter().enumerate() {
            let point = |intensity: f32, position: Vec3| -> Row { (intensity, 1.0, 1.0, 0.0, position, Vec3::ZERO) };
            let distant = |irradiance: f32| -> Row { (irradiance, 1.0, 0.0, 1.0, Vec3::ZERO, Vec3::ZERO) };
            let (l, m, k, q, center, vector) = match light {
                Light::Point(p) => point(p.intensity.luminance(), p.position),
                Light::Spot(s) => {
                    e.spots.push(index);
                    point(s.intensity.luminance(), s.position)
                }
                Light::Directional(d) => distant(d.irradiance.luminance()),
                Light::Constant(c) => distant(PI * c.radiance.luminance()),
                Light::EnvMap(env) => distant(PI * env.mean_luminance()),
                Light::Area(a) => {
                    let shape = &shapes[a.shape as usize];
                    let center = (0..shape.primitive_count() as u32)
                        .fold(crate::geometry::bounds::Bounds3::EMPTY, |b, p| b.union(shape.primitive_bounds(p)))
                        .centroid();
                    let quarter_area = 0.25 * shape.area();
                    (a.radiance.luminance(), quarter_area, 1.0, quarter_area, center, vector_area(shape))
                }
            };
            (e.l[index], e.m[index], e.k[index], e.q[index]) = (l, m, k, q);
            for axis in 0..3 {
                e.center[axis][index] = center[axis];
                e.vector_area[axis][index] = vector[axis];
            }
        }
        LightSelection { n: lights.len(), estimates: Box::new(e) }
    }

    /// Whether the choice is uniform (one light, or more than [`MAX_LIGHTS`]).
    #[must_use]
    pub fn is_uniform(&self) -> bool {
        self.n == 0
    }

    /// The estimated importance of every light at `x` (module docs) into `out`, each ≥ 0 and finite.
    fn importances(&self, lights: &[Light], x: Vec3, out: &mut [f32; MAX_LIGHTS]) {
        let e = &*self.estimates;
        let zero = Float8::splat(0.0);
        // Infinite (x at a point light): large, but summable over every light.
        let large = Float8::splat(f32::MAX / (MAX_LIGHTS as f32 * 2.0));
        for start in (0..self.n).step_by(8) {
            let column = |c: &[f32; MAX_LIGHTS]| Float8::from_fn(|i| c[start + i]);
            let d = [0, 1, 2].map(|axis| Float8::splat(x[axis]) - column(&e.center[axis]));
            let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let a_dot_d = column(&e.vector_area[0]) * d[0] + column(&e.vector_area[1]) * d[1] + column(&e.vector_area[2]) * d[2];
            let facing = Float8::select(d2.gt(zero), a_dot_d / d2.sqrt(), zero);
            let value = column(&e.l) * column(&e.m).max(facing) / (column(&e.k) * d2 + column(&e.q));
            let value = Float8::select(value.is_finite() & value.gt(zero), value, Float8::select(value.eq(Float8::splat(f32::INFINITY)), large, zero));
            for i in 0..8 {
                out[start + i] = value.lane(i);
            }
        }
        for &s in &e.spots {
            if let Light::Spot(spot) = &lights[s] {
                out[s] *= spot.falloff_at(x);
            }
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
        let n = self.n;
        self.importances(lights, x, weights);
        let sum: f32 = weights[..n].iter().sum();
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{disk::Disk, sphere::Sphere};
    use crate::light::{area::AreaLight, directional::DirectionalLight, point::PointLight, spot::SpotLight, ConstantLight};
    use crate::math::transform::Transform;
    use crate::spectrum::Rgb;

    /// The importance of one light at `x` by the module doc's table, one light at a time, in f64.
    fn by_the_table(light: &Light, shapes: &[Shape], x: Vec3) -> f64 {
        let dist2 = |p: Vec3| f64::from((x - p).length_squared());
        match light {
            Light::Point(p) => f64::from(p.intensity.luminance()) / dist2(p.position),
            Light::Spot(s) => f64::from(s.intensity.luminance()) * f64::from(s.falloff_at(x)) / dist2(s.position),
            Light::Directional(d) => f64::from(d.irradiance.luminance()),
            Light::Constant(c) => std::f64::consts::PI * f64::from(c.radiance.luminance()),
            Light::EnvMap(e) => std::f64::consts::PI * f64::from(e.mean_luminance()),
            Light::Area(a) => {
                let shape = &shapes[a.shape as usize];
                let center = (0..shape.primitive_count() as u32)
                    .fold(crate::geometry::bounds::Bounds3::EMPTY, |b, p| b.union(shape.primitive_bounds(p)))
                    .centroid();
                let quarter = 0.25 * f64::from(shape.area());
                let d = x - center;
                let facing = f64::from(vector_area(shape).dot(d.normalize()));
                f64::from(a.radiance.luminance()) * quarter.max(facing) / (dist2(center) + quarter)
            }
        }
    }

    /// The estimates eight lights at a time give what the module doc's table gives light by light: ten
    /// lights of every kind (two blocks of lanes), at points near and far, in front of and behind the flat
    /// emitters, inside and outside the spot's cone; and a point on a point light is large and finite.
    #[test]
    fn estimates_in_lanes_follow_the_table() {
        let shapes = vec![
            Shape::Sphere(Sphere::new(Vec3::new(1.0, 2.0, 0.0), 0.5, Transform::IDENTITY, false).unwrap()),
            Shape::Disk(Disk::new(Transform::translate(Vec3::new(-1.0, 0.0, 3.0)), false)),
            Shape::Disk(Disk::new(Transform::translate(Vec3::new(2.0, -1.0, -2.0)), true)),
        ];
        let lights = vec![
            Light::Point(PointLight { position: Vec3::new(0.0, 2.0, 0.0), intensity: Rgb::splat(10.0) }),
            Light::Area(AreaLight { shape: 0, radiance: Rgb::new(4.0, 2.0, 1.0) }),
            Light::Constant(ConstantLight { radiance: Rgb::splat(0.3) }),
            Light::Spot(SpotLight::new(
                Transform::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y).unwrap(),
                Rgb::splat(50.0),
                20.0,
                15.0,
            )),
            Light::Area(AreaLight { shape: 1, radiance: Rgb::splat(2.0) }),
            Light::Directional(DirectionalLight { direction: -Vec3::Z, irradiance: Rgb::splat(1.5) }),
            Light::Point(PointLight { position: Vec3::new(3.0, -4.0, 1.0), intensity: Rgb::splat(0.5) }),
            Light::Area(AreaLight { shape: 2, radiance: Rgb::splat(7.0) }),
            Light::Point(PointLight { position: Vec3::new(-5.0, 0.0, 0.0), intensity: Rgb::splat(30.0) }),
            Light::Constant(ConstantLight { radiance: Rgb::splat(0.01) }),
        ];
        let selection = LightSelection::new(&lights, &shapes);
        let points = [Vec3::ZERO, Vec3::new(0.1, -0.2, 0.3), Vec3::new(-1.0, 0.5, 4.0), Vec3::new(2.0, -1.0, -3.0), Vec3::new(9.0, 9.0, -9.0)];
        for x in points {
            let mut got = [0.0f32; MAX_LIGHTS];
            selection.importances(&lights, x, &mut got);
            for (i, light) in lights.iter().enumerate() {
                let want = by_the_table(light, &shapes, x);
                assert!((f64::from(got[i]) - want).abs() <= 1e-5 * want, "light {i} at {x}: {} vs {want}", got[i]);
            }
            let total: f32 = (0..lights.len()).map(|i| selection.pmf(&lights, x, i)).sum();
            assert!((total - 1.0).abs() < 1e-6, "at {x}: the choice's probabilities sum to {total}");
        }
        // The spot's cone holds the origin and not (9, 9, −9); the flat emitters face +z and −z.
        let mut at = [0.0f32; MAX_LIGHTS];
        selection.importances(&lights, Vec3::new(9.0, 9.0, -9.0), &mut at);
        assert_eq!(at[3], 0.0);
        selection.importances(&lights, Vec3::new(0.0, 2.0, 0.0), &mut at);
        assert!(at[0].is_finite() && at[0] > 1e30, "on the point light: {}", at[0]);
        let p = selection.pmf(&lights, Vec3::new(0.0, 2.0, 0.0), 0);
        assert!(p.is_finite() && p > 0.79, "{p}");
    }
}
