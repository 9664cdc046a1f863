//! The local shading frame: the normal is +z, and every BSDF works in these coordinates.
//!
//! The helpers below read angles straight off a unit direction `w` expressed in the frame
//! (`cos θ = w.z`, `sin²θ = 1 − z²`, `cos φ = x / sin θ`, …), as pbrt-v4's `CosTheta` family does.

use crate::math::lanes::{Real, V3};
use glam::Vec3;

/// The tangents (s, t) of [`Frame::from_normal`] around the unit normal `n`, in lanes: Duff et al. 2017,
/// "Building an Orthonormal Basis, Revisited" (JCGT 6(1), Listing 3), the sign of n_z taken as the sign of
/// a comparison (so n_z = −0 counts as positive).
#[inline(always)]
#[must_use]
pub fn tangents<R: Real>(n: V3<R>) -> (V3<R>, V3<R>) {
    let one = R::splat(1.0);
    let sign = R::select(n.z.lt(R::splat(0.0)), -one, one);
    let a = -one / (sign + n.z);
    let b = n.x * n.y * a;
    let s = V3::new(one + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let t = V3::new(b, sign + n.y * n.y * a, -n.y);
    (s, t)
}

/// The shading tangents (s, t) of Mitsuba 3 (`SurfaceInteraction::initialize_sh_frame`) around the unit
/// normal `n`, in lanes: s is `dp_du` (a shape's ∂p/∂u) made orthogonal to `n` (Gram–Schmidt) and
/// normalised, t = n × s. Where that vanishes (∂p/∂u zero, at a sphere's pole or a disk's centre, or along
/// `n`), those of [`tangents`], as Mitsuba's are there.
#[inline(always)]
#[must_use]
pub fn tangents_along<R: Real>(n: V3<R>, dp_du: V3<R>) -> (V3<R>, V3<R>) {
    let s = dp_du.sub(n.scale(n.dot(dp_du)));
    let len2 = s.dot(s);
    // 2026-12: below the smallest normal f32 the direction is rounding noise and the length would not
    // invert safely.
    let regular = len2.gt(R::splat(f32::MIN_POSITIVE));
    let s = V3::select(regular, s.div(len2.sqrt()), tangents(n).0);
    (s, n.cross(s))
}

/// An orthonormal basis `(s, t, n)`; `to_local` and `to_world` convert directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub s: Vec3,
    pub t: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// A frame around the unit normal `n`, built with the branchless construction of
    /// Duff et al. 2017, "Building an Orthonormal Basis, Revisited" (JCGT 6(1), Listing 3).
    #[must_use]
    pub fn from_normal(n: Vec3) -> Self {
        debug_assert!((n.length_squared() - 1.0).abs() < 1e-4, "normal must be unit length");
        let (s, t) = tangents::<f32>(n.into());
        Frame { s: s.into(), t: t.into(), n }
    }

    /// Mitsuba 3's shading frame around the unit normal `n` with its first tangent along `dp_du`, made
    /// orthogonal to `n` ([`tangents_along`]).
    #[must_use]
    pub fn from_normal_and_dp_du(n: Vec3, dp_du: Vec3) -> Self {
        debug_assert!((n.length_squared() - 1.0).abs() < 1e-4, "normal must be unit length");
        let (s, t) = tangents_along::<f32>(n.into(), dp_du.into());
        Frame { s: s.into(), t: t.into(), n }
    }

    #[inline]
    #[must_use]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    #[inline]
    #[must_use]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

#[inline]
#[must_use]
pub fn cos_theta(w: Vec3) -> f32 {
    w.z
}

#[inline]
#[must_use]
pub fn abs_cos_theta(w: Vec3) -> f32 {
    w.z.abs()
}

#[inline]
#[must_use]
pub fn cos2_theta(w: Vec3) -> f32 {
    w.z * w.z
}

/// sin²θ, clamped at zero: `1 − z²` can round below zero for |z| ≈ 1 (2026-11: f32 rounding).
#[inline]
#[must_use]
pub fn sin2_theta(w: Vec3) -> f32 {
    (1.0 - cos2_theta(w)).max(0.0)
}

#[inline]
#[must_use]
pub fn sin_theta(w: Vec3) -> f32 {
    sin2_theta(w).sqrt()
}

/// tan θ; infinite on the horizon.
#[inline]
#[must_use]
pub fn tan_theta(w: Vec3) -> f32 {
    sin_theta(w) / cos_theta(w)
}

#[inline]
#[must_use]
pub fn tan2_theta(w: Vec3) -> f32 {
    sin2_theta(w) / cos2_theta(w)
}

/// cos φ; 1 at the pole, where φ is undefined.
#[inline]
#[must_use]
pub fn cos_phi(w: Vec3) -> f32 {
    let s = sin_theta(w);
    if s == 0.0 {
        1.0
    } else {
        (w.x / s).clamp(-1.0, 1.0)
    }
}

/// sin φ; 0 at the pole, where φ is undefined.
#[inline]
#[must_use]
pub fn sin_phi(w: Vec3) -> f32 {
    let s = sin_theta(w);
    if s == 0.0 {
        0.0
    } else {
        (w.y / s).clamp(-1.0, 1.0)
    }
}

/// Whether `a` and `b` lie in the same hemisphere of the frame (both above or both below).
#[inline]
#[must_use]
pub fn same_hemisphere(a: Vec3, b: Vec3) -> bool {
    a.z * b.z > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_orthonormal_for_many_normals() {
        for n in [Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(0.3, -0.4, 0.866).normalize(), Vec3::new(1e-7, 0.0, -1.0).normalize()] {
            let f = Frame::from_normal(n);
            assert!((f.s.length() - 1.0).abs() < 1e-5);
            assert!((f.t.length() - 1.0).abs() < 1e-5);
            assert!(f.s.dot(f.t).abs() < 1e-5 && f.s.dot(f.n).abs() < 1e-5 && f.t.dot(f.n).abs() < 1e-5);
            // Right-handed: s × t = n.
            assert!((f.s.cross(f.t) - n).length() < 1e-5);
            let v = Vec3::new(0.2, 0.5, -0.7).normalize();
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
            assert!((f.to_local(n) - Vec3::Z).length() < 1e-5);
        }
    }

    #[test]
    fn trig_helpers_match_spherical_coordinates() {
        let (theta, phi) = (0.7f32, 2.1f32);
        let w = crate::math::spherical::spherical_direction(theta.sin(), theta.cos(), phi);
        assert!((cos_theta(w) - theta.cos()).abs() < 1e-6);
        assert!((sin_theta(w) - theta.sin()).abs() < 1e-6);
        assert!((tan_theta(w) - theta.tan()).abs() < 1e-5);
        assert!((cos_phi(w) - phi.cos()).abs() < 1e-6);
        assert!((sin_phi(w) - phi.sin()).abs() < 1e-6);
        assert_eq!(cos_phi(Vec3::Z), 1.0);
        assert_eq!(sin_phi(Vec3::Z), 0.0);
    }
}
