//! Named optical constants: the complex index (η, k) of metals for `conductor.material`, and the index of
//! refraction of dielectrics for `int_ior` / `ext_ior`, with Mitsuba 3's names and values so that a scene
//! means the same in gonio and in Mitsuba.
//!
//! Metals are measured spectra (`data/ior/NAME.eta.spd`, `NAME.k.spd`, embedded in the binary; see
//! `data/ior/SOURCES.md`) reduced to linear sRGB by [`spectrum_to_rgb`], which follows Mitsuba 3's
//! `spectrum_list_to_srgb(wavelengths, values, bounded = false)` as its RGB variants apply it when a
//! conductor names a `material`:
//!
//! 1. sample λᵢ = 360 + 470·i/999 nm for i = 0 … 999 (1000 points, both ends included);
//! 2. skip λᵢ outside [first, last] tabulated wavelength (the spectrum counts as 0 there — it is *not*
//!    extended by its end values);
//! 3. add s(λᵢ)·(x̄, ȳ, z̄)(λᵢ), with s the piecewise-linear interpolant of the table and the CIE 1931 2°
//!    functions linearly interpolated from their 5 nm table ([`super::cie`]); no illuminant (no D65);
//! 4. scale the sum by 470/1000 nm and by 1/106.75026 (1/∫ȳ), XYZ → linear sRGB (Rec. 709 primaries,
//!    D65 white, the matrix of [`xyz_to_linear_srgb`]), and clamp negative components to 0.
//!
//! So a spectrum equal to 1 everywhere maps to Y = 1, i.e. linear sRGB ≈ (1.2049, 0.9482, 0.9093) — the
//! equal-energy white E — not to (1, 1, 1).
//!
//! ```
//! use gonio::spectrum::named;
//! let (eta, k) = named::conductor("Au").unwrap();
//! assert!((eta.b() - 1.442_045).abs() < 1e-5 && (k.r() - 3.982_997).abs() < 1e-5);
//! assert_eq!(named::dielectric_ior("bk7"), Some(1.5046));
//! ```

use std::sync::OnceLock;

use super::cie::{cie1931_xyz, CIE_MAX, CIE_MIN, CIE_Y_NORMALIZATION};
use super::illuminant::d65;
use super::piecewise::PiecewiseLinear;
use super::Rgb;

/// Names accepted by `conductor.material`: `"none"` (a perfect mirror) and every metal with embedded
/// data, spelled as Mitsuba 3 spells them (its `data/ior/NAME.eta.spd` file names; case-sensitive).
pub const CONDUCTORS: &[&str] =
    &["none", "a-C", "Ag", "Al", "Au", "Be", "Cr", "Cu", "Ir", "Li", "Mo", "Ni_palik", "Rh", "Ta", "TiN", "V_palik", "W"];

/// The embedded spectra: (name, η table, k table), in the `.spd` text format of [`parse_spd`].
macro_rules! spd_tables {
    ($($name:literal),* $(,)?) => {
        &[$((
            $name,
            include_str!(concat!("../../data/ior/", $name, ".eta.spd")),
            include_str!(concat!("../../data/ior/", $name, ".k.spd")),
        )),*]
    };
}
const CONDUCTOR_SPECTRA: &[(&str, &str, &str)] =
    spd_tables!("a-C", "Ag", "Al", "Au", "Be", "Cr", "Cu", "Ir", "Li", "Mo", "Ni_palik", "Rh", "Ta", "TiN", "V_palik", "W",);

