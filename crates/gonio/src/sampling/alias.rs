//! An alias table: a discrete distribution over `n` entries, sampled in constant time (Walker 1977,
//! "An efficient method for generating discrete random variables with general distributions"; the linear
//! construction of Vose 1991, "A linear algorithm for generating random numbers with a given
//! distribution", IEEE TSE 17(9); pbrt-v4 §A.1 "The Alias Method" as a statement of the same facts).
//!
//! The table has `bins` equal bins. Bin `b` keeps its own entry with probability `q_b` and otherwise
//! gives its alias `a_b`, so entry `i` is chosen with probability
//! (q_i + Σ_{b : a_b = i} (1 − q_b)) / bins, which the construction makes equal to `func[i] / Σ func`.
//! Sampling is one uniform number for the bin and one for the coin: no search, whatever the table's size.
//! Like the other distributions of [`super`] it is a triplet of sorts: [`AliasTable::sample`] and
//! [`AliasTable::pmf`] (a discrete choice has no continuous inverse; the remapped numbers it returns are
//! what a caller reuses).
//!
//! ```
//! use gonio::sampling::alias::AliasTable;
//! let t = AliasTable::new(&[1.0, 3.0]);
//! assert_eq!(t.pmf(1), 0.75);
//! let s = t.sample(0.9, 0.2, 0.5);
//! assert_eq!(s.index, 1);
//! assert!(s.pmf == 0.75 && (0.0..1.0).contains(&s.u_coin));
//! ```

/// The largest `f32` below 1: remapped numbers stay in [0, 1) (2026-12: `(u − q)/(1 − q)` rounds up to 1
/// for u just below 1).
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// log₂ of the number of bins one `f32` sample reaches exactly: uniform numbers are multiples of 2⁻²⁴
/// ([`super::Pcg32::next_f32`]), so `⌊u · 2^m⌋` gives every bin the same number of values of `u` for m ≤ 24.
const BIN_BITS: u32 = 24;

/// One bin: the probability of keeping its own entry, and the entry given otherwise.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Bin {
    q: f32,
    alias: u32,
}

/// One sample of an [`AliasTable`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AliasSample {
    /// The chosen entry.
    pub index: usize,
    /// The probability of choosing it, `func[index] / Σ func`.
    pub pmf: f32,
    /// The coin's number rescaled to [0, 1), uniform and independent of the choice: ready for reuse.
    pub u_coin: f32,
    /// The third number, rescaled to [0, 1) where a table of more than 2²⁴ bins took bits of it for the
    /// bin, else as given.
    pub u_low: f32,
}

/// A discrete distribution over `len()` entries proportional to a tabulated function (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct AliasTable {
    /// 2^m bins, m the smallest with 2^m ≥ the number of entries; bins past the entries are empty (q = 0).
    bins: Vec<Bin>,
    /// log₂ of the number of bins.
    bits: u32,
    /// The probability of each entry (`func[i] / Σ func`; uniform when every entry is 0).
    pmf: Vec<f32>,
    /// Σ func of the function as given (0 when every entry is 0).
    sum: f64,
}

