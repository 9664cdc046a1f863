//! `constant` — a uniform environment: radiance L from every direction that escapes the scene.
//!
//! | parameter  | type | default | meaning     |
//! |------------|------|---------|-------------|
//! | `radiance` | rgb  | 1       | L           |
//!
//! Sampled uniformly over the sphere (density 1/4π), as Mitsuba's `constant` emitter.

use super::LightSample;
use crate::geometry::ray::spawn_ray;
use crate::geometry::Ray;
use crate::sampling::warp::{sample_uniform_sphere, uniform_sphere_pdf};
use crate::spectrum::Rgb;
use glam::{Vec2, Vec3};

#[derive(Clone, Debug, PartialEq)]
pub struct ConstantLight {
    pub radiance: Rgb,
}

impl ConstantLight {
    #[must_use]
    pub fn sample_li(&self, p: Vec3, n: Vec3, u: Vec2) -> Option<LightSample> {
        let wi = sample_uniform_sphere(u);
        let shadow = if n == Vec3::ZERO { Ray::new(p, wi, f32::INFINITY) } else { spawn_ray(p, n, wi) };
        Some(LightSample { wi, li: self.radiance, pdf: uniform_sphere_pdf(wi), delta: false, shadow })
    }

    /// Density of [`Self::sample_li`] for direction `wi`.
    #[must_use]
    pub fn pdf_li(&self, wi: Vec3) -> f32 {
        uniform_sphere_pdf(wi)
    }
}
