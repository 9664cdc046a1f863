//! The scene's rendering mode, and what spectral mode supports of a scene (issue 30; docs/spectral.md).
//!
//! In spectral mode a path carries three wavelengths in the renderer's three channels
//! ([`crate::spectrum::sampled`]), and every colour is taken to its spectrum where it is used: emission and
//! the reflectance of `diffuse` surfaces in the path tracer's lanes, and a model's colours by
//! [`reflectances_at`] on a copy of the model for each lane that hits it. The colours converted that way are
//! those a model reads as they are ([`Bsdf::reflectance_slot`]) and a conductor's index (a named metal's
//! spectra, as Mitsuba 3's spectral variants read them, or `eta`/`k` given as colours), in the model itself
//! or in the models it holds as they are ([`Bsdf::for_each_nested`]: a `twosided`, `blendbsdf`, `sum`,
//! `mask`, `normalmap` or `bumpmap`), and a `measured` file's spectra. Everything else a model derives
//! from a colour when it is built (an energy-compensated lobe, the colours of models that precompute from
//! them, RGB measured data, …) is refused
//! at load by [`check_bsdf`], naming the parameter, rather than rendered wrongly. A model without colours
//! (every colour grey, as a `dielectric`'s defaults) is the same at every wavelength and runs as in RGB
//! mode.

use super::material::{Slot, TextureValue};
use super::Material;
use crate::bsdf::textured_reflectance;
use crate::bsdf::Bsdf;
use crate::error::{Error, Result};
use crate::light::Light;
use crate::math::lanes::Real;
use crate::props::{Props, Value};
use crate::spectrum::illuminant::Spectrum;
use crate::spectrum::piecewise::PiecewiseLinear;
use crate::spectrum::sampled::{emission_at, reflectance_at, PATH_WAVELENGTHS};
use crate::spectrum::upsample::{srgb_table, RgbIlluminantSpectrum, SigmoidPolynomial};
use crate::spectrum::Rgb;
use std::sync::Arc;

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

/// How a material depends on wavelength in spectral mode ([`check_bsdf`]); ordered, so that a material's
/// is the largest of its models'.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub enum Dependence {
    /// The same at every wavelength (every colour grey): it runs as in RGB mode.
    #[default]
    None,
    /// It has colours (or a model that reads the wavelengths itself, [`Bsdf::set_wavelengths`]): each lane
    /// runs a copy of its model set to the lane's wavelengths ([`reflectances_at`]).
    Colours,
    /// Its index of refraction varies with wavelength ([`crate::bsdf::dielectric::Dispersion`]) and its
    /// directions with it (a `dielectric` or `roughdielectric`; a `thindielectric`'s do not): each lane
    /// runs a copy of its model at the lane's hero wavelength, and the path follows that wavelength alone
    /// from there (the others are terminated: pbrt-v4's rule, docs/spectral.md).
    Dispersion,
}

/// What spectral mode keeps of a scene beside its RGB form (empty in RGB mode): which materials have colours,
/// and the spectra of the constant colours, fitted once at load ([`srgb_table`]'s `fit`: the round trip
/// to 1e-4) rather than looked up at every use.
#[derive(Clone, Debug)]
pub struct SpectralScene {
    /// Per shape, how its material depends on wavelength ([`check_bsdf`]).
    pub dependence: Vec<Dependence>,
    /// Per shape, the reflectance spectrum of a `diffuse` material of one colour.
    diffuse: Vec<Option<DiffuseSpectrum>>,
    /// Per shape, the colours its material was given as tables ([`given_spectra`]).
    pub given: Vec<GivenSpectra>,
    /// Per light of one colour ([`Light::constant_colour`]): that colour's largest component, and its
    /// spectrum — as the scene gave it (an emitter's `<spectrum>`), else the colour's RGB illuminant
    /// spectrum.
    lights: Vec<Option<(f32, Arc<Spectrum>)>>,
}

/// A constant `diffuse` reflectance's spectrum.
#[derive(Clone, Debug)]
enum DiffuseSpectrum {
    /// Upsampled from its colour.
    Fitted(SigmoidPolynomial),
    /// The table the scene gave ([`given_spectra`]).
    Given(Arc<PiecewiseLinear>),
}

