//! Light sources: `area` (emission from a shape), `point`, `spot`, `projector`, `directional`, and the environments
//! `constant` (uniform) and `envmap` (a lat-long image, importance sampled) — one file each, one variant
//! each below. `point`, `spot`, `projector` and `directional` are delta lights: only light sampling finds them.
//!
//! Every light answers three questions for next-event estimation and multiple importance sampling:
//! sample a direction from a reference point ([`Light::sample_li`]), the solid-angle density of a
//! direction that BSDF sampling found ([`Light::pdf_li`]), and the radiance seen along it.

pub mod area;
pub mod constant;
pub mod directional;
pub mod envmap;
pub mod point;
pub mod projector;
pub mod selection;
pub mod spot;

pub use area::AreaLight;
pub use constant::ConstantLight;
pub use directional::DirectionalLight;
pub use envmap::EnvMap;
pub use point::PointLight;
pub use projector::ProjectorLight;
pub use selection::LightSelection;
pub use spot::SpotLight;

use crate::geometry::{Ray, Shape};
use crate::spectrum::Rgb;
use glam::{Vec2, Vec3};

/// A sampled direction towards a light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// World-space unit direction from the reference point towards the light.
    pub wi: Vec3,
    /// Radiance arriving along `wi` if unoccluded (for a point light: intensity / distance²).
    pub li: Rgb,
    /// Solid-angle density of `wi`; for delta lights 1 (with `delta` set).
    pub pdf: f32,
    pub delta: bool,
    /// The visibility ray (already offset at both ends).
    pub shadow: Ray,
}

/// Any gonio light.
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    Area(AreaLight),
    Point(PointLight),
    Spot(SpotLight),
    Projector(ProjectorLight),
    Directional(DirectionalLight),
    Constant(ConstantLight),
    EnvMap(EnvMap),
}

impl Light {
    /// Sample a direction towards the light from `p` (geometric normal `n`, zero for no surface).
    #[must_use]
    pub fn sample_li(&self, shapes: &[Shape], p: Vec3, n: Vec3, uc: f32, u: Vec2) -> Option<LightSample> {
        match self {
            Light::Area(l) => l.sample_li(&shapes[l.shape as usize], p, n, uc, u),
            Light::Point(l) => l.sample_li(p, n),
            Light::Spot(l) => l.sample_li(p, n),
            Light::Projector(l) => l.sample_li(p, n),
            Light::Directional(l) => l.sample_li(p, n),
            Light::Constant(l) => l.sample_li(p, n, u),
            Light::EnvMap(l) => l.sample_li(p, n, uc, u),
        }
    }

    /// The light's colour where it is one colour throughout, every value it gives being that colour times a
    /// number (a distance's falloff, a spot's profile, a cosine): the radiance of an area or constant light,
    /// the intensity of a point or untextured spot light, the irradiance of a directional one. `None` for
    /// textured lights (a projector, a textured spot, an environment map).
    #[must_use]
    pub fn constant_colour(&self) -> Option<Rgb> {
        match self {
            Light::Area(l) => Some(l.radiance),
            Light::Point(l) => Some(l.intensity),
            Light::Spot(l) => (!l.is_textured()).then_some(l.intensity),
            Light::Directional(l) => Some(l.irradiance),
            Light::Constant(l) => Some(l.radiance),
            Light::Projector(_) | Light::EnvMap(_) => None,
        }
    }

    /// Whether the light is a delta distribution (no chance of hitting it by BSDF sampling).
    #[must_use]
    pub fn is_delta(&self) -> bool {
        matches!(self, Light::Point(_) | Light::Spot(_) | Light::Projector(_) | Light::Directional(_))
    }

    /// Whether the light is an environment (seen by rays that escape the scene).
    #[must_use]
    pub fn is_environment(&self) -> bool {
        matches!(self, Light::Constant(_) | Light::EnvMap(_))
    }

    /// For an environment: the radiance arriving along world direction `wi` (a ray that escaped towards
    /// `wi`) and the solid-angle density with which [`Self::sample_li`] picks `wi`. `None` for other lights.
    #[must_use]
    pub fn environment(&self, wi: Vec3) -> Option<(Rgb, f32)> {
        match self {
            Light::Constant(l) => Some((l.radiance, l.pdf_li(wi))),
            Light::EnvMap(l) => {
                let e = l.eval_lanes::<f32>(wi.into(), 1);
                Some((Rgb(e.li), e.pdf))
            }
            _ => None,
        }
    }
}