/// (η, k) of a named conductor, reduced to linear sRGB as Mitsuba 3's RGB variants do (see the module
/// docs). `"none"` gives (0, 1); gonio treats it as a 100 % mirror before it looks at η and k.
#[must_use]
pub fn conductor(name: &str) -> Option<(Rgb, Rgb)> {
    if name == "none" {
        return Some((Rgb::ZERO, Rgb::ONE));
    }
    // The reductions are computed once, on first use (32 spectra × 1000 samples).
    static PRESETS: OnceLock<Vec<(&'static str, Rgb, Rgb)>> = OnceLock::new();
    let presets = PRESETS.get_or_init(|| {
        CONDUCTOR_SPECTRA.iter().map(|&(name, eta, k)| (name, embedded_spd_to_rgb(name, eta), embedded_spd_to_rgb(name, k))).collect()
    });
    presets.iter().find(|p| p.0 == name).map(|&(_, eta, k)| (eta, k))
}

/// (η, k) of a named conductor as spectra (the embedded `.spd` tables, linearly interpolated; their nodes
/// span at least 310–885 nm): what spectral mode evaluates at a path's wavelengths. `None` for `"none"`
/// and unknown names.
#[must_use]
pub fn conductor_spectra(name: &str) -> Option<&'static (PiecewiseLinear, PiecewiseLinear)> {
    static TABLES: OnceLock<Vec<(&'static str, (PiecewiseLinear, PiecewiseLinear))>> = OnceLock::new();
    let tables = TABLES.get_or_init(|| {
        let table = |name: &str, text: &str| {
            PiecewiseLinear::from_spd(text).unwrap_or_else(|e| panic!("embedded spectrum of `{name}` is malformed: {e}"))
        };
        CONDUCTOR_SPECTRA.iter().map(|&(name, eta, k)| (name, (table(name, eta), table(name, k)))).collect()
    });
    tables.iter().find(|t| t.0 == name).map(|t| &t.1)
}

/// Reduces one embedded table. The tables are compiled in and checked by the tests, so a parse error
/// here is a bug in gonio, not bad user input.
fn embedded_spd_to_rgb(name: &str, text: &str) -> Rgb {
    let (wavelengths, values) = parse_spd(text).unwrap_or_else(|e| panic!("embedded spectrum of `{name}` is malformed: {e}"));
    spectrum_to_rgb(&wavelengths, &values)
}

/// Named dielectrics and their index of refraction at ~589 nm (sodium D line), from Mitsuba 3's
/// `include/mitsuba/render/ior.h` (commit b45b0a9), whose values come from E. Hecht, *Optics*, 4th ed.
const DIELECTRIC_TABLE: &[(&str, f32)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000_036),
    ("hydrogen", 1.000_132),
    ("air", 1.000_277),
    ("carbon dioxide", 1.000_45),
    ("water", 1.3330),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.520_45),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.5750),
    ("diamond", 2.419),
];

/// Names accepted as dielectric indices (`int_ior`, `ext_ior`); Mitsuba 3's list (`ior.h`), with the
/// values of E. Hecht, *Optics*, 4th ed., at ~589 nm. Names with spaces are keys as written.
pub const DIELECTRICS: &[&str] = &[
    "vacuum",
    "helium",
    "hydrogen",
    "air",
    "carbon dioxide",
    "water",
    "acetone",
    "ethanol",
    "carbon tetrachloride",
    "glycerol",
    "benzene",
    "silicone oil",
    "bromine",
    "water ice",
    "fused quartz",
    "pyrex",
    "acrylic glass",
    "polypropylene",
    "bk7",
    "sodium chloride",
    "amber",
    "pet",
    "diamond",
];

/// The index of refraction of a named dielectric at ~589 nm. Like Mitsuba, the name is matched
/// ignoring ASCII case (`"BK7"` is `"bk7"`).
#[must_use]
pub fn dielectric_ior(name: &str) -> Option<f32> {
    DIELECTRIC_TABLE.iter().find(|(n, _)| n.eq_ignore_ascii_case(name)).map(|&(_, ior)| ior)
}

/// Number of wavelengths at which [`spectrum_to_rgb`] samples [`CIE_MIN`, `CIE_MAX`] (Mitsuba 3's
/// `spectrum_list_to_srgb` uses 1000).
const SPECTRUM_TO_RGB_STEPS: usize = 1000;

