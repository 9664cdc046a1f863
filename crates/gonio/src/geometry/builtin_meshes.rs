//! The built-in meshes of Mitsuba's `rectangle` ([-1, 1]² in the z = 0 plane, normal +z,
//! uv = ((x + 1)/2, (y + 1)/2)) and `cube` ([-1, 1]³, outward normals, uv per face).

use super::Mesh;
use crate::error::Result;
use crate::math::Transform;
use glam::{Vec2, Vec3};

/// Object-space quads: (corner, edge u, edge v), each giving a face with normal u × v.
fn quads_to_mesh(quads: &[(Vec3, Vec3, Vec3)], to_world: &Transform, flip_normals: bool, at: &str) -> Result<Mesh> {
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    let mut indices = Vec::new();
    // A mirroring to_world reverses the winding; Mitsuba's analytic rectangle keeps the transformed normal
    // (inverse transpose) instead, so the winding is reversed back.
    let mirror = to_world.flips_handedness();
    for &(corner, eu, ev) in quads {
        let base = positions.len() as u32;
        for (s, t) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            positions.push(corner + eu * s + ev * t);
            uvs.push(Vec2::new(s, t));
        }
        if mirror {
            indices.extend([[base, base + 2, base + 1], [base, base + 3, base + 2]]);
        } else {
            indices.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
        }
    }
    Mesh::new(positions, None, Some(uvs), indices, to_world, true, flip_normals, at)
}

/// Mitsuba's `rectangle`.
pub fn rectangle(to_world: &Transform, flip_normals: bool, at: &str) -> Result<Mesh> {
    quads_to_mesh(&[(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 2.0, 0.0))], to_world, flip_normals, at)
}

/// Mitsuba's `cube`: six faces with outward normals.
pub fn cube(to_world: &Transform, flip_normals: bool, at: &str) -> Result<Mesh> {
    let (x, y, z) = (Vec3::X * 2.0, Vec3::Y * 2.0, Vec3::Z * 2.0);
    let m = Vec3::splat(-1.0);
    let quads = [
        (Vec3::new(-1.0, -1.0, 1.0), x, y), // +z
        (m, y, x),                          // −z
        (Vec3::new(1.0, -1.0, -1.0), y, z), // +x
        (m, z, y),                          // −x
        (Vec3::new(-1.0, 1.0, -1.0), z, x), // +y
        (m, x, z),                          // −y
    ];
    quads_to_mesh(&quads, to_world, flip_normals, at)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Ray;

    #[test]
    fn cube_normals_point_outwards() {
        let c = cube(&Transform::IDENTITY, false, "t").unwrap();
        assert!((c.area() - 24.0).abs() < 1e-5);
        for d in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
            let r = Ray::new(d * 3.0, -d, 10.0);
            let (tri, h) = (0..12).filter_map(|t| c.intersect(t, &r).map(|h| (t, h))).min_by(|a, b| a.1.t.total_cmp(&b.1.t)).unwrap();
            assert!((c.interaction(tri, &r, &h, true).n - d).length() < 1e-6, "{d}");
        }
    }

    #[test]
    fn mirrored_rectangle_keeps_transformed_normal() {
        let r = rectangle(&Transform::scale(Vec3::new(-1.0, 1.0, 1.0)).unwrap(), false, "t").unwrap();
        let ray = Ray::new(Vec3::new(0.1, 0.1, 1.0), -Vec3::Z, 10.0);
        let (tri, h) = (0..2).find_map(|t| r.intersect(t, &ray).map(|h| (t, h))).unwrap();
        assert!((r.interaction(tri, &ray, &h, true).n - Vec3::Z).length() < 1e-6);
    }
}
