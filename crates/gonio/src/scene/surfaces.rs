//! The surfaces a packet of rays found, in lanes: what the path tracer's phases read at each vertex.
//!
//! Packet traversal keeps only each ray's distance and slot. Where the slot holds a flat-shaded triangle
//! (or parallelogram) (the common case: every built-in `rectangle`, `cube` and face-normal mesh, and the
//! planar parts of meshes with vertex normals: [`Mesh::flat_frame`](crate::geometry::mesh::Mesh::flat_frame)),
//! the point is o + t d, computed in lanes, the shading frame, constant over the triangle, and the
//! geometric normal are copied, and where the material reads texture coordinates they are an affine function of
//! the point ([`UvMap`](crate::geometry::mesh::UvMap), one per such slot). (2026-12: the point from the barycentrics had the triangles
//! hit gathered into a `Triangle8` and tested again, for every flat lane: 5.7 % of a Cornell box render;
//! and the texture coordinates from the barycentrics, by the mesh's vertices, a further 2 % of a
//! material spheres render. o + t d is off the plane by about t · 10⁻⁷, far below the ray offset; at
//! grazing incidence it can lie beyond the triangle's edge by a few 10⁻⁵ of t, within the ray offset
//! too. Mitsuba's `rectangle` takes o + t d in its own space.)
//! Spheres need only the distance, which the packet test computed as the scalar test does: their points,
//! normals and frames ([`sphere_tangents`], Mitsuba's ∂p/∂u frame) are computed in lanes too. Smooth-shaded
//! triangles are gathered from the leaves' packets and tested again in lanes for their barycentrics; the
//! point, the interpolated normal ([`smooth_normal`]) and the ∂p/∂u frame follow in lanes, the same
//! numbers as for one ray (2026-12: one lane at a time they were a tenth of a material-preview render).
//! Other shapes (disks, cylinders) build their interaction one lane at a time, as [`Scene::interaction_at`]
//! does for a single ray. 2026-12: building interactions one lane at a time had been a tenth of a
//! Cornell box render.

use super::{Scene, EMPTY_SLOT};
use crate::geometry::bvh::{bits, Hits8, LANES};
use crate::geometry::mesh::{face_normal, smooth_normal, Triangle8};
use crate::geometry::ray::{ray_point, RayLanes};
use crate::geometry::sphere::{sphere_surface, sphere_tangents};
use crate::geometry::{Ray, Shape, SurfaceInteraction};
use crate::math::frame::tangents_along;
use crate::math::lanes::V3;
use crate::math::simd::{Float8, Mask8};
use crate::math::Frame;
use crate::spectrum::Rgb;
use glam::{Vec2, Vec3};

/// Three numbers per lane (a direction, a point or an RGB value), as rows x, y, z (or r, g, b).
#[derive(Clone, Copy, Debug, Default)]
pub struct Rows3(pub [[f32; LANES]; 3]);

impl Rows3 {
    /// The rows as lanes.
    #[inline(always)]
    #[must_use]
    pub fn lanes(&self) -> V3<Float8> {
        V3::new(Float8::load(&self.0[0]), Float8::load(&self.0[1]), Float8::load(&self.0[2]))
    }

    #[inline(always)]
    pub fn store(&mut self, v: V3<Float8>) {
        *self = Self::from_lanes(v);
    }

    /// Lanes as rows.
    #[inline(always)]
    #[must_use]
    pub fn from_lanes(v: V3<Float8>) -> Self {
        Rows3([v.x.to_array(), v.y.to_array(), v.z.to_array()])
    }

    #[inline(always)]
    pub fn get(&self, lane: usize) -> Vec3 {
        Vec3::new(self.0[0][lane], self.0[1][lane], self.0[2][lane])
    }

    #[inline(always)]
    pub fn set(&mut self, lane: usize, v: Vec3) {
        (self.0[0][lane], self.0[1][lane], self.0[2][lane]) = (v.x, v.y, v.z);
    }

    #[inline(always)]
    pub fn rgb(&self, lane: usize) -> Rgb {
        Rgb([self.0[0][lane], self.0[1][lane], self.0[2][lane]])
    }

    #[inline(always)]
    pub fn set_rgb(&mut self, lane: usize, v: Rgb) {
        (self.0[0][lane], self.0[1][lane], self.0[2][lane]) = (v.0[0], v.0[1], v.0[2]);
    }
}

