//! The lit sphere: one material on a unit sphere, seen by a camera that it fills, under an environment or a
//! directional light — the "lit sphere" view of Disney's BRDF Explorer, rendered by the path tracer (no
//! second renderer: the scene is assembled from the same [`Scene`] parts the XML loader builds).
//!
//! | lighting                 | what it is                                                                |
//! |--------------------------|---------------------------------------------------------------------------|
//! | [`Lighting::Environment`] | a lat-long image (EXR/HDR/PNG) as an importance-sampled `envmap`          |
//! | [`Lighting::EnvironmentImage`] | the same, from an image already read (an interactive view reads it once) |
//! | [`Lighting::GradientSky`] | the built-in sky of [`gradient_sky`]: blue zenith, pale horizon, brown ground, a small sun |
//! | [`Lighting::Constant`]    | uniform radiance L from every direction (L = 1: the white furnace)        |
//! | [`Lighting::Directional`] | a directional light of irradiance π (a white Lambertian surface facing it has radiance 1) plus a uniform ambient (the CLI uses [`AMBIENT`]) |
//!
//! [`render_preview`] renders a directional light and its ambient as two images and adds them (light
//! transport is linear in the emitters): in one scene the integrator would pick one of the two lights per
//! sample, and the dim ambient would cost half the samples of the bright light — binary noise on the lit side.
//!
//! [`Sweep`] renders one material over a grid of its parameters (`gonio preview --grid`, `gonio.preview`,
//! `gonio.distributed.preview`), and [`contact_sheet`] lays the spheres out.
//!
//! ## Geometry
//! World +y is up, +x to the right of the image, +z towards the camera (the camera sits at (0, 0, 5) and
//! looks at the origin; the sphere of radius 1 fills the central ~90 % of the frame). The sphere is turned
//! so that its poles (Mitsuba's sphere has them on its local z axis) point up and down: textures wrap it
//! like a globe's map and an anisotropic model's tangent follows the lines of latitude. In an environment map
//! +y is up and the image's centre column faces −z (Mitsuba's `envmap` mapping), so the camera sees the
//! centre of the map behind the sphere and the sphere reflects the map's edges.
//!
//! ```
//! use gonio::preview::{preview_scene, Lighting};
//! use gonio::scene::Material;
//! let material = Material::Fixed(gonio::Bsdf::from_json(r#"{"type": "diffuse"}"#).unwrap());
//! let scene = preview_scene(material, &Lighting::Constant(gonio::Rgb::ONE), 32, None).unwrap();
//! assert_eq!((scene.film.width, scene.film.height), (32, 32));
//! ```

use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::film::{FilmSpec, Filter};
use crate::geometry::sphere::Sphere;
use crate::geometry::Shape;
use crate::image::{read_image, Image};
use crate::light::{ConstantLight, DirectionalLight, EnvMap, Light};
use crate::math::Transform;
use crate::render::render;
use crate::scene::spectral::Dependence;
use crate::scene::{IntegratorKind, Material, SamplerSpec, Scene};
use crate::spectrum::Rgb;
use glam::Vec3;
use std::f32::consts::PI;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

mod sweep;
pub use sweep::{GridAxis, Sweep, MAX_POINTS};

/// Radiance of the uniform ambient that accompanies a directional light (the unlit side is not pure black).
pub const AMBIENT: f32 = 0.04;

/// Camera distance from the sphere's centre.
const CAMERA_DISTANCE: f32 = 5.0;

/// The sphere fills this fraction of the frame's width.
const FILL: f32 = 0.9;

/// How the sphere is lit.
#[derive(Clone, Debug, PartialEq)]
pub enum Lighting {
    /// A lat-long environment image (linear radiance), as Mitsuba's `envmap`.
    Environment(PathBuf),
    /// The same, already read (shared by the renders of an interactive view; `name` names it in errors).
    EnvironmentImage { image: Arc<Image>, name: String },
    /// The built-in sky of [`gradient_sky`].
    GradientSky,
    /// Uniform radiance from every direction.
    Constant(Rgb),
    /// A directional light shining from `towards_light` (world space, need not be unit), plus a uniform
    /// `ambient` radiance (0 for none).
    Directional { towards_light: Vec3, ambient: f32 },
}

