//! Affine transforms of points, vectors and normals, and the elementary transforms of Mitsuba's
//! `<transform>` element (translate, rotate, scale, matrix, lookat).
//!
//! Composition follows Mitsuba's scene format: each operation inside `<transform>` *left*-multiplies the
//! matrix accumulated so far, so `<scale/><rotate/><translate/>` means `T · R · S` (scale first).

use super::lanes::{Real, V3};
use glam::{Mat4, Vec3, Vec4};

/// A 4×4 affine transform with its inverse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub matrix: Mat4,
    pub inverse: Mat4,
}

impl Default for Transform {
    fn default() -> Self {
        Transform::IDENTITY
    }
}

impl Transform {
    pub const IDENTITY: Transform = Transform { matrix: Mat4::IDENTITY, inverse: Mat4::IDENTITY };

    /// A transform from a matrix; `None` when it is singular or not finite.
    #[must_use]
    pub fn from_matrix(matrix: Mat4) -> Option<Self> {
        let det = matrix.determinant();
        if !det.is_finite() || det == 0.0 {
            return None;
        }
        let inverse = matrix.inverse();
        inverse.is_finite().then_some(Transform { matrix, inverse })
    }

    /// A transform from 16 numbers listing the matrix row by row (Mitsuba's `<matrix value>`, numpy's
    /// layout), rounded to `f32`; `None` when it is singular or not finite.
    #[must_use]
    pub fn from_rows(rows: &[f64; 16]) -> Option<Self> {
        let values: Vec<f32> = rows.iter().map(|&x| x as f32).collect();
        // glam stores columns: read the rows as columns, then transpose.
        Transform::from_matrix(Mat4::from_cols_slice(&values).transpose())
    }

    #[must_use]
    pub fn translate(v: Vec3) -> Self {
        Transform { matrix: Mat4::from_translation(v), inverse: Mat4::from_translation(-v) }
    }

    /// Scale by `s` per axis; `None` when a factor is zero.
    #[must_use]
    pub fn scale(s: Vec3) -> Option<Self> {
        Transform::from_matrix(Mat4::from_scale(s))
    }

    /// Rotation by `angle_deg` degrees about `axis` (right-handed, Rodrigues' formula); `None` for a zero axis.
    #[must_use]
    pub fn rotate(axis: Vec3, angle_deg: f32) -> Option<Self> {
        let axis = axis.try_normalize()?;
        let m = Mat4::from_axis_angle(axis, angle_deg.to_radians());
        Some(Transform { matrix: m, inverse: m.transpose() })
    }

    /// The camera-to-world transform of Mitsuba's `<lookat>`: local +z looks from `origin` towards
    /// `target`, local +y is `up` made orthogonal, local +x = up × dir (the image's left).
    /// `None` when origin = target or `up` is parallel to the viewing direction.
    #[must_use]
    pub fn look_at(origin: Vec3, target: Vec3, up: Vec3) -> Option<Self> {
        let dir = (target - origin).try_normalize()?;
        let left = up.cross(dir).try_normalize()?;
        let new_up = dir.cross(left);
        let m = Mat4::from_cols(left.extend(0.0), new_up.extend(0.0), dir.extend(0.0), origin.extend(1.0));
        Transform::from_matrix(m)
    }

    /// `self` applied after `first`: the matrix `self · first`.
    #[must_use]
    pub fn then_after(self, first: Transform) -> Transform {
        Transform { matrix: self.matrix * first.matrix, inverse: first.inverse * self.inverse }
    }

    #[must_use]
    pub fn inverse(self) -> Transform {
        Transform { matrix: self.inverse, inverse: self.matrix }
    }

    #[inline]
    #[must_use]
    pub fn point(&self, p: Vec3) -> Vec3 {
        let r = self.matrix * p.extend(1.0);
        if r.w == 1.0 {
            r.truncate()
        } else {
            r.truncate() / r.w
        }
    }

    /// [`Self::point`] in lanes ([`Real`]), by the same operations: glam's column order
    /// ((c₀x + c₁y) + c₂z) + c₃·1 per coordinate, and the division by w unless w is 1.
    #[inline(always)]
    #[must_use]
    pub fn point_lanes<R: Real>(&self, p: V3<R>) -> V3<R> {
        let row = |i: usize| self.row_lanes(i, p, 1.0);
        let (q, w) = (V3::new(row(0), row(1), row(2)), row(3));
        V3::select(w.eq(R::splat(1.0)), q, q.div(w))
    }

    /// [`Self::vector`] in lanes, by the same operations: ((c₀x + c₁y) + c₂z) + c₃·0 per coordinate.
    #[inline(always)]
    #[must_use]
    pub fn vector_lanes<R: Real>(&self, v: V3<R>) -> V3<R> {
        V3::new(self.row_lanes(0, v, 0.0), self.row_lanes(1, v, 0.0), self.row_lanes(2, v, 0.0))
    }