/// The surfaces found by eight rays: meaningful in the lanes of `found`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Surfaces8 {
    /// Lanes whose ray hit a surface.
    pub found: u32,
    /// Lanes whose surface is an emitter's (an area light's shape).
    pub emits: u32,
    /// The point hit.
    pub p: Rows3,
    /// Geometric normal (unit, the shape's outward side).
    pub n: Rows3,
    /// Shading frame (s, t, ns).
    pub s: Rows3,
    pub t: Rows3,
    pub ns: Rows3,
    /// Texture coordinates, for lanes whose material is textured (else zero).
    pub uv: [[f32; LANES]; 2],
    /// The shape hit, and the primitive within it.
    pub shape: [u32; LANES],
    pub prim: [u32; LANES],
}

impl Surfaces8 {
    /// Lane `lane` as an interaction record, `t` its ray's distance.
    #[must_use]
    pub fn interaction(&self, lane: usize, t: f32) -> SurfaceInteraction {
        SurfaceInteraction {
            t,
            p: self.p.get(lane),
            n: self.n.get(lane),
            shading: Frame { s: self.s.get(lane), t: self.t.get(lane), n: self.ns.get(lane) },
            uv: Vec2::new(self.uv[0][lane], self.uv[1][lane]),
            shape: self.shape[lane],
            prim: self.prim[lane],
        }
    }

    #[inline(always)]
    fn set_frame(&mut self, lane: usize, f: &Frame) {
        self.s.set(lane, f.s);
        self.t.set(lane, f.t);
        self.ns.set(lane, f.n);
    }
}

/// The lanes of a packet on smooth-shaded triangles ([`Scene::surfaces_into`]): their triangles gathered
/// from the packets of the BVH's leaves, vertex normals (as stored), ∂p/∂u, normal signs, and which of
/// them read texture coordinates.
#[derive(Default)]
struct SmoothLanes {
    lanes: u32,
    textured: u32,
    triangles: Triangle8,
    normals: [Rows3; 3],
    dp_du: Rows3,
    sign: [f32; LANES],
}

impl Scene {
    /// The surfaces at the closest hits `hits` of the rays `rays` in `lanes` (from
    /// [`Scene::intersect_rays`]), as [`Scene::interaction_at`] would build them one by one: the same
    /// numbers, computed in lanes where the shape allows.
    #[must_use]
    pub fn surfaces(&self, rays: &RayLanes<Float8>, hits: &Hits8, lanes: u32) -> Surfaces8 {
        let mut out = Surfaces8::default();
        self.surfaces_into(rays, hits, lanes, &mut out);
        out
    }

