//! From plugin descriptions to scene objects: shapes (with their BSDF and area light), lights, the
//! sensor with its film and sampler, and the integrator. Every plugin type or parameter gonio does not
//! know is an error naming the place in the file.

use super::mitsuba_xml::SceneDescription;
use super::spectral::{check_bsdf, given_spectra, Dependence, GivenSpectra, Mode};
use super::{Aov, AovKind, IntegratorKind, Material, SamplerSpec, Scene};
use crate::bsdf::{Bsdf, Diffuse};
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::film::FilmSpec;
use crate::geometry::builtin_meshes::{cube, rectangle};
use crate::geometry::cylinder::{Cylinder, CylinderError};
use crate::geometry::disk::Disk;
use crate::geometry::sdf_grid::{read_vol, SdfGrid};
use crate::geometry::sphere::Sphere;
use crate::geometry::{Mesh, Shape};
use crate::light::{AreaLight, ConstantLight, DirectionalLight, EnvMap, Light, PointLight, ProjectorLight, SpotLight};
use crate::math::Transform;
use crate::props::{Props, EMISSION};
use crate::spectrum::illuminant::Spectrum;
use crate::spectrum::Rgb;
use glam::Vec3;
use std::sync::Arc;

const SHAPES: &str = "sphere, rectangle, cube, disk, cylinder, obj, ply, serialized, sdfgrid, shapegroup, instance";

impl Scene {
    /// Build every plugin of a parsed scene.
    pub fn build(desc: SceneDescription) -> Result<Scene> {
        Scene::build_in(desc, Mode::Rgb)
    }

    /// [`Scene::build`] for rendering in `mode`.
    ///
    /// # Errors
    /// Also, in spectral mode, a material it does not take yet ([`super::spectral::check_bsdf`]).
    pub fn build_in(desc: SceneDescription, mode: Mode) -> Result<Scene> {
        let mut warnings = desc.warnings.clone();
        // The shapes' bitmaps decoded together, in parallel, and held until the shapes are built.
        let mut files = Vec::new();
        for p in &desc.shapes {
            bitmap_files(p, &mut files);
        }
        let _decoded = crate::texture::bitmap::decode_images(&files);
        let mut built = Built { mode, ..Built::default() };
        for p in &desc.shapes {
            match p.plugin_type() {
                // A declaration for the instances that `<ref>` it; its shapes are built by each instance.
                "shapegroup" => check_shape_group(p)?,
                "instance" => {
                    let to_world = p.transform("to_world")?;
                    let groups = p.nested_of("shape");
                    let group = match groups.as_slice() {
                        [g] if g.plugin_type() == "shapegroup" => g,
                        _ => return Err(Error::spec(p.at(), "an `instance` takes one <ref id=\"…\"> to a `shapegroup`")),
                    };
                    for s in group.nested_of("shape") {
                        built.add(s, &to_world)?;
                    }
                    p.finish()?;
                }
                _ => built.add(p, &Transform::IDENTITY)?,
            }
        }
        let Built { shapes, materials, shape_lights, mut lights, dependence, colours, mut light_spectra, .. } = built;
        for e in &desc.emitters {
            let light = light_from_props(e)?;
            if light.is_environment() && lights.iter().any(Light::is_environment) {
                return Err(Error::spec(e.at(), "a scene takes at most one environment emitter"));
            }
            lights.push(light);
            light_spectra.push(EMISSION.iter().find_map(|name| e.spectrum(name)));
        }
        let sensor = desc.sensor.as_ref().ok_or_else(|| Error::spec(&desc.source, "the scene has no <sensor>"))?;
        let film = match sensor.nested_of("film").as_slice() {
            [] => FilmSpec::mitsuba_default(),
            [f] => FilmSpec::from_props(f, &mut warnings)?,
            [_, second, ..] => return Err(Error::spec(second.at(), "a sensor takes one <film>")),
        };
        let sampler = match sensor.nested_of("sampler").as_slice() {
            [] => SamplerSpec { sample_count: 4, seed: 0 },
            [s] => sampler_from_props(s, &mut warnings)?,
            [_, second, ..] => return Err(Error::spec(second.at(), "a sensor takes one <sampler>")),
        };
        let camera = Camera::from_props(sensor, film.width, film.height)?;
        sensor.finish()?;
        let integrator = match &desc.integrator {
            Some(p) => integrator_from_props(p)?,
            None => IntegratorKind::Path { max_depth: -1, rr_depth: 5, hide_emitters: false },
        };
        if let (Some(IntegratorKind::Direct { emitter_samples: n @ 2.., .. }), Some(p)) = (integrator.rgb(), &desc.integrator) {
            if lights.iter().any(Light::is_delta) {
                // Mitsuba 3's `direct` gives a delta light's sample the MIS weight 1 instead of 1/n
                // (`src/integrators/direct.cpp`: `select(ds.delta, 1, mis_weight(…) * m_weight_lum)`), so
                // with n emitter samples point, spot and directional lights count n times (3.9.1 renders
                // `scenes/hello.xml` 4.0× brighter with emitter_samples = 4 than with 1). gonio averages the
                // n samples, the estimate the file asks for.
                warnings.push(format!(
                    "{}: `direct` with emitter_samples = {n} and a point, spot or directional light: Mitsuba 3 counts each of \
                     that light's samples at full weight ({n}× brighter); gonio averages them",
                    p.at()
                ));
            }
        }
        let mut scene = Scene::assemble(shapes, materials, shape_lights, lights, camera, film, sampler, integrator, warnings);
        if mode == Mode::Spectral {
            if matches!(scene.integrator, IntegratorKind::Aov { .. }) {
                return Err(Error::spec(&desc.source, "spectral mode renders the `path` and `direct` integrators; `aov` needs --mode rgb"));
            }
            scene.make_spectral(dependence, colours, &light_spectra);
        }
        Ok(scene)
    }
}