impl Lighting {
    /// The lighting named as `gonio preview --env` names it: `gradient` (the built-in sky), `constant`
    /// (uniform radiance 1: the white furnace), else a lat-long image file.
    #[must_use]
    pub fn environment(name: &str) -> Lighting {
        match name {
            "gradient" => Lighting::GradientSky,
            "constant" => Lighting::Constant(Rgb::ONE),
            path => Lighting::Environment(PathBuf::from(path)),
        }
    }

    /// A directional light shining from `towards_light` with the dim uniform [`AMBIENT`] (`gonio preview
    /// --light`).
    #[must_use]
    pub fn sun(towards_light: Vec3) -> Lighting {
        Lighting::Directional { towards_light, ambient: AMBIENT }
    }
}

/// The sun of the built-in sky: its direction (towards it), angular radius and radiance.
const SUN_DIRECTION: Vec3 = Vec3::new(0.45, 0.55, 0.7);
const SUN_RADIUS_DEG: f32 = 2.5;
/// Radiance of the sun's disk: its irradiance at normal incidence is L · 2π(1 − cos r) ≈ 2.
const SUN_RADIANCE: f32 = 330.0;

/// The built-in sky as a `width × height` lat-long image in the `envmap` mapping (module docs): a sky from
/// a pale horizon (0.75, 0.72, 0.66) to a blue zenith (0.16, 0.3, 0.62) over a uniform brown ground
/// (0.2, 0.17, 0.14), and a sun disk of radius 2.5° at elevation ~33°, in front of the sphere, up and to
/// the right. Rows sit on the poles (row 0 straight up), columns at u = (x + ½) / W, as the `envmap` lookup
/// expects.
#[must_use]
pub fn gradient_sky(width: usize, height: usize) -> Image {
    let mut image = Image::new(width, height);
    let sun = SUN_DIRECTION.normalize();
    let cos_sun = SUN_RADIUS_DEG.to_radians().cos();
    let horizon = Rgb::new(0.75, 0.72, 0.66);
    let zenith = Rgb::new(0.16, 0.3, 0.62);
    let ground = Rgb::new(0.2, 0.17, 0.14);
    for y in 0..height {
        let theta = PI * y as f32 / (height.max(2) - 1) as f32;
        for x in 0..width {
            let phi = 2.0 * PI * (x as f32 + 0.5) / width as f32;
            let d = Vec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos());
            let mut c = if d.y >= 0.0 {
                // Square root: the sky stays pale near the horizon and turns blue higher up.
                let t = d.y.sqrt();
                horizon * (1.0 - t) + zenith * t
            } else {
                ground
            };
            if d.dot(sun) >= cos_sun {
                c += Rgb::splat(SUN_RADIANCE);
            }
            image.set(x, y, c);
        }
    }
    image
}

