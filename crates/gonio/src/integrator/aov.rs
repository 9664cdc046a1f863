//! `aov` — Mitsuba 3's arbitrary output variables (its `src/integrators/aov.cpp`): values of the surface
//! each camera ray hits first, as further channels of the film beside the image of nested integrators.
//!
//! | parameter          | type   | default    | meaning                                                        |
//! |--------------------|--------|------------|----------------------------------------------------------------|
//! | `aovs`             | string | (required) | `name:type` pairs separated by commas or spaces, e.g. `"dd.y:depth, nn:sh_normal"` |
//! | nested integrators | plugin | none       | any number of `path` or `direct`, each under its parameter name (`_arg_0`, … when unnamed) |
//!
//! The film's channels, in Mitsuba 3.9.1's order ([`IntegratorKind::channels`]): `R`, `G`, `B` (the first
//! nested integrator's image, what it renders alone; black without one), then for each nested integrator
//! `name.R`, `name.G`, `name.B`, `name.A`, then for each entry of `aovs` its channels. (The image is that
//! one bit for bit, except where a `prim_index` or `uv` output changes which pairs of triangles the BVH
//! tests as one parallelogram — none for `prim_index`, only those whose texture coordinates agree for
//! `uv` —: the same hits, to rounding.)
//!
//! | type          | channels        | value at the camera ray's first hit                                     |
//! |---------------|-----------------|-------------------------------------------------------------------------|
//! | `depth`       | `name.T`        | the distance along the (unit) ray from its origin on the near plane, as Mitsuba's cameras start rays there |
//! | `position`    | `name.X, .Y, .Z`| the point, world space                                                  |
//! | `uv`          | `name.U, .V`    | the texture coordinates                                                 |
//! | `geo_normal`  | `name.X, .Y, .Z`| the geometric normal (the shape's outward side, after `flip_normals`)   |
//! | `sh_normal`   | `name.X, .Y, .Z`| the shading normal (interpolated vertex normals on smooth meshes)       |
//! | `prim_index`  | `name.I`        | the triangle's index in its mesh (0 on spheres, disks, cylinders)       |
//! | `shape_index` | `name.I`        | the shape's position among the scene's shapes, from 1, in file order    |
//!
//! Where the ray hits nothing every output is 0, as in Mitsuba 3 (which zeroes the interaction record there).
//! A nested integrator's `A` is Mitsuba's validity of its sample: 1 where the camera ray hits a surface, and
//! for `path` also where it escapes to an environment emitter that is not hidden (`hide_emitters`); else 0.
//! Every channel is splatted with the film's reconstruction filter as the colour is (Mitsuba 3's film treats
//! its channels alike), so at silhouettes depths and indices are fractional mixtures, as Mitsuba's
//! documentation warns for the indices.
//!
//! `shape_index` is what Mitsuba 3's JIT variants write (a shape's registry id: 1, 2, … in the order the
//! scene creates its shapes, measured with 3.9.1 `llvm_ad_rgb`); its scalar variants write the low bits of
//! a pointer. Mitsuba's `albedo`, `dp_du`, `dp_dv`, `duv_dx`, `duv_dy` and `boundary_test` are refused when
//! the scene is read, naming the place.
//!
//! ```
//! use gonio::scene::{mitsuba_xml, IntegratorKind, Scene};
//! let xml = r#"<scene version="3.0.0">
//!     <integrator type="aov"><string name="aovs" value="dd.y:depth, nn:sh_normal"/>
//!         <integrator type="path" name="image"/></integrator>
//!     <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/>
//!         <integer name="height" value="4"/></film></sensor>
//!     <shape type="sphere"/></scene>"#;
//! let scene = Scene::build(mitsuba_xml::load_str(xml, "aov.xml", std::path::Path::new("."), &[]).unwrap()).unwrap();
//! let names = scene.integrator.channels();
//! assert_eq!(names, ["R", "G", "B", "image.R", "image.G", "image.B", "image.A", "dd.y.T", "nn.X", "nn.Y", "nn.Z"]);
//! ```

