//! `Twice<R>`: two registers of a lane type as one, each operation done on both halves back to back.
//!
//! Why: the glossy kernels are chains of dependent divisions and square roots (a GGX conductor's `f`:
//! normalise, D, then per channel √, √, ÷, ÷ of the Fresnel term), about 45 ns of latency per register of
//! rows on the AVX-512 build machine (2026-12: ÷ 3.0 ns, √ 4.2 ns, × 0.85 ns, measured), while the
//! register's work keeps the divider busy for only about 20. The out-of-order core overlaps too little of
//! the next register's chain with this one's (300-odd instructions a register). With two independent
//! registers whose operations alternate, two chains are always in flight. The AVX-512 drivers nest it,
//! `Twice<Twice<Avx16>>`: four chains, 64 rows (one thread, CPU time per 10⁶ rows against `Twice<Avx16>`:
//! roughconductor `f` 3.2 → 2.8 ms, roughplastic `f` 2.7 → 2.5 ms, `sample` 6.7 → 6.2 ms; a third level
//! was slower, its registers spilling). Each lane is still computed by the same IEEE operations as an
//! `f32`, so results are unchanged bit for bit.

#![cfg_attr(not(all(target_arch = "x86_64", gonio_avx512)), allow(dead_code))] // used by the AVX-512 drivers (and its tests)

use super::lanes::{Real, Rows, V3};
use super::{Vec2, Vec3};
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Two registers of `R` (lanes `0..R::LANES` in the first), or two masks.
#[derive(Clone, Copy)]
pub(crate) struct Twice<R>(R, R);

macro_rules! binary {
    ($tr:ident, $f:ident) => {
        impl<R: Real> $tr for Twice<R> {
            type Output = Self;
            #[inline(always)]
            fn $f(self, o: Self) -> Self {
                Twice(self.0.$f(o.0), self.1.$f(o.1))
            }
        }
        impl<R: Real> $tr<f32> for Twice<R> {
            type Output = Self;
            #[inline(always)]
            fn $f(self, o: f32) -> Self {
                Twice(self.0.$f(o), self.1.$f(o))
            }
        }
    };
}
binary!(Add, add);
binary!(Sub, sub);
binary!(Mul, mul);
binary!(Div, div);

impl<R: Real> Neg for Twice<R> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Twice(-self.0, -self.1)
    }
}

impl<M: BitAnd<Output = M>> BitAnd for Twice<M> {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, o: Self) -> Self {
        Twice(self.0 & o.0, self.1 & o.1)
    }
}

impl<M: BitOr<Output = M>> BitOr for Twice<M> {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, o: Self) -> Self {
        Twice(self.0 | o.0, self.1 | o.1)
    }
}

impl<M: Not<Output = M>> Not for Twice<M> {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        Twice(!self.0, !self.1)
    }
}

macro_rules! unary {
    ($($f:ident),*) => {$(
        #[inline(always)]
        fn $f(self) -> Self {
            Twice(self.0.$f(), self.1.$f())
        }
    )*};
}

macro_rules! compare {
    ($($f:ident),*) => {$(
        #[inline(always)]
        fn $f(self, o: Self) -> Self::Mask {
            Twice(self.0.$f(o.0), self.1.$f(o.1))
        }
    )*};
}

impl<R: Real> Real for Twice<R> {
    type Mask = Twice<R::Mask>;
    const LANES: usize = 2 * R::LANES;

