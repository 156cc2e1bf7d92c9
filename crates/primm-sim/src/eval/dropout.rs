//! Seeded removal of a fraction of measurements for the missed-detection rows of the
//! scenario-wise tracking table (`tab:scenario_mot`, "10% Miss" and "20% Miss").
//!
//! The mask depends only on the number of measurements, the fraction and the seed, never on the
//! method, so every method is re-run on exactly the same reduced input. Usage:
//!
//! 1. flatten a sequence's measurements in a fixed order (frame order, then order within the
//!    frame) and build [`DropoutMask::new`] with a per-sequence seed from [`sequence_seed`];
//! 2. feed the kept measurements to the tracker;
//! 3. evaluate with one record per original measurement, where a dropped one is still a
//!    ground-truth object frame but has no track (`track_id = None`, `prior = None`); the
//!    ground-truth frame count of the missed-detection rows then equals the nominal one, as in
//!    the paper's table.
//!
//! Exactly `round(fraction · n)` items are dropped (halves round away from zero). The drop order
//! is one seeded random permutation, so with the same seed the 10 % set is contained in the 20 %
//! set. The permutation is a Fisher–Yates shuffle driven by ChaCha8 with rejection sampling,
//! written out here so that it does not depend on a library's shuffling algorithm.

use rand::{RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::record::EvalError;

/// Which items of a list of known length are removed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DropoutMask {
    dropped: Vec<bool>,
    dropped_count: usize,
}

impl DropoutMask {
    /// Mask for `len` items dropping `round(fraction · len)` of them, chosen by `seed`.
    pub fn new(len: usize, fraction: f64, seed: u64) -> Result<Self, EvalError> {
        if !(0.0..=1.0).contains(&fraction) {
            return Err(EvalError::InvalidDropFraction(fraction));
        }
        let dropped_count = ((fraction * len as f64).round() as usize).min(len);
        let order = seeded_permutation(len, seed);
        let mut dropped = vec![false; len];
        for &index in &order[..dropped_count] {
            dropped[index] = true;
        }
        Ok(Self { dropped, dropped_count })
    }

    /// Number of items the mask was built for.
    pub fn len(&self) -> usize {
        self.dropped.len()
    }

    /// Whether the mask covers no item.
    pub fn is_empty(&self) -> bool {
        self.dropped.is_empty()
    }

    /// Number of dropped items.
    pub fn dropped_count(&self) -> usize {
        self.dropped_count
    }

    /// Whether item `index` is dropped (`false` outside the mask).
    pub fn is_dropped(&self, index: usize) -> bool {
        self.dropped.get(index).copied().unwrap_or(false)
    }

    /// One flag per item, `true` where dropped.
    pub fn flags(&self) -> &[bool] {
        &self.dropped
    }

    /// Splits `items` into (kept, dropped), both in their original order.
    pub fn partition<T>(&self, items: Vec<T>) -> Result<(Vec<T>, Vec<T>), EvalError> {
        if items.len() != self.dropped.len() {
            return Err(EvalError::LengthMismatch { expected: self.dropped.len(), actual: items.len() });
        }
        let mut kept = Vec::with_capacity(items.len() - self.dropped_count);
        let mut dropped = Vec::with_capacity(self.dropped_count);
        for (item, &is_dropped) in items.into_iter().zip(&self.dropped) {
            if is_dropped {
                dropped.push(item);
            } else {
                kept.push(item);
            }
        }
        Ok((kept, dropped))
    }

    /// Copies of the kept items, in their original order.
    pub fn kept<T: Clone>(&self, items: &[T]) -> Result<Vec<T>, EvalError> {
        Ok(self.partition(items.to_vec())?.0)
    }
}