/// The shapes of a scene as they are built, with their materials, their area lights' indices and the
/// lights so far.
#[derive(Default)]
struct Built {
    shapes: Vec<Shape>,
    materials: Vec<Material>,
    shape_lights: Vec<Option<u32>>,
    lights: Vec<Light>,
    mode: Mode,
    /// In spectral mode, how each material depends on wavelength ([`super::spectral::check_bsdf`]).
    dependence: Vec<Dependence>,
    /// In spectral mode, the colours each material was given as tables ([`super::spectral::given_spectra`]).
    colours: Vec<GivenSpectra>,
    /// Per light, the spectrum its emission was given as, where an `<emitter>`'s `<spectrum>` gave one.
    light_spectra: Vec<Option<Arc<Spectrum>>>,
}

impl Built {
    /// Add shape `p`, placed by `outer` after its own `to_world` (an instance's transform, or the identity).
    fn add(&mut self, p: &Props, outer: &Transform) -> Result<()> {
        self.shapes.push(shape_from_props(p, outer)?);
        let (nested, emitters) = (p.nested_of("bsdf"), p.nested_of("emitter"));
        // Without a <bsdf>, Mitsuba 3 gives a shape a `diffuse` of reflectance 0.5, and an emitting shape
        // one of reflectance 0 (its `Shape` constructor): a light that reflects nothing. (Until
        // 2026-12-03 gonio gave lights 0.5 too: the material spheres' light reflected the floor's light
        // back onto it: 0.4 % of the image's mean, 1 % of the near floor's brightness, against Mitsuba's.)
        let default_reflectance = if emitters.is_empty() { 0.5 } else { 0.0 };
        self.materials.push(match nested.as_slice() {
            [] => Material::Fixed(Bsdf::Diffuse(Diffuse::new(Rgb::splat(default_reflectance)))),
            [one] => Material::from_props(one)?,
            [_, second, ..] => return Err(Error::spec(second.at(), "a shape takes one <bsdf>")),
        });
        if self.mode == Mode::Spectral {
            self.dependence.push(match nested.as_slice() {
                [one] => check_bsdf(one)?,
                _ => Dependence::None,
            });
            self.colours.push(match nested.as_slice() {
                [one] => given_spectra(one),
                _ => GivenSpectra::NONE,
            });
        }
        if let (Some(material), Some(shape)) = (self.materials.last(), self.shapes.last()) {
            for m in material.mesh_attributes() {
                let names: Vec<&str> = match shape {
                    Shape::Mesh(mesh) => mesh.attributes().iter().map(|a| a.name.as_str()).collect(),
                    _ => Vec::new(),
                };
                if !names.contains(&m.name.as_str()) {
                    let has = if names.is_empty() { "none".to_string() } else { names.join(", ") };
                    return Err(Error::spec(
                        m.at.as_str(),
                        format!("mesh_attribute `{}`: the shape at {} has no such attribute (it has: {has})", m.name, p.at()),
                    ));
                }
            }
        }
        self.shape_lights.push(match emitters.as_slice() {
            [] => None,
            [e] => {
                if matches!(self.shapes.last(), Some(Shape::SdfGrid(_))) {
                    return Err(Error::spec(e.at(), "an `sdfgrid` cannot be an area light (as in Mitsuba 3: it has no area to sample)"));
                }
                if e.plugin_type() != "area" {
                    return Err(Error::spec(e.at(), format!("a shape can only carry an `area` emitter, not `{}`", e.plugin_type())));
                }
                let radiance = e.rgb_in("radiance", Rgb::ONE, 0.0, f32::MAX)?;
                e.finish()?;
                self.lights.push(Light::Area(AreaLight { shape: (self.shapes.len() - 1) as u32, radiance }));
                self.light_spectra.push(e.spectrum("radiance"));
                Some((self.lights.len() - 1) as u32)
            }
            [_, second, ..] => return Err(Error::spec(second.at(), "a shape takes one <emitter>")),
        });
        p.finish()?;
        Ok(())
    }
}

