//! A function of wavelength given at ascending nodes and linearly interpolated between them: the form of
//! every tabulated spectrum gonio reads (`.spd` files, pbrt-v4's `*_eta.txt` tables, the CIE D65 table).
//!
//! Outside the nodes there are two conventions, and each caller chooses by method: a *spectrum* (an
//! emission, a reflectance) is 0 there, as in Mitsuba 3's `irregular` spectrum and pbrt-v4's
//! `PiecewiseLinearSpectrum` ([`PiecewiseLinear::eval`]); an *index of refraction* keeps its end values
//! ([`PiecewiseLinear::eval_clamped`]) — an index of 0 has no meaning.
//!
//! ```
//! use gonio::spectrum::piecewise::PiecewiseLinear;
//! let s = PiecewiseLinear::new(vec![400.0, 500.0], vec![1.0, 3.0]).unwrap();
//! assert_eq!(s.eval(450.0), 2.0);
//! assert_eq!(s.eval(600.0), 0.0);
//! assert_eq!(s.eval_clamped(600.0), 3.0);
//! ```

use super::named::{parse_spd, SpdError};

/// Values at ascending wavelengths (nm), linearly interpolated.
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseLinear {
    lambda: Vec<f64>,
    value: Vec<f64>,
}

impl PiecewiseLinear {
    /// A table from its nodes.
    ///
    /// # Errors
    /// [`SpdError`] if the lengths differ or there are fewer than two nodes ([`SpdError::TooFewPoints`]),
    /// if a wavelength does not exceed the one before it ([`SpdError::NotAscending`], line = node index
    /// + 1), or if a number is not finite ([`SpdError::Syntax`]).
    pub fn new(lambda: Vec<f64>, value: Vec<f64>) -> Result<Self, SpdError> {
        if lambda.len() != value.len() || lambda.len() < 2 {
            return Err(SpdError::TooFewPoints(lambda.len().min(value.len())));
        }
        for (i, (l, v)) in lambda.iter().zip(&value).enumerate() {
            if !l.is_finite() || !v.is_finite() {
                return Err(SpdError::Syntax { line: i + 1, reason: format!("({l}, {v}) is not a finite pair") });
            }
            if i > 0 && *l <= lambda[i - 1] {
                return Err(SpdError::NotAscending { line: i + 1, wavelength: *l });
            }
        }
        Ok(PiecewiseLinear { lambda, value })
    }

    /// A table from `.spd` text ("wavelength value" lines, `#` comments; see [`parse_spd`]).
    ///
    /// # Errors
    /// The [`SpdError`] of [`parse_spd`].
    pub fn from_spd(text: &str) -> Result<Self, SpdError> {
        let (lambda, value) = parse_spd(text)?;
        Ok(PiecewiseLinear { lambda, value })
    }

    /// The nodes' wavelengths, nm.
    #[must_use]
    pub fn wavelengths(&self) -> &[f64] {
        &self.lambda
    }

    /// The nodes' values.
    #[must_use]
    pub fn values(&self) -> &[f64] {
        &self.value
    }

    /// The value of every node, where they are all equal (a table that does not vary).
    #[must_use]
    pub fn flat_value(&self) -> Option<f64> {
        match self.value.as_slice() {
            [v, rest @ ..] if rest.iter().all(|r| r == v) => Some(*v),
            _ => None,
        }
    }

    /// The interpolated value at `lambda` nm; 0 outside [first, last] node (and for NaN).
    #[must_use]
    pub fn eval(&self, lambda: f64) -> f64 {
        let (first, last) = (self.lambda[0], self.lambda[self.lambda.len() - 1]);
        if !(first..=last).contains(&lambda) {
            return 0.0;
        }
        self.interpolate(lambda)
    }

    /// The interpolated value at `lambda` nm, the end values outside the nodes (NaN gives NaN).
    #[must_use]
    pub fn eval_clamped(&self, lambda: f64) -> f64 {
        let (first, last) = (self.lambda[0], self.lambda[self.lambda.len() - 1]);
        if lambda.is_nan() {
            return f64::NAN;
        }
        self.interpolate(lambda.clamp(first, last))
    }

    /// Linear interpolation for `lambda` within the nodes.
    fn interpolate(&self, lambda: f64) -> f64 {
        let n = self.lambda.len();
        // The interval [x0, x1] holding λ (the last one for λ = last node).
        let i0 = self.lambda.partition_point(|&x| x <= lambda).saturating_sub(1).min(n - 2);
        let (x0, x1) = (self.lambda[i0], self.lambda[i0 + 1]);
        let t = (lambda - x0) / (x1 - x0);
        (1.0 - t).mul_add(self.value[i0], t * self.value[i0 + 1])
    }
}