/// Reduces a piecewise-linear spectrum (`values` at ascending `wavelengths` in nm) to linear sRGB exactly
/// as Mitsuba 3's `spectrum_list_to_srgb(wavelengths, values, bounded = false)` does (the steps are in
/// the module docs): unbounded above, negative components clamped to 0, zero outside the table.
///
/// Malformed input does not panic: extra entries of the longer slice are ignored, fewer than two
/// points give black, and a zero-width interval takes its right value.
#[must_use]
pub fn spectrum_to_rgb(wavelengths: &[f64], values: &[f64]) -> Rgb {
    debug_assert_eq!(wavelengths.len(), values.len(), "one value per wavelength");
    let n = wavelengths.len().min(values.len());
    clamped_rgb(SpectrumToRgb::new(&wavelengths[..n]).linear_rgb(&values[..n]))
}

/// Reduces a *reflectance* spectrum to linear sRGB as Mitsuba 3's RGB variants reduce the `<spectrum>` of
/// a BSDF parameter: the colour it has under D65, the white of sRGB — [`spectrum_to_rgb`] of the spectrum
/// times [`d65`] (of luminance 1), so that 1 everywhere gives (1, 1, 1) — with negative components clamped
/// to 0 (a parameter with a range clamps the rest: [`crate::props::Props::rgb_in`]). Measured on Mitsuba
/// 3.9.1 `scalar_rgb` (2026-12-06, the reflectance of a `diffuse`): a flat 0.78 over 400–700 nm gives
/// (0.7764, 0.7798, 0.7760) there; a spectrum of three dips to 0.05 (at 450, 550 and 610 nm) gives
/// (0.3456, 0.4363, 0.2434), where gonio's reduction before, by the response to the equal-energy white,
/// gave 26 % more red. Also the reduction of the spectral RGL files ([`crate::bsdf::measured`]).
#[must_use]
pub fn reflectance_to_rgb(wavelengths: &[f64], values: &[f64]) -> Rgb {
    let n = wavelengths.len().min(values.len());
    clamped_rgb(SpectrumToRgb::under_d65(&wavelengths[..n]).linear_rgb(&values[..n]))
}

#[allow(clippy::cast_possible_truncation)] // gonio renders in f32
fn clamped_rgb(rgb: [f64; 3]) -> Rgb {
    Rgb::new(rgb[0].max(0.0) as f32, rgb[1].max(0.0) as f32, rgb[2].max(0.0) as f32)
}

/// The reduction of [`spectrum_to_rgb`] for one fixed list of wavelengths, as the linear map it is: the
/// linear sRGB of a piecewise-linear spectrum is Σₖ vₖ Wₖ, with Wₖ the (unclamped) sRGB of the k-th "hat"
/// basis function (1 at λₖ, 0 at the other nodes). The weights are computed once by the four steps of the
/// module docs; reducing a spectrum is then 3 multiply–adds per wavelength, which is what a table of
/// thousands of spectra (a spectral RGL file) needs.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectrumToRgb {
    /// Wₖ: the linear sRGB of the k-th hat function.
    weights: Vec<[f64; 3]>,
}

impl SpectrumToRgb {
    /// The reduction for spectra tabulated at `wavelengths` (nm, ascending). Fewer than two wavelengths,
    /// or none inside [[`CIE_MIN`], [`CIE_MAX`]], give a reduction to black.
    #[must_use]
    pub fn new(wavelengths: &[f64]) -> Self {
        Self::weighted(wavelengths, |_| 1.0)
    }

    /// The reduction of reflectances seen under D65 ([`reflectance_to_rgb`]): each spectrum times [`d65`].
    #[must_use]
    pub fn under_d65(wavelengths: &[f64]) -> Self {
        Self::weighted(wavelengths, d65)
    }