/// The colours of a material that were given as tables (a `<spectrum>` of `λ:value` pairs or an `.spd`
/// file), which spectral mode renders as given instead of upsampling their RGB reductions: each with its
/// place in the model ([`Slot`]: the models the material holds, and the parameter).
#[derive(Clone, Debug, Default)]
pub struct GivenSpectra(Vec<(Slot, Arc<PiecewiseLinear>)>);

impl GivenSpectra {
    /// No colour given as a table.
    pub const NONE: GivenSpectra = GivenSpectra(Vec::new());

    /// The table given for parameter `name` of the material's own model.
    fn table(&self, name: &str) -> Option<&Arc<PiecewiseLinear>> {
        self.0.iter().find(|(slot, _)| slot.is_top(name)).map(|(_, t)| t)
    }
}

/// The colours of `<bsdf>` `p` given as tables, where spectral mode converts colours ([`CONVERTED`] in the
/// model or in the models it holds through [`CONTAINERS`]; [`check_bsdf`] refuses the others).
#[must_use]
pub fn given_spectra(p: &Props) -> GivenSpectra {
    fn visit(root: &Props, p: &Props, path: &mut Vec<String>, out: &mut Vec<(Slot, Arc<PiecewiseLinear>)>) {
        for (name, value, _) in p.values() {
            if let Value::Nested(m) = value {
                if is_model(m) && CONTAINERS.contains(&p.plugin_type()) {
                    path.push(name.to_string());
                    visit(root, m, path, out);
                    path.pop();
                }
                continue;
            }
            let spectrum = p.spectrum(name);
            let Some(Spectrum::Tabulated(table)) = spectrum.as_deref() else { continue };
            if !CONVERTED.contains(&name) {
                continue;
            }
            path.push(name.to_string());
            if let Some(slot) = Slot::of(root, path) {
                out.push((slot, Arc::new(table.clone())));
            }
            path.pop();
        }
    }
    let mut out = Vec::new();
    visit(p, p, &mut Vec::new(), &mut out);
    GivenSpectra(out)
}

impl SpectralScene {
    /// The spectra of `materials` (one per shape: `dependence` as [`check_bsdf`] found it, `colours` as
    /// [`given_spectra`] did; empty for none) and `lights` (`given`: per light, the spectrum its emission was
    /// given as, if it was).
    #[must_use]
    pub fn new(
        materials: &[Material],
        lights: &[Light],
        dependence: Vec<Dependence>,
        colours: Vec<GivenSpectra>,
        given: &[Option<Arc<Spectrum>>],
    ) -> Self {
        let diffuse = materials
            .iter()
            .enumerate()
            .map(|(i, m)| match m {
                Material::Fixed(Bsdf::Diffuse(d)) => Some(match colours.get(i).and_then(|g| g.table("reflectance")) {
                    Some(table) => DiffuseSpectrum::Given(table.clone()),
                    None => DiffuseSpectrum::Fitted(srgb_table().fit(d.reflectance)),
                }),
                _ => None,
            })
            .collect();
        let lights = lights
            .iter()
            .enumerate()
            .map(|(i, l)| {
                let c = l.constant_colour().filter(|c| c.max_component() > 0.0)?;
                let spectrum =
                    given.get(i).cloned().flatten().unwrap_or_else(|| Arc::new(Spectrum::Illuminant(RgbIlluminantSpectrum::new(c))));
                Some((c.max_component(), spectrum))
            })
            .collect();
        SpectralScene { dependence, diffuse, given: colours, lights }
    }

    /// The reflectance `rgb` of shape `shape`'s diffuse material at the wavelengths `lambda`: from the table
    /// it was given as, else its fitted spectrum where its colour is constant, else (a texture's texel) by
    /// [`reflectance_at`].
    #[inline]
    #[must_use]
    pub fn reflectance(&self, shape: usize, rgb: [f32; 3], lambda: [f32; PATH_WAVELENGTHS]) -> [f32; PATH_WAVELENGTHS] {
        match self.diffuse.get(shape) {
            Some(Some(DiffuseSpectrum::Fitted(p))) => lambda.map(|l| p.eval(l)),
            #[allow(clippy::cast_possible_truncation)]
            Some(Some(DiffuseSpectrum::Given(table))) => lambda.map(|l| textured_reflectance(table.eval(f64::from(l)) as f32)),
            _ => reflectance_at(rgb, lambda),
        }
    }