/// A scene holding one unit sphere with `material` at the origin, a `size × size` film and `lighting`,
/// rendered by the path tracer (unbounded depth, Russian roulette from depth 5; the environment is seen
/// behind the sphere). In spectral mode (`spectral`: how the material depends on wavelength, as
/// [`check_bsdf`](crate::scene::spectral::check_bsdf) found it) the scene carries wavelengths
/// (docs/spectral.md).
///
/// # Errors
/// When the environment image cannot be read (the error names the file) or `size` is 0.
pub fn preview_scene(material: Material, lighting: &Lighting, size: u32, spectral: Option<Dependence>) -> Result<Scene> {
    if size == 0 {
        return Err(Error::spec("preview", "the image size must be at least 1 pixel"));
    }
    let mut lights = Vec::new();
    match lighting {
        Lighting::Environment(path) => {
            let image = read_image(path)?;
            lights.push(Light::EnvMap(EnvMap::new(&image, 1.0, Transform::IDENTITY, &path.display().to_string())?));
        }
        Lighting::EnvironmentImage { image, name } => {
            lights.push(Light::EnvMap(EnvMap::new(image, 1.0, Transform::IDENTITY, name)?));
        }
        Lighting::GradientSky => {
            lights.push(Light::EnvMap(EnvMap::new(&gradient_sky(512, 256), 1.0, Transform::IDENTITY, "the built-in sky")?));
        }
        Lighting::Constant(radiance) => lights.push(Light::Constant(ConstantLight { radiance: *radiance })),
        Lighting::Directional { towards_light, ambient } => {
            let direction = towards_light
                .try_normalize()
                .filter(|d| d.is_finite())
                .ok_or_else(|| Error::spec("preview", format!("the light direction must be a non-zero vector, got {towards_light}")))?;
            if !(ambient.is_finite() && *ambient >= 0.0) {
                return Err(Error::spec("preview", format!("the ambient radiance must be finite and ≥ 0, got {ambient}")));
            }
            lights.push(Light::Directional(DirectionalLight { direction: -direction, irradiance: Rgb::splat(PI) }));
            if *ambient > 0.0 {
                lights.push(Light::Constant(ConstantLight { radiance: Rgb::splat(*ambient) }));
            }
        }
    }
    // The sphere's poles (its local ±z, where uv textures converge) point up and down, like a globe's.
    let globe = Transform::rotate(Vec3::X, -90.0).ok_or_else(|| Error::spec("preview", "cannot turn the sphere"))?;
    let sphere = Sphere::new(Vec3::ZERO, 1.0, globe, false).ok_or_else(|| Error::spec("preview", "cannot build the sphere"))?;
    let to_world = Transform::look_at(Vec3::new(0.0, 0.0, CAMERA_DISTANCE), Vec3::ZERO, Vec3::Y)
        .ok_or_else(|| Error::spec("preview", "cannot place the camera"))?;
    // The sphere subtends a half-angle asin(1/d); widen the view so that it fills FILL of the frame.
    let fov = 2.0 * ((1.0 / CAMERA_DISTANCE).asin().tan() / FILL).atan().to_degrees();
    let camera = Camera::new(to_world, fov, "x", size, size, 0.01, 1.0e4, "preview")?;
    let mut scene = Scene::assemble(
        vec![Shape::Sphere(sphere)],
        vec![material],
        vec![None],
        lights,
        camera,
        FilmSpec { width: size, height: size, filter: Filter::BOX },
        SamplerSpec { sample_count: 64, seed: 0 },
        IntegratorKind::Path { max_depth: -1, rr_depth: 5, hide_emitters: false },
        Vec::new(),
    );
    if let Some(dependence) = spectral {
        scene.make_spectral(vec![dependence], Vec::new(), &[]);
    }
    Ok(scene)
}

/// A rendered lit sphere.
#[derive(Clone, Debug, PartialEq)]
pub struct PreviewImage {
    pub image: Image,
    /// Samples that were NaN or infinite, dropped (counted as black).
    pub nonfinite: u64,
}

/// Render the lit sphere of [`preview_scene`] with `spp` samples per pixel. `material` builds the material
/// (called once per rendered part: a directional light and its ambient are rendered apart and added, see
/// the module docs); `spectral` as [`preview_scene`] takes it. `cancel` stops the render between tiles.
///
/// # Errors
/// Those of `material` and [`preview_scene`]; `spp` 0.
pub fn render_preview(
    material: &dyn Fn() -> Result<Material>,
    lighting: &Lighting,
    size: u32,
    spp: u32,
    seed: u64,
    spectral: Option<Dependence>,
    cancel: &AtomicBool,
) -> Result<PreviewImage> {
    if spp == 0 {
        return Err(Error::spec("preview", "the samples per pixel must be at least 1"));
    }
    let parts = match lighting {
        Lighting::Directional { towards_light, ambient } if *ambient > 0.0 => {
            vec![Lighting::Directional { towards_light: *towards_light, ambient: 0.0 }, Lighting::Constant(Rgb::splat(*ambient))]
        }
        other => vec![other.clone()],
    };
    let mut sum: Option<Image> = None;
    let mut nonfinite = 0;
    for part in &parts {
        let scene = preview_scene(material()?, part, size, spectral)?;
        let out = render(&scene, spp, seed, cancel, &|_| {});
        nonfinite += out.nonfinite;
        let image = Image { width: out.width as usize, height: out.height as usize, data: out.data };
        sum = Some(match sum {
            None => image,
            Some(mut acc) => {
                acc.data.iter_mut().zip(&image.data).for_each(|(a, b)| *a += b);
                acc
            }
        });
    }
    let image = sum.ok_or_else(|| Error::spec("preview", "nothing to render"))?;
    Ok(PreviewImage { image, nonfinite })
}