    #[inline(always)]
    fn splat(v: f32) -> Self {
        Twice(R::splat(v), R::splat(v))
    }
    unary!(sqrt, abs, round);
    #[inline(always)]
    fn xor_sign(self, o: Self) -> Self {
        Twice(self.0.xor_sign(o.0), self.1.xor_sign(o.1))
    }
    #[inline(always)]
    fn pow2(self) -> Self {
        Twice(self.0.pow2(), self.1.pow2())
    }
    #[inline(always)]
    fn split_exponent(self) -> (Self, Self) {
        let (a, b) = (self.0.split_exponent(), self.1.split_exponent());
        (Twice(a.0, b.0), Twice(a.1, b.1))
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        Twice(self.0.min(o.0), self.1.min(o.1))
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        Twice(self.0.max(o.0), self.1.max(o.1))
    }
    #[inline(always)]
    fn clamp(self, lo: f32, hi: f32) -> Self {
        Twice(self.0.clamp(lo, hi), self.1.clamp(lo, hi))
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        Twice(self.0.mul_add(a.0, b.0), self.1.mul_add(a.1, b.1))
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f32) -> f32) -> Self {
        Twice(self.0.map(&f), self.1.map(&f))
    }
    #[inline(always)]
    fn lerp_table<const N: usize>(self, table: &[f32; N]) -> Self {
        Twice(self.0.lerp_table(table), self.1.lerp_table(table))
    }
    compare!(lt, le, gt, ge, eq, ne);
    #[inline(always)]
    fn is_finite(self) -> Self::Mask {
        Twice(self.0.is_finite(), self.1.is_finite())
    }
    #[inline(always)]
    fn is_nan(self) -> Self::Mask {
        Twice(self.0.is_nan(), self.1.is_nan())
    }
    #[inline(always)]
    fn select(m: Self::Mask, a: Self, b: Self) -> Self {
        Twice(R::select(m.0, a.0, b.0), R::select(m.1, a.1, b.1))
    }
    #[inline(always)]
    fn any(m: Self::Mask) -> bool {
        R::any(m.0 | m.1)
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f32 {
        if i < R::LANES {
            self.0.lane(i)
        } else {
            self.1.lane(i - R::LANES)
        }
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> f32) -> Self {
        let first = R::from_fn(&mut f);
        Twice(first, R::from_fn(|i| f(i + R::LANES)))
    }
    #[inline(always)]
    fn bitmask(m: Self::Mask) -> u64 {
        R::bitmask(m.0) | R::bitmask(m.1) << R::LANES
    }
}

impl<R: Rows> Rows for Twice<R> {
    #[inline(always)]
    fn load(v: &[f32]) -> Self {
        let (a, b) = v.split_at(R::LANES);
        Twice(R::load(a), R::load(b))
    }
    #[inline(always)]
    fn store(self, out: &mut [f32]) {
        let (a, b) = out.split_at_mut(R::LANES);
        self.0.store(a);
        self.1.store(b);
    }
    #[inline(always)]
    fn load3(v: &[Vec3]) -> V3<Self> {
        let (a, b) = v.split_at(R::LANES);
        let (a, b) = (R::load3(a), R::load3(b));
        V3::new(Twice(a.x, b.x), Twice(a.y, b.y), Twice(a.z, b.z))
    }
    #[inline(always)]
    fn load2(v: &[Vec2]) -> (Self, Self) {
        let (a, b) = v.split_at(R::LANES);
        let ((ax, ay), (bx, by)) = (R::load2(a), R::load2(b));
        (Twice(ax, bx), Twice(ay, by))
    }
    #[inline(always)]
    fn store3(x: Self, y: Self, z: Self, out: &mut [[f32; 3]]) {
        let (a, b) = out.split_at_mut(R::LANES);
        R::store3(x.0, y.0, z.0, a);
        R::store3(x.1, y.1, z.1, b);
    }
    #[inline(always)]
    fn store_u32(self, out: &mut [u32]) {
        let (a, b) = out.split_at_mut(R::LANES);
        self.0.store_u32(a);
        self.1.store_u32(b);
    }
    #[inline(always)]
    fn store_mask(m: Self::Mask, out: &mut [bool]) {
        let (a, b) = out.split_at_mut(R::LANES);
        R::store_mask(m.0, a);
        R::store_mask(m.1, b);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lane-type checks of `math::lanes` on two portable registers, and on two AVX-512 ones where the
    /// CPU has them.
    #[test]
    fn twice_is_a_lane_type() {
        crate::math::lanes::check_lane_type::<Twice<crate::math::lanes::F32x8>>();
        #[cfg(all(target_arch = "x86_64", gonio_avx512))]
        {
            #[target_feature(enable = "avx512f,avx2,fma")]
            unsafe fn run() {
                crate::math::lanes::check_lane_type::<Twice<crate::math::avx512::Avx16>>();
            }
            if crate::math::avx512::detected() {
                // SAFETY: the CPU has the features.
                unsafe { run() }
            }
        }
    }
}