    /// [`SpectralScene::emission`] where light `light` has a spectrum fitted from its one colour (an
    /// [`RgbIlluminantSpectrum`]), in lanes (`rgb` and `lambda` per channel, one light for every lane):
    /// that spectrum times the factor `rgb` is of the light's colour (its largest component over the
    /// colour's; NaN stays NaN). `None` for a light of no one colour or whose spectrum was given, and for
    /// `None`.
    #[inline(always)]
    #[must_use]
    pub fn fitted_emission<R: Real>(&self, light: Option<usize>, rgb: [R; 3], lambda: [R; PATH_WAVELENGTHS]) -> Option<[R; 3]> {
        let (max, spectrum) = self.light_spectrum(light)?;
        let Spectrum::Illuminant(spectrum) = spectrum.as_ref() else { return None };
        let factor = emission_factor(rgb, *max);
        Some(lambda.map(|l| factor * spectrum.eval_lanes(l)))
    }

    /// Light `light`'s spectrum and its colour's largest component, where it has one colour.
    #[inline(always)]
    fn light_spectrum(&self, light: Option<usize>) -> Option<&(f32, Arc<Spectrum>)> {
        light.and_then(|i| self.lights.get(i)).and_then(Option::as_ref)
    }

    /// Emission `rgb` from light `light` (its index; `None` if not known) at the wavelengths `lambda`: the
    /// light's fitted spectrum times the factor `rgb` is of its colour, where it has one colour; else by
    /// [`emission_at`].
    #[inline]
    #[must_use]
    pub fn emission(&self, light: Option<usize>, rgb: [f32; 3], lambda: [f32; PATH_WAVELENGTHS]) -> [f32; PATH_WAVELENGTHS] {
        if let Some(values) = self.fitted_emission(light, rgb, lambda) {
            return values;
        }
        let Some((max, spectrum)) = self.light_spectrum(light) else {
            return emission_at(rgb, lambda);
        };
        let factor = emission_factor(rgb, *max);
        #[allow(clippy::cast_possible_truncation)]
        lambda.map(|l| factor * spectrum.eval(f64::from(l)) as f32)
    }
}

/// The factor emission `rgb` is of a light's colour whose largest component is `max`: rgb's largest (negative
/// counting as 0) over `max`; NaN where a component is NaN, so that the emission is NaN there.
#[inline(always)]
fn emission_factor<R: Real>(rgb: [R; 3], max: f32) -> R {
    let nan = rgb[0].is_nan() | rgb[1].is_nan() | rgb[2].is_nan();
    R::select(nan, R::splat(f32::NAN), rgb[0].max(rgb[1]).max(rgb[2]).max(R::splat(0.0)) / max)
}

impl super::Scene {
    /// Make this scene render in spectral mode: its environment maps' texels taken to spectra, the table
    /// RGB values are taken to spectra with built now rather than by the first path, and its
    /// [`SpectralScene`] (`dependence` and `colours` per shape, as [`check_bsdf`] and [`given_spectra`]
    /// found them; `given` per light, the spectrum its emission was given as, if it was).
    pub(crate) fn make_spectral(&mut self, dependence: Vec<Dependence>, colours: Vec<GivenSpectra>, given: &[Option<Arc<Spectrum>>]) {
        for light in &mut self.lights {
            if let Light::EnvMap(env) = light {
                env.prepare_spectra();
            }
        }
        let _ = srgb_table();
        self.spectral = Some(SpectralScene::new(&self.materials, &self.lights, dependence, colours, given));
    }
}

/// The colour parameters spectral mode converts per lane, where the model holds them as they are
/// ([`Bsdf::reflectance_slot`]).
const CONVERTED: &[&str] =
    &["reflectance", "specular_reflectance", "specular_transmittance", "diffuse_reflectance", "base_color", "transmittance"];

/// Models whose colours spectral mode converts in the models they hold ([`reflectances_at`],
/// [`Bsdf::for_each_nested`]).
const CONTAINERS: &[&str] = &["twosided", "blendbsdf", "sum", "mask", "normalmap", "bumpmap"];

/// Whether spectral mode renders the `<bsdf>` `p` (see the module docs), and how it depends on wavelength.
///
/// # Errors
/// A colour or an index spectral mode does not take yet, naming the parameter and where it was given.
pub fn check_bsdf(p: &Props) -> Result<Dependence> {
    check_model(p, true)
}

