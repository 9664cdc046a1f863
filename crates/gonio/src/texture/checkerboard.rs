//! `checkerboard` — Mitsuba's two-colour checkerboard over uv.
//!
//! | parameter | type      | default  | meaning                                 |
//! |-----------|-----------|----------|-----------------------------------------|
//! | `color0`  | rgb       | 0.4      | colour where frac(u) and frac(v) are on the same side of ½ |
//! | `color1`  | rgb       | 0.2      | the other squares                        |
//! | `to_uv`   | transform | identity | applied to (u, v, 0) before the lookup   |

use crate::error::Result;
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

    #[inline]
    #[must_use]
    pub fn eval(&self, uv: Vec2) -> Rgb {
        let q = self.to_uv.point(Vec3::new(uv.x, uv.y, 0.0));
        let (a, b) = (q.x - q.x.floor() > 0.5, q.y - q.y.floor() > 0.5);
        if a == b {
            self.color0
        } else {
            self.color1
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
    }
}