    /// The reduction of spectra times `weight(λ)`.
    fn weighted(wavelengths: &[f64], weight: impl Fn(f64) -> f64) -> Self {
        debug_assert!(wavelengths.windows(2).all(|w| w[0] <= w[1]), "wavelengths must ascend");
        let n = wavelengths.len();
        let mut xyz = vec![[0.0_f64; 3]; n];
        if n >= 2 {
            let (first, last) = (wavelengths[0], wavelengths[n - 1]);
            for i in 0..SPECTRUM_TO_RGB_STEPS {
                // Step 1: 1000 wavelengths spanning the CIE range, both ends included.
                let lambda = CIE_MIN + (i as f64 / (SPECTRUM_TO_RGB_STEPS - 1) as f64) * (CIE_MAX - CIE_MIN);
                // Step 2: outside the table the spectrum counts as 0.
                if !(first..=last).contains(&lambda) {
                    continue;
                }
                // Step 3: the interval [x0, x1] holding λ (the last one for λ = last); the linear
                // interpolant puts weight 1 − t on the left node and t on the right one.
                let i0 = (wavelengths.partition_point(|&w| w <= lambda).saturating_sub(1)).min(n - 2);
                let (x0, x1) = (wavelengths[i0], wavelengths[i0 + 1]);
                let t = if x1 > x0 { (lambda - x0) / (x1 - x0) } else { 1.0 };
                let cmf = cie1931_xyz(lambda).map(|v| v * weight(lambda));
                for c in 0..3 {
                    xyz[i0][c] += (1.0 - t) * cmf[c];
                    xyz[i0 + 1][c] += t * cmf[c];
                }
            }
        }
        // Step 4: Mitsuba's scale is 470 nm / 1000 (not / 999), then 1/∫ȳ; XYZ → linear sRGB is linear too.
        let scale = (CIE_MAX - CIE_MIN) / SPECTRUM_TO_RGB_STEPS as f64 * CIE_Y_NORMALIZATION;
        SpectrumToRgb { weights: xyz.into_iter().map(|w| xyz_to_linear_srgb(w.map(|v| v * scale))).collect() }
    }

    /// Number of wavelengths the reduction expects.
    #[must_use]
    pub fn len(&self) -> usize {
        self.weights.len()
    }

    /// Whether it expects no wavelengths.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }

    /// Whether every spectrum reduces to black (fewer than two wavelengths, or none in the CIE range).
    #[must_use]
    pub fn is_black(&self) -> bool {
        self.weights.iter().all(|w| *w == [0.0; 3])
    }

    /// Linear sRGB of the spectrum with `values` at the wavelengths, unclamped (negative where the
    /// spectrum is out of the sRGB gamut). `values` has one entry per wavelength.
    #[must_use]
    pub fn linear_rgb(&self, values: &[f64]) -> [f64; 3] {
        debug_assert_eq!(values.len(), self.weights.len(), "one value per wavelength");
        let mut rgb = [0.0_f64; 3];
        for (w, v) in self.weights.iter().zip(values) {
            for c in 0..3 {
                rgb[c] += w[c] * v;
            }
        }
        rgb
    }
}

/// CIE XYZ → linear sRGB (Rec. 709 primaries, D65 white), with the coefficients Mitsuba 3 uses
/// (`xyz_to_srgb`: IEC 61966-2-1 to 6 decimals, stored as `f32`).
#[must_use]
pub fn xyz_to_linear_srgb(xyz: [f64; 3]) -> [f64; 3] {
    const M: [[f32; 3]; 3] = [[3.240_479, -1.537_15, -0.498_535], [-0.969_256, 1.875_991, 0.041_556], [0.055_648, -0.204_043, 1.057_311]];
    M.map(|row| f64::from(row[0]) * xyz[0] + f64::from(row[1]) * xyz[1] + f64::from(row[2]) * xyz[2])
}

/// Why a `.spd` text could not be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpdError {
    /// A line is not "wavelength value" (two finite numbers).
    #[error("line {line}: {reason}")]
    Syntax { line: usize, reason: String },
    /// A wavelength does not exceed the one before it.
    #[error("line {line}: wavelength {wavelength} nm does not exceed the previous one")]
    NotAscending { line: usize, wavelength: f64 },
    /// Fewer than two (wavelength, value) pairs.
    #[error("a spectrum needs at least two points, found {0}")]
    TooFewPoints(usize),
}