impl AliasTable {
    /// A table proportional to `func`, built in O(n) (Vose 1991, section III). Entries must be finite and
    /// non-negative; others are treated as 0 (a debug assertion flags them). When every entry is 0 (or
    /// `func` is empty, which gives one entry) the distribution is uniform and [`Self::sum`] is 0.
    ///
    /// The bins are a power of two (at most twice the entries), so that a bin is chosen exactly uniformly
    /// from an `f32` sample (see [`Self::sample`]): with n bins not a power of two, ⌊u · n⌋ for the 2²⁴
    /// values of `u` gives some bins one value more than others, 3 % more for n ≈ 2¹⁹ (a 1k × ½k map).
    #[must_use]
    pub fn new(func: &[f32]) -> Self {
        debug_assert!(func.iter().all(|v| v.is_finite() && *v >= 0.0), "AliasTable: entries must be finite and ≥ 0");
        // Release builds never panic on user data: invalid entries count as 0 (2026-12, as Distribution1D).
        let clean = |v: f32| if v.is_finite() && v > 0.0 { f64::from(v) } else { 0.0 };
        let n = func.len().max(1);
        let sum: f64 = func.iter().map(|&v| clean(v)).sum();
        let uniform = !(sum > 0.0);
        let weight = |i: usize| if uniform { 1.0 } else { func.get(i).map_or(0.0, |&v| clean(v)) };
        let total = if uniform { n as f64 } else { sum };
        let bits = n.next_power_of_two().trailing_zeros();
        let len = 1usize << bits;
        // Each entry's share of the bins, p_i = pmf_i · bins (mean 1 over the bins; padding bins 0).
        let mut share: Vec<f64> = (0..len).map(|i| if i < n { weight(i) / total * len as f64 } else { 0.0 }).collect();
        let (mut small, mut large): (Vec<u32>, Vec<u32>) = (0..len as u32).partition(|&i| share[i as usize] < 1.0);
        let mut bins = vec![Bin { q: 1.0, alias: 0 }; len];
        // Vose's pairing: a bin short of 1 is topped up by an entry with more than 1, whose surplus shrinks;
        // every step settles one bin, so the loop runs at most `len` times.
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            bins[s as usize] = Bin { q: share[s as usize] as f32, alias: l };
            share[l as usize] -= 1.0 - share[s as usize];
            if share[l as usize] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // What is left is 1 up to rounding (Vose, section III): those bins keep their own entry.
        for i in small.into_iter().chain(large) {
            bins[i as usize] = Bin { q: 1.0, alias: i };
        }
        let pmf = (0..n).map(|i| (weight(i) / total) as f32).collect();
        AliasTable { bins, bits, pmf, sum }
    }

    /// The number of entries.
    #[inline]
    #[must_use]
    pub fn len(&self) -> usize {
        self.pmf.len()
    }

    /// Whether there are no entries (never: an empty table becomes one entry).
    #[inline]
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.pmf.is_empty()
    }

    /// Σ of the tabulated function (invalid entries as 0); 0 when every entry was 0.
    #[inline]
    #[must_use]
    pub fn sum(&self) -> f64 {
        self.sum
    }

    /// The probability with which [`Self::sample`] chooses `index` (0 outside the table).
    #[inline]
    #[must_use]
    pub fn pmf(&self, index: usize) -> f32 {
        self.pmf.get(index).copied().unwrap_or(0.0)
    }

    /// Choose an entry: the bin from `u_bin` (⌊u_bin · 2^m⌋, exact), its own entry if `u_coin < q`, else its
    /// alias. The coin's number is rescaled to [0, 1) within the side it fell on, so it stays uniform and
    /// independent of the choice. Tables of more than 2²⁴ bins take the bin's low m − 24 bits from `u_low`
    /// (one `f32` sample has 24 random bits) and rescale it; smaller tables hand `u_low` back unchanged.
    /// Numbers outside [0, 1) are clamped into it.
    #[inline]
    #[must_use]
    pub fn sample(&self, u_bin: f32, u_coin: f32, u_low: f32) -> AliasSample {
        debug_assert!((0.0..1.0).contains(&u_bin) && (0.0..1.0).contains(&u_coin), "AliasTable::sample: {u_bin}, {u_coin}");
        let (bin, u_low) = choose_bin(self.bits, BIN_BITS, u_bin, u_low);
        let Bin { q, alias } = self.bins[bin];
        let (index, u_coin) = if u_coin < q {
            (bin, u_coin / q)
        } else {
            // q < 1 here (u_coin < 1 ≤ q otherwise), so 1 − q > 0.
            (alias as usize, (u_coin - q) / (1.0 - q))
        };
        let index = index.min(self.pmf.len() - 1);
        AliasSample { index, pmf: self.pmf[index], u_coin: u_coin.clamp(0.0, ONE_MINUS_EPSILON), u_low }
    }
}