/// [`check_bsdf`] for a model reached through [`CONTAINERS`] only (`convertible`) or not. A colour is taken
/// where [`reflectances_at`] sets it: the model built from `p` (its textures left at their defaults) holds
/// it in a [`Bsdf::reflectance_slot`], or it is a conductor's named metal ([`Bsdf::conductor_fresnel`]). A
/// dispersive index is taken where [`Bsdf::dispersion_mut`] or [`Bsdf::set_wavelengths`] sets it.
fn check_model(p: &Props, convertible: bool) -> Result<Dependence> {
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
    let mut dependence = Dependence::None;
    if plugin == "thindielectric" && built()?.is_dispersive() {
        // Its directions do not depend on the index: it takes every wavelength (`ThinDielectric::set_wavelengths`).
        if !convertible {
            return Err(Error::spec(
                p.at(),
                "spectral mode does not take a dispersive index here (`int_ior`/`ext_ior` of `thindielectric`) yet; render it with --mode rgb",
            ));
        }
        dependence = Dependence::Colours;
    } else if matches!(plugin, "dielectric" | "roughdielectric") && built()?.is_dispersive() {
        let refuse = |what: &str| {
            Err(Error::spec(
                p.at(),
                format!("spectral mode does not take {what} (`int_ior`/`ext_ior` of `{plugin}`) yet; render it with --mode rgb"),
            ))
        };
        if built()?.dispersion_mut().is_none() {
            return refuse("a dispersive index in an energy-compensated model");
        }
        if !convertible {
            return refuse("a dispersive index here");
        }
        dependence = Dependence::Dispersion;
    }
    for (name, value, at) in p.values() {
        let refuse = |what: &str| {
            Err(Error::spec(
                at,
                format!("spectral mode does not take {what} (parameter `{name}` of `{plugin}`) yet; render it with --mode rgb"),
            ))
        };
        let what = if compensated { "a colour of an energy-compensated model" } else { "this colour" };
        // A colour: three numbers not all equal, or a table that is not flat (whose reduction may be grey).
        let colour = matches!(value, Value::List(l) if l.len() == 3 && name != "normalmap" && !(l[0] == l[1] && l[1] == l[2]))
            || matches!(p.spectrum(name).as_deref(), Some(Spectrum::Tabulated(t)) if t.flat_value().is_none());
        match value {
            // A dispersive index is taken above.
            _ if matches!(name, "int_ior" | "ext_ior") => {}
            _ if colour => {
                let index = matches!(name, "eta" | "k") && built()?.conductor_fresnel().is_some();
                if !(convertible && (index || CONVERTED.contains(&name) && built()?.reflectance_slot(name).is_some())) {
                    return refuse(what);
                }
                dependence = dependence.max(Dependence::Colours);
            }
            Value::String(s) if name == "material" && s != "none" => {
                if !(convertible && built()?.conductor_fresnel().is_some()) {
                    return refuse(if compensated { "a named metal in an energy-compensated model" } else { "a named metal here" });
                }
                dependence = dependence.max(Dependence::Colours);
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
                    dependence = dependence.max(Dependence::Colours);
                }
            }
            Value::Nested(m) if is_model(m) => {
                dependence = dependence.max(check_model(m, convertible && CONTAINERS.contains(&plugin))?);
            }
            _ => {}
        }
    }
    if plugin == "measured" {
        if !matches!(built()?, Bsdf::Measured(m) if m.has_spectra()) {
            return Err(Error::spec(
                p.at(),
                "spectral mode takes a `measured` file's spectra (fields `spectra` and `wavelengths`), and this file has RGB data only; render it with --mode rgb",
            ));
        }
        if !convertible {
            return Err(Error::spec(p.at(), "spectral mode does not take a `measured` model here yet; render it with --mode rgb"));
        }
        dependence = dependence.max(Dependence::Colours);
    }
    if plugin == "merl" {
        return Err(Error::spec(p.at(), "spectral mode does not take `merl` (its RGB data); render it with --mode rgb"));
    }
    Ok(dependence)
}

/// Whether a nested plugin is a model (not a texture nor a spectrum).
fn is_model(p: &Props) -> bool {
    p.class() != "texture"
}

