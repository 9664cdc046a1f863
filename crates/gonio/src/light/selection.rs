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
//! | `projector`   | π · scale · Ē / d², Ē the projected image's mean (as if it shone in every direction) |
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
use crate::geometry::bvh::bits;
use crate::geometry::Shape;
use crate::math::lanes::{Real, V3};
use crate::math::simd::Float8;
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
                // Its mean intensity in the frame, as if it shone everywhere.
                Light::Projector(p) => Estimate::Point { position: p.position, intensity: p.mean_intensity(), spot: None },
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

    /// The estimated importance of light `index` at `x` (module docs), ≥ 0 and finite; in lanes, each lane
    /// the single call's number bit for bit (a spot's falloff is found lane by lane).
    #[inline]
    fn importance<R: Real>(&self, lights: &[Light], index: usize, x: V3<R>) -> R {
        let zero = R::splat(0.0);
        let value = match self.estimates[index] {
            Estimate::Distant(e) => R::splat(e),
            Estimate::Point { position, intensity, spot } => {
                let falloff = match spot.map(|s| &lights[s]) {
                    Some(Light::Spot(s)) => R::from_fn(|i| s.falloff_at(Vec3::new(x.x.lane(i), x.y.lane(i), x.z.lane(i)))),
                    _ => R::splat(1.0),
                };
                let d = x.sub(V3::splat(position));
                R::splat(intensity) * falloff / d.dot(d)
            }
            Estimate::Area { radiance, center, quarter_area, vector_area } => {
                let d = x.sub(V3::splat(center));
                let d2 = d.dot(d);
                let facing = R::select(d2.gt(zero), V3::splat(vector_area).dot(d) / d2.sqrt(), zero);
                R::splat(radiance) * R::splat(quarter_area).max(facing) / (d2 + quarter_area)
            }
        };
        let kept = value.is_finite() & value.gt(zero);
        let infinite = value.abs().eq(R::splat(f32::INFINITY));
        R::select(kept, value, R::select(infinite, R::splat(f32::MAX / (MAX_LIGHTS as f32 * 2.0)), zero))
    }

    /// Choose one of the `lights` (the scene's, which this choice was made for) for the shading point `x` with
    /// the uniform number `u`: its index, the probability of having chosen it, and the choice's sums at
    /// `x`, with which [`Self::pmf_with`] gives the probability of any other light there without
    /// estimating every light again.
    #[must_use]
    #[inline]
    pub fn sample(&self, lights: &[Light], x: Vec3, u: f32) -> (usize, f32, SelectionSums) {
        let n = lights.len();
        if self.is_uniform() {
            // `(u · n) as usize`, at most n − 1.
            return (((u * n as f32) as usize).min(n - 1), 1.0 / n as f32, SelectionSums::UNIFORM);
        }
        let mut weights = [0.0f32; MAX_LIGHTS];
        let sums = self.weights(lights, V3::from(x), &mut weights).lane(0);
        let (index, pmf) = choose(&weights[..n], sums.total, u);
        (index, pmf, sums)
    }

    /// [`Self::sample`] for eight shading points `x` (the lanes of `lanes`) with the uniform numbers `u`:
    /// each lane's light, probability and sums, the single call's bit for bit, with the estimates made in
    /// lanes.
    #[inline]
    #[must_use]
    pub fn sample_lanes(&self, lights: &[Light], x: V3<Float8>, u: Float8, lanes: u32) -> [(usize, f32, SelectionSums); 8] {
        let mut out = [(0, 1.0, SelectionSums::UNIFORM); 8];
        if self.is_uniform() {
            for lane in bits(lanes) {
                out[lane] = self.sample(lights, Vec3::ZERO, u.lane(lane));
            }
            return out;
        }
        let n = lights.len();
        let mut weights = [Float8::splat(0.0); MAX_LIGHTS];
        let sums = self.weights(lights, x, &mut weights);
        let rows: [[f32; 8]; MAX_LIGHTS] = std::array::from_fn(|i| if i < n { weights[i].to_array() } else { [0.0; 8] });
        for lane in bits(lanes) {
            let mine: [f32; MAX_LIGHTS] = std::array::from_fn(|i| rows[i][lane]);
            let sums = sums.lane(lane);
            let (index, pmf) = choose(&mine[..n], sums.total, u.lane(lane));
            out[lane] = (index, pmf, sums);
        }
        out
    }

    /// The probability that [`Self::sample`] chooses light `index` for the shading point `x`.
    #[must_use]
    pub fn pmf(&self, lights: &[Light], x: Vec3, index: usize) -> f32 {
        if self.is_uniform() {
            return 1.0 / lights.len() as f32;
        }
        let mut weights = [0.0f32; MAX_LIGHTS];
        let sums = self.weights(lights, V3::from(x), &mut weights);
        weights[index] / sums.total
    }

    /// [`Self::pmf`] with the sums [`Self::sample`] returned at `x`: the same number, from light `index`'s
    /// estimate alone.
    #[must_use]
    pub fn pmf_with(&self, lights: &[Light], x: Vec3, index: usize, sums: SelectionSums) -> f32 {
        if self.is_uniform() {
            return 1.0 / lights.len() as f32;
        }
        sums.weight(self.importance(lights, index, V3::from(x)), lights.len()) / sums.total
    }

    /// Each light's weight at `x` (into `weights`), (1 − s) imp/Σimp + s/n with s = [`UNIFORM_SHARE`] (all
    /// uniform where every importance is 0), and the sums they were made with; in lanes as at one point.
    #[inline]
    fn weights<R: Real>(&self, lights: &[Light], x: V3<R>, weights: &mut [R; MAX_LIGHTS]) -> SelectionSums<R> {
        let n = self.estimates.len();
        let mut sum = R::splat(0.0);
        for (i, w) in weights[..n].iter_mut().enumerate() {
            *w = self.importance(lights, i, x);
            sum = sum + *w;
        }
        let mixed = sum.gt(R::splat(0.0)) & sum.is_finite();
        let share = R::select(mixed, R::splat(UNIFORM_SHARE), R::splat(1.0));
        let scale = R::select(mixed, R::splat(1.0 - UNIFORM_SHARE) / sum, R::splat(0.0));
        let mut sums = SelectionSums { share, scale, total: R::splat(0.0) };
        let mut total = R::splat(0.0);
        for w in &mut weights[..n] {
            *w = sums.weight(*w, n);
            total = total + *w;
        }
        sums.total = total;
        sums
    }
}

