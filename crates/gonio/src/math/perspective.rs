//! The pinhole projection of Mitsuba's `perspective` sensor and `projector` emitter: camera space looks
//! along +z, and image point (x, y) ∈ [0, 1]² (x to the right, y down, as the image's pixels) sees the
//! direction ((1 − 2x) tan_x, (1 − 2y) tan_y, 1) — +x of camera space is the image's left (Mitsuba 3,
//! `perspective_projection` in `include/mitsuba/render/sensor.h`).

use glam::Vec3;

/// The tangents of the half field of view along x and y for a field of view of `fov_deg` degrees along
/// `axis` (`x`, `y`, `diagonal`, `smaller` or `larger`) of an image of `aspect` = width / height; for
/// another axis name, the message that says so (the caller gives its place).
pub fn tan_half_angles(fov_deg: f32, axis: &str, aspect: f32) -> Result<(f32, f32), String> {
    let t = (fov_deg.to_radians() * 0.5).tan();
    let axis = match axis {
        "smaller" if aspect > 1.0 => "y",
        "smaller" => "x",
        "larger" if aspect > 1.0 => "x",
        "larger" => "y",
        other => other,
    };
    match axis {
        "x" => Ok((t, t / aspect)),
        "y" => Ok((t * aspect, t)),
        "diagonal" => {
            let diag = (1.0 + 1.0 / (aspect * aspect)).sqrt();
            Ok((t / diag, t / (diag * aspect)))
        }
        other => Err(format!("`fov_axis` must be x, y, smaller, larger or diagonal, got `{other}`")),
    }
}

/// The image point (x, y) a camera-space point `local` (z > 0) projects to, for half-angle tangents
/// `tan_x`, `tan_y`: the inverse of the direction above.
#[must_use]
pub fn project(local: Vec3, tan_x: f32, tan_y: f32) -> (f32, f32) {
    (0.5 - 0.5 * local.x / (local.z * tan_x), 0.5 - 0.5 * local.y / (local.z * tan_y))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_inverts_the_pinhole_direction() {
        let (tx, ty) = tan_half_angles(40.0, "x", 1.5).unwrap();
        assert!((tx - 20f32.to_radians().tan()).abs() < 1e-7 && (ty - tx / 1.5).abs() < 1e-7);
        for (x, y) in [(0.0, 0.0), (1.0, 1.0), (0.25, 0.8)] {
            let d = Vec3::new((1.0 - 2.0 * x) * tx, (1.0 - 2.0 * y) * ty, 1.0) * 3.0;
            let (px, py) = project(d, tx, ty);
            assert!((px - x).abs() < 1e-6 && (py - y).abs() < 1e-6, "({x}, {y}) → ({px}, {py})");
        }
        assert_eq!(tan_half_angles(40.0, "smaller", 2.0), tan_half_angles(40.0, "y", 2.0));
        assert_eq!(tan_half_angles(40.0, "larger", 0.5), tan_half_angles(40.0, "y", 0.5));
        assert_eq!(tan_half_angles(40.0, "z", 1.0), Err("`fov_axis` must be x, y, smaller, larger or diagonal, got `z`".into()));
    }
}
