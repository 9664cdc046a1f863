//! gonio's 4-wide SAH BVH with 4-wide triangle packets against obvhs 0.4's compressed 8-wide BVH
//! (CWBVH, PLOC build, Ylitie et al. 2017), single-threaded, on tessellated spheres of 10³…10⁶ triangles
//! and on the Cornell box of ../shared/scenes.
//!
//! Both answer the renderer's two questions for the same rays (random origins inside the mesh's box,
//! uniform directions): the closest hit as a full `SurfaceInteraction` (obvhs finds the triangle and its
//! distance, gonio's `Shape::interaction` then builds the same interaction), and occlusion of a segment
//! (gonio `Scene::occluded`, obvhs `ray_traverse_miss`). Each side's answers are checked against the
//! other's (same triangle hit, distances within 1e-4 relative).

use glam::Vec3A;
use gonio::geometry::{PrimHit, Ray, Shape};
use gonio::math::Vec3;
use gonio::sampling::warp::sample_uniform_sphere;
use gonio::sampling::Pcg32;
use gonio::scene::Scene;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::RayHit;
use obvhs::rt_triangle::RtTriangle;
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

const RAYS: usize = 200_000;
const ROUNDS: usize = 3;

/// A UV sphere of `rings` × `segments` (2·segments·(rings − 1) triangles) as a binary PLY.
fn write_sphere_ply(path: &Path, rings: usize, segments: usize) -> usize {
    let mut verts = vec![[0.0f32, 0.0, 1.0]];
    for r in 1..rings {
        let th = std::f32::consts::PI * r as f32 / rings as f32;
        for k in 0..segments {
            let ph = std::f32::consts::TAU * k as f32 / segments as f32;
            verts.push([th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()]);
        }
    }
    verts.push([0.0, 0.0, -1.0]);
    let idx = |r: usize, k: usize| (1 + r * segments + k % segments) as i32;
    let mut faces = Vec::new();
    for k in 0..segments {
        faces.push([0, idx(0, k), idx(0, k + 1)]);
    }
    for r in 0..rings - 2 {
        for k in 0..segments {
            faces.push([idx(r, k), idx(r + 1, k), idx(r + 1, k + 1)]);
            faces.push([idx(r, k), idx(r + 1, k + 1), idx(r, k + 1)]);
        }
    }
    let south = (verts.len() - 1) as i32;
    for k in 0..segments {
        faces.push([south, idx(rings - 2, k + 1), idx(rings - 2, k)]);
    }
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        verts.len(),
        faces.len()
    )
    .into_bytes();
    for v in &verts {
        for c in v {
            out.extend(c.to_le_bytes());
        }
    }
    for f in &faces {
        out.push(3);
        for i in f {
            out.extend(i.to_le_bytes());
        }
    }
    std::fs::write(path, out).unwrap();
    faces.len()
}

fn sphere_scene(dir: &Path, rings: usize) -> (Scene, usize) {
    let ply = dir.join(format!("sphere-{rings}.ply"));
    let n = write_sphere_ply(&ply, rings, rings);
    let xml = dir.join(format!("sphere-{rings}.xml"));
    std::fs::write(
        &xml,
        format!(
            r#"<scene version="3.0.0"><sensor type="perspective"><film type="hdrfilm"/></sensor>
            <shape type="ply"><string name="filename" value="{}"/>
            <boolean name="face_normals" value="true"/></shape></scene>"#,
            ply.display()
        ),
    )
    .unwrap();
    (Scene::load(&xml, &[]).unwrap(), n)
}

/// Every triangle of the scene's meshes as (shape, triangle) and obvhs triangles.
fn triangles(scene: &Scene) -> (Vec<(u32, u32)>, Vec<Triangle>) {
    let (mut refs, mut tris) = (Vec::new(), Vec::new());
    for (s, shape) in scene.shapes.iter().enumerate() {
        let Shape::Mesh(m) = shape else { continue };
        for t in 0..m.triangle_count() as u32 {
            let [p0, e1, e2] = m.triangle_edges(t);
            let v = |p: Vec3| Vec3A::new(p.x, p.y, p.z);
            refs.push((s as u32, t));
            tris.push(Triangle { v0: v(p0), v1: v(p0 + e1), v2: v(p0 + e2) });
        }
    }
    (refs, tris)
}

fn rays(lo: Vec3, hi: Vec3, tmax: f32) -> Vec<Ray> {
    let mut rng = Pcg32::new(5, 11);
    (0..RAYS)
        .map(|_| {
            let o = lo + (hi - lo) * Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            Ray::new(o, sample_uniform_sphere(rng.next_vec2()), tmax)
        })
        .collect()
}

fn mrays(d: Duration) -> f64 {
    RAYS as f64 / d.as_secs_f64() / 1e6
}

