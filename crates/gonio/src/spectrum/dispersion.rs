//! Dispersion: an index of refraction that varies with wavelength.
//!
//! | form | formula (λ in µm) | parameters |
//! |---|---|---|
//! | [`Sellmeier`] | n² = 1 + Σᵢ Bᵢ λ² / (λ² − Cᵢ), up to 4 terms | Bᵢ (dimensionless), Cᵢ (µm²) |
//! | [`Cauchy`] | n = A + B / λ² + C / λ⁴ | A, B (µm²), C (µm⁴) |
//! | [`Cauchy::from_abbe`] | the two-term Cauchy law through n_d with Abbe number V_d | n_d, V_d |
//! | [`Ior::Tabulated`] | linear interpolation of (λ nm, n) pairs, end values outside | a table |
//!
//! The **Abbe number** is V_d = (n_d − 1) / (n_F − n_C) at the Fraunhofer lines d = 587.56 nm (helium),
//! F = 486.13 nm and C = 656.27 nm (hydrogen). glTF's `KHR_materials_dispersion` (and OpenPBR after it)
//! defines a material's dispersion by V_d alone and turns it into a Cauchy law: since
//! n_F − n_C = B (λ_F⁻² − λ_C⁻²) for n = A + B/λ²,
//!
//! ```text
//! B = (n_d − 1) / (V_d (λ_F⁻² − λ_C⁻²)),   A = n_d − B / λ_d².
//! ```
//!
//! **Named glasses** ([`Ior::named`], names matched ignoring ASCII case), with the source of each:
//!
//! | name | form | source | n_d (published) |
//! |---|---|---|---|
//! | `bk7` | Sellmeier | Schott N-BK7 data sheet | 1.51680 (V_d 64.17) |
//! | `fused silica` | Sellmeier | I. H. Malitson, "Interspecimen comparison of the refractive index of fused silica", JOSA 55 (1965) 1205 | 1.4585 |
//! | `baf10` | Sellmeier | Schott N-BAF10 data sheet | 1.67003 (V_d 47.11) |
//! | `f2` | Sellmeier | Schott F2 data sheet | 1.62004 (V_d 36.37) |
//! | `sf11` | Sellmeier | Schott SF11 data sheet | 1.78472 (V_d 25.68) |
//! | `water` | Sellmeier, 4 terms | M. Daimon & A. Masumura, "Measurement of the refractive index of distilled water from the near-infrared region to the ultraviolet region", Applied Optics 46 (2007) 3811, 20.0 °C | 1.3334 (their fit; 1.3330 is the usual n_D at 20 °C) |
//! | `diamond` | Sellmeier, 2 terms | F. Peter, "Über Brechungsindizes und Absorptionskonstanten des Diamanten zwischen 644 und 226 mμ", Zeitschrift für Physik 15 (1923) 358 | 2.4175 |
//! | `glass-BK7`, `glass-BAF10`, `glass-FK51A`, `glass-LASF9`, `glass-F5`, `glass-F10`, `glass-F11` | tabulated | pbrt-v4's named spectra (`src/pbrt/util/spectrum.cpp`, Apache-2.0; `data/ior/pbrt-v4/`, names as pbrt-v4 spells them) | — |
//!
//! Schott's coefficients are those of its optical glass catalogue (Sellmeier form, valid about
//! 0.3–2.5 µm). These indices are for the glass in air, as the catalogues give them; like Mitsuba,
//! gonio takes an index as relative to the exterior medium, `ext_ior`.
//!
//! ```
//! use gonio::spectrum::dispersion::{Ior, LAMBDA_D};
//! let bk7 = Ior::named("BK7").unwrap();
//! assert!((bk7.eta(LAMBDA_D) - 1.5168).abs() < 1e-4);
//! assert!(bk7.eta(400.0) > bk7.eta(700.0)); // normal dispersion: blue bends more
//! assert!((bk7.abbe_number() - 64.17).abs() < 0.05);
//! ```

use super::named::SpdError;
use super::piecewise::PiecewiseLinear;

/// The helium d line, nm: where n_d is quoted.
pub const LAMBDA_D: f64 = 587.56;
/// The hydrogen F line, nm.
pub const LAMBDA_F: f64 = 486.13;
/// The hydrogen C line, nm.
pub const LAMBDA_C: f64 = 656.27;

/// Why a dispersion law could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DispersionError {
    /// A Sellmeier law with more terms than [`Sellmeier::MAX_TERMS`], or B and C of different lengths.
    #[error("a Sellmeier law takes 1 to {max} (B, C) pairs, got {b} B and {c} C values", max = Sellmeier::MAX_TERMS)]
    SellmeierTerms { b: usize, c: usize },
    /// A coefficient is NaN or infinite.
    #[error("coefficient {name} = {value} is not finite")]
    NotFinite { name: &'static str, value: f64 },
    /// An Abbe number or n_d out of range (V_d must be > 0 and n_d ≥ 1).
    #[error("{name} = {value} is out of range ({reason})")]
    OutOfRange { name: &'static str, value: f64, reason: &'static str },
    /// A malformed table.
    #[error("index table: {0}")]
    Table(#[from] SpdError),
}

fn finite(name: &'static str, value: f64) -> Result<f64, DispersionError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(DispersionError::NotFinite { name, value })
    }
}