/// Model `b` at the wavelengths `lambda`, in `b` and in the models it holds ([`Bsdf::for_each_nested`]):
/// each colour parameter of `CONVERTED` (those [`check_bsdf`] takes) replaced by its reflectance spectrum's
/// values at `lambda` (the table it was given as, in `given`, clamped to [0, 1] as a texture's value; else
/// its colour's upsampled spectrum), and what a model reads of the wavelengths itself set by
/// [`Bsdf::set_wavelengths`] (a conductor's index from its spectra, a dispersive dielectric's at the hero
/// wavelength `lambda[0]`, a dispersive `thindielectric`'s per channel, a `measured` file's spectra).
pub fn reflectances_at(b: &mut Bsdf, lambda: [f32; PATH_WAVELENGTHS], given: &GivenSpectra) {
    convert(b, lambda);
    for (slot, table) in &given.0 {
        #[allow(clippy::cast_possible_truncation)]
        let value = Rgb(lambda.map(|l| table.eval(f64::from(l)) as f32));
        slot.write(b, &TextureValue::Colour(value));
    }
}

/// [`reflectances_at`] without the tables.
fn convert(b: &mut Bsdf, lambda: [f32; PATH_WAVELENGTHS]) {
    b.set_wavelengths(lambda);
    for name in CONVERTED {
        if let Some(r) = b.reflectance_slot(name) {
            *r = Rgb(reflectance_at(r.0, lambda));
        }
    }
    b.for_each_nested(&mut |m| convert(m, lambda));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::simd::Float8;
    use crate::sampling::Pcg32;
    use crate::scene::{mitsuba_xml, Scene};
    use std::path::Path;

    /// The emission of lights fitted from a colour, in lanes (as the path tracer's packets take it), is
    /// each lane's [`SpectralScene::emission`] bit for bit, NaN and negative colours included; a light whose
    /// spectrum was given (a black body) has no fitted spectrum and keeps its own.
    #[test]
    fn fitted_emission_in_lanes_is_each_lanes() {
        let xml = r#"<scene version="3.0.0"><sensor type="perspective"/>
            <emitter type="point"><rgb name="intensity" value="4, 2, 0.5"/></emitter>
            <emitter type="constant"><rgb name="radiance" value="0.1, 0.3, 0.9"/></emitter>
            <emitter type="point"><point name="position" x="1" y="0" z="0"/>
                <spectrum name="intensity" type="blackbody"><float name="temperature" value="3000"/></spectrum></emitter>
            </scene>"#;
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/ior");
        let scene = Scene::build_in(mitsuba_xml::load_str(xml, "lights.xml", &dir, &[]).unwrap(), Mode::Spectral).unwrap();
        let spectral = scene.spectral.as_ref().unwrap();
        let mut rng = Pcg32::new(3, 5);
        for round in 0..200 {
            let mut rgb: [[f32; 8]; 3] = std::array::from_fn(|_| std::array::from_fn(|_| 5.0 * rng.next_f32() - 0.5));
            if round % 7 == 0 {
                rgb[round % 3][round % 8] = f32::NAN;
            }
            let lambda: [[f32; 8]; 3] = std::array::from_fn(|_| std::array::from_fn(|_| 360.0 + 470.0 * rng.next_f32()));
            let lanes = |rows: &[[f32; 8]; 3]| rows.map(|r| Float8::load(&r));
            for light in [Some(0), Some(1)] {
                let values = spectral.fitted_emission(light, lanes(&rgb), lanes(&lambda)).unwrap().map(Float8::to_array);
                for l in 0..8 {
                    let one = spectral.emission(light, [rgb[0][l], rgb[1][l], rgb[2][l]], [lambda[0][l], lambda[1][l], lambda[2][l]]);
                    for c in 0..3 {
                        let (a, b) = (values[c][l], one[c]);
                        assert!(
                            a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()) || (a == 0.0 && b == 0.0),
                            "light {light:?} lane {l} channel {c}: {a} against {b}"
                        );
                    }
                }
            }
            assert!(spectral.fitted_emission(Some(2), lanes(&rgb), lanes(&lambda)).is_none());
            assert!(spectral.fitted_emission(None, lanes(&rgb), lanes(&lambda)).is_none());
        }
    }
}