/// Tiles laid out in a grid of `columns` (row-major; all tiles the same size), separated by `gap` pixels of
/// the colour `gap_colour`.
///
/// # Errors
/// When the tiles differ in size, or there are none.
pub fn tile(tiles: &[Image], columns: usize, gap: usize, gap_colour: Rgb) -> Result<Image> {
    let first = tiles.first().ok_or_else(|| Error::spec("preview", "no images to lay out"))?;
    let (w, h) = (first.width, first.height);
    if let Some(t) = tiles.iter().find(|t| (t.width, t.height) != (w, h)) {
        return Err(Error::spec("preview", format!("tiles differ in size: {w}×{h} and {}×{}", t.width, t.height)));
    }
    let columns = columns.clamp(1, tiles.len());
    let rows = tiles.len().div_ceil(columns);
    let mut out = Image::new(columns * w + (columns - 1) * gap, rows * h + (rows - 1) * gap);
    for y in 0..out.height {
        for x in 0..out.width {
            out.set(x, y, gap_colour);
        }
    }
    for (i, t) in tiles.iter().enumerate() {
        let (x0, y0) = ((i % columns) * (w + gap), (i / columns) * (h + gap));
        for y in 0..h {
            let row = 3 * ((y0 + y) * out.width + x0);
            out.data[row..row + 3 * w].copy_from_slice(&t.data[3 * y * w..3 * (y + 1) * w]);
        }
    }
    Ok(out)
}

/// Colour of the gaps between the spheres of a contact sheet (a dark grey, apart from a black background).
const SHEET_GAP: Rgb = Rgb::new(0.02, 0.02, 0.02);

