//! Textures: colours that vary over a surface, evaluated at a hit's uv. Materials evaluate them into a
//! plain [`crate::bsdf::Bsdf`] (see [`crate::scene::material`]).
//!
//! Plugins: `checkerboard` ([`checkerboard`]) and `bitmap` ([`bitmap`]).

pub mod bitmap;
pub mod checkerboard;

pub use bitmap::Bitmap;
pub use checkerboard::Checkerboard;

use crate::error::{Error, Result};
use crate::props::Props;
use crate::spectrum::Rgb;
use glam::Vec2;

/// Any gonio texture.
#[derive(Clone, Debug, PartialEq)]
pub enum Texture {
    Checkerboard(Checkerboard),
    Bitmap(Bitmap),
}

impl Texture {
    /// Build from a `<texture>` description.
    pub fn from_props(p: &Props) -> Result<Texture> {
        let t = match p.plugin_type() {
            "checkerboard" => Texture::Checkerboard(Checkerboard::from_props(p)?),
            "bitmap" => Texture::Bitmap(Bitmap::from_props(p)?),
            other => return Err(Error::spec(p.at(), format!("unsupported texture `{other}` (gonio has: checkerboard, bitmap)"))),
        };
        p.finish()?;
        Ok(t)
    }

    /// Width and height in texels: a bitmap's image, (1, 1) for others (as Mitsuba's `Texture::resolution`).
    #[must_use]
    pub fn resolution(&self) -> (usize, usize) {
        match self {
            Texture::Checkerboard(_) => (1, 1),
            Texture::Bitmap(b) => b.resolution(),
        }
    }

    /// The colour at texture coordinates `uv`.
    #[inline]
    #[must_use]
    pub fn eval(&self, uv: Vec2) -> Rgb {
        match self {
            Texture::Checkerboard(c) => c.eval(uv),
            Texture::Bitmap(b) => b.eval(uv),
        }
    }

    /// The value for a float parameter (Mitsuba's `eval_1`): a bitmap's luminance, a checkerboard's scalar
    /// lookup (see [`Checkerboard::eval_1`]).
    #[inline]
    #[must_use]
    pub fn eval_1(&self, uv: Vec2) -> f32 {
        match self {
            Texture::Checkerboard(c) => c.eval_1(uv),
            Texture::Bitmap(b) => b.eval(uv).luminance(),
        }
    }

    /// The gradient ∂/∂(u, v) of [`Self::eval_1`] (Mitsuba's `eval_1_grad`, what `bumpmap` reads): a
    /// bitmap's ([`Bitmap::eval_1_grad`]); 0 for a checkerboard, constant between its edges.
    #[inline]
    #[must_use]
    pub fn eval_1_grad(&self, uv: Vec2) -> Vec2 {
        match self {
            Texture::Checkerboard(_) => Vec2::ZERO,
            Texture::Bitmap(b) => b.eval_1_grad(uv),
        }
    }
}
