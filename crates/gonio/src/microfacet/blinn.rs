//! Normalised Blinn (Blinn 1977; normalised as Walter 2007's Phong distribution, eq. 30):
//! D = (e + 2)/(2π) · cos^e θm, stored by its equivalent Beckmann roughness α = √(2/(e + 2)) (Walter 2007
//! §5.2), isotropic only. Its Λ is the Beckmann Λ of that α (the usual correspondence, exact only as
//! e → ∞); it has no visible-normal sampler (asked for one, it samples D·cos: sampling the equivalent
//! Beckmann's visible normals instead was tried, 2026-11: its lighter tails give unbounded weights
//! D_Blinn/D_Beckmann at small e, and the albedo estimate at e = 0 read 1.45 from 65 536 samples where
//! the true value is below 1).
//!
//! Its powers are evaluated per lane by the standard library's `ln_1p`, `exp` and `exp_m1` ([`Real::map`]):
//! narrow Blinn lobes (e up to 2·10⁸) need them to the last bit (see [`Blinn::d`]), and Blinn is used by
//! `torrance_sparrow` only.

use super::beckmann::Beckmann;
use super::distribution::Distribution;
use crate::math::lanes::{Real, V3};
use std::f32::consts::PI;

/// The Blinn distribution of equivalent Beckmann roughness `alpha` (exponent e = 2/α² − 2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blinn {
    pub alpha: f32,
}

/// The Blinn exponent e whose distribution corresponds to Beckmann roughness `alpha`: e = 2/α² − 2
/// (Walter 2007, §5.2).
#[inline]
#[must_use]
pub fn blinn_exponent_from_alpha(alpha: f32) -> f32 {
    debug_assert!(alpha > 0.0);
    2.0 / (alpha * alpha) - 2.0
}

/// The Beckmann roughness α = √(2/(e + 2)) corresponding to the Blinn exponent `exponent` (Walter 2007, §5.2).
#[inline]
#[must_use]
pub fn alpha_from_blinn_exponent(exponent: f32) -> f32 {
    debug_assert!(exponent >= 0.0);
    (2.0 / (exponent + 2.0)).sqrt()
}

impl Blinn {
    /// The exponent e.
    #[inline(always)]
    #[must_use]
    pub fn exponent(&self) -> f32 {
        blinn_exponent_from_alpha(self.alpha)
    }
}

impl Distribution for Blinn {
    const HAS_VISIBLE: bool = false;

    #[inline(always)]
    fn alphas<R: Real>(&self) -> (R, R) {
        (R::splat(self.alpha), R::splat(self.alpha))
    }

    /// cos^e θm = (1 − sin²θm)^{e/2} from sin²θm = (x² + y²)/|ωm|², not z^e: an f32 z near 1 carries 6·10⁻⁸
    /// rounding, which z^e turns into e·6·10⁻⁸ relative (10⁻³ at e = 2·10⁴; 2026-11: the noise kept the
    /// chi-square's cell integrals of such a lobe from converging), while the small x, y carry theirs
    /// relative to themselves. Dividing by |ωm|² also cancels its departure from unit length. e = 0: 1/π.
    #[inline(always)]
    fn d<R: Real>(&self, wm: V3<R>) -> R {
        let e = self.exponent();
        let zero = R::splat(0.0);
        let xy2 = wm.x * wm.x + wm.y * wm.y;
        let sin2 = xy2 / (xy2 + wm.z * wm.z);
        let d = sin2.map(|s| (e + 2.0) / (2.0 * PI) * (0.5 * e * (-s).ln_1p()).exp());
        let d = if e == 0.0 { R::splat(1.0 / PI) } else { d };
        R::select(wm.z.le(zero), zero, d)
    }

    #[inline(always)]
    fn lambda_upper<R: Real>(&self, x: R, y: R, z: R) -> R {
        Beckmann { alpha_x: self.alpha, alpha_y: self.alpha }.lambda_upper(x, y, z)
    }

    /// Walter 2007 eq. 31: cos θm = u^{1/(e+2)}, so tan²θm = u^{−2/(e+2)} − 1 = expm1(−2 ln u/(e + 2)),
    /// not from 1 − cos²θm, which loses sin θ to f32 rounding for narrow lobes (2026-11: chi-square failed
    /// at α = 0.01). u = 0 is taken as f32's smallest normal number.
    #[inline(always)]
    fn tan2_d_cos<R: Real>(&self, ux: R, _a: R) -> R {
        let e = self.exponent();
        ux.map(|u| (-2.0 * u.max(f32::MIN_POSITIVE).ln() / (e + 2.0)).exp_m1())
    }

    /// No visible-normal sampler: D·cos (see the module doc).
    #[inline(always)]
    fn sample_visible<R: Real>(&self, _wo: V3<R>, ux: R, uy: R) -> V3<R> {
        self.sample_d_cos(ux, uy)
    }
}
