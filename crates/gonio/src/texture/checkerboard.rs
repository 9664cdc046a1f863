//! `checkerboard` — Mitsuba's two-colour checkerboard over uv.
//!
//! | parameter | type      | default  | meaning                                 |
//! |-----------|-----------|----------|-----------------------------------------|
//! | `color0`  | rgb       | 0.4      | colour where frac(u) and frac(v) are on the same side of ½ |
//! | `color1`  | rgb       | 0.2      | the other squares                        |
//! | `to_uv`   | transform | identity | applied to (u, v, 0) before the lookup   |

use crate::error::Result;
use crate::math::lanes::V3;
use crate::math::simd::{Float8, Mask8};
use crate::math::Transform;
use crate::props::Props;
use crate::spectrum::Rgb;
use glam::{Vec2, Vec3};

#[derive(Clone, Debug, PartialEq)]
pub struct Checkerboard {
    pub color0: Rgb,
    pub color1: Rgb,
    pub to_uv: Transform,
}

impl Checkerboard {
    pub fn from_props(p: &Props) -> Result<Self> {
        Ok(Checkerboard {
            color0: p.rgb_in("color0", Rgb::splat(0.4), 0.0, f32::MAX)?,
            color1: p.rgb_in("color1", Rgb::splat(0.2), 0.0, f32::MAX)?,
            to_uv: p.transform("to_uv")?,
        })
    }

    /// Whether `uv` falls in a `color0` square of the colour lookup: frac(u) and frac(v) on the same side of ½.
    #[inline]
    fn same_side(&self, uv: Vec2) -> bool {
        let q = self.to_uv.point(Vec3::new(uv.x, uv.y, 0.0));
        (q.x - q.x.floor() > 0.5) == (q.y - q.y.floor() > 0.5)
    }

    /// [`Self::same_side`] in lanes, by the same operations: the lanes whose (u, v) falls in a `color0`
    /// square of the colour lookup.
    #[inline(always)]
    #[must_use]
    pub fn same_side_lanes(&self, u: Float8, v: Float8) -> Mask8 {
        let q = self.to_uv.point_lanes(V3::new(u, v, Float8::splat(0.0)));
        let upper = |x: Float8| (x - x.floor()).gt(Float8::splat(0.5));
        let (a, b) = (upper(q.x), upper(q.y));
        (a & b) | !(a | b)
    }

    #[inline]
    #[must_use]
    pub fn eval(&self, uv: Vec2) -> Rgb {
        if self.same_side(uv) {
            self.color0
        } else {
            self.color1
        }
    }

    /// The scalar lookup for float parameters (`alpha`, `opacity`, …), as Mitsuba 3's `eval_1`: the grey
    /// value (luminance) of the colours, **with the squares swapped** relative to [`Self::eval`] — Mitsuba
    /// 3.9.1's `checkerboard.cpp` tests `mask.x != mask.y` for `color0` in `eval_1` but `==` in `eval`
    /// (checked against the `mitsuba` 3.9.1 wheel; its regression scene `test_textured_roughconductor`
    /// depends on it).
    #[inline]
    #[must_use]
    pub fn eval_1(&self, uv: Vec2) -> f32 {
        if self.same_side(uv) {
            self.color1.luminance()
        } else {
            self.color0.luminance()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn squares_alternate() {
        let c = Checkerboard { color0: Rgb::ONE, color1: Rgb::ZERO, to_uv: Transform::scale(Vec3::new(2.0, 2.0, 1.0)).unwrap() };
        assert_eq!(c.eval(Vec2::new(0.1, 0.1)), Rgb::ONE);
        assert_eq!(c.eval(Vec2::new(0.3, 0.1)), Rgb::ZERO);
        assert_eq!(c.eval(Vec2::new(0.3, 0.3)), Rgb::ONE);
        // Mitsuba 3.9.1: checkerboard(color0 = 0.05, color1 = 0.3) gives eval = 0.05 but eval_1 = 0.3 at
        // uv (0.1, 0.1), and eval = 0.3, eval_1 = 0.05 at (0.7, 0.1).
        let m = Checkerboard { color0: Rgb::splat(0.05), color1: Rgb::splat(0.3), to_uv: Transform::IDENTITY };
        assert_eq!((m.eval(Vec2::new(0.1, 0.1)).r(), m.eval_1(Vec2::new(0.1, 0.1))), (0.05, 0.3));
        assert_eq!((m.eval(Vec2::new(0.7, 0.1)).r(), m.eval_1(Vec2::new(0.7, 0.1))), (0.3, 0.05));
    }

    /// The lanes pick the square [`Checkerboard::eval`] picks, for scaled, rotated, shifted and projective
    /// `to_uv` transforms, at random points (negative ones included), on square edges and at ±0, ±∞, NaN.
    #[test]
    fn lanes_pick_the_same_squares() {
        let rotate = Transform::rotate(Vec3::Z, 30.0).unwrap();
        let shift = Transform::translate(Vec3::new(-0.25, 3.5, 0.0));
        let mut projective = Transform::IDENTITY;
        projective.matrix.x_axis.w = 0.3;
        projective.matrix.w_axis.w = 1.7;
        let special = [0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 2.5, 1e8, -1e8, f32::INFINITY, f32::NEG_INFINITY, f32::NAN];
        let mut rng = crate::sampling::Pcg32::new(5, 1);
        for to_uv in [Transform::IDENTITY, Transform::scale(Vec3::new(20.0, 7.0, 1.0)).unwrap(), rotate, shift, projective] {
            let c = Checkerboard { color0: Rgb::ONE, color1: Rgb::ZERO, to_uv };
            let mut points: Vec<Vec2> = special.iter().flat_map(|&u| special.iter().map(move |&v| Vec2::new(u, v))).collect();
            points.extend((0..2000).map(|_| Vec2::new(rng.next_f32() * 8.0 - 4.0, rng.next_f32() * 8.0 - 4.0)));
            for chunk in points.chunks(8) {
                let uv = |i: usize| chunk.get(i).copied().unwrap_or(Vec2::ZERO);
                let got = c.same_side_lanes(Float8::from_fn(|i| uv(i).x), Float8::from_fn(|i| uv(i).y));
                for i in 0..chunk.len() {
                    assert_eq!(got.lane(i), c.same_side(uv(i)), "uv {} with {:?}", uv(i), c.to_uv);
                }
            }
        }
    }
}