/// The light that a uniform number `u` chooses by the `weights` (summing to `total`), and its
/// probability: the first whose running sum passes u · total, or for rounding in the sum the last with a
/// positive weight.
#[inline]
fn choose(weights: &[f32], total: f32, u: f32) -> (usize, f32) {
    let target = u * total;
    let mut sum = 0.0;
    for (i, w) in weights.iter().enumerate() {
        sum += w;
        if target < sum {
            return (i, w / total);
        }
    }
    let last = weights.iter().rposition(|w| *w > 0.0).unwrap_or(weights.len() - 1);
    (last, weights[last] / total)
}

/// What a light's probability at a shading point takes besides its own estimate (the light choice's
/// `weights` there): its weight is imp · `scale` + `share` / n, its probability that over `total`; in
/// lanes, one set per lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SelectionSums<R = f32> {
    share: R,
    scale: R,
    total: R,
}

impl SelectionSums {
    /// The sums of a uniform choice (unused by it).
    pub const UNIFORM: SelectionSums = SelectionSums { share: 1.0, scale: 0.0, total: 1.0 };
}

impl<R: Real> SelectionSums<R> {
    /// The weight of a light of estimated importance `importance` among `n`.
    #[inline]
    fn weight(self, importance: R, n: usize) -> R {
        importance * self.scale + self.share * (1.0 / n as f32)
    }

    /// Lane `i`'s sums.
    #[inline]
    fn lane(self, i: usize) -> SelectionSums {
        SelectionSums { share: self.share.lane(i), scale: self.scale.lane(i), total: self.total.lane(i) }
    }
}