/// A per-sequence seed derived from a base seed and the sequence's name (FNV-1a of the name,
/// mixed with the base seed by SplitMix64); stable across platforms and releases.
pub fn sequence_seed(base_seed: u64, sequence_name: &str) -> u64 {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for byte in sequence_name.bytes() {
        hash ^= u64::from(byte);
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    splitmix64(base_seed ^ splitmix64(hash))
}

fn splitmix64(value: u64) -> u64 {
    let mut z = value.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A uniformly random permutation of `0..len`.
fn seeded_permutation(len: usize, seed: u64) -> Vec<usize> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut order: Vec<usize> = (0..len).collect();
    for i in (1..len).rev() {
        let j = uniform_below(&mut rng, i as u64 + 1) as usize;
        order.swap(i, j);
    }
    order
}

/// Uniform integer in `0..bound` (`bound > 0`) by rejection sampling.
fn uniform_below(rng: &mut impl RngCore, bound: u64) -> u64 {
    let zone = u64::MAX - (u64::MAX % bound);
    loop {
        let value = rng.next_u64();
        if value < zone {
            return value % bound;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_count_and_determinism() {
        let a = DropoutMask::new(1000, 0.1, 7).unwrap();
        let b = DropoutMask::new(1000, 0.1, 7).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.dropped_count(), 100);
        assert_eq!(a.flags().iter().filter(|&&flag| flag).count(), 100);
        // 0.2 · 17 = 3.4 → 3; 0.1 · 15 = 1.5 → 2 (half away from zero).
        assert_eq!(DropoutMask::new(17, 0.2, 1).unwrap().dropped_count(), 3);
        assert_eq!(DropoutMask::new(15, 0.1, 1).unwrap().dropped_count(), 2);
        assert_ne!(a, DropoutMask::new(1000, 0.1, 8).unwrap());
    }

    #[test]
    fn lower_rate_is_subset_of_higher_rate() {
        let ten = DropoutMask::new(500, 0.1, 42).unwrap();
        let twenty = DropoutMask::new(500, 0.2, 42).unwrap();
        for index in 0..500 {
            assert!(!ten.is_dropped(index) || twenty.is_dropped(index));
        }
        assert_eq!(twenty.dropped_count(), 100);
    }

    #[test]
    fn partition_keeps_order_and_is_item_agnostic() {
        let mask = DropoutMask::new(10, 0.3, 3).unwrap();
        let numbers: Vec<u32> = (0..10).collect();
        let words: Vec<String> = (0..10).map(|k| format!("m{k}")).collect();
        let (kept_numbers, dropped_numbers) = mask.partition(numbers).unwrap();
        let (kept_words, _) = mask.partition(words).unwrap();
        assert_eq!(kept_numbers.len(), 7);
        assert_eq!(dropped_numbers.len(), 3);
        assert!(kept_numbers.windows(2).all(|pair| pair[0] < pair[1]));
        let expected: Vec<String> = kept_numbers.iter().map(|k| format!("m{k}")).collect();
        assert_eq!(kept_words, expected);
        for k in dropped_numbers {
            assert!(mask.is_dropped(k as usize));
        }
        assert!(matches!(mask.kept(&[1, 2, 3]), Err(EvalError::LengthMismatch { expected: 10, actual: 3 })));
    }

    #[test]
    fn invalid_fractions_and_edges() {
        assert!(DropoutMask::new(10, -0.1, 0).is_err());
        assert!(DropoutMask::new(10, 1.5, 0).is_err());
        assert!(DropoutMask::new(10, f64::NAN, 0).is_err());
        assert_eq!(DropoutMask::new(10, 1.0, 0).unwrap().dropped_count(), 10);
        assert_eq!(DropoutMask::new(10, 0.0, 0).unwrap().dropped_count(), 0);
        assert!(DropoutMask::new(0, 0.5, 0).unwrap().is_empty());
    }

    #[test]
    fn every_position_is_dropped_about_equally_often() {
        // Over 2000 seeds, each of 20 positions should be dropped in about 10 % of the masks
        // (binomial sd ≈ 6.7 around 200); allow ±50.
        let mut hits = [0u32; 20];
        for seed in 0..2000 {
            let mask = DropoutMask::new(20, 0.1, seed).unwrap();
            for (index, hit) in hits.iter_mut().enumerate() {
                *hit += u32::from(mask.is_dropped(index));
            }
        }
        assert!(hits.iter().all(|&hit| (150..=250).contains(&hit)), "{hits:?}");
    }

    #[test]
    fn sequence_seeds_differ_by_name_and_base() {
        assert_eq!(sequence_seed(1, "sequence_1"), sequence_seed(1, "sequence_1"));
        assert_ne!(sequence_seed(1, "sequence_1"), sequence_seed(1, "sequence_2"));
        assert_ne!(sequence_seed(1, "sequence_1"), sequence_seed(2, "sequence_1"));
    }
}
