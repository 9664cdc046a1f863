//! How a distribution holds its roughness: one value for every lane (`f32`, what a model holds), or one
//! value per lane of a packet ([`PerLane`]: the path tracer's lanes on a surface whose roughness is a
//! texture). [`Ggx`](super::Ggx) and [`Beckmann`](super::Beckmann) are written once over it, so a
//! textured roughness runs the same kernel as a constant one, for all its lanes at once.

use crate::math::lanes::Real;

/// A roughness in lanes: the distributions read α and 1/α through this.
pub trait Roughness: Copy + std::fmt::Debug + PartialEq {
    /// α in lanes.
    fn lanes<R: Real>(self) -> R;
    /// 1/α in lanes (for one value, divided once and broadcast).
    fn recip<R: Real>(self) -> R;
}

impl Roughness for f32 {
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

/// One roughness per lane of a packet of [`PER_LANE`]; read by kernels of at most that many lanes (a
/// wider lane type repeats them: only the path tracer's eight-lane packets build one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PerLane(pub [f32; PER_LANE]);

impl Roughness for PerLane {
    #[inline(always)]
    fn lanes<R: Real>(self) -> R {
        debug_assert!(R::LANES <= PER_LANE, "a roughness per lane of {PER_LANE} read in {} lanes", R::LANES);
        R::from_fn(|i| self.0[i % PER_LANE])
    }

    #[inline(always)]
    fn recip<R: Real>(self) -> R {
        R::splat(1.0) / self.lanes::<R>()
    }
}