/// The files of the `bitmap` textures in `p` and the descriptions nested in it.
fn bitmap_files(p: &Props, out: &mut Vec<String>) {
    if p.plugin_type() == "bitmap" {
        if let Ok(Some(file)) = p.string("filename") {
            out.push(file);
        }
    }
    for nested in p.nested() {
        bitmap_files(nested, out);
    }
}

/// Check a `shapegroup`: shapes only, none of them a group or carrying an emitter (Mitsuba 3 refuses
/// both: instances share their shapes, and an instanced light would need its own area and sampling).
fn check_shape_group(g: &Props) -> Result<()> {
    for s in g.nested() {
        if s.class() != "shape" {
            return Err(Error::spec(s.at(), format!("a `shapegroup` holds shapes only, not a <{}>", s.class())));
        }
        if matches!(s.plugin_type(), "shapegroup" | "instance") {
            return Err(Error::spec(s.at(), format!("a `shapegroup` cannot hold a `{}` (no nested instancing)", s.plugin_type())));
        }
        if let Some(e) = s.nested_of("emitter").first() {
            return Err(Error::spec(
                e.at(),
                "a shape in a `shapegroup` cannot carry an emitter (instanced lights are not supported, as in Mitsuba 3)",
            ));
        }
    }
    g.finish()
}