    /// [`Self::surfaces`] of the lanes `lanes` into `out`, a record the caller keeps from packet to packet:
    /// in those lanes `found`, `emits` and the texture coordinates start again from zero, and the lanes
    /// without a hit keep their earlier points, normals, frames, shapes and primitives (all valid numbers
    /// and indices); the other lanes keep all they hold (the path tracer traces some lanes again before it
    /// shades the packet). (2026-12: returned by value, the record's 616 bytes were zeroed and copied every
    /// bounce, 2 % of a material spheres render.)
    pub fn surfaces_into(&self, rays: &RayLanes<Float8>, hits: &Hits8, lanes: u32, out: &mut Surfaces8) {
        (out.found, out.emits) = (out.found & !lanes, out.emits & !lanes);
        for lane in bits(lanes) {
            (out.uv[0][lane], out.uv[1][lane]) = (0.0, 0.0);
        }
        // Lanes on flat triangles, and those of them whose material reads texture coordinates.
        let (mut flat, mut flat_uv) = (0u32, 0u32);
        // Lanes on spheres (their centres, radii and pole axes), those with flipped normals, and those textured.
        let (mut centers, mut radii, mut poles, mut round, mut flipped, mut round_uv) =
            (Rows3::default(), [1.0f32; LANES], Rows3::default(), 0u32, 0u32, 0u32);
        let mut smooth = SmoothLanes::default();
        let (o, d) = ([rays.o.x, rays.o.y, rays.o.z].map(Float8::to_array), [rays.d.x, rays.d.y, rays.d.z].map(Float8::to_array));
        for lane in bits(lanes) {
            let slot = hits.slot[lane];
            if slot == EMPTY_SLOT {
                continue;
            }
            out.found |= 1 << lane;
            let r = self.prims.slots[slot as usize];
            (out.shape[lane], out.prim[lane]) = (r.shape, r.prim);
            out.emits |= u32::from(self.shape_lights[r.shape as usize].is_some()) << lane;
            let textured = self.textured[r.shape as usize];
            let shape = &self.shapes[r.shape as usize];
            if let Shape::Mesh(mesh) = shape {
                if r.smooth {
                    if let Some(normals) = mesh.vertex_normals(r.prim) {
                        // Smooth-shaded triangles are never paired into parallelograms, so the slot's edges
                        // are the triangle's: its normal and ∂p/∂u from them, not from the mesh's records.
                        debug_assert!(r.corner.is_none());
                        let (packet, from) = (&self.prims.triangles[slot as usize / LANES], slot as usize % LANES);
                        smooth.triangles.copy_lane(lane, packet, from);
                        let [_, e1, e2] = packet.edges(from);
                        for (rows, n) in smooth.normals.iter_mut().zip(normals) {
                            rows.set(lane, n);
                        }
                        smooth.dp_du.set(lane, mesh.dp_du_of_edges(r.prim, e1, e2));
                        smooth.sign[lane] = mesh.normal_sign();
                        out.n.set(lane, face_normal(e1.cross(e2), mesh.normal_sign()));
                        smooth.lanes |= 1 << lane;
                        smooth.textured |= u32::from(textured) << lane;
                        continue;
                    }
                } else if let Some(frame) = mesh.flat_frame(r.prim) {
                    flat_uv |= u32::from(textured) << lane;
                    out.set_frame(lane, frame);
                    out.n.set(lane, mesh.geometric_normal(r.prim));
                    flat |= 1 << lane;
                    continue;
                }
            }
            if let Shape::Sphere(sphere) = shape {
                // A sphere's surface needs only the distance, which the packet test computed as the scalar
                // test does.
                centers.set(lane, sphere.center);
                radii[lane] = sphere.radius;
                poles.set(lane, sphere.pole_axis());
                round |= 1 << lane;
                flipped |= u32::from(sphere.flip_normals) << lane;
                round_uv |= u32::from(textured) << lane;
                continue;
            }
            let ray = Ray::new(Vec3::new(o[0][lane], o[1][lane], o[2][lane]), Vec3::new(d[0][lane], d[1][lane], d[2][lane]), f32::INFINITY);
            let Some(si) = self.interaction_at(slot, &ray) else { continue };
            out.p.set(lane, si.p);
            out.n.set(lane, si.n);
            out.set_frame(lane, &si.shading);
            (out.uv[0][lane], out.uv[1][lane]) = (si.uv.x, si.uv.y);
        }
        if flat != 0 {
            // The point.
            let m = Mask8::from_bitmask(flat);
            out.p.store(V3::select(m, ray_point(rays.o, rays.d, hits.t), out.p.lanes()));
            for lane in bits(flat_uv) {
                let r = self.prims.slots[hits.slot[lane] as usize];
                if let Some(map) = self.prims.uv_maps.get(r.uv_map as usize) {
                    let uv = map.at(out.p.get(lane));
                    (out.uv[0][lane], out.uv[1][lane]) = (uv.x, uv.y);
                }
            }
        }
        if smooth.lanes != 0 {
            // The hit found again in lanes, as `interaction_at` finds it for one ray, and the surface there.
            let (hit, p, b1, b2) = smooth.triangles.points_of_rays(rays.o, rays.d);
            let normals = smooth.normals.map(|rows| rows.lanes());
            let ns = smooth_normal(normals, b1, b2, Float8::load(&smooth.sign), out.n.lanes());
            let (s, t) = tangents_along(ns, smooth.dp_du.lanes());
            let m = Mask8::from_bitmask(smooth.lanes) & hit;
            for (rows, v) in [(&mut out.p, p), (&mut out.s, s), (&mut out.t, t), (&mut out.ns, ns)] {
                rows.store(V3::select(m, v, rows.lanes()));
            }
            let (b1, b2) = (b1.to_array(), b2.to_array());
            for lane in bits(smooth.textured & m.bitmask()) {
                let r = self.prims.slots[hits.slot[lane] as usize];
                if let Shape::Mesh(mesh) = &self.shapes[r.shape as usize] {
                    let uv = mesh.uv_at(r.prim, Vec2::new(b1[lane], b2[lane]));
                    (out.uv[0][lane], out.uv[1][lane]) = (uv.x, uv.y);
                }
            }
        }
        if round != 0 {
            let (p, outward) = sphere_surface(rays.o, rays.d, hits.t, centers.lanes(), Float8::load(&radii));
            let n = V3::select(Mask8::from_bitmask(flipped), outward.neg(), outward);
            let (s, t) = sphere_tangents(poles.lanes(), outward, n);
            let m = Mask8::from_bitmask(round);
            for (rows, v) in [(&mut out.p, p), (&mut out.n, n), (&mut out.s, s), (&mut out.t, t), (&mut out.ns, n)] {
                rows.store(V3::select(m, v, rows.lanes()));
            }
            for lane in bits(round_uv) {
                let r = self.prims.slots[hits.slot[lane] as usize];
                if let Shape::Sphere(sphere) = &self.shapes[r.shape as usize] {
                    let uv = sphere.uv_at(if flipped & (1 << lane) != 0 { -out.n.get(lane) } else { out.n.get(lane) });
                    (out.uv[0][lane], out.uv[1][lane]) = (uv.x, uv.y);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Transform;
    use crate::sampling::Pcg32;
    use crate::scene::mitsuba_xml;
    use std::path::Path;

    /// Rectangles (flat, with texture coordinates), a cube, a face-normal mesh without texture coordinates
    /// (a disk is not a mesh: tested again) and spheres, one of each material kind the lanes treat apart; the
    /// cube emits.
    const SCENE: &str = r#"<scene version="3.0.0">
        <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
        <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/><scale value="3"/><translate y="-1"/></transform>
            <bsdf type="diffuse"><texture type="checkerboard" name="reflectance"/></bsdf></shape>
        <shape type="cube"><transform name="to_world"><scale value="0.4"/><rotate y="1" angle="30"/><translate x="0.8"/></transform>
            <emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>
        <shape type="sphere"><point name="center" x="-0.8" y="0" z="0"/><float name="radius" value="0.5"/>
            <transform name="to_world"><rotate x="1" angle="50"/></transform>
            <bsdf type="diffuse"><texture type="checkerboard" name="reflectance"/></bsdf></shape>
        <shape type="sphere"><point name="center" x="0" y="0.9" z="-0.5"/><float name="radius" value="0.3"/><boolean name="flip_normals" value="true"/></shape>
        <shape type="disk"><transform name="to_world"><translate z="-1.5"/></transform></shape>
    </scene>"#;

    /// Eight rays from above the scene of [`SCENE`] towards its shapes.
    fn random_rays(rng: &mut Pcg32) -> [Ray; LANES] {
        std::array::from_fn(|_| {
            let o = Vec3::new(rng.next_f32() * 4.0 - 2.0, rng.next_f32() * 2.0, 3.0);
            let target = Vec3::new(rng.next_f32() * 4.0 - 2.0, rng.next_f32() * 2.0 - 1.0, rng.next_f32() * 2.0 - 1.5);
            Ray::new(o, (target - o).normalize(), f32::INFINITY)
        })
    }

    /// Shapes with the same constant `diffuse` reflectance (through a `<ref>` or equal values) share a
    /// material class; textured, other and differently coloured materials have their own.
    #[test]
    fn equal_diffuse_materials_share_a_class() {
        const CLASSES: &str = r#"<scene version="3.0.0">
            <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
            <bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.8, 0.7, 0.6"/></bsdf>
            <shape type="rectangle"><ref id="white"/></shape>
            <shape type="sphere"><bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
            <shape type="rectangle"><ref id="white"/></shape>
            <shape type="cube"><bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.7, 0.6"/></bsdf></shape>
            <shape type="rectangle"><bsdf type="diffuse"><texture type="checkerboard" name="reflectance"/></bsdf></shape>
            <shape type="rectangle"><bsdf type="conductor"/></shape>
            <shape type="disk"><bsdf type="conductor"/></shape>
        </scene>"#;
        let scene = Scene::build(mitsuba_xml::load_str(CLASSES, "t.xml", Path::new("."), &[]).unwrap()).unwrap();
        assert_eq!(scene.material_class, [0, 1, 0, 0, 4, 5, 6]);
    }

    /// `surfaces_into` on some lanes fills those as `surfaces` would and leaves the other lanes as they were
    /// (the path tracer traces the lanes that freed again before it shades).
    #[test]
    fn surfaces_into_keeps_other_lanes() {
        let scene = Scene::build(mitsuba_xml::load_str(SCENE, "t.xml", Path::new("."), &[]).unwrap()).unwrap();
        let mut rng = Pcg32::new(5, 2);
        let (mut kept, mut refilled) = (0, 0);
        for _ in 0..100 {
            let (first, second) = (RayLanes::from_rays(&random_rays(&mut rng)), RayLanes::from_rays(&random_rays(&mut rng)));
            let mut record = scene.surfaces(&first, &scene.intersect_rays(&first, 0xff), 0xff);
            let before = record;
            let again = rng.next_u32() & 0xff;
            scene.surfaces_into(&second, &scene.intersect_rays(&second, again), again, &mut record);
            let want = scene.surfaces(&second, &scene.intersect_rays(&second, again), again);
            for lane in 0..LANES {
                let (from, bit) = (if again & (1 << lane) != 0 { &want } else { &before }, 1 << lane);
                assert_eq!(record.found & bit, from.found & bit, "lane {lane}");
                assert_eq!(record.emits & bit, from.emits & bit, "lane {lane}");
                if from.found & bit != 0 {
                    assert_eq!(record.interaction(lane, 1.0), from.interaction(lane, 1.0), "lane {lane}");
                    if again & bit != 0 {
                        refilled += 1;
                    } else {
                        kept += 1;
                    }
                }
            }
        }
        assert!(kept > 100 && refilled > 100, "{kept} lanes kept, {refilled} traced again");
    }

    /// The sphere frames in lanes are Mitsuba 3's: s along ∂p/∂u of the turned sphere's parameterisation.
    /// The frames were read from Mitsuba 3.9.1 (`scalar_rgb`, `si.sh_frame`) for the rays from `o` towards
    /// the centre; the last lane is the same sphere's pole.
    #[test]
    fn sphere_frames_in_lanes_are_mitsubas() {
        const TURNED: &str = r#"<scene version="3.0.0">
            <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
            <shape type="sphere"><transform name="to_world"><scale value="1.5"/><rotate x="0.70710678" y="0.70710678" angle="40"/>
                <translate x="0.5" y="-0.2" z="0.1"/></transform></shape>
        </scene>"#;
        let scene = Scene::build(mitsuba_xml::load_str(TURNED, "t.xml", Path::new("."), &[]).unwrap()).unwrap();
        let c = Vec3::new(0.5, -0.2, 0.1);
        let pole = Transform::rotate(Vec3::new(1.0, 1.0, 0.0), 40.0).unwrap().vector(Vec3::Z);
        let frames = [
            (
                Vec3::new(3.5, 0.3, 0.9),
                Vec3::new(-0.285_681_96, 0.740_193_96, 0.608_686_15),
                Vec3::new(-0.091_518_916, -0.653_326_1, 0.751_524_8),
            ),
            (
                Vec3::new(0.8, -3.2, 0.3),
                Vec3::new(0.872_676_1, 0.054_920_882, -0.485_201_18),
                Vec3::new(0.478_099_26, 0.105_936_19, 0.871_893_76),
            ),
            (
                Vec3::new(-1.5, 0.8, 2.1),
                Vec3::new(-0.559_244_2, -0.814_996_3, -0.151_746_1),
                Vec3::new(0.492_748_86, -0.473_993_57, 0.729_745_7),
            ),
        ];
        let rays: [Ray; LANES] = std::array::from_fn(|lane| match frames.get(lane) {
            Some(&(o, _, _)) => Ray::new(o, (c - o).normalize(), f32::INFINITY),
            None => Ray::new(c + pole * 4.0, -pole, f32::INFINITY),
        });
        let lanes = RayLanes::from_rays(&rays);
        let hits = scene.intersect_rays(&lanes, 0xff);
        let got = scene.surfaces(&lanes, &hits, 0xff);
        assert_eq!(got.found, 0xff);
        for (lane, &(_, s, t)) in frames.iter().enumerate() {
            // 2026-12: 2e-5 absorbs the f32 rounding of two renderers computing the same point.
            assert!(
                (got.s.get(lane) - s).length() < 2e-5 && (got.t.get(lane) - t).length() < 2e-5,
                "lane {lane}: {} {}",
                got.s.get(lane),
                got.t.get(lane)
            );
        }
        // At the pole ∂p/∂u vanishes: Duff's frame, finite and orthonormal.
        let f = got.interaction(LANES - 1, 1.0).shading;
        assert!((f.s.cross(f.t) - f.n).length() < 1e-5 && f.s.dot(f.n).abs() < 1e-5, "{f:?}");
    }

    /// A mesh file with vertex normals behind [`SCENE`]'s shapes: a quad whose normals agree (flat-shaded
    /// with them) and a triangle whose normals differ (smooth-shaded).
    const NORMALS_OBJ: &str = "v 0.3 -0.9 -1.0\nv 1.8 -0.9 -1.0\nv 1.8 0.9 -1.0\nv 0.3 0.9 -1.0\n\
        v -1.8 -0.9 -1.2\nv -0.3 -0.9 -1.2\nv -1.05 0.9 -0.8\n\
        vn 0 0 1\nvn 0.3 0 1\nvn -0.3 0 1\nvn 0 0.2 1\n\
        vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.2 0.1\nvt 0.9 0.3\nvt 0.4 0.8\n\
        f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\nf 5/5/2 6/6/3 7/7/4\n";

    /// Each lane of [`Scene::surfaces`] is the interaction [`Scene::intersect`] finds for its ray alone: the
    /// same shape, primitive, point, normals, frame and texture coordinates, bit for bit (with a mesh file
    /// of vertex normals and texture coordinates added, textured, its normals flipped: flat- and
    /// smooth-shaded triangles).
    #[test]
    fn lanes_match_single_rays() {
        let obj = std::env::temp_dir().join(format!("gonio-surfaces-{}.obj", std::process::id()));
        std::fs::write(&obj, NORMALS_OBJ).unwrap();
        let with_obj = SCENE.replace(
            "</scene>",
            &format!(
                r#"<shape type="obj"><string name="filename" value="{}"/><boolean name="flip_normals" value="true"/>
                <bsdf type="diffuse"><texture type="checkerboard" name="reflectance"/></bsdf></shape></scene>"#,
                obj.display()
            ),
        );
        let scene = mitsuba_xml::load_str(&with_obj, "t.xml", Path::new("."), &[]).and_then(Scene::build);
        std::fs::remove_file(&obj).unwrap();
        let scene = scene.unwrap();
        let Some(Shape::Mesh(file_mesh)) = scene.shapes.last() else { panic!("the mesh file's shape") };
        assert!(file_mesh.flat_frame(0).is_some() && file_mesh.flat_frame(1).is_some() && file_mesh.flat_frame(2).is_none());
        let file_shape = scene.shapes.len() as u32 - 1;
        let (mut with_normals_flat, mut with_normals_smooth) = (0, 0);
        let mut rng = Pcg32::new(3, 9);
        let (mut flat, mut other, mut emitting) = (0, 0, 0);
        for _ in 0..200 {
            let rays = random_rays(&mut rng);
            let lanes = RayLanes::from_rays(&rays);
            let live = 0b1011_1111;
            let hits = scene.intersect_rays(&lanes, live);
            let s = scene.surfaces(&lanes, &hits, live);
            for (lane, ray) in rays.iter().enumerate() {
                let want = if live & (1 << lane) != 0 { scene.intersect(ray) } else { None };
                assert_eq!(s.found & (1 << lane) != 0, want.is_some(), "lane {lane}");
                let Some(want) = want else { continue };
                let got = s.interaction(lane, want.t);
                assert_eq!(got, want, "lane {lane}");
                assert_eq!(s.emits & (1 << lane) != 0, scene.shape_lights[want.shape as usize].is_some(), "lane {lane}");
                emitting += usize::from(s.emits & (1 << lane) != 0);
                match &scene.shapes[want.shape as usize] {
                    Shape::Mesh(m) if want.shape == file_shape => {
                        if m.flat_frame(want.prim).is_some() {
                            with_normals_flat += 1;
                        } else {
                            with_normals_smooth += 1;
                        }
                    }
                    Shape::Mesh(_) => flat += 1,
                    _ => other += 1,
                }
            }
        }
        assert!(flat > 300 && other > 100 && emitting > 20, "{flat} mesh, {other} other and {emitting} emitter hits");
        assert!(
            with_normals_flat > 20 && with_normals_smooth > 20,
            "{with_normals_flat} flat and {with_normals_smooth} smooth hits on the mesh with normals"
        );
    }
}