/// A contact sheet: the lit spheres `tiles` (all the same size) in rows of `columns`, scaled by
/// 2^`exposure`, separated by gaps of 1/64 of a sphere's width (at least a pixel). One tile is that image,
/// scaled. What `gonio preview` writes, and `gonio.preview(…).sheet()`.
///
/// # Errors
/// Those of [`tile`]; an exposure outside [−30, 30].
pub fn contact_sheet(tiles: &[Image], columns: usize, exposure: f32) -> Result<Image> {
    if !(exposure.is_finite() && exposure.abs() <= 30.0) {
        return Err(Error::spec("preview", format!("the exposure must be in [-30, 30], got {exposure}")));
    }
    let scale = exposure.exp2();
    let scaled: Vec<Image> =
        tiles.iter().map(|t| Image { width: t.width, height: t.height, data: t.data.iter().map(|v| v * scale).collect() }).collect();
    let gap = scaled.first().map_or(1, |t| (t.width / 64).max(1));
    tile(&scaled, columns, gap, SHEET_GAP)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Bsdf;

    fn render_mean_of_centre(bsdf: &str, lighting: &Lighting, size: u32, spp: u32) -> (Image, Rgb) {
        let material = Material::Fixed(Bsdf::from_json(bsdf).unwrap());
        let scene = preview_scene(material, lighting, size, None).unwrap();
        let out = render(&scene, spp, 7, &AtomicBool::new(false), &|_| {});
        let image = Image { width: out.width as usize, height: out.height as usize, data: out.data };
        // The central half of the frame lies on the sphere (it fills 90 % of the width).
        let (lo, hi) = (size as usize / 4, 3 * size as usize / 4);
        let mut sum = Rgb::ZERO;
        for y in lo..hi {
            for x in lo..hi {
                sum += image.get(x, y);
            }
        }
        (image, sum / ((hi - lo) * (hi - lo)) as f32)
    }

    #[test]
    fn white_furnace_sphere_matches_the_environment() {
        // A white Lambertian sphere under uniform radiance 1 reflects exactly 1 everywhere (it is convex: no
        // inter-reflection); the mean over ~1000 pixels × 16 spp has a standard error well below 1 %.
        let (image, centre) = render_mean_of_centre(r#"{"type": "diffuse", "reflectance": 1}"#, &Lighting::Constant(Rgb::ONE), 64, 16);
        for c in centre.0 {
            assert!((c - 1.0).abs() < 0.02, "furnace: sphere centre averages {centre}, expected 1");
        }
        // The corners see the environment: exactly its radiance.
        assert_eq!(image.get(0, 0), Rgb::ONE);
        assert_eq!(image.get(63, 63), Rgb::ONE);
    }

    #[test]
    fn directional_light_lights_the_side_facing_it() {
        let lighting = Lighting::Directional { towards_light: Vec3::new(1.0, 0.0, 0.0), ambient: AMBIENT };
        let material = || Ok(Material::Fixed(Bsdf::from_json(r#"{"type": "diffuse", "reflectance": 0.8}"#)?));
        let image = render_preview(&material, &lighting, 32, 4, 1, None, &AtomicBool::new(false)).unwrap().image;
        // +x is the image's right: the right edge of the sphere faces the light (radiance ≈ ρ · cos θ + ambient),
        // the left edge sees only the ambient (ρ · AMBIENT = 0.032 in expectation; one pixel at 4 spp is noisy).
        let (left, right) = (image.get(5, 16), image.get(26, 16));
        assert!(right.r() > 0.4, "lit side {right}");
        assert!(left.r() < 0.1, "unlit side {left}");
        assert!((image.get(0, 0).r() - AMBIENT).abs() < 1e-6, "background {}", image.get(0, 0));
    }

    #[test]
    fn gradient_sky_is_brightest_at_the_sun_and_blue_above() {
        let sky = gradient_sky(64, 32);
        let top = sky.get(10, 0);
        assert!(top.b() > top.r(), "zenith {top}");
        let ground = sky.get(10, 31);
        assert_eq!(ground, Rgb::new(0.2, 0.17, 0.14));
        let max = sky.data.iter().copied().fold(0.0f32, f32::max);
        assert!(max > 100.0, "the sun is in the map");
    }

    #[test]
    fn bad_lighting_and_size_are_errors() {
        let m = || Material::Fixed(Bsdf::from_json(r#"{"type": "diffuse"}"#).unwrap());
        assert!(preview_scene(m(), &Lighting::Directional { towards_light: Vec3::ZERO, ambient: 0.0 }, 8, None).is_err());
        assert!(preview_scene(m(), &Lighting::Directional { towards_light: Vec3::Y, ambient: f32::NAN }, 8, None).is_err());
        assert!(preview_scene(m(), &Lighting::Constant(Rgb::ONE), 0, None).is_err());
        let e = preview_scene(m(), &Lighting::Environment("/no/such/sky.hdr".into()), 8, None).unwrap_err();
        assert!(e.to_string().contains("/no/such/sky.hdr"), "{e}");
    }

    #[test]
    fn tiles_are_laid_out_with_gaps() {
        let mut a = Image::new(2, 2);
        a.set(1, 1, Rgb::ONE);
        let b = Image::new(2, 2);
        let out = tile(&[a.clone(), b.clone(), a.clone()], 2, 1, Rgb::splat(0.5)).unwrap();
        assert_eq!((out.width, out.height), (5, 5));
        assert_eq!(out.get(1, 1), Rgb::ONE);
        assert_eq!(out.get(2, 0), Rgb::splat(0.5));
        assert_eq!(out.get(1, 4), Rgb::ONE);
        assert_eq!(out.get(4, 4), Rgb::splat(0.5));
        assert!(tile(&[a, Image::new(3, 2)], 2, 1, Rgb::ZERO).is_err());
    }
}