use super::{radiance_by, start, CameraSample};
use crate::scene::{AovKind, IntegratorKind, Scene};
use crate::spectrum::Rgb;

/// The channels after `R`, `G`, `B` ([`IntegratorKind::channels`]) of each camera sample: `out` holds
/// `channels − 3` values per sample, in `samples`' order. `rgb` is what [`super::radiance`] gave the samples
/// (the first nested integrator's radiance); the other nested integrators render theirs here, from the
/// same random streams. Nothing to do for integrators other than `aov`.
pub fn channels(scene: &Scene, seed: u64, samples: &[CameraSample], rgb: &[Rgb], out: &mut [f32]) {
    let IntegratorKind::Aov { integrators, outputs } = &scene.integrator else { return };
    let k = scene.integrator.channels().len() - 3;
    debug_assert_eq!((rgb.len(), out.len()), (samples.len(), k * samples.len()));
    let mut others = vec![vec![Rgb::ZERO; samples.len()]; integrators.len().saturating_sub(1)];
    for ((_, kind), l) in integrators.iter().skip(1).zip(&mut others) {
        radiance_by(kind, scene, seed, samples, l);
    }
    for (i, (s, v)) in samples.iter().zip(out.chunks_exact_mut(k.max(1))).enumerate() {
        // The sample's camera ray (the one its paths start with) and its first hit.
        let (ray, _) = start(scene, seed, *s);
        let hit = scene.intersect(&ray);
        let mut at = 0;
        let mut put = |values: &[f32]| {
            v[at..at + values.len()].copy_from_slice(values);
            at += values.len();
        };
        for (j, (_, kind)) in integrators.iter().enumerate() {
            let l = if j == 0 { rgb[i] } else { others[j - 1][i] };
            let sky = matches!(kind, IntegratorKind::Path { hide_emitters: false, .. }) && scene.environment.is_some();
            put(&[l.0[0], l.0[1], l.0[2], if hit.is_some() || sky { 1.0 } else { 0.0 }]);
        }
        for aov in outputs {
            let Some(si) = &hit else {
                put(&[0.0; 3][..aov.kind.suffixes().len()]);
                continue;
            };
            match aov.kind {
                AovKind::Depth => put(&[si.t]),
                AovKind::Position => put(&si.p.to_array()),
                AovKind::Uv => put(&si.uv.to_array()),
                AovKind::GeoNormal => put(&si.n.to_array()),
                AovKind::ShNormal => put(&si.shading.n.to_array()),
                AovKind::PrimIndex => put(&[si.prim as f32]),
                AovKind::ShapeIndex => put(&[(si.shape + 1) as f32]),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::render;
    use crate::scene::mitsuba_xml;
    use std::f32::consts::PI;
    use std::path::Path;
    use std::sync::atomic::AtomicBool;

    /// An orthographic camera at z = 5 looking down −z over [−1, 1]² (`size`² pixels, `rfilter` as given): a
    /// rectangle over [0, 1] × [−½, ½] at z = 0 and a sphere of radius 0.4 at (−½, ½, 0); the rest is
    /// empty. Mitsuba 3.9.1 (`llvm_ad_rgb`) renders the same scene with depth 4.99 on the rectangle,
    /// shape indices 1 and 2, and the rectangle's triangle 1 above its diagonal y = x.
    fn scene(integrator: &str, rfilter: &str, size: u32) -> Scene {
        let xml = format!(
            r#"<scene version="3.0.0">{integrator}
            <sensor type="orthographic"><transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
                <film type="hdrfilm"><integer name="width" value="{size}"/><integer name="height" value="{size}"/><rfilter type="{rfilter}"/></film>
                <sampler type="independent"><integer name="sample_count" value="16"/></sampler></sensor>
            <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><translate x="0.5"/></transform></shape>
            <shape type="sphere"><point name="center" x="-0.5" y="0.5" z="0"/><float name="radius" value="0.4"/></shape>
            <emitter type="point"><point name="position" x="0" y="0" z="3"/><rgb name="intensity" value="5"/></emitter>
            </scene>"#
        );
        Scene::build(mitsuba_xml::load_str(&xml, "aov.xml", Path::new("."), &[]).unwrap()).unwrap()
    }

    const ALL: &str = r#"<integrator type="aov">
        <string name="aovs" value="d:depth, p:position, uv:uv, ng:geo_normal, ns:sh_normal, pi:prim_index, si:shape_index"/>
        <integrator type="path" name="image"/><integrator type="direct" name="second"/></integrator>"#;

    /// The values at the first hit of each camera ray, against their closed forms from the ray (origin
    /// (x, y, 4.99) on the near plane, direction −z): on the rectangle depth 4.99, the point, uv =
    /// ((x_local + 1)/2, (y_local + 1)/2), normals +z, triangle 1 where y_local > x_local; on the sphere
    /// depth 4.99 − √(r² − ρ²), normals (p − c)/r, uv = (φ/2π, θ/π); zero where nothing is hit.
    #[test]
    fn outputs_are_the_first_hits_closed_forms() {
        let scene = scene(ALL, "box", 8);
        assert_eq!(scene.integrator.channels().len(), 3 + 8 + 14);
        let samples: Vec<CameraSample> = (0..64 * 64).map(|i| CameraSample { x: i % 8, y: (i / 8) % 8, k: i / 64 }).collect();
        let rgb: Vec<Rgb> = (0..samples.len()).map(|i| Rgb::splat(i as f32)).collect();
        let mut out = vec![f32::NAN; 22 * samples.len()];
        channels(&scene, 7, &samples, &rgb, &mut out);
        let mut second = vec![Rgb::ZERO; samples.len()];
        radiance_by(
            &IntegratorKind::Direct { emitter_samples: 1, bsdf_samples: 1, hide_emitters: false },
            &scene,
            7,
            &samples,
            &mut second,
        );
        let (mut on_rectangle, mut on_sphere, mut missed) = (0, 0, 0);
        for (i, (s, v)) in samples.iter().zip(out.chunks_exact(22)).enumerate() {
            let (ray, _) = start(&scene, 7, *s);
            let (x, y) = (ray.o.x, ray.o.y);
            assert!((ray.o.z - 4.99).abs() < 1e-6 && ray.d == glam::Vec3::NEG_Z, "{ray:?}");
            let (xl, yl) = ((x - 0.5) / 0.5, y / 0.5);
            let rho2 = (x + 0.5).powi(2) + (y - 0.5).powi(2);
            // Rays within 1e-4 of an edge are left out: f32 rounding may put them on either side.
            let (inside, outside) = (xl.abs().max(yl.abs()) < 1.0 - 1e-4, xl.abs().max(yl.abs()) > 1.0 + 1e-4);
            let (round, not_round) = (rho2.sqrt() < 0.4 - 1e-4, rho2.sqrt() > 0.4 + 1e-4);
            let want: Vec<f32> = if inside {
                on_rectangle += 1;
                let u = [(xl + 1.0) / 2.0, (yl + 1.0) / 2.0];
                // (On the diagonal, either triangle.)
                let prim = if (yl - xl).abs() < 1e-4 { v[20] } else { f32::from(u8::from(yl > xl)) };
                [&[4.99, x, y, 0.0], &u[..], &[0.0, 0.0, 1.0, 0.0, 0.0, 1.0, prim, 1.0]].concat()
            } else if round && outside {
                on_sphere += 1;
                let z = (0.16 - rho2).sqrt();
                let n = glam::Vec3::new(x + 0.5, y - 0.5, z) / 0.4;
                let phi = n.y.atan2(n.x).rem_euclid(2.0 * PI);
                [&[4.99 - z, x, y, z, phi / (2.0 * PI), n.z.acos() / PI], &n.to_array()[..], &n.to_array()[..], &[0.0, 2.0]].concat()
            } else if outside && not_round {
                missed += 1;
                vec![0.0; 14]
            } else {
                continue;
            };
            let hit = if want[0] > 0.0 { 1.0 } else { 0.0 };
            let nested = [rgb[i].0[0], rgb[i].0[1], rgb[i].0[2], hit, second[i].0[0], second[i].0[1], second[i].0[2], hit];
            assert_eq!(v[..8], nested, "sample {s:?}");
            for (c, (got, want)) in v[8..].iter().zip(&want).enumerate() {
                // f32 rounding of the hit and its normal: a few ulps of values up to 5.
                assert!((got - want).abs() < 2e-5, "sample {s:?}: channel {} is {got}, want {want}", scene.integrator.channels()[11 + c]);
            }
        }
        assert!(on_rectangle > 800 && on_sphere > 500 && missed > 1500, "{on_rectangle} {on_sphere} {missed}");
    }

    /// The film: RGB is the nested `path` integrator's image bit for bit, and every channel is filtered as
    /// the colour: with the box filter a pixel wholly on the rectangle holds its depth and indices exactly,
    /// one wholly off everything zeros, one cut by the rectangle's diagonal a fraction (as in Mitsuba);
    /// with the Gaussian, a pixel whose whole footprint lies on the rectangle its depth.
    #[test]
    fn the_film_filters_every_channel_and_keeps_the_nested_image() {
        let no = AtomicBool::new(false);
        for rfilter in ["box", "gaussian"] {
            let alone = render(&scene(r#"<integrator type="path"/>"#, rfilter, 16), 16, 3, &no, &|_| {});
            let aov = render(&scene(ALL, rfilter, 16), 16, 3, &no, &|_| {});
            assert_eq!(aov.data, alone.data, "{rfilter}");
            assert!(alone.aovs.names.is_empty());
            let names = &aov.aovs.names;
            assert_eq!(names[..8], ["image.R", "image.G", "image.B", "image.A", "second.R", "second.G", "second.B", "second.A"]);
            assert_eq!(
                names[8..],
                ["d.T", "p.X", "p.Y", "p.Z", "uv.U", "uv.V", "ng.X", "ng.Y", "ng.Z", "ns.X", "ns.Y", "ns.Z", "pi.I", "si.I"]
            );
            assert_eq!(aov.aovs.data.len(), 22 * 16 * 16);
            let at = |x: usize, y: usize, name: &str| aov.aovs.data[22 * (16 * y + x) + names.iter().position(|n| n == name).unwrap()];
            for x in 0..16 {
                for y in 0..16 {
                    let rgb = &aov.data[3 * (16 * y + x)..3 * (16 * y + x + 1)];
                    assert_eq!([at(x, y, "image.R"), at(x, y, "image.G"), at(x, y, "image.B")], rgb, "({x}, {y})");
                }
            }
            // Pixel (12, 8) spans x ∈ [0.5, 0.625], y ∈ [−0.125, 0]: the rectangle's lower triangle only;
            // the Gaussian's footprint around it (2.5 pixels) still lies on the rectangle.
            let depth = at(12, 8, "d.T");
            assert!((depth - 4.99).abs() < if rfilter == "box" { 1e-7 } else { 1e-6 }, "{rfilter}: {depth}");
            assert_eq!([at(12, 8, "image.A"), at(12, 8, "ng.Z"), at(12, 8, "ns.Z"), at(12, 8, "si.I")], [1.0; 4], "{rfilter}");
            if rfilter == "box" {
                assert_eq!(at(12, 8, "pi.I"), 0.0);
                // Pixel (12, 15) lies below the rectangle, wholly off every shape.
                assert!(aov.aovs.data[22 * (16 * 15 + 12)..22 * (16 * 15 + 13)].iter().all(|&v| v == 0.0));
                // Pixel (12, 7) is cut in half by the diagonal.
                let pi = at(12, 7, "pi.I");
                assert!(pi > 0.0 && pi < 1.0, "{pi}");
            }
        }
    }
}
