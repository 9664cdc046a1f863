//! Textures: colours that vary over a surface, evaluated at a hit's uv. Materials evaluate them into a
//! plain [`crate::bsdf::Bsdf`] (see [`crate::scene::material`]).
//!
//! Plugins: `checkerboard` ([`checkerboard`]) and `bitmap` ([`bitmap`]), read at texture coordinates; and
//! `mesh_attribute` ([`mesh_attribute`]), read from the mesh at a hit, for BSDF parameters only.

pub mod bitmap;
pub mod checkerboard;
pub mod mesh_attribute;

pub use bitmap::Bitmap;
pub use checkerboard::Checkerboard;
pub use mesh_attribute::MeshAttribute;

use crate::error::{Error, Result};
use crate::math::simd::Float8;
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
    /// Build from a `<texture>` description: a texture read at texture coordinates (`mesh_attribute`,
    /// which reads the surface, is refused here: see [`SurfaceTexture::from_props`]).
    pub fn from_props(p: &Props) -> Result<Texture> {
        let t = match p.plugin_type() {
            "checkerboard" => Texture::Checkerboard(Checkerboard::from_props(p)?),
            "bitmap" => Texture::Bitmap(Bitmap::from_props(p)?),
            "mesh_attribute" => {
                return Err(Error::spec(p.at(), "a `mesh_attribute` texture can only be a BSDF parameter (it reads the mesh at a hit)"))
            }
            other => {
                return Err(Error::spec(p.at(), format!("unsupported texture `{other}` (gonio has: checkerboard, bitmap, mesh_attribute)")))
            }
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

    /// [`Self::eval`] in lanes, at texture coordinates (`u`, `v`) of the lanes set in `lanes` (the others
    /// unspecified): the same values as one lane at a time.
    #[inline]
    #[must_use]
    pub fn eval_lanes(&self, u: Float8, v: Float8, lanes: u32) -> [Float8; 3] {
        match self {
            Texture::Bitmap(b) => b.eval_lanes(u, v, lanes),
            Texture::Checkerboard(c) => {
                let first = c.same_side_lanes(u, v);
                std::array::from_fn(|i| Float8::select(first, Float8::splat(c.color0.0[i]), Float8::splat(c.color1.0[i])))
            }
        }
    }

    /// [`Self::eval_1`] in lanes, at texture coordinates (`u`, `v`) of the lanes set in `lanes` (the others
    /// unspecified): the same values as one lane at a time.
    #[inline]
    #[must_use]
    pub fn eval_1_lanes(&self, u: Float8, v: Float8, lanes: u32) -> Float8 {
        match self {
            Texture::Checkerboard(c) => {
                let (l0, l1) = (Float8::splat(c.color0.luminance()), Float8::splat(c.color1.luminance()));
                Float8::select(c.same_side_lanes(u, v), l1, l0)
            }
            Texture::Bitmap(b) => Rgb::luminance_lanes(b.eval_lanes(u, v, lanes)),
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

/// A texture on a BSDF parameter: one read at texture coordinates, or a mesh attribute read at the hit.
#[derive(Clone, Debug, PartialEq)]
pub enum SurfaceTexture {
    Uv(Texture),
    MeshAttribute(MeshAttribute),
}

impl SurfaceTexture {
    /// Build from a `<texture>` description given to a BSDF.
    pub fn from_props(p: &Props) -> Result<SurfaceTexture> {
        if p.plugin_type() == "mesh_attribute" {
            let m = MeshAttribute::from_props(p)?;
            p.finish()?;
            return Ok(SurfaceTexture::MeshAttribute(m));
        }
        Texture::from_props(p).map(SurfaceTexture::Uv)
    }
}
