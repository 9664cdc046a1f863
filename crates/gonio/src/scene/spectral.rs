//! The scene's rendering mode, and what spectral mode supports of a scene (issue 30; docs/spectral.md).
//!
//! In spectral mode a path carries three wavelengths in the renderer's three channels
//! ([`crate::spectrum::sampled`]), and every colour is taken to its spectrum where it is used: emission and
//! the reflectance of `diffuse` surfaces in the path tracer's lanes, and a model's colours by
//! [`reflectances_at`] on a copy of the model for each lane that hits it. The colours converted that way are
//! those a model reads as they are ([`Bsdf::reflectance_slot`]) and a conductor's index (a named metal's
//! spectra, as Mitsuba 3's spectral variants read them, or `eta`/`k` given as colours), in the model itself
//! or in the models it holds as they are ([`Bsdf::for_each_nested`]: a `twosided`, `blendbsdf`, `sum`,
//! `mask`, `normalmap` or `bumpmap`). Everything else a model derives from a colour when it is built (an
//! energy-compensated lobe, the colours of models that precompute from them, measured data, …) is refused
//! at load by [`check_bsdf`], naming the parameter, rather than rendered wrongly. A model without colours
//! (every colour grey, as a `dielectric`'s defaults) is the same at every wavelength and runs as in RGB
//! mode.

use super::Material;
use crate::bsdf::Bsdf;
use crate::error::{Error, Result};
use crate::light::Light;
use crate::props::{Props, Value};
use crate::spectrum::sampled::{emission_at, reflectance_at, PATH_WAVELENGTHS};
use crate::spectrum::upsample::{srgb_table, RgbIlluminantSpectrum, SigmoidPolynomial};
use crate::spectrum::Rgb;

/// How the renderer carries light.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Mode {
    /// Three linear sRGB channels.
    #[default]
    Rgb,
    /// Three sampled wavelengths per path, recorded by the film through the CIE 1931 observer.
    Spectral,
}

impl Mode {
    /// `rgb` or `spectral`.
    ///
    /// # Errors
    /// Any other name, with the accepted ones.
    pub fn parse(name: &str) -> Result<Mode> {
        match name {
            "rgb" => Ok(Mode::Rgb),
            "spectral" => Ok(Mode::Spectral),
            _ => Err(Error::spec("mode", format!("unknown mode `{name}`; expected `rgb` or `spectral`"))),
        }
    }

    /// The name [`Mode::parse`] reads.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Mode::Rgb => "rgb",
            Mode::Spectral => "spectral",
        }
    }
}

/// What spectral mode keeps of a scene beside its RGB form (empty in RGB mode): which materials have colours,
/// and the spectra of the constant colours, fitted once at load ([`srgb_table`]'s `fit`: the round trip
/// to 1e-4) rather than looked up at every use.
#[derive(Clone, Debug)]
pub struct SpectralScene {
    /// Per shape, whether its material has colours ([`check_bsdf`]): its model is then copied per lane and
    /// set to the lane's wavelengths ([`reflectances_at`]).
    pub chromatic: Vec<bool>,
    /// Per shape, the reflectance spectrum of a `diffuse` material of one colour.
    diffuse: Vec<Option<SigmoidPolynomial>>,
    /// Per light, the spectrum of its colour where it has one ([`Light::constant_colour`]), and that
    /// colour's largest component.
    lights: Vec<Option<(f32, RgbIlluminantSpectrum)>>,
}

impl SpectralScene {
    /// The spectra of `materials` (one per shape, `chromatic` as [`check_bsdf`] found them) and `lights`.
    #[must_use]
    pub fn new(materials: &[Material], lights: &[Light], chromatic: Vec<bool>) -> Self {
        let diffuse = materials
            .iter()
            .map(|m| match m {
                Material::Fixed(Bsdf::Diffuse(d)) => Some(srgb_table().fit(d.reflectance)),
                _ => None,
            })
            .collect();
        let lights = lights
            .iter()
            .map(|l| l.constant_colour().filter(|c| c.max_component() > 0.0).map(|c| (c.max_component(), RgbIlluminantSpectrum::new(c))))
            .collect();
        SpectralScene { chromatic, diffuse, lights }
    }

    /// The reflectance `rgb` of shape `shape`'s diffuse material at the wavelengths `lambda`: from its
    /// fitted spectrum where its colour is constant, else (a texture's texel) by [`reflectance_at`].
    #[inline]
    #[must_use]
    pub fn reflectance(&self, shape: usize, rgb: [f32; 3], lambda: [f32; PATH_WAVELENGTHS]) -> [f32; PATH_WAVELENGTHS] {
        match self.diffuse.get(shape) {
            Some(Some(p)) => lambda.map(|l| p.eval(l)),
            _ => reflectance_at(rgb, lambda),
        }
    }

    /// Emission `rgb` from light `light` (its index; `None` if not known) at the wavelengths `lambda`: the
    /// light's fitted spectrum times the factor `rgb` is of its colour, where it has one colour; else by
    /// [`emission_at`].
    #[inline]
    #[must_use]
    pub fn emission(&self, light: Option<usize>, rgb: [f32; 3], lambda: [f32; PATH_WAVELENGTHS]) -> [f32; PATH_WAVELENGTHS] {
        let Some((max, spectrum)) = light.and_then(|i| self.lights.get(i).copied().flatten()) else {
            return emission_at(rgb, lambda);
        };
        if rgb.iter().any(|v| v.is_nan()) {
            return [f32::NAN; PATH_WAVELENGTHS];
        }
        let factor = rgb[0].max(rgb[1]).max(rgb[2]).max(0.0) / max;
        lambda.map(|l| factor * spectrum.eval(l))
    }
}