/// The vector area ∫ n dA of an emitting shape: its area times its normal for a disk or a flat mesh, 0 for
/// a sphere, a cylinder or a closed mesh (Mitsuba's meshes emit on the side of their triangles' normal,
/// p₁ − p₀ × p₂ − p₀).
fn vector_area(shape: &Shape) -> Vec3 {
    match shape {
        // An open cylinder's normals cancel round its circumference.
        Shape::Sphere(_) | Shape::Cylinder(_) => Vec3::ZERO,
        // Never an emitter (refused at load); no area.
        Shape::SdfGrid(_) => Vec3::ZERO,
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
            Light::Projector(p) => f64::from(p.mean_intensity()) / dist2(p.position),
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

    /// The estimates are the module doc's table: ten lights of every kind, at points near and far, in
    /// front of and behind the flat emitters, inside and outside the spot's cone; and a point on a point
    /// light is large and finite.
    #[test]
    fn estimates_follow_the_table() {
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
        let points =
            [Vec3::ZERO, Vec3::new(0.1, -0.2, 0.3), Vec3::new(-1.0, 0.5, 4.0), Vec3::new(2.0, -1.0, -3.0), Vec3::new(9.0, 9.0, -9.0)];
        for x in points {
            for (i, light) in lights.iter().enumerate() {
                let (got, want) = (selection.importance(&lights, i, V3::from(x)), by_the_table(light, &shapes, x));
                assert!((f64::from(got) - want).abs() <= 1e-5 * want, "light {i} at {x}: {got} vs {want}");
            }
            let total: f32 = (0..lights.len()).map(|i| selection.pmf(&lights, x, i)).sum();
            assert!((total - 1.0).abs() < 1e-6, "at {x}: the choice's probabilities sum to {total}");
            // The sums a sample returns give every light's probability as `pmf` does, bit for bit, and
            // the sample's own.
            for u in [0.0, 0.3, 0.97] {
                let (chosen, p, sums) = selection.sample(&lights, x, u);
                assert_eq!(p, selection.pmf(&lights, x, chosen));
                for i in 0..lights.len() {
                    assert_eq!(selection.pmf_with(&lights, x, i, sums), selection.pmf(&lights, x, i), "light {i} at {x}");
                }
            }
        }
        // The spot's cone holds the origin and not (9, 9, −9); the flat emitters face +z and −z.
        assert_eq!(selection.importance(&lights, 3, V3::from(Vec3::new(9.0, 9.0, -9.0))), 0.0);
        let on_light = selection.importance(&lights, 0, V3::from(Vec3::new(0.0, 2.0, 0.0)));
        assert!(on_light.is_finite() && on_light > 1e30, "on the point light: {on_light}");
        let p = selection.pmf(&lights, Vec3::new(0.0, 2.0, 0.0), 0);
        assert!(p.is_finite() && p > 0.79, "{p}");
        // In lanes, each lane's choice is the single call's, bit for bit (the point light's own position,
        // inside and outside the spot's cone, behind the disks), and lanes left out keep the default.
        let mut x = points.to_vec();
        x.extend([Vec3::new(0.0, 2.0, 0.0), Vec3::new(-1.0, 0.0, 2.0), Vec3::new(0.3, 0.1, 1.0)]);
        let xl = V3::new(Float8::from_fn(|i| x[i].x), Float8::from_fn(|i| x[i].y), Float8::from_fn(|i| x[i].z));
        for (k, lanes) in [0xffu32, 0b1011_0110].into_iter().enumerate() {
            let u = Float8::from_fn(|i| ((i * 37 + k * 11) % 100) as f32 / 100.0);
            let got = selection.sample_lanes(&lights, xl, u, lanes);
            for i in 0..8 {
                let want =
                    if lanes & (1 << i) != 0 { selection.sample(&lights, x[i], u.lane(i)) } else { (0, 1.0, SelectionSums::UNIFORM) };
                assert_eq!((got[i].0, got[i].1.to_bits(), got[i].2), (want.0, want.1.to_bits(), want.2), "lane {i} at {}", x[i]);
            }
        }
    }
}
