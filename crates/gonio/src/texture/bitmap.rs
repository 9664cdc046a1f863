//! `bitmap` — an image texture, looked up as Mitsuba 3's `bitmap` does.
//!
//! | parameter     | type      | default    | meaning                                                     |
//! |---------------|-----------|------------|-------------------------------------------------------------|
//! | `filename`    | string    | —          | EXR, HDR, PNG or JPEG (LDR files are sRGB-decoded to linear) |
//! | `raw`         | boolean   | false      | keep LDR values as stored (no sRGB decoding)                |
//! | `filter_type` | string    | `bilinear` | `bilinear` or `nearest`                                     |
//! | `wrap_mode`   | string    | `repeat`   | `repeat`, `mirror` or `clamp`                               |
//! | `to_uv`       | transform | identity   | applied to (u, v, 0) before the lookup                      |
//!
//! Texel (x, y) covers [x, x + 1)/W × [y, y + 1)/H of uv space with row 0 at the *top* of the image
//! (v = 0 is the first row); bilinear lookups blend the four texels around (u W − ½, v H − ½).

use crate::error::{Error, Result};
use crate::image::{linear_to_srgb, read_image, Image};
use crate::math::Transform;
use crate::props::Props;
use crate::spectrum::Rgb;
use glam::{Vec2, Vec3};
use std::path::Path;
use std::sync::Arc;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    Repeat,
    Mirror,
    Clamp,
}

impl Wrap {
    /// Map an integer texel coordinate into [0, n).
    #[inline]
    fn apply(self, i: i64, n: usize) -> usize {
        let n = n as i64;
        if (0..n).contains(&i) {
            // Every mode leaves [0, n) as it is (most lookups: no integer division).
            return i as usize;
        }
        let r = match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m < n {
                    m
                } else {
                    2 * n - 1 - m
                }
            }
        };
        r as usize
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Bitmap {
    image: Arc<Image>,
    bilinear: bool,
    wrap: Wrap,
    to_uv: Transform,
}

impl Bitmap {
    pub fn from_props(p: &Props) -> Result<Self> {
        let at = p.at_param("filename").to_string();
        let filename = p.string("filename")?.ok_or_else(|| Error::spec(p.at(), "`bitmap` needs a `filename`"))?;
        let mut image = read_image(Path::new(&filename))?;
        let is_ldr = matches!(
            Path::new(&filename).extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref(),
            Some("png" | "jpg" | "jpeg")
        );
        if p.bool("raw", false)? && is_ldr {
            image.data.iter_mut().for_each(|v| *v = linear_to_srgb(*v));
        }
        let bilinear = match p.string("filter_type")?.as_deref() {
            None | Some("bilinear") => true,
            Some("nearest") => false,
            Some(other) => {
                return Err(Error::spec(p.at_param("filter_type"), format!("`filter_type` must be bilinear or nearest, got `{other}`")))
            }
        };
        let wrap = match p.string("wrap_mode")?.as_deref() {
            None | Some("repeat") => Wrap::Repeat,
            Some("mirror") => Wrap::Mirror,
            Some("clamp") => Wrap::Clamp,
            Some(other) => {
                return Err(Error::spec(p.at_param("wrap_mode"), format!("`wrap_mode` must be repeat, mirror or clamp, got `{other}`")))
            }
        };
        if image.width == 0 || image.height == 0 {
            return Err(Error::spec(at, format!("`{filename}` has no pixels")));
        }
        Ok(Bitmap { image: Arc::new(image), bilinear, wrap, to_uv: p.transform("to_uv")? })
    }

    #[inline]
    /// Texel (`x`, `y`) of the image, both coordinates already wrapped into it.
    fn texel(&self, x: usize, y: usize) -> Rgb {
        let i = 3 * (y * self.image.width + x);
        let d = &self.image.data;
        Rgb::new(d[i], d[i + 1], d[i + 2])
    }

    #[must_use]
    pub fn eval(&self, uv: Vec2) -> Rgb {
        let q = self.to_uv.point(Vec3::new(uv.x, uv.y, 0.0));
        let (w, h) = (self.image.width as f32, self.image.height as f32);
        let (iw, ih) = (self.image.width, self.image.height);
        if !self.bilinear {
            return self.texel(self.wrap.apply((q.x * w).floor() as i64, iw), self.wrap.apply((q.y * h).floor() as i64, ih));
        }
        let (x, y) = (q.x * w - 0.5, q.y * h - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        // Each of the two columns and rows wrapped once.
        let (c0, c1) = (self.wrap.apply(x0, iw), self.wrap.apply(x0 + 1, iw));
        let (r0, r1) = (self.wrap.apply(y0, ih), self.wrap.apply(y0 + 1, ih));
        let top = self.texel(c0, r0) * (1.0 - fx) + self.texel(c1, r0) * fx;
        let bottom = self.texel(c0, r1) * (1.0 - fx) + self.texel(c1, r1) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_modes() {
        assert_eq!(Wrap::Repeat.apply(-1, 4), 3);
        assert_eq!(Wrap::Clamp.apply(7, 4), 3);
        assert_eq!(Wrap::Mirror.apply(4, 4), 3);
        assert_eq!(Wrap::Mirror.apply(-1, 4), 0);
    }

    #[test]
    fn lookups_hit_texel_centres() {
        let mut data = vec![0.0; 3 * 4];
        data[3] = 1.0; // texel (1, 0) red
        let b =
            Bitmap { image: Arc::new(Image { width: 2, height: 2, data }), bilinear: true, wrap: Wrap::Clamp, to_uv: Transform::IDENTITY };
        assert_eq!(b.eval(Vec2::new(0.75, 0.25)).r(), 1.0);
        assert!((b.eval(Vec2::new(0.5, 0.25)).r() - 0.5).abs() < 1e-6);
        assert_eq!(b.eval(Vec2::new(0.75, 0.75)).r(), 0.0);
    }
}