    /// Row `i` of the matrix times (v, w), in glam's column order.
    #[inline(always)]
    fn row_lanes<R: Real>(&self, i: usize, v: V3<R>, w: f32) -> R {
        let m = &self.matrix;
        let c = |axis: Vec4| R::splat(axis[i]);
        c(m.x_axis) * v.x + c(m.y_axis) * v.y + c(m.z_axis) * v.z + c(m.w_axis) * R::splat(w)
    }

    #[inline]
    #[must_use]
    pub fn vector(&self, v: Vec3) -> Vec3 {
        (self.matrix * Vec4::new(v.x, v.y, v.z, 0.0)).truncate()
    }

    /// Normals transform with the inverse transpose; the result is not normalised.
    #[inline]
    #[must_use]
    pub fn normal(&self, n: Vec3) -> Vec3 {
        (self.inverse.transpose() * Vec4::new(n.x, n.y, n.z, 0.0)).truncate()
    }

    /// Whether the transform mirrors space (negative determinant of the linear part).
    #[must_use]
    pub fn flips_handedness(&self) -> bool {
        glam::Mat3::from_mat4(self.matrix).determinant() < 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::simd::Float8;

    /// `point_lanes` and `vector_lanes` compute `point`'s and `vector`'s numbers bit for bit, on one `f32`
    /// and in eight lanes, for random affine and projective matrices and points.
    #[test]
    fn points_in_lanes_match() {
        let mut rng = crate::sampling::Pcg32::new(11, 2);
        let mut r = || rng.next_f32() * 6.0 - 3.0;
        for k in 0..200 {
            let mut rows: [f64; 16] = std::array::from_fn(|_| f64::from(r()));
            if k % 2 == 0 {
                rows[12..].copy_from_slice(&[0.0, 0.0, 0.0, 1.0]);
            }
            let Some(t) = Transform::from_rows(&rows) else { continue };
            let points: [Vec3; 8] = std::array::from_fn(|_| Vec3::new(r(), r(), r()));
            let lanes = V3::new(Float8::from_fn(|i| points[i].x), Float8::from_fn(|i| points[i].y), Float8::from_fn(|i| points[i].z));
            let (got, got_v) = (t.point_lanes(lanes), t.vector_lanes(lanes));
            for (i, p) in points.iter().enumerate() {
                let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                let lane = |v: &V3<Float8>| Vec3::new(v.x.lane(i), v.y.lane(i), v.z.lane(i));
                let (want, want_v) = (t.point(*p), t.vector(*p));
                let one: Vec3 = t.point_lanes(V3::<f32>::from(*p)).into();
                assert_eq!(bits(one), bits(want), "{p} by {t:?}");
                assert_eq!(bits(lane(&got)), bits(want), "{p} by {t:?}");
                let one_v: Vec3 = t.vector_lanes(V3::<f32>::from(*p)).into();
                assert_eq!(bits(one_v), bits(want_v), "vector {p} by {t:?}");
                assert_eq!(bits(lane(&got_v)), bits(want_v), "vector {p} by {t:?}");
            }
        }
    }

    #[test]
    fn composition_order_is_scale_then_rotate_then_translate() {
        // <scale value="2"/><rotate z="1" angle="90"/><translate x="1"/> = T · R · S.
        let s = Transform::scale(Vec3::splat(2.0)).unwrap();
        let r = Transform::rotate(Vec3::Z, 90.0).unwrap();
        let t = Transform::translate(Vec3::X);
        let m = t.then_after(r.then_after(s));
        // (1,0,0) → scale (2,0,0) → rotate (0,2,0) → translate (1,2,0), by hand.
        assert!((m.point(Vec3::X) - Vec3::new(1.0, 2.0, 0.0)).length() < 1e-6);
        assert!((m.inverse().point(Vec3::new(1.0, 2.0, 0.0)) - Vec3::X).length() < 1e-6);
        let expected = Mat4::from_cols_array_2d(&[[0.0, 2.0, 0.0, 0.0], [-2.0, 0.0, 0.0, 0.0], [0.0, 0.0, 2.0, 0.0], [1.0, 0.0, 0.0, 1.0]]);
        assert!(m.matrix.abs_diff_eq(expected, 1e-6), "{:?}", m.matrix);
    }

    #[test]
    fn look_at_axes() {
        let t = Transform::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y).unwrap();
        assert!((t.vector(Vec3::Z) - Vec3::NEG_Z).length() < 1e-6);
        assert!((t.vector(Vec3::Y) - Vec3::Y).length() < 1e-6);
        // Looking down −z with +y up, local +x (the image's left) is world −x.
        assert!((t.vector(Vec3::X) - Vec3::NEG_X).length() < 1e-6);
        assert!(Transform::look_at(Vec3::ZERO, Vec3::Y, Vec3::Y).is_none());
    }

    #[test]
    fn normals_stay_perpendicular_under_nonuniform_scale() {
        let t = Transform::scale(Vec3::new(1.0, 4.0, 1.0)).unwrap().then_after(Transform::rotate(Vec3::Z, 30.0).unwrap());
        let (tangent, n) = (Vec3::new(1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0));
        assert!(t.vector(tangent).dot(t.normal(n)).abs() < 1e-5);
    }
}