fn shape_from_props(p: &Props, outer: &Transform) -> Result<Shape> {
    let to_world = outer.then_after(p.transform("to_world")?);
    let flip = p.bool("flip_normals", false)?;
    let at = p.at();
    Ok(match p.plugin_type() {
        "sphere" => {
            let center = p.vector("center")?.unwrap_or(Vec3::ZERO);
            let radius = p.float_positive("radius", 1.0)?;
            Shape::Sphere(Sphere::new(center, radius, to_world, flip).ok_or_else(|| {
                Error::spec(
                    p.at_param("to_world"),
                    "a sphere's `to_world` must scale uniformly (rotate, translate and scale by one factor)",
                )
            })?)
        }
        "rectangle" => Shape::Mesh(rectangle(&to_world, flip, at)?),
        "cube" => Shape::Mesh(cube(&to_world, flip, at)?),
        "disk" => Shape::Disk(Disk::new(to_world, flip)),
        "cylinder" => {
            let p0 = p.vector("p0")?.unwrap_or(Vec3::ZERO);
            let p1 = p.vector("p1")?.unwrap_or(Vec3::Z);
            let radius = p.float_positive("radius", 1.0)?;
            Shape::Cylinder(Cylinder::new(p0, p1, radius, to_world, flip).map_err(|e| match e {
                CylinderError::NoAxis => Error::spec(
                    p.at_param(if p.has("p1") { "p1" } else { "p0" }),
                    format!("a cylinder's `p0` and `p1` must differ (its axis runs from one to the other), got {p0} and {p1}"),
                ),
                CylinderError::NotCircular => Error::spec(
                    p.at_param("to_world"),
                    "a cylinder's `to_world` must keep its cross-section a circle (rotate, translate, scale x and y by one factor; no shear)",
                ),
            })?)
        }
        "sdfgrid" => {
            let filename = p.string("filename")?.ok_or_else(|| Error::spec(at, "`sdfgrid` needs a `filename` (a grid volume file)"))?;
            let smooth = match p.string("normals")?.as_deref() {
                None | Some("smooth") => true,
                Some("analytic") => false,
                Some(other) => {
                    return Err(Error::spec(p.at_param("normals"), format!("`normals` is `smooth` or `analytic`, got `{other}`")))
                }
            };
            let place = format!("{}: {filename}", p.at_param("filename"));
            let bytes =
                std::fs::read(&filename).map_err(|e| Error::spec(p.at_param("filename"), format!("cannot read {filename}: {e}")))?;
            let (res, values) = read_vol(&bytes).map_err(|e| Error::spec(p.at_param("filename"), format!("{filename}: {e}")))?;
            Shape::SdfGrid(SdfGrid::new(res, values, to_world, smooth, flip).map_err(|e| Error::spec(place.as_str(), e.to_string()))?)
        }
        kind @ ("obj" | "ply" | "serialized") => {
            let filename = p.string("filename")?.ok_or_else(|| Error::spec(at, format!("`{kind}` needs a `filename`")))?;
            let face_normals = p.bool("face_normals", false)?;
            // Mitsuba's OBJ loader flips v (v ↦ 1 − v) by default; mesh_io returns the file's values.
            let flip_tex = if kind == "obj" { p.bool("flip_tex_coords", true)? } else { false };
            // Mitsuba's `serialized` picks one mesh of a multi-mesh file by `shape_index` (0-based).
            let shape_index = if kind == "serialized" { p.integer_in("shape_index", 0, 0, i64::from(u32::MAX))? as usize } else { 0 };
            let data = super::mesh_files::load(kind, std::path::Path::new(&filename), shape_index, p.at_param("filename"))?;
            let uvs = data.uvs.map(|uv| uv.into_iter().map(|t| if flip_tex { glam::Vec2::new(t.x, 1.0 - t.y) } else { t }).collect());
            Shape::Mesh(
                Mesh::from_file_data(
                    data.positions,
                    data.normals,
                    uvs,
                    data.indices,
                    &to_world,
                    face_normals,
                    flip,
                    &format!("{at} ({filename})"),
                )?
                .with_attributes(data.attributes),
            )
        }
        other => return Err(Error::spec(at, format!("unsupported shape `{other}` (gonio has: {SHAPES})"))),
    })
}

fn light_from_props(e: &Props) -> Result<Light> {
    let light = match e.plugin_type() {
        "point" => {
            let to_world = e.transform("to_world")?;
            let position = match e.vector("position")? {
                Some(p) if e.has("to_world") => {
                    return Err(Error::spec(e.at_param("position"), format!("give `position` or `to_world`, not both (position {p})")))
                }
                Some(p) => p,
                None => to_world.point(Vec3::ZERO),
            };
            Light::Point(PointLight { position, intensity: e.rgb_in("intensity", Rgb::ONE, 0.0, f32::MAX)? })
        }
        "spot" => Light::Spot(SpotLight::from_props(e)?),
        "projector" => Light::Projector(ProjectorLight::from_props(e)?),
        "directional" => Light::Directional(DirectionalLight::from_props(e)?),
        "constant" => Light::Constant(ConstantLight { radiance: e.rgb_in("radiance", Rgb::ONE, 0.0, f32::MAX)? }),
        "envmap" => Light::EnvMap(EnvMap::from_props(e)?),
        "area" => return Err(Error::spec(e.at(), "an `area` emitter must be nested in a <shape>")),
        other => {
            return Err(Error::spec(
                e.at(),
                format!("unsupported emitter `{other}` (gonio has: area, point, spot, projector, directional, constant, envmap)"),
            ))
        }
    };
    e.finish()?;
    Ok(light)
}

