//! What materials read from the surface at a hit: each shape's ∂p/∂u and ∂p/∂v ([`Shape::uv_partials`],
//! for `bumpmap`) are the derivatives of the texture coordinates the scene gives its hits, checked by tracing
//! rays to points moved a little along them; `mesh_attribute` gives the vertex values interpolated at hits.

use gonio::geometry::Ray;
use gonio::math::{Vec2, Vec3};
use gonio::sampling::Pcg32;
use gonio::scene::{mitsuba_xml, Scene};
use std::path::Path;

/// A bump-mapped material (so that hits carry texture coordinates) on a sphere, a disk, a cylinder and a
/// rectangle, each turned and scaled.
fn scene() -> Scene {
    let bsdf = r#"<bsdf type="bumpmap"><texture type="checkerboard" name="h"/><bsdf type="diffuse"/></bsdf>"#;
    let text = format!(
        r#"<scene version="3.0.0"><sensor type="perspective"/>
            <shape type="sphere"><float name="radius" value="0.7"/>
                <transform name="to_world"><rotate x="0.6" y="0.8" angle="40"/><translate x="-3"/></transform>{bsdf}</shape>
            <shape type="disk"><transform name="to_world"><scale x="0.8" y="0.8"/><rotate y="1" angle="30"/><translate x="-1"/></transform>{bsdf}</shape>
            <shape type="cylinder"><float name="radius" value="0.4"/>
                <transform name="to_world"><rotate x="1" angle="70"/><translate x="1"/></transform>{bsdf}</shape>
            <shape type="rectangle"><transform name="to_world"><scale x="0.6" y="0.9"/><rotate z="1" angle="25"/><rotate x="1" angle="20"/><translate x="3"/></transform>{bsdf}</shape>
        </scene>"#
    );
    Scene::build(mitsuba_xml::load_str(&text, "t.xml", Path::new("."), &[]).unwrap()).unwrap()
}

/// Moving a hit by ε ∂p/∂u changes its texture coordinates by (ε, 0), and by ε ∂p/∂v by (0, ε), to first
/// order (within 5 % of ε, with ε = 10⁻³), on every shape, at 100 hits each (away from the seams of the
/// periodic coordinates).
#[test]
fn partials_are_the_derivatives_of_the_texture_coordinates() {
    let scene = scene();
    let mut rng = Pcg32::new(7, 3);
    let mut checked = [0; 4];
    let eps = 1e-3;
    for _ in 0..4000 {
        let target = Vec3::new([-3.0, -1.0, 1.0, 3.0][rng.next_u32() as usize % 4], 0.0, 0.0)
            + Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, rng.next_f32() - 0.5) * 1.2;
        let o = Vec3::new(0.0, 0.5, 8.0);
        let Some(si) = scene.intersect(&Ray::new(o, (target - o).normalize(), f32::INFINITY)) else { continue };
        if checked[si.shape as usize] >= 100 || !(0.05..0.95).contains(&si.uv.x) || !(0.05..0.95).contains(&si.uv.y) {
            continue;
        }
        let (du, dv) = scene.shapes[si.shape as usize].uv_partials(si.prim, si.p, &si.shading);
        for (d, want) in [(du, Vec2::new(eps, 0.0)), (dv, Vec2::new(0.0, eps))] {
            let moved = si.p + d * eps;
            let Some(next) = scene.intersect(&Ray::new(o, (moved - o).normalize(), f32::INFINITY)) else { continue };
            if next.shape != si.shape || (next.p - moved).length() > 1e-2 * d.length() * eps + 1e-5 {
                continue; // another surface, or the ray grazes the shape there
            }
            let got = next.uv - si.uv;
            assert!((got - want).length() < 0.05 * eps, "shape {} at uv {}: moved by {d} · ε, uv by {got}, want {want}", si.shape, si.uv);
        }
        checked[si.shape as usize] += 1;
    }
    assert!(checked.iter().all(|&c| c >= 50), "hits checked per shape: {checked:?}");
}

/// A `mesh_attribute` texture reads the PLY file's vertex colours at the hit, interpolated with its
/// barycentrics (here a diffuse reflectance on one triangle: hits at chosen barycentrics); a name the mesh
/// lacks, and the texture on a light, are errors that say where.
#[test]
fn mesh_attributes_are_interpolated_at_hits() {
    use gonio::bsdf::Bsdf;
    use gonio::spectrum::Rgb;
    let dir = std::env::temp_dir().join(format!("gonio-mesh-attribute-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ply = dir.join("tri.ply");
    std::fs::write(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float color_0\n\
         property float color_1\nproperty float color_2\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
         0 0 0 0.9 0.1 0.2\n2 0 0 0.1 0.8 0.3\n0 2 0 0.2 0.3 0.7\n3 0 1 2\n",
    )
    .unwrap();
    let scene_with = |name: &str| {
        let text = format!(
            r#"<scene version="3.0.0"><sensor type="perspective"/>
                <shape type="ply"><string name="filename" value="{}"/>
                    <bsdf type="diffuse"><texture type="mesh_attribute" name="reflectance"><string name="name" value="{name}"/></texture></bsdf>
                </shape></scene>"#,
            ply.display()
        );
        Scene::build(mitsuba_xml::load_str(&text, "m.xml", Path::new("."), &[])?)
    };
    let scene = scene_with("vertex_color").unwrap();
    let corners = [Rgb::new(0.9, 0.1, 0.2), Rgb::new(0.1, 0.8, 0.3), Rgb::new(0.2, 0.3, 0.7)];
    for (b1, b2) in [(0.2f32, 0.3f32), (0.6, 0.1), (0.05, 0.9)] {
        let target = Vec3::new(2.0 * b1, 2.0 * b2, 0.0);
        let o = Vec3::new(0.3, -0.2, 3.0);
        let si = scene.intersect(&Ray::new(o, (target - o).normalize(), f32::INFINITY)).unwrap();
        let Bsdf::Diffuse(d) = scene.bsdf_at(&si).into_owned() else { panic!("a diffuse model") };
        let want = corners[0] * (1.0 - b1 - b2) + corners[1] * b1 + corners[2] * b2;
        assert!((0..3).all(|c| (d.reflectance.0[c] - want.0[c]).abs() < 1e-5), "at ({b1}, {b2}): {:?} against {want:?}", d.reflectance);
    }
    let e = scene_with("vertex_uv").err().unwrap().to_string();
    assert!(e.contains("m.xml:3:") && e.contains("mesh_attribute `vertex_uv`") && e.contains("it has: vertex_color"), "{e}");
    let text = r#"<scene version="3.0.0"><sensor type="perspective"/><emitter type="spot">
        <texture type="mesh_attribute" name="texture"><string name="name" value="vertex_color"/></texture></emitter></scene>"#;
    let e = mitsuba_xml::load_str(text, "s.xml", Path::new("."), &[]).and_then(Scene::build).err().unwrap().to_string();
    assert!(e.contains("s.xml:2:") && e.contains("can only be a BSDF parameter"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}
