//! Linear RGB triples, the unit of colour throughout gonio (spectral rendering comes later).
//!
//! Values are linear (not gamma-encoded) Rec. 709 / sRGB primaries. [`Rgb::luminance`] uses the Rec. 709
//! luminance weights, as Mitsuba's `luminance()` does for RGB variants.

use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Sub};

/// A linear RGB triple (laid out as `[f32; 3]`, so a slice of them is a slice of floats).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(transparent)]
pub struct Rgb(pub [f32; 3]);

impl Rgb {
    pub const ZERO: Rgb = Rgb([0.0; 3]);
    pub const ONE: Rgb = Rgb([1.0; 3]);

    #[inline]
    #[must_use]
    pub const fn new(r: f32, g: f32, b: f32) -> Self {
        Rgb([r, g, b])
    }

    #[inline]
    #[must_use]
    pub const fn splat(v: f32) -> Self {
        Rgb([v; 3])
    }

    #[inline]
    #[must_use]
    pub fn r(self) -> f32 {
        self.0[0]
    }
    #[inline]
    #[must_use]
    pub fn g(self) -> f32 {
        self.0[1]
    }
    #[inline]
    #[must_use]
    pub fn b(self) -> f32 {
        self.0[2]
    }

    /// Apply `op` to each channel.
    #[inline]
    #[must_use]
    pub fn map(self, op: impl Fn(f32) -> f32) -> Self {
        Rgb([op(self.0[0]), op(self.0[1]), op(self.0[2])])
    }

    /// Combine two triples channel by channel.
    #[inline]
    #[must_use]
    pub fn zip(self, other: Rgb, op: impl Fn(f32, f32) -> f32) -> Self {
        Rgb([op(self.0[0], other.0[0]), op(self.0[1], other.0[1]), op(self.0[2], other.0[2])])
    }

    /// Rec. 709 luminance.
    #[inline]
    #[must_use]
    pub fn luminance(self) -> f32 {
        Self::luminance_lanes(self.0)
    }

    /// [`Self::luminance`] of colours in lanes (the same operations in each lane).
    #[inline(always)]
    #[must_use]
    pub fn luminance_lanes<R: crate::math::lanes::Real>(c: [R; 3]) -> R {
        c[0] * 0.212_671 + c[1] * 0.715_160 + c[2] * 0.072_169
    }

    #[inline]
    #[must_use]
    pub fn max_component(self) -> f32 {
        self.0[0].max(self.0[1]).max(self.0[2])
    }

    #[inline]
    #[must_use]
    pub fn min_component(self) -> f32 {
        self.0[0].min(self.0[1]).min(self.0[2])
    }

    #[inline]
    #[must_use]
    pub fn is_black(self) -> bool {
        self.0 == [0.0; 3]
    }

    #[inline]
    #[must_use]
    pub fn is_finite(self) -> bool {
        self.0.iter().all(|v| v.is_finite())
    }

    /// Channel-wise square root.
    #[inline]
    #[must_use]
    pub fn sqrt(self) -> Self {
        self.map(f32::sqrt)
    }

    /// Channels as `f64`, for verification integrals.
    #[inline]
    #[must_use]
    pub fn to_f64(self) -> [f64; 3] {
        [self.0[0] as f64, self.0[1] as f64, self.0[2] as f64]
    }
}

impl Add for Rgb {
    type Output = Rgb;
    #[inline]
    fn add(self, o: Rgb) -> Rgb {
        self.zip(o, |a, b| a + b)
    }
}
impl AddAssign for Rgb {
    #[inline]
    fn add_assign(&mut self, o: Rgb) {
        *self = *self + o;
    }
}
impl Sub for Rgb {
    type Output = Rgb;
    #[inline]
    fn sub(self, o: Rgb) -> Rgb {
        self.zip(o, |a, b| a - b)
    }
}
impl Mul for Rgb {
    type Output = Rgb;
    #[inline]
    fn mul(self, o: Rgb) -> Rgb {
        self.zip(o, |a, b| a * b)
    }
}
impl MulAssign for Rgb {
    #[inline]
    fn mul_assign(&mut self, o: Rgb) {
        *self = *self * o;
    }
}
impl Mul<f32> for Rgb {
    type Output = Rgb;
    #[inline]
    fn mul(self, s: f32) -> Rgb {
        self.map(|a| a * s)
    }
}
impl Mul<Rgb> for f32 {
    type Output = Rgb;
    #[inline]
    fn mul(self, c: Rgb) -> Rgb {
        c * self
    }
}
impl MulAssign<f32> for Rgb {
    #[inline]
    fn mul_assign(&mut self, s: f32) {
        *self = *self * s;
    }
}
impl Div<f32> for Rgb {
    type Output = Rgb;
    #[inline]
    fn div(self, s: f32) -> Rgb {
        self.map(|a| a / s)
    }
}

impl std::fmt::Display for Rgb {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "[{}, {}, {}]", self.0[0], self.0[1], self.0[2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn luminance_of_white_is_one() {
        assert!((Rgb::ONE.luminance() - 1.0).abs() < 1e-5);
    }

    #[test]
    fn arithmetic_is_channelwise() {
        let a = Rgb::new(1.0, 2.0, 3.0);
        let b = Rgb::new(0.5, 0.25, 2.0);
        assert_eq!(a * b, Rgb::new(0.5, 0.5, 6.0));
        assert_eq!(a + b, Rgb::new(1.5, 2.25, 5.0));
        assert_eq!(a * 2.0, Rgb::new(2.0, 4.0, 6.0));
        assert_eq!(a.max_component(), 3.0);
    }
}

/// The sRGB transfer function (IEC 61966-2-1), encoded value in [0, 1] → linear value. The piecewise curve:
/// `v / 12.92` for `v ≤ 0.04045`, else `((v + 0.055) / 1.055)^2.4`. Values outside [0, 1] follow the same
/// formula (negative inputs stay on the linear segment).
#[inline]
#[must_use]
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// The inverse of [`srgb_to_linear`] (IEC 61966-2-1): `12.92 v` for `v ≤ 0.0031308`, else
/// `1.055 v^(1/2.4) − 0.055`. No clamping: callers that quantise clamp first.
#[inline]
#[must_use]
pub fn linear_to_srgb(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod srgb_tests {
    use super::*;

    #[test]
    fn srgb_curve_round_trips_and_hits_known_points() {
        for i in 0..=1000 {
            let v = i as f32 / 1000.0;
            assert!((linear_to_srgb(srgb_to_linear(v)) - v).abs() < 1e-5, "{v}");
        }
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        // 50 % grey in sRGB is about 21.4 % linear.
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
        // The two pieces meet (continuity at the breakpoint).
        assert!((srgb_to_linear(0.040_45) - ((0.040_45f32 + 0.055) / 1.055).powf(2.4)).abs() < 1e-6);
    }
}