/// The sampler: `independent`, or one of Mitsuba's stratified samplers, whose sample count gonio rounds
/// as Mitsuba 3.9.1 does (so a file renders with the spp Mitsuba uses) but whose samples it draws
/// independently, with a warning: the same expected image, with the independent sampler's noise.
fn sampler_from_props(s: &Props, warnings: &mut Vec<String>) -> Result<SamplerSpec> {
    let kind = s.plugin_type();
    if !matches!(kind, "independent" | "stratified" | "multijitter" | "orthogonal" | "ldsampler") {
        return Err(Error::spec(
            s.at(),
            format!("unsupported sampler `{kind}` (gonio has: independent; stratified, multijitter, orthogonal and ldsampler sampled independently)"),
        ));
    }
    let requested = s.integer_in("sample_count", 4, 1, i64::from(u32::MAX))? as u32;
    let seed = s.integer_in("seed", 0, 0, i64::MAX)? as u64;
    if matches!(kind, "stratified" | "multijitter" | "orthogonal") {
        let _ = s.bool("jitter", true)?;
    }
    if kind == "orthogonal" {
        // Mitsuba builds orthogonal arrays of strength 2 only.
        let _ = s.integer_in("strength", 2, 2, 2)?;
    }
    let sample_count = u32::try_from(mitsuba_sample_count(kind, requested)).map_err(|_| {
        Error::spec(
            s.at_param("sample_count"),
            format!("`{kind}` rounds `sample_count` {requested} up to more than {} samples per pixel", u32::MAX),
        )
    })?;
    if kind != "independent" {
        warnings.push(format!(
            "{}: sampler `{kind}` is sampled independently by gonio ({sample_count} spp, as Mitsuba rounds {requested}): \
             the same expected image, with more noise than Mitsuba's",
            s.at()
        ));
    }
    s.finish()?;
    Ok(SamplerSpec { sample_count, seed })
}

/// The sample count Mitsuba 3.9.1's samplers use for a requested `n` (`Sampler::sample_count()` after
/// loading): `stratified` ⌈√n⌉², `multijitter` a × ⌈n / a⌉ with a = ⌈√n⌉, `ldsampler` the next power of two,
/// `orthogonal` p² for the smallest prime p with p² ≥ n (Bose's construction of strength 2).
/// In u64: the rounded count of a `u32` request may not fit a `u32`.
fn mitsuba_sample_count(kind: &str, n: u32) -> u64 {
    let n = u64::from(n);
    let root = (1..=n).find(|r| r * r >= n).unwrap_or(1);
    match kind {
        "stratified" => root * root,
        "multijitter" => root * n.div_ceil(root),
        "ldsampler" => n.next_power_of_two(),
        "orthogonal" => {
            let is_prime = |p: u64| p >= 2 && (2..p).take_while(|d| d * d <= p).all(|d| p % d != 0);
            let p = (root..).find(|&p| is_prime(p)).unwrap_or(root);
            p * p
        }
        _ => n,
    }
}

fn integrator_from_props(p: &Props) -> Result<IntegratorKind> {
    let kind = match p.plugin_type() {
        "moment" => {
            // Mitsuba's `moment` adds the second moment as extra channels; gonio renders the inner integrator.
            let inner = p.nested_of("integrator");
            match inner.as_slice() {
                [one] => integrator_from_props(one)?,
                _ => return Err(Error::spec(p.at(), format!("`moment` needs exactly one nested <integrator>, got {}", inner.len()))),
            }
        }
        "path" => IntegratorKind::Path {
            max_depth: p.integer_in("max_depth", -1, -1, i64::from(i32::MAX))? as i32,
            rr_depth: p.integer_in("rr_depth", 5, 1, i64::from(i32::MAX))? as i32,
            hide_emitters: p.bool("hide_emitters", false)?,
        },
        "direct" => {
            let shading = p.integer_in("shading_samples", 1, 0, 1 << 20)? as u32;
            IntegratorKind::Direct {
                emitter_samples: p.integer_in("emitter_samples", i64::from(shading), 0, 1 << 20)? as u32,
                bsdf_samples: p.integer_in("bsdf_samples", i64::from(shading), 0, 1 << 20)? as u32,
                hide_emitters: p.bool("hide_emitters", false)?,
            }
        }
        "aov" => aov_from_props(p)?,
        other => return Err(Error::spec(p.at(), format!("unsupported integrator `{other}` (gonio has: path, direct, moment, aov)"))),
    };
    p.finish()?;
    Ok(kind)
}

