//! How a model holds a parameter its lane code reads: one value for every lane (`f32`, what a model built
//! from a description holds), or one value per lane of a packet ([`PerLane`]: the path tracer's lanes on
//! a surface where the parameter is a texture). A model's lane code written once over [`Param`] runs a
//! textured parameter in the same kernel as a constant one, for all its lanes at once.

use super::lanes::Real;

/// A parameter in lanes.
pub trait Param: Copy + std::fmt::Debug + PartialEq {
    /// The value in lanes.
    fn lanes<R: Real>(self) -> R;
    /// 1 / the value in lanes (for one value, divided once and broadcast).
    fn recip<R: Real>(self) -> R;
}

impl Param for f32 {
    #[inline(always)]
    fn lanes<R: Real>(self) -> R {
        R::splat(self)
    }

    #[inline(always)]
    fn recip<R: Real>(self) -> R {
        R::splat(1.0 / self)
    }
}

/// Lanes per [`PerLane`]: the path tracer's packets.
pub const PER_LANE: usize = 8;

/// One value per lane of a packet of [`PER_LANE`]; read by kernels of at most that many lanes (a wider
/// lane type would repeat them: only the path tracer's eight-lane packets build one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PerLane(pub [f32; PER_LANE]);

impl Param for PerLane {
    #[inline(always)]
    fn lanes<R: Real>(self) -> R {
        debug_assert!(R::LANES <= PER_LANE, "a value per lane of {PER_LANE} read in {} lanes", R::LANES);
        R::from_fn(|i| self.0[i % PER_LANE])
    }

    #[inline(always)]
    fn recip<R: Real>(self) -> R {
        R::splat(1.0) / self.lanes::<R>()
    }
}