/// The Sellmeier law n²(λ) = 1 + Σᵢ Bᵢ λ² / (λ² − Cᵢ), λ in µm, Cᵢ in µm² (the squares of the
/// resonance wavelengths), with up to [`Self::MAX_TERMS`] terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sellmeier {
    /// Bᵢ; unused terms are 0.
    b: [f64; Sellmeier::MAX_TERMS],
    /// Cᵢ in µm²; unused terms are 0.
    c: [f64; Sellmeier::MAX_TERMS],
}

impl Sellmeier {
    /// The most terms a law may have (water's law has 4).
    pub const MAX_TERMS: usize = 4;

    /// A law from its B and C coefficients (C in µm²).
    ///
    /// # Errors
    /// [`DispersionError::SellmeierTerms`] for 0 or more than 4 terms or unequal lengths,
    /// [`DispersionError::NotFinite`] for a NaN or infinite coefficient.
    pub fn new(b: &[f64], c: &[f64]) -> Result<Self, DispersionError> {
        if b.len() != c.len() || b.is_empty() || b.len() > Self::MAX_TERMS {
            return Err(DispersionError::SellmeierTerms { b: b.len(), c: c.len() });
        }
        let mut law = Sellmeier { b: [0.0; Self::MAX_TERMS], c: [0.0; Self::MAX_TERMS] };
        for i in 0..b.len() {
            law.b[i] = finite("B", b[i])?;
            law.c[i] = finite("C", c[i])?;
        }
        Ok(law)
    }

    /// The index at `lambda` nm. Where the law gives n² < 0 (inside an absorption band, far outside the
    /// range it was fitted on) the result is 0 rather than NaN.
    #[must_use]
    pub fn eta(&self, lambda: f64) -> f64 {
        let l2 = (lambda * 1e-3) * (lambda * 1e-3);
        let n2 = 1.0 + self.b.iter().zip(&self.c).map(|(b, c)| b * l2 / (l2 - c)).sum::<f64>();
        n2.max(0.0).sqrt()
    }
}

/// The Cauchy law n(λ) = A + B / λ² + C / λ⁴, λ in µm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cauchy {
    /// A (dimensionless).
    pub a: f64,
    /// B in µm².
    pub b: f64,
    /// C in µm⁴ (0 for the two-term law).
    pub c: f64,
}

impl Cauchy {
    /// The two-term law (C = 0) with index `n_d` at [`LAMBDA_D`] and Abbe number `abbe` (V_d), as
    /// glTF's `KHR_materials_dispersion` defines it (module docs). V_d = ∞ gives a constant index.
    ///
    /// # Errors
    /// [`DispersionError::OutOfRange`] for n_d < 1 or NaN, or V_d ≤ 0 or NaN.
    pub fn from_abbe(n_d: f64, abbe: f64) -> Result<Self, DispersionError> {
        if !(n_d >= 1.0) || !n_d.is_finite() {
            return Err(DispersionError::OutOfRange { name: "n_d", value: n_d, reason: "an index ≥ 1" });
        }
        if !(abbe > 0.0) {
            return Err(DispersionError::OutOfRange { name: "abbe", value: abbe, reason: "V_d > 0" });
        }
        let inv2 = |lambda_nm: f64| 1.0 / (lambda_nm * 1e-3 * lambda_nm * 1e-3);
        // n_F − n_C = B (λ_F⁻² − λ_C⁻²) = (n_d − 1) / V_d; then A from n(λ_d) = n_d.
        let b = (n_d - 1.0) / (abbe * (inv2(LAMBDA_F) - inv2(LAMBDA_C)));
        Ok(Cauchy { a: n_d - b * inv2(LAMBDA_D), b, c: 0.0 })
    }

    /// The index at `lambda` nm.
    #[must_use]
    pub fn eta(&self, lambda: f64) -> f64 {
        let inv2 = 1.0 / ((lambda * 1e-3) * (lambda * 1e-3));
        self.c.mul_add(inv2 * inv2, self.b.mul_add(inv2, self.a))
    }
}

/// An index of refraction as a function of wavelength.
#[derive(Clone, Debug, PartialEq)]
pub enum Ior {
    /// The same index at every wavelength (no dispersion).
    Constant(f64),
    /// A [`Sellmeier`] law.
    Sellmeier(Sellmeier),
    /// A [`Cauchy`] law (also the form of an Abbe number).
    Cauchy(Cauchy),
    /// (λ nm, n) pairs, linearly interpolated, the end values outside the table.
    Tabulated(PiecewiseLinear),
}