fn compare(label: &str, scene: &Scene, lo: Vec3, hi: Vec3, shadow_len: f32) {
    let gonio_build = scene.bvh_seconds;
    let (refs, tris) = triangles(scene);
    let t0 = Instant::now();
    let bvh = build_cwbvh_from_tris(&tris, BvhBuildParams::medium_build(), &mut Duration::default());
    // Triangles in leaf order, as obvhs' own examples do, so that traversal indexes them directly.
    let ordered: Vec<RtTriangle> = bvh.primitive_indices.iter().map(|&i| RtTriangle::from(&tris[i as usize])).collect();
    let obvhs_build = t0.elapsed().as_secs_f64();

    let closest = rays(lo, hi, f32::INFINITY);
    let shadow = rays(lo, hi, shadow_len);
    let to_o = |r: &Ray| obvhs::ray::Ray::new(Vec3A::new(r.o.x, r.o.y, r.o.z), Vec3A::new(r.d.x, r.d.y, r.d.z), 0.0, r.tmax);

    // Closest hit → interaction. Each query runs ROUNDS times, alternating the two, and the fastest round
    // counts (the machine is shared).
    let (mut g_closest, mut o_closest, mut g_shadow, mut o_shadow) = (Duration::MAX, Duration::MAX, Duration::MAX, Duration::MAX);
    let (mut g, mut o, mut g_occ, mut o_occ) = (Vec::new(), Vec::new(), 0, 0);
    for _ in 0..ROUNDS {
        let t0 = Instant::now();
        g = closest.iter().map(|r| scene.intersect(r).map(|si| (si.shape, si.prim, si.t))).collect();
        g_closest = g_closest.min(t0.elapsed());
        let t0 = Instant::now();
        o = closest
            .iter()
            .map(|r| {
                let mut hit = RayHit::none();
                if !bvh.ray_traverse(to_o(r), &mut hit, |ray, id| ordered[id].intersect(ray)) {
                    return None;
                }
                let (s, t) = refs[bvh.primitive_indices[hit.primitive_id as usize] as usize];
                let shape = &scene.shapes[s as usize];
                // Barycentrics of the one triangle found (gonio's test), then the same interaction.
                let ph = shape.intersect(t, r).unwrap_or(PrimHit { t: hit.t, uv: Default::default() });
                let si = shape.interaction(s, t, r, &ph);
                Some((si.shape, si.prim, si.t))
            })
            .collect();
        o_closest = o_closest.min(t0.elapsed());

        // Occlusion.
        let t0 = Instant::now();
        g_occ = shadow.iter().filter(|r| scene.occluded(r)).count();
        g_shadow = g_shadow.min(t0.elapsed());
        let t0 = Instant::now();
        o_occ = shadow.iter().filter(|r| !bvh.ray_traverse_miss(to_o(r), |ray, id| ordered[id].intersect(ray))).count();
        o_shadow = o_shadow.min(t0.elapsed());
    }
    let agree = g.iter().zip(&o).filter(|(a, b)| match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => (a.0, a.1) == (b.0, b.1) || (a.2 - b.2).abs() <= 1e-4 * a.2.max(1.0),
        _ => false,
    });
    let agree = agree.count();

    println!(
        "{label:<22} {:>9} {:>10.4} {:>10.4} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>8.4} {:>7}/{:<7}",
        tris.len(),
        gonio_build,
        obvhs_build,
        mrays(g_closest),
        mrays(o_closest),
        mrays(g_shadow),
        mrays(o_shadow),
        agree as f64 / RAYS as f64,
        g_occ,
        o_occ
    );
}

fn main() {
    let dir = std::env::temp_dir().join(format!("gonio-bvh-compare-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    println!("single thread, {RAYS} rays per query, fastest of {ROUNDS} alternating rounds; build in s; Mrays/s; agree = share of closest hits on the same triangle (or same t)");
    println!(
        "{:<22} {:>9} {:>10} {:>10} {:>9} {:>9} {:>9} {:>9} {:>8} {:>15}",
        "scene", "triangles", "build g", "build o", "hit g", "hit o", "occl g", "occl o", "agree", "occluded g/o"
    );
    let cornell = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes/cornell-box.xml");
    match Scene::load(&cornell, &[]) {
        Ok(scene) => compare("cornell-box", &scene, Vec3::splat(-0.95), Vec3::splat(0.95), 0.5),
        Err(e) => println!("cornell-box skipped: {e}"),
    }
    for rings in [23, 71, 224, 708] {
        let (scene, n) = sphere_scene(&dir, rings);
        // Rays start inside the sphere's box (inside and outside the sphere).
        compare(&format!("sphere {n}"), &scene, Vec3::splat(-1.2), Vec3::splat(1.2), 0.3);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