/// Mitsuba 3's `aov` integrator: `aovs`, a list of `name:type` separated by commas or spaces (as Mitsuba
/// splits it), and nested integrators (`path` or `direct`), named by their parameter names. Every channel
/// name must be new.
fn aov_from_props(p: &Props) -> Result<IntegratorKind> {
    let kinds = || AovKind::ALL.map(|(_, name, _)| name).join(", ");
    let list =
        p.string("aovs")?.ok_or_else(|| Error::spec(p.at(), format!("`aov` needs `aovs`, a list of name:type (types: {})", kinds())))?;
    let at = p.at_param("aovs");
    let mut outputs = Vec::new();
    for item in list.split([',', ' ', '\t', '\n']).filter(|t| !t.is_empty()) {
        let Some((name, kind)) = item.split_once(':').filter(|(n, k)| !n.is_empty() && !k.is_empty() && !k.contains(':')) else {
            return Err(Error::spec(at, format!("`aovs`: `{item}` is not a name:type pair (e.g. \"dd.y:depth\")")));
        };
        let Some(&(kind, _, _)) = AovKind::ALL.iter().find(|(_, n, _)| *n == kind) else {
            let known = if ["albedo", "dp_du", "dp_dv", "duv_dx", "duv_dy", "boundary_test"].contains(&kind) {
                "a Mitsuba 3 type gonio does not output yet"
            } else {
                "an unknown type"
            };
            return Err(Error::spec(at, format!("`aovs`: `{kind}` in `{item}` is {known} (gonio has: {})", kinds())));
        };
        outputs.push(Aov { name: name.to_string(), kind });
    }
    let mut integrators = Vec::new();
    for (name, nested) in p.nested_named() {
        let integrator = match nested.class() {
            "integrator" => true,
            "" => matches!(nested.plugin_type(), "path" | "direct" | "moment" | "aov"),
            _ => false,
        };
        if !integrator {
            return Err(Error::spec(
                nested.at(),
                format!("`aov` nests integrators (gonio's: path, direct), not the {} `{}`", nested.class(), nested.plugin_type()),
            ));
        }
        if matches!(nested.plugin_type(), "aov" | "moment") {
            // Their own further channels (Mitsuba's `name.…` after every nested integrator's RGBA) are not
            // rendered by gonio.
            return Err(Error::spec(
                nested.at(),
                format!("an `aov` integrator cannot nest `{}` in gonio (only path, direct)", nested.plugin_type()),
            ));
        }
        integrators.push((name.to_string(), integrator_from_props(nested)?));
    }
    let kind = IntegratorKind::Aov { integrators, outputs };
    let channels = kind.channels();
    if let Some(twice) = channels.iter().enumerate().find_map(|(i, c)| channels[..i].contains(c).then_some(c)) {
        return Err(Error::spec(at, format!("`aov`: the channel `{twice}` is named twice")));
    }
    Ok(kind)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::mitsuba_xml;
    use std::path::Path;

    /// Sample counts as Mitsuba 3.9.1 reports them after loading (`mi.load_dict({"type": …, "sample_count":
    /// n}).sample_count()`): stratified 10 → 16, multijitter 10 → 12, ldsampler 10 → 16, orthogonal 10 and
    /// 16 → 25.
    #[test]
    fn sample_counts_round_as_mitsubas() {
        for (kind, n, want) in [
            ("stratified", 10, 16),
            ("stratified", 16, 16),
            ("multijitter", 10, 12),
            ("multijitter", 16, 16),
            ("ldsampler", 10, 16),
            ("ldsampler", 16, 16),
            ("orthogonal", 10, 25),
            ("orthogonal", 16, 25),
            ("independent", 10, 10),
            ("independent", u32::MAX, u64::from(u32::MAX)),
            ("stratified", u32::MAX, 65_536 * 65_536),
        ] {
            assert_eq!(mitsuba_sample_count(kind, n), want, "{kind} {n}");
        }
        let p = Props::from_json(r#"{"type": "stratified", "sample_count": 10, "jitter": false}"#).unwrap();
        let mut warnings = Vec::new();
        assert_eq!(sampler_from_props(&p, &mut warnings).unwrap().sample_count, 16);
        assert!(warnings[0].contains("sampler `stratified` is sampled independently by gonio (16 spp"), "{warnings:?}");
        let p = Props::from_json(r#"{"type": "sobol"}"#).unwrap();
        assert!(sampler_from_props(&p, &mut warnings).unwrap_err().to_string().contains("unsupported sampler `sobol`"));
    }

    /// A shape without a `<bsdf>` is a `diffuse` of reflectance 0.5, or 0 where it emits (as in Mitsuba 3);
    /// a `<bsdf>` given to an emitting shape is kept.
    #[test]
    fn default_bsdf_is_black_on_emitters() {
        const SCENE: &str = r#"<scene version="3.0.0">
            <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
            <shape type="rectangle"/>
            <shape type="rectangle"><emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>
            <shape type="rectangle"><bsdf type="diffuse"><rgb name="reflectance" value="0.3"/></bsdf>
                <emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>
        </scene>"#;
        let scene = Scene::build(mitsuba_xml::load_str(SCENE, "t.xml", Path::new("."), &[]).unwrap()).unwrap();
        let reflectance: Vec<Option<Rgb>> = scene.materials.iter().map(|m| m.diffuse_reflectance(glam::Vec2::ZERO)).collect();
        assert_eq!(reflectance, [Some(Rgb::splat(0.5)), Some(Rgb::splat(0.0)), Some(Rgb::splat(0.3))]);
    }

    fn scene(shapes: &str) -> Result<Scene> {
        let text = format!(
            r#"<scene version="3.0.0"><sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/>
               <integer name="height" value="4"/></film></sensor>{shapes}</scene>"#
        );
        Scene::build(mitsuba_xml::load_str(&text, "t.xml", Path::new("."), &[])?)
    }

    /// An `instance` of a `shapegroup` is its shapes placed by the instance's `to_world` after their own
    /// (the group itself renders nothing): the same hits, normals and materials as the shapes given so.
    #[test]
    fn instances_place_their_group() {
        let group = r#"<shape type="shapegroup" id="g">
                <shape type="sphere"><point name="center" x="1" y="0" z="0"/><float name="radius" value="0.5"/>
                    <bsdf type="diffuse"><rgb name="reflectance" value="0.3"/></bsdf></shape>
                <shape type="rectangle"><transform name="to_world"><rotate y="1" angle="-80"/></transform></shape>
            </shape>"#;
        let place = r#"<transform name="to_world"><rotate z="1" angle="30"/><scale value="1.5"/><translate z="2"/></transform>"#;
        let instanced =
            scene(&format!(r#"{group}<shape type="instance"><ref id="g"/></shape><shape type="instance"><ref id="g"/>{place}</shape>"#))
                .unwrap();
        let direct = scene(&format!(
            r#"<shape type="sphere"><point name="center" x="1" y="0" z="0"/><float name="radius" value="0.5"/>
                   <bsdf type="diffuse"><rgb name="reflectance" value="0.3"/></bsdf></shape>
               <shape type="rectangle"><transform name="to_world"><rotate y="1" angle="-80"/></transform></shape>
               <shape type="sphere"><point name="center" x="1" y="0" z="0"/><float name="radius" value="0.5"/>
                   <bsdf type="diffuse"><rgb name="reflectance" value="0.3"/></bsdf>{place}</shape>
               <shape type="rectangle"><transform name="to_world"><rotate y="1" angle="-80"/><rotate z="1" angle="30"/>
                   <scale value="1.5"/><translate z="2"/></transform></shape>"#
        ))
        .unwrap();
        assert_eq!(instanced.shapes.len(), 4);
        let reflectance = |s: &Scene| s.materials.iter().map(|m| m.diffuse_reflectance(glam::Vec2::ZERO)).collect::<Vec<_>>();
        assert_eq!(reflectance(&instanced), reflectance(&direct));
        let mut hits = 0;
        for i in 0..400 {
            let (y, z) = ((i % 20) as f32 * 0.2 - 2.0, (i / 20) as f32 * 0.25 - 1.0);
            let ray = crate::geometry::Ray::new(Vec3::new(-6.0, y, z), Vec3::new(1.0, 0.05, 0.02).normalize(), f32::INFINITY);
            let (a, b) = (instanced.intersect(&ray), direct.intersect(&ray));
            assert_eq!(a.is_some(), b.is_some(), "ray {i}");
            if let (Some(a), Some(b)) = (a, b) {
                hits += 1;
                assert_eq!(a.shape, b.shape, "ray {i}");
                assert!((a.p - b.p).length() < 1e-5 && (a.n - b.n).length() < 1e-5, "ray {i}: {a:?} against {b:?}");
            }
        }
        assert!(hits > 100, "{hits} of 400 rays hit");
    }

    /// What Mitsuba 3 refuses in instancing gonio refuses too, at the place.
    #[test]
    fn shape_groups_refuse_emitters_nesting_and_other_plugins() {
        let error = |shapes: &str| match scene(shapes) {
            Ok(_) => panic!("{shapes} loads"),
            Err(e) => e.to_string(),
        };
        let e = error(r#"<shape type="shapegroup" id="g"><shape type="sphere"><emitter type="area"/></shape></shape>"#);
        assert!(e.contains("t.xml:2:119:") && e.contains("cannot carry an emitter"), "{e}");
        let e = error(r#"<shape type="shapegroup" id="g"><shape type="shapegroup" id="h"><shape type="sphere"/></shape></shape>"#);
        assert!(e.contains("no nested instancing"), "{e}");
        let e = error(r#"<shape type="shapegroup" id="g"><bsdf type="diffuse"/></shape>"#);
        assert!(e.contains("holds shapes only, not a <bsdf>"), "{e}");
        let e = error(r#"<shape type="shapegroup" id="g"><float name="radius" value="1"/></shape>"#);
        assert!(e.contains("unknown parameter `radius` for `shapegroup`"), "{e}");
        let e = error(r#"<shape type="instance"><shape type="sphere"/></shape>"#);
        assert!(e.contains("an `instance` takes one <ref id=\"…\"> to a `shapegroup`"), "{e}");
    }

    /// Mitsuba 3's `aov` integrator: its channels in Mitsuba's order (unnamed nested integrators as
    /// `_arg_0`, …), and every malformed or unsupported part refused at its place.
    #[test]
    fn aov_integrators_read_as_mitsubas() {
        let load = |integrator: &str| {
            let text = format!(
                "<scene version=\"3.0.0\">\n{integrator}\n<sensor type=\"perspective\"><film type=\"hdrfilm\"><integer name=\"width\" value=\"4\"/>\
                 <integer name=\"height\" value=\"4\"/></film></sensor><shape type=\"sphere\"/></scene>"
            );
            mitsuba_xml::load_str(&text, "t.xml", Path::new("."), &[]).and_then(Scene::build)
        };
        let scene = load(
            r#"<integrator type="aov"><string name="aovs" value=" a.b:uv,c:prim_index  s:shape_index"/>
            <integrator type="path"/><integrator type="direct" name="d"/><integrator type="path"/></integrator>"#,
        )
        .unwrap();
        let want = "R G B _arg_0.R _arg_0.G _arg_0.B _arg_0.A d.R d.G d.B d.A _arg_1.R _arg_1.G _arg_1.B _arg_1.A a.b.U a.b.V c.I s.I";
        assert_eq!(scene.integrator.channels().join(" "), want);
        assert_eq!(scene.integrator.rgb(), Some(&IntegratorKind::Path { max_depth: -1, rr_depth: 5, hide_emitters: false }));
        let none = load(r#"<integrator type="aov"><string name="aovs" value="dd:depth"/></integrator>"#).unwrap();
        assert_eq!((none.integrator.channels().join(" "), none.integrator.rgb()), ("R G B dd.T".to_string(), None));
        for (aovs, nested, want) in [
            ("dd:depthx", "", "t.xml:2:24: `aovs`: `depthx` in `dd:depthx` is an unknown type (gonio has: depth, position, uv, geo_normal, sh_normal, prim_index, shape_index)"),
            ("nn:sh_normal, al:albedo", "", "`albedo` in `al:albedo` is a Mitsuba 3 type gonio does not output yet"),
            ("dd", "", "t.xml:2:24: `aovs`: `dd` is not a name:type pair"),
            ("dd:depth:x", "", "`dd:depth:x` is not a name:type pair"),
            (":depth", "", "`:depth` is not a name:type pair"),
            ("a:depth, a:depth", "", "t.xml:2:24: `aov`: the channel `a.T` is named twice"),
            ("a:position a:geo_normal", "", "the channel `a.X` is named twice"),
            ("a:depth", r#"<bsdf type="diffuse"/>"#, "t.xml:2:61: `aov` nests integrators (gonio's: path, direct), not the bsdf `diffuse`"),
            ("a:depth", r#"<integrator type="aov"><string name="aovs" value=""/></integrator>"#, "t.xml:2:61: an `aov` integrator cannot nest `aov`"),
            ("a:depth", r#"<integrator type="moment"><integrator type="path"/></integrator>"#, "cannot nest `moment` in gonio"),
            ("a:depth", r#"<integrator type="path"><integer name="max_depth" value="-2"/></integrator>"#, "`max_depth`"),
        ] {
            let text = format!(r#"<integrator type="aov"><string name="aovs" value="{aovs}"/>{nested}</integrator>"#);
            match load(&text) {
                Ok(_) => panic!("{text} loads"),
                Err(e) => assert!(e.to_string().contains(want), "{text}: {e}"),
            }
        }
        let e = load(r#"<integrator type="aov"><integrator type="path"/></integrator>"#).err().unwrap().to_string();
        assert!(e.contains("t.xml:2:1: `aov` needs `aovs`"), "{e}");
    }
}