/// The colour parameters spectral mode converts per lane, where the model holds them as they are
/// ([`Bsdf::reflectance_slot`]).
const CONVERTED: &[&str] =
    &["reflectance", "specular_reflectance", "specular_transmittance", "diffuse_reflectance", "base_color", "transmittance"];

/// Models whose colours spectral mode converts in the models they hold ([`reflectances_at`],
/// [`Bsdf::for_each_nested`]).
const CONTAINERS: &[&str] = &["twosided", "blendbsdf", "sum", "mask", "normalmap", "bumpmap"];

/// Whether spectral mode renders the `<bsdf>` `p` (see the module docs); `Ok(true)` where it has colours
/// (that are not grey), which then vary with wavelength.
///
/// # Errors
/// A colour spectral mode does not take yet, naming the parameter and where it was given.
pub fn check_bsdf(p: &Props) -> Result<bool> {
    check_model(p, true)
}

/// [`check_bsdf`] for a model reached through [`CONTAINERS`] only (`convertible`) or not. A colour is taken
/// where [`reflectances_at`] sets it: the model built from `p` (its textures left at their defaults) holds
/// it in a [`Bsdf::reflectance_slot`], or it is a conductor's named metal ([`Bsdf::conductor_fresnel`]).
fn check_model(p: &Props, convertible: bool) -> Result<bool> {
    let plugin = p.plugin_type();
    let compensated = p.values().any(|(name, v, _)| name == "energy_compensation" && matches!(v, Value::Bool(true)));
    let mut model: Option<Bsdf> = None;
    let mut built = || -> Result<Bsdf> {
        if model.is_none() {
            let mut untextured = p.clone();
            untextured.take_textures();
            model = Some(Bsdf::from_props(&untextured)?);
        }
        Ok(model.clone().unwrap_or_else(|| unreachable!("built above")))
    };
    let mut chromatic = false;
    for (name, value, at) in p.values() {
        let refuse = |what: &str| {
            Err(Error::spec(
                at,
                format!("spectral mode does not take {what} (parameter `{name}` of `{plugin}`) yet; render it with --mode rgb"),
            ))
        };
        let what = if compensated { "a colour of an energy-compensated model" } else { "this colour" };
        match value {
            Value::List(l) if l.len() == 3 && name != "normalmap" && !(l[0] == l[1] && l[1] == l[2]) => {
                let index = matches!(name, "eta" | "k") && built()?.conductor_fresnel().is_some();
                if !(convertible && (index || CONVERTED.contains(&name) && built()?.reflectance_slot(name).is_some())) {
                    return refuse(what);
                }
                chromatic = true;
            }
            Value::String(s) if name == "material" && s != "none" => {
                if !(convertible && built()?.conductor_fresnel().is_some()) {
                    return refuse(if compensated { "a named metal in an energy-compensated model" } else { "a named metal here" });
                }
                chromatic = true;
            }
            Value::Nested(t) if t.class() == "texture" => {
                let scalar = super::material::SCALAR_PARAMETERS.contains(&name) || plugin == "bumpmap" || name == "normalmap";
                if !scalar {
                    // A texture on a colour: its texels are taken to spectra where the model's value is read
                    // (the diffuse lanes, or the model's copy per lane).
                    if !(convertible && CONVERTED.contains(&name) && built()?.reflectance_slot(name).is_some()) {
                        return refuse(if compensated {
                            "a texture on a colour of an energy-compensated model"
                        } else {
                            "a texture on this colour"
                        });
                    }
                    chromatic = true;
                }
            }
            Value::Nested(m) if is_model(m) => {
                chromatic |= check_model(m, convertible && CONTAINERS.contains(&plugin))?;
            }
            _ => {}
        }
    }
    if matches!(plugin, "measured" | "merl") {
        return Err(Error::spec(p.at(), format!("spectral mode does not take `{plugin}` (its RGB data) yet; render it with --mode rgb")));
    }
    Ok(chromatic)
}

/// Whether a nested plugin is a model (not a texture nor a spectrum).
fn is_model(p: &Props) -> bool {
    p.class() != "texture"
}

/// Model `b` at the wavelengths `lambda`, in `b` and in the models it holds ([`Bsdf::for_each_nested`]):
/// each colour parameter of `CONVERTED` (those [`check_bsdf`] takes) replaced by its reflectance spectrum's
/// values at `lambda`, and a conductor's index by its spectra's ([`crate::bsdf::Conductor::set_wavelengths`]).
pub fn reflectances_at(b: &mut Bsdf, lambda: [f32; PATH_WAVELENGTHS]) {
    if let Some(c) = b.conductor_fresnel() {
        c.set_wavelengths(lambda);
    }
    for name in CONVERTED {
        if let Some(r) = b.reflectance_slot(name) {
            *r = Rgb(reflectance_at(r.0, lambda));
        }
    }
    b.for_each_nested(&mut |m| reflectances_at(m, lambda));
}