/// The bin of a table of 2^`bits` bins for `u_bin` (and `u_low`, rescaled, where `bits` > `high_bits`):
/// ⌊u_bin · 2^h⌋ with h = min(bits, high_bits) gives the top h bits, exactly (a power-of-two scaling), and
/// ⌊u_low · 2^(bits − h)⌋ the rest.
#[inline]
fn choose_bin(bits: u32, high_bits: u32, u_bin: f32, u_low: f32) -> (usize, f32) {
    let (high, low_bits) = (bits.min(high_bits), bits.saturating_sub(high_bits));
    let top = ((u_bin * (1u64 << high) as f32).max(0.0) as usize).min((1usize << high) - 1);
    if low_bits == 0 {
        return (top, u_low);
    }
    let scaled = u_low.clamp(0.0, ONE_MINUS_EPSILON) * (1u64 << low_bits) as f32;
    let j = (scaled as usize).min((1usize << low_bits) - 1);
    (top << low_bits | j, (scaled - j as f32).min(ONE_MINUS_EPSILON))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec2;
    use crate::sampling::Pcg32;
    use crate::verify::chi2::{chi2_plane, Chi2Config};

    fn tables() -> Vec<Vec<f32>> {
        vec![
            vec![1.0, 2.0, 3.0, 4.0],
            vec![0.0, 5.0, 0.0, 0.0, 1.0, 0.0],
            vec![7.0],
            vec![0.0, 0.0, 0.0],
            vec![1e-6, 1.0, 1e3, 0.5, 0.0, 2.0, 0.01],
            (0..37).map(|i| ((i * 7919) % 13) as f32 * 0.25).collect(),
        ]
    }

    /// The probability of each entry implied by the bins, in f64: (q_i + Σ_{a_b = i} (1 − q_b)) / bins.
    fn implied(t: &AliasTable) -> Vec<f64> {
        let mut p = vec![0.0; t.bins.len()];
        for (b, bin) in t.bins.iter().enumerate() {
            p[b] += f64::from(bin.q);
            p[bin.alias as usize] += 1.0 - f64::from(bin.q);
        }
        p.iter().map(|v| v / t.bins.len() as f64).collect()
    }

    #[test]
    fn bins_give_func_over_its_sum() {
        for f in tables() {
            let t = AliasTable::new(&f);
            let sum: f64 = f.iter().map(|&v| f64::from(v)).sum();
            let p = implied(&t);
            for (i, &pi) in p.iter().enumerate() {
                let want = if i >= f.len() {
                    0.0
                } else if sum > 0.0 {
                    f64::from(f[i]) / sum
                } else {
                    1.0 / f.len() as f64
                };
                // q is stored in f32: each bin's split is exact up to 2⁻²⁴ of a bin.
                assert!((pi - want).abs() <= 2.0 * f64::from(f32::EPSILON), "{f:?}: entry {i}: {pi} vs {want}");
                if i < f.len() {
                    assert!((f64::from(t.pmf(i)) - want).abs() <= f64::from(f32::EPSILON) * want, "{f:?}: pmf({i})");
                }
            }
            // Padding bins never give themselves, and zero entries are never given.
            for (b, bin) in t.bins.iter().enumerate() {
                let entry_zero = b >= f.len() || (sum > 0.0 && f[b] == 0.0);
                assert!(!entry_zero || bin.q == 0.0, "{f:?}: bin {b} keeps a zero entry");
                let a = bin.alias as usize;
                assert!(bin.q == 1.0 || (a < f.len() && (sum == 0.0 || f[a] > 0.0)), "{f:?}: bin {b} → {a}");
            }
        }
    }

    #[test]
    fn sample_returns_its_pmf_and_never_a_zero_entry() {
        let mut rng = Pcg32::new(3, 1);
        for f in tables() {
            let t = AliasTable::new(&f);
            for _ in 0..10_000 {
                let s = t.sample(rng.next_f32(), rng.next_f32(), rng.next_f32());
                assert_eq!(s.pmf, t.pmf(s.index));
                assert!(s.pmf > 0.0, "{f:?}: sampled entry {} of pmf 0", s.index);
                assert!((0.0..1.0).contains(&s.u_coin) && (0.0..1.0).contains(&s.u_low));
            }
            // The ends of [0, 1).
            for u in [0.0, ONE_MINUS_EPSILON] {
                let s = t.sample(u, u, u);
                assert!(s.index < t.len() && s.pmf > 0.0);
            }
        }
    }

    #[test]
    fn degenerate_inputs() {
        let t = AliasTable::new(&[]);
        assert_eq!((t.len(), t.pmf(0), t.sum()), (1, 1.0, 0.0));
        assert_eq!(t.sample(0.7, 0.3, 0.2).index, 0);
        let z = AliasTable::new(&[0.0; 3]);
        assert_eq!(z.sum(), 0.0);
        assert!((0..3).all(|i| (z.pmf(i) - 1.0 / 3.0).abs() < 1e-7));
        assert_eq!(z.pmf(3), 0.0);
        // Invalid entries count as 0 in release builds (debug builds assert).
        if !cfg!(debug_assertions) {
            let bad = AliasTable::new(&[f32::NAN, 1.0, -2.0, f32::INFINITY]);
            assert_eq!((bad.pmf(0), bad.pmf(1), bad.pmf(2), bad.pmf(3)), (0.0, 1.0, 0.0, 0.0));
        }
    }

    /// More bins than one number resolves: the low bits come from `u_low` (with 2 bits per number here in
    /// place of 24), so every bin is reached, each by an equal share of (u_bin, u_low).
    #[test]
    fn bins_past_one_numbers_bits_take_the_third() {
        let mut hits = [0u32; 32];
        let steps = 64;
        for a in 0..steps {
            for b in 0..steps {
                let (u_bin, u_low) = (a as f32 / steps as f32, b as f32 / steps as f32);
                let (bin, rest) = choose_bin(5, 2, u_bin, u_low);
                assert!((0.0..1.0).contains(&rest));
                hits[bin] += 1;
            }
        }
        assert!(hits.iter().all(|&h| h == steps * steps / 32), "{hits:?}");
        assert_eq!(choose_bin(5, 2, 0.3, 0.75), (1 << 3 | 6, 0.0));
        assert_eq!(choose_bin(3, 24, 0.3, 0.75), (2, 0.75));
    }

    /// Chi-square of sampled entries against `pmf`, with the shared harness: entry i and the remapped
    /// coin as the point ((i + u_coin) / n, ½) of the unit square, whose density is pmf_i · n.
    #[test]
    fn chi_square_of_sampled_entries() {
        let f = [0.2_f32, 0.0, 3.0, 1.0, 0.0, 0.0, 2.5, 0.7, 1e-3, 4.0, 0.5];
        let t = AliasTable::new(&f);
        let n = t.len() as f32;
        let sample = |u: Vec2| {
            let s = t.sample(u.x, u.y, 0.5);
            Vec2::new((s.index as f32 + s.u_coin) / n, 0.5)
        };
        let pdf = |p: Vec2| f64::from(t.pmf(((p.x * n) as usize).min(t.len() - 1)) * n);
        let r = chi2_plane(sample, pdf, Vec2::ZERO, Vec2::ONE, (4 * f.len(), 1), &Chi2Config::default());
        assert!(r.passed, "{r}");
        // A wrong table (the entries reversed) fails.
        let wrong = AliasTable::new(&f.iter().rev().copied().collect::<Vec<_>>());
        let sample = |u: Vec2| {
            let s = wrong.sample(u.x, u.y, 0.5);
            Vec2::new((s.index as f32 + s.u_coin) / n, 0.5)
        };
        let r = chi2_plane(sample, pdf, Vec2::ZERO, Vec2::ONE, (4 * f.len(), 1), &Chi2Config::default());
        assert!(!r.passed, "{r}");
    }
}