/// Sellmeier coefficients (B₁…, C₁… in µm²) of the named glasses; sources in the module docs.
const SELLMEIER_GLASSES: &[(&str, &[f64], &[f64])] = &[
    // Schott N-BK7.
    ("bk7", &[1.039_612_12, 0.231_792_344, 1.010_469_45], &[0.006_000_698_67, 0.020_017_914_4, 103.560_653]),
    // Malitson 1965, his three-term law: resonance wavelengths 0.0684043, 0.1162414, 9.896161 µm, squared.
    (
        "fused silica",
        &[0.696_166_3, 0.407_942_6, 0.897_479_4],
        &[0.068_404_3 * 0.068_404_3, 0.116_241_4 * 0.116_241_4, 9.896_161 * 9.896_161],
    ),
    // Schott N-BAF10.
    ("baf10", &[1.585_149_5, 0.143_559_385, 1.085_212_69], &[0.009_266_812_82, 0.042_448_980_5, 105.613_573]),
    // Schott F2.
    ("f2", &[1.345_333_59, 0.209_073_176, 0.937_357_162], &[0.009_977_438_71, 0.047_045_076_7, 111.886_764]),
    // Schott SF11.
    ("sf11", &[1.737_596_95, 0.313_747_346, 1.898_781_01], &[0.013_188_707, 0.062_306_814_2, 155.236_29]),
    // Daimon & Masumura 2007, distilled water at 20.0 °C, their 4-term fit.
    (
        "water",
        &[5.684_027_565e-1, 1.726_177_391e-1, 2.086_189_578e-2, 1.130_748_688e-1],
        &[5.101_829_712e-3, 1.821_153_936e-2, 2.620_722_293e-2, 1.069_792_721e1],
    ),
    // Peter 1923: resonance wavelengths 0.175 and 0.106 µm, squared.
    ("diamond", &[0.3306, 4.3356], &[0.175 * 0.175, 0.106 * 0.106]),
];

/// pbrt-v4's tabulated glass indices (name, embedded table).
const TABULATED_GLASSES: &[(&str, &str)] = &[
    ("glass-BK7", include_str!("../../data/ior/pbrt-v4/GlassBK7_eta.txt")),
    ("glass-BAF10", include_str!("../../data/ior/pbrt-v4/GlassBAF10_eta.txt")),
    ("glass-FK51A", include_str!("../../data/ior/pbrt-v4/GlassFK51A_eta.txt")),
    ("glass-LASF9", include_str!("../../data/ior/pbrt-v4/GlassLASF9_eta.txt")),
    ("glass-F5", include_str!("../../data/ior/pbrt-v4/GlassSF5_eta.txt")),
    ("glass-F10", include_str!("../../data/ior/pbrt-v4/GlassSF10_eta.txt")),
    ("glass-F11", include_str!("../../data/ior/pbrt-v4/GlassSF11_eta.txt")),
];

/// Every name [`Ior::named`] accepts.
pub const NAMED_GLASSES: &[&str] = &[
    "bk7",
    "fused silica",
    "baf10",
    "f2",
    "sf11",
    "water",
    "diamond",
    "glass-BK7",
    "glass-BAF10",
    "glass-FK51A",
    "glass-LASF9",
    "glass-F5",
    "glass-F10",
    "glass-F11",
];

impl Ior {
    /// A named dispersive glass (table in the module docs), matched ignoring ASCII case.
    #[must_use]
    pub fn named(name: &str) -> Option<Ior> {
        if let Some(&(_, b, c)) = SELLMEIER_GLASSES.iter().find(|g| g.0.eq_ignore_ascii_case(name)) {
            // The table is compiled in and has 2 to 4 finite terms per glass.
            return Sellmeier::new(b, c).ok().map(Ior::Sellmeier);
        }
        TABULATED_GLASSES
            .iter()
            .find(|g| g.0.eq_ignore_ascii_case(name))
            .and_then(|&(_, text)| PiecewiseLinear::from_spd(text).ok())
            .map(Ior::Tabulated)
    }

    /// The index given n_d and an Abbe number, as glTF's `KHR_materials_dispersion` defines it
    /// ([`Cauchy::from_abbe`]).
    ///
    /// # Errors
    /// As [`Cauchy::from_abbe`].
    pub fn from_abbe(n_d: f64, abbe: f64) -> Result<Ior, DispersionError> {
        Cauchy::from_abbe(n_d, abbe).map(Ior::Cauchy)
    }

    /// The index at `lambda` nm.
    #[must_use]
    pub fn eta(&self, lambda: f64) -> f64 {
        match self {
            Ior::Constant(n) => *n,
            Ior::Sellmeier(law) => law.eta(lambda),
            Ior::Cauchy(law) => law.eta(lambda),
            Ior::Tabulated(table) => table.eval_clamped(lambda),
        }
    }

    /// Whether the index varies with wavelength (a renderer terminates the secondary wavelengths at a
    /// refraction only then).
    #[must_use]
    pub fn is_dispersive(&self) -> bool {
        !matches!(self, Ior::Constant(_))
    }

    /// The Abbe number V_d = (n_d − 1) / (n_F − n_C) of this index (∞ for a constant index > 1, NaN for 1).
    #[must_use]
    pub fn abbe_number(&self) -> f64 {
        (self.eta(LAMBDA_D) - 1.0) / (self.eta(LAMBDA_F) - self.eta(LAMBDA_C))
    }
}
