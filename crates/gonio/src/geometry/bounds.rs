//! Axis-aligned bounding boxes.

use glam::Vec3;

/// An axis-aligned box; the empty box has `min = +∞`, `max = −∞`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds3 {
    pub min: Vec3,
    pub max: Vec3,
}

impl Default for Bounds3 {
    fn default() -> Self {
        Bounds3::EMPTY
    }
}

impl Bounds3 {
    pub const EMPTY: Bounds3 = Bounds3 { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) };

    #[inline]
    #[must_use]
    pub fn from_point(p: Vec3) -> Self {
        Bounds3 { min: p, max: p }
    }

    #[inline]
    #[must_use]
    pub fn union(self, o: Bounds3) -> Self {
        Bounds3 { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    #[inline]
    #[must_use]
    pub fn with_point(self, p: Vec3) -> Self {
        Bounds3 { min: self.min.min(p), max: self.max.max(p) }
    }

    #[inline]
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    #[inline]
    #[must_use]
    pub fn centroid(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    #[inline]
    #[must_use]
    pub fn diagonal(&self) -> Vec3 {
        self.max - self.min
    }

    /// Surface area; 0 for the empty box.
    #[inline]
    #[must_use]
    pub fn surface_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.diagonal();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// The axis (0, 1, 2) along which the box is longest.
    #[inline]
    #[must_use]
    pub fn longest_axis(&self) -> usize {
        let d = self.diagonal();
        if d.x >= d.y && d.x >= d.z {
            0
        } else if d.y >= d.z {
            1
        } else {
            2
        }
    }

    /// Slab test: the entry distance if the ray `o + t d` (with `inv_d = 1/d`) meets the box within
    /// (0, tmax). NaNs from 0·∞ fall out of the comparisons as misses or full spans, both conservative.
    #[inline]
    #[must_use]
    pub fn hit(&self, o: Vec3, inv_d: Vec3, tmax: f32) -> Option<f32> {
        let t0 = (self.min - o) * inv_d;
        let t1 = (self.max - o) * inv_d;
        // Plain comparisons compile to minss/maxss; glam's NaN-aware min/max cost twice as much here, and a
        // NaN slab (0 · ∞ for a ray in a face's plane) only ever widens the interval (2026-11).
        let (mut tnear, mut tfar) = (0.0f32, tmax);
        for axis in 0..3 {
            let (a, b) = if t0[axis] < t1[axis] { (t0[axis], t1[axis]) } else { (t1[axis], t0[axis]) };
            tnear = if a > tnear { a } else { tnear };
            tfar = if b < tfar { b } else { tfar };
        }
        (tnear <= tfar).then_some(tnear)
    }
}