/// Parses a spectrum in the `.spd` text format of Mitsuba's `data/ior/` files: lines starting with `#`
/// (after optional spaces) and blank lines are skipped; every other line is "wavelength_nm value"
/// separated by whitespace. Wavelengths must ascend strictly and there must be at least two points.
///
/// # Errors
/// [`SpdError`] with the 1-based line number of the first bad line.
pub fn parse_spd(text: &str) -> Result<(Vec<f64>, Vec<f64>), SpdError> {
    let mut wavelengths = Vec::new();
    let mut values = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let trimmed = raw.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let syntax = |reason: String| SpdError::Syntax { line, reason };
        let mut tokens = trimmed.split_whitespace();
        let mut number = |what: &str| -> Result<f64, SpdError> {
            let token = tokens.next().ok_or_else(|| syntax(format!("missing {what}")))?;
            match token.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(syntax(format!("{what} `{token}` is not a finite number"))),
            }
        };
        let wavelength = number("wavelength")?;
        let value = number("value")?;
        if let Some(extra) = tokens.next() {
            return Err(syntax(format!("unexpected `{extra}` after the wavelength-value pair")));
        }
        if wavelengths.last().is_some_and(|&previous| wavelength <= previous) {
            return Err(SpdError::NotAscending { line, wavelength });
        }
        wavelengths.push(wavelength);
        values.push(value);
    }
    if wavelengths.len() < 2 {
        return Err(SpdError::TooFewPoints(wavelengths.len()));
    }
    Ok((wavelengths, values))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mitsuba 3.9.1's RGB (η, k) of every preset, from
    /// ```text
    /// python -c "import mitsuba as mi; mi.set_variant('scalar_rgb'); \
    ///   p = mi.traverse(mi.load_dict({'type': 'conductor', 'material': NAME})); \
    ///   print([f'{float(c):.9e}' for c in p['eta.value']], [f'{float(c):.9e}' for c in p['k.value']])"
    /// ```
    /// for each NAME (Mitsuba's own data/ior files, byte-identical to the embedded ones).
    #[rustfmt::skip]
    const MITSUBA_REFERENCE: &[(&str, [f64; 3], [f64; 3])] = &[
        ("Ag", [1.552761942e-01, 1.167279556e-01, 1.383876354e-01], [4.828354359e+00, 3.122222424e+00, 2.146901131e+00]),
        ("Al", [1.657500863e+00, 8.804047108e-01, 5.212444663e-01], [9.223811150e+00, 6.269502163e+00, 4.837004185e+00]),
        ("Au", [1.430359781e-01, 3.753070831e-01, 1.442045331e+00], [3.982996941e+00, 2.385556459e+00, 1.603359222e+00]),
        ("Be", [4.185012341e+00, 3.185029268e+00, 2.784061193e+00], [3.835465908e+00, 3.010122299e+00, 2.868993998e+00]),
        ("Cr", [4.369667530e+00, 2.916505337e+00, 1.654904604e+00], [5.206546783e+00, 4.231306076e+00, 3.754698753e+00]),
        ("Cu", [2.010054737e-01, 9.237495065e-01, 1.102215409e+00], [3.913262129e+00, 2.453045130e+00, 2.142089844e+00]),
        ("Ir", [3.086299896e+00, 2.082190514e+00, 1.617914557e+00], [5.592153072e+00, 4.067088127e+00, 3.267312050e+00]),
        ("Li", [2.657909393e-01, 1.956183165e-01, 2.209486216e-01], [3.540154934e+00, 2.311123371e+00, 1.668607235e+00]),
        ("Mo", [4.483973980e+00, 3.525130749e+00, 2.776310444e+00], [4.111437321e+00, 3.420826912e+00, 3.150607347e+00]),
        ("Ni_palik", [2.367304564e+00, 1.663373113e+00, 1.467078090e+00], [4.498811722e+00, 3.050153017e+00, 2.345439196e+00]),
        ("Rh", [2.585793495e+00, 1.860216379e+00, 1.554263353e+00], [6.782260418e+00, 4.702987194e+00, 3.976073027e+00]),
        ("Ta", [2.062721014e+00, 2.392938852e+00, 2.627928734e+00], [2.408359766e+00, 1.741486430e+00, 1.947027802e+00]),
        ("TiN", [1.648449659e+00, 1.150516033e+00, 1.379823446e+00], [3.368328094e+00, 1.943498135e+00, 1.102067709e+00]),
        ("V_palik", [4.277582169e+00, 3.512948751e+00, 2.761071444e+00], [3.491300821e+00, 2.889454842e+00, 3.111521959e+00]),
        ("W", [4.370816708e+00, 3.300246477e+00, 2.998407364e+00], [3.500640631e+00, 2.604873896e+00, 2.273233175e+00]),
        ("a-C", [2.944045782e+00, 2.227136374e+00, 1.968161702e+00], [8.874648809e-01, 7.992985249e-01, 8.152899742e-01]),
    ];

    /// Both sides are `f32` roundings of the same double-precision sum. Observed: the same `f32` for every
    /// channel of every preset (worst relative difference 3.6e-10, the 10-digit printing of the
    /// references); 1e-7 (about one `f32` ulp) only leaves room for summation-order rounding.
    const TOLERANCE: f64 = 1e-7;

    fn max_relative_error(got: Rgb, want: [f64; 3]) -> f64 {
        got.to_f64().iter().zip(want).map(|(g, w)| (g - w).abs() / w.abs().max(1e-30)).fold(0.0, f64::max)
    }

    #[test]
    fn presets_match_mitsuba() {
        assert_eq!(MITSUBA_REFERENCE.len() + 1, CONDUCTORS.len());
        for &(name, eta_ref, k_ref) in MITSUBA_REFERENCE {
            let (eta, k) = conductor(name).unwrap();
            let error = max_relative_error(eta, eta_ref).max(max_relative_error(k, k_ref));
            assert!(error < TOLERANCE, "{name}: η {eta} vs {eta_ref:?}, k {k} vs {k_ref:?}: {error:e}");
        }
    }

    #[test]
    fn every_conductor_name_resolves() {
        assert_eq!(conductor("none"), Some((Rgb::ZERO, Rgb::ONE)));
        let data_names: Vec<&str> = CONDUCTOR_SPECTRA.iter().map(|s| s.0).collect();
        assert_eq!(&CONDUCTORS[1..], &data_names[..]);
        for name in CONDUCTORS {
            let (eta, k) = conductor(name).unwrap_or_else(|| panic!("{name}"));
            assert!(eta.is_finite() && k.is_finite() && eta.min_component() >= 0.0, "{name}");
        }
        for &(name, eta, k) in CONDUCTOR_SPECTRA {
            assert!(parse_spd(eta).is_ok() && parse_spd(k).is_ok(), "{name}");
        }
    }

    #[test]
    fn unknown_names_give_none() {
        assert_eq!(conductor("Unobtainium"), None);
        assert_eq!(conductor("au"), None); // conductor names are case-sensitive, as Mitsuba's file names
        assert_eq!(conductor(""), None);
        assert_eq!(dielectric_ior("unobtainium"), None);
        assert_eq!(dielectric_ior(""), None);
    }

    #[test]
    fn dielectrics() {
        assert_eq!(dielectric_ior("bk7"), Some(1.5046));
        assert_eq!(dielectric_ior("BK7"), Some(1.5046));
        assert_eq!(dielectric_ior("water ice"), Some(1.31));
        assert_eq!(dielectric_ior("carbon dioxide"), Some(1.000_45));
        assert_eq!(dielectric_ior("diamond"), Some(2.419));
        let table_names: Vec<&str> = DIELECTRIC_TABLE.iter().map(|d| d.0).collect();
        assert_eq!(DIELECTRICS, &table_names[..]);
        assert!(DIELECTRICS.iter().all(|n| dielectric_ior(n).is_some_and(|ior| ior >= 1.0)));
    }

    /// Mitsuba 3.9.1 through the same double-precision path as the presets: files `data/ior/one.eta.spd`
    /// ("300 1\n900 1") and `data/ior/one.k.spd` ("500 1\n600 1") in a directory DIR, then
    /// ```text
    /// python -c "import mitsuba as mi; mi.set_variant('scalar_rgb'); mi.file_resolver().prepend(DIR); \
    ///   p = mi.traverse(mi.load_dict({'type': 'conductor', 'material': 'one'})); \
    ///   print([f'{float(c):.9e}' for c in p['eta.value']], [f'{float(c):.9e}' for c in p['k.value']])"
    /// ```
    /// (The Python binding `mi.spectrum_list_to_srgb` of scalar variants is the single-precision
    /// instantiation and differs from these by up to 9e-7.)
    #[test]
    fn constant_spectra_match_mitsuba() {
        // 1 over the whole CIE range: the equal-energy white with Y = 1 — not (1, 1, 1), as no
        // illuminant enters the integral.
        let white = spectrum_to_rgb(&[300.0, 900.0], &[1.0, 1.0]);
        assert!(max_relative_error(white, [1.204_883_695, 0.948_228_180_4, 0.909_266_829_5]) < TOLERANCE);
        assert!((f64::from(white.luminance()) - 1.0).abs() < 1e-3);
        // 1 on [500, 600] nm only: zero outside the table, and blue (−0.0856) clamped to 0.
        let band = spectrum_to_rgb(&[500.0, 600.0], &[1.0, 1.0]);
        assert!(max_relative_error(band + Rgb::new(0.0, 0.0, 1.0), [0.273_065_120_0, 0.987_912_774_1, 1.0]) < TOLERANCE);
        assert_eq!(band.b(), 0.0);
        // Linear in the spectrum.
        let doubled = spectrum_to_rgb(&[300.0, 900.0], &[2.0, 2.0]);
        assert!(max_relative_error(doubled, (white * 2.0).to_f64()) < 1e-6);
    }

    #[test]
    fn degenerate_spectra_do_not_panic() {
        assert_eq!(spectrum_to_rgb(&[], &[]), Rgb::ZERO);
        assert_eq!(spectrum_to_rgb(&[550.0], &[1.0]), Rgb::ZERO);
        assert_eq!(spectrum_to_rgb(&[900.0, 1000.0], &[1.0, 1.0]), Rgb::ZERO);
    }

    #[test]
    fn parse_spd_reads_comments_and_pairs() {
        let text = "# comment\n\n  # indented comment\n400 1.5\n500\t2.0  \n600 2.5e0\n";
        assert_eq!(parse_spd(text), Ok((vec![400.0, 500.0, 600.0], vec![1.5, 2.0, 2.5])));
    }

    #[test]
    fn parse_spd_rejects_malformed_text() {
        let syntax_line = |text: &str| match parse_spd(text) {
            Err(SpdError::Syntax { line, .. }) => line,
            other => panic!("{text:?}: {other:?}"),
        };
        assert_eq!(syntax_line("400 1\n500\n"), 2); // missing value
        assert_eq!(syntax_line("400 1\n500 2 3\n"), 2); // excess token
        assert_eq!(syntax_line("# x\n400 one\n"), 2); // not a number
        assert_eq!(syntax_line("400 1\nnan 2\n"), 2); // not finite
        assert_eq!(syntax_line("400 1\n500 inf\n"), 2);
        assert_eq!(parse_spd("500 1\n400 2\n"), Err(SpdError::NotAscending { line: 2, wavelength: 400.0 }));
        assert_eq!(parse_spd("500 1\n500 2\n"), Err(SpdError::NotAscending { line: 2, wavelength: 500.0 }));
        assert_eq!(parse_spd("# only a comment\n"), Err(SpdError::TooFewPoints(0)));
        assert_eq!(parse_spd("500 1\n"), Err(SpdError::TooFewPoints(1)));
        assert_eq!(parse_spd(""), Err(SpdError::TooFewPoints(0)));
    }
}
