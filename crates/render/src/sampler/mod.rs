//! Sample generators. Every value is a pure function of (pixel, sample index,
//! dimension, seed): no state survives between samples and nothing depends on the
//! thread, so images are bit-identical at any thread count.
//!
//! Dimensions are consumed in order by `get_1d`/`get_2d`, one dimension id per call.
//! The Sobol sampler pads 2D Sobol points across dimension pairs with hash-based Owen
//! scrambling and index shuffling (Burley, "Practical Hash-based Owen Scrambling",
//! JCGT 2020), which keeps every pair well stratified and decorrelates the pairs.
//! Where an integrand couples draws strongly, a draw may instead continue an earlier
//! draw's Sobol point (`get_2d_as_anchor`, `get_2d_continuing`): the draws then form one
//! low-discrepancy net over the pixel's samples rather than independent pairs.
//! Halton points use the primes of their dimension pair as bases (halton.rs), and
//! the stratified sampler jitters within a per-pixel random order of strata
//! (stratified.rs). Streams not tied to a pixel (photons) have no strata count, so a
//! stratified sampler draws independent numbers there.

mod halton;
mod sobol;
mod stratified;

use glam::Vec2;

use radiant_math::hash::{hash_u64s, mix64, u32_to_unit_f32};
use radiant_scene::SamplerKind;

pub use halton::{PRIME_COUNT, PRIMES, randomized_radical_inverse};
pub use sobol::{owen_scramble, scrambled_sobol, sobol_u32};
use sobol::{
    owen_scramble_reversed, scrambled_further_sobol_pair, scrambled_sobol_0, scrambled_sobol_pair,
};
pub use stratified::{permute, stratified_1d, stratified_2d};

/// The sampler state for one pixel sample.
#[derive(Clone, Debug)]
pub struct PixelSample {
    kind: SamplerKind,
    /// Hash of (pixel, seed): decorrelates pixels.
    pixel_key: u64,
    index: u32,
    /// `index` with its bits reversed, as Burley's index shuffle reads it.
    index_reversed: u32,
    dim: u32,
    /// A stream not tied to a pixel ([`PixelSample::for_stream`]).
    in_stream: bool,
}

impl PixelSample {
    /// Starts sample `index` of pixel `(x, y)`.
    pub fn new(kind: SamplerKind, seed: u64, x: u32, y: u32, index: u32) -> PixelSample {
        PixelSample {
            kind,
            pixel_key: hash_u64s(&[x as u64, y as u64, seed]),
            index,
            index_reversed: index.reverse_bits(),
            dim: 0,
            in_stream: false,
        }
    }

    /// A sample stream not tied to a pixel (photon paths, gather rays): `stream` names
    /// the work item, `index` the sample within it.
    pub fn for_stream(kind: SamplerKind, seed: u64, stream: u64, index: u32) -> PixelSample {
        PixelSample {
            kind,
            pixel_key: hash_u64s(&[stream, 0x5eed_5eed, seed]),
            index,
            index_reversed: index.reverse_bits(),
            dim: 0,
            in_stream: true,
        }
    }

    /// Branch `j` of `k` taken from this sample at its current dimension: the same pixel,
    /// sample index `index · k + j` from here on. The k branches of a pixel's n samples
    /// are then its first n·k samples in the dimensions that follow, as well stratified
    /// as n·k samples would be (a stratified sampler, whose strata count is fixed, draws
    /// the branches' numbers independently).
    pub fn branch(&self, k: u32, j: u32) -> PixelSample {
        let index = self.index.wrapping_mul(k).wrapping_add(j);
        PixelSample {
            index,
            index_reversed: index.reverse_bits(),
            in_stream: self.in_stream || matches!(self.kind, SamplerKind::Stratified { .. }),
            ..self.clone()
        }
    }

    /// Skips to a dimension (for integrators that lay out dimensions per bounce).
    pub fn set_dimension(&mut self, dim: u32) {
        self.dim = dim;
    }

    pub fn dimension(&self) -> u32 {
        self.dim
    }

    /// Burley's sample-index shuffle: the index is Owen-scrambled as if it were a binary
    /// fraction, so each bit flips depending only on the bits above it. The first 2^k
    /// indices then map to one aligned block of 2^k Sobol points, still a (0,2)-net, but
    /// a different block and order for each dimension pair. Returned bit-reversed, as
    /// the scramble leaves it; the Sobol tables read it so.
    #[inline(always)]
    fn shuffled_index_reversed(&self, key: u64) -> u32 {
        owen_scramble_reversed(self.index_reversed, (key >> 16) as u32)
    }

    /// The Sobol value of dimension key `key` (dimension 0 of the shuffled index).
    #[inline(always)]
    fn sobol_1d(&self, key: u64) -> f32 {
        let r = self.shuffled_index_reversed(key);
        u32_to_unit_f32(scrambled_sobol_0(r, (key >> 32) as u32))
    }

    /// The Sobol pair of dimension key `key`: dimensions 0 and 1 of the shuffled index.
    #[inline(always)]
    fn sobol_2d(&self, key: u64) -> Vec2 {
        sobol_2d_at(self.shuffled_index_reversed(key), key)
    }

    #[inline(always)]
    fn next_key(&mut self) -> u64 {
        let k = dimension_key(self.pixel_key, self.dim);
        self.dim += 1;
        k
    }

    /// [`get_2d`](Self::get_2d), and the draw as an anchor that later draws may continue
    /// (see [`get_2d_continuing`](Self::get_2d_continuing)). Always inlined, as the next
    /// one: the path tracer's split walk, a large function, otherwise calls both
    /// (0.5 % of its instructions; the unsplit walk inlines them either way).
    #[inline(always)]
    pub fn get_2d_as_anchor(&mut self) -> (Vec2, SobolAnchor) {
        if self.kind != SamplerKind::Sobol {
            return (
                self.get_2d(),
                SobolAnchor {
                    shuffled_index_reversed: 0,
                },
            );
        }
        let key = self.next_key();
        let r = self.shuffled_index_reversed(key);
        (
            sobol_2d_at(r, key),
            SobolAnchor {
                shuffled_index_reversed: r,
            },
        )
    }

    /// A 2D draw that takes further dimensions of the Sobol point an earlier 2D draw,
    /// `anchor`, took dimensions 0 and 1 of: the same shuffled sample index, Owen-scrambled
    /// with this draw's own key. Padding pairs independently (as [`get_2d`](Self::get_2d)
    /// does) stratifies each pair alone; draws that continue one point are stratified
    /// jointly, a (t, 4)- or (t, 6)-net over a pixel's samples with small t (the tests
    /// state them). Worth it where the integrand couples the draws strongly, such as the
    /// directions of a path's first two bounces. Other samplers draw as `get_2d`.
    #[inline(always)]
    pub fn get_2d_continuing(&mut self, anchor: SobolAnchor, pair: ContinuedPair) -> Vec2 {
        if self.kind != SamplerKind::Sobol {
            return self.get_2d();
        }
        let h = mix64(self.next_key());
        let further = match pair {
            ContinuedPair::Second => sobol::SECOND_PAIR,
            ContinuedPair::Third => sobol::THIRD_PAIR,
        };
        let [x, y] = scrambled_further_sobol_pair(
            further,
            anchor.shuffled_index_reversed,
            [h as u32, (h >> 32) as u32],
        );
        Vec2::new(u32_to_unit_f32(x), u32_to_unit_f32(y))
    }

    /// [`get_2d_continuing`](Self::get_2d_continuing) when `needed`; otherwise (0, 0),
    /// the dimension consumed either way (as [`get_2d_if`](Self::get_2d_if)).
    #[inline]
    pub fn get_2d_continuing_if(
        &mut self,
        needed: bool,
        anchor: SobolAnchor,
        pair: ContinuedPair,
    ) -> Vec2 {
        if needed {
            self.get_2d_continuing(anchor, pair)
        } else {
            self.dim += 1;
            Vec2::ZERO
        }
    }

    /// One uniform number in [0, 1).
    #[inline]
    pub fn get_1d(&mut self) -> f32 {
        // Sobol, the default, inline; the other samplers behind a call.
        if self.kind == SamplerKind::Sobol {
            let key = self.next_key();
            return self.sobol_1d(key);
        }
        self.get_1d_other()
    }

    #[inline(never)]
    fn get_1d_other(&mut self) -> f32 {
        let dim = self.dim;
        let key = self.next_key();
        match self.kind {
            SamplerKind::Independent => independent(key, self.index),
            SamplerKind::Sobol => self.sobol_1d(key),
            SamplerKind::Halton { randomization } => {
                let prime = 2 * dim as usize;
                if prime < PRIME_COUNT {
                    randomized_radical_inverse(self.index, prime, key, randomization)
                } else {
                    independent(key, self.index)
                }
            }
            SamplerKind::Stratified { x, y, jitter } => {
                if self.in_stream {
                    independent(key, self.index)
                } else {
                    stratified_1d(self.index, x * y, jitter, key)
                }
            }
        }
    }

    /// [`get_1d`](Self::get_1d) when `needed`; otherwise 0 without computing the number.
    /// The dimension is consumed either way, so the dimensions that follow do not depend
    /// on whether this one was used (a hashed Sobol value costs about a tenth of a
    /// diffuse bounce's shading, and roulette and single-light choices skip most).
    #[inline]
    pub fn get_1d_if(&mut self, needed: bool) -> f32 {
        if needed {
            self.get_1d()
        } else {
            self.dim += 1;
            0.0
        }
    }

    /// A pair of uniform numbers in [0, 1)^2, stratified together.
    #[inline]
    pub fn get_2d(&mut self) -> Vec2 {
        if self.kind == SamplerKind::Sobol {
            let key = self.next_key();
            return self.sobol_2d(key);
        }
        self.get_2d_other()
    }

    /// [`get_2d`](Self::get_2d) when `needed`; otherwise (0, 0) without computing the
    /// pair, the dimension consumed either way (as [`get_1d_if`](Self::get_1d_if)).
    #[inline]
    pub fn get_2d_if(&mut self, needed: bool) -> Vec2 {
        if needed {
            self.get_2d()
        } else {
            self.dim += 1;
            Vec2::ZERO
        }
    }

    #[inline(never)]
    fn get_2d_other(&mut self) -> Vec2 {
        let dim = self.dim;
        let key = self.next_key();
        match self.kind {
            SamplerKind::Independent => independent_2d(key, self.index),
            SamplerKind::Sobol => self.sobol_2d(key),
            SamplerKind::Halton { randomization } => {
                let prime = 2 * dim as usize;
                if prime + 1 < PRIME_COUNT {
                    Vec2::new(
                        randomized_radical_inverse(self.index, prime, key, randomization),
                        randomized_radical_inverse(
                            self.index,
                            prime + 1,
                            mix64(key),
                            randomization,
                        ),
                    )
                } else {
                    independent_2d(key, self.index)
                }
            }
            SamplerKind::Stratified { x, y, jitter } => {
                if self.in_stream {
                    independent_2d(key, self.index)
                } else {
                    stratified_2d(self.index, x, y, jitter, key)
                }
            }
        }
    }
}

/// A 2D draw whose Sobol point later draws continue: the sample index as that draw
/// shuffled it, bit-reversed (meaningless for samplers other than Sobol, which ignore
/// it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SobolAnchor {
    shuffled_index_reversed: u32,
}

/// Which further dimensions of an anchor's Sobol point a continuing draw takes:
/// `Second` dimensions 2 and 3, `Third` dimensions 4 and 5.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContinuedPair {
    Second,
    Third,
}

/// The Sobol pair of dimension key `key` at the shuffled index whose bit reversal is
/// `r`: dimensions 0 and 1, Owen-scrambled with a hash of the key.
#[inline(always)]
fn sobol_2d_at(r: u32, key: u64) -> Vec2 {
    let h = mix64(key);
    let [x, y] = scrambled_sobol_pair(r, [h as u32, (h >> 32) as u32]);
    Vec2::new(u32_to_unit_f32(x), u32_to_unit_f32(y))
}

/// The key of dimension `dim` of the pixel (or stream) `pixel_key`: what shuffles and
/// scrambles that dimension's points, the same for all of the pixel's samples.
#[inline(always)]
fn dimension_key(pixel_key: u64, dim: u32) -> u64 {
    mix64(pixel_key ^ (dim as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15))
}

fn independent(key: u64, index: u32) -> f32 {
    u32_to_unit_f32(mix64(key ^ index as u64) as u32)
}

fn independent_2d(key: u64, index: u32) -> Vec2 {
    let h = mix64(key ^ index as u64);
    Vec2::new(u32_to_unit_f32(h as u32), u32_to_unit_f32((h >> 32) as u32))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Stratification check: with 2^k samples, each of the 2^k elementary intervals of
    /// every shape (0,2)-net must hold exactly one point.
    fn is_02_net(points: &[Vec2]) -> bool {
        let n = points.len();
        let k = n.trailing_zeros();
        (0..=k).all(|a| {
            let nx = 1usize << a;
            let ny = 1usize << (k - a);
            let mut seen = vec![false; n];
            points.iter().all(|p| {
                let cx = (p.x * nx as f32) as usize;
                let cy = (p.y * ny as f32) as usize;
                let cell = cy * nx + cx;
                !std::mem::replace(&mut seen[cell], true)
            })
        })
    }

    #[test]
    fn sobol_pairs_are_02_nets_in_every_dimension_pair() {
        for dim_pair in 0..6u32 {
            for &(x, y) in &[(0u32, 0u32), (17, 3), (255, 255)] {
                let pts: Vec<Vec2> = (0..64)
                    .map(|i| {
                        let mut s = PixelSample::new(SamplerKind::Sobol, 7, x, y, i);
                        s.set_dimension(dim_pair);
                        s.get_2d()
                    })
                    .collect();
                assert!(is_02_net(&pts), "pair {dim_pair} pixel ({x},{y})");
            }
        }
    }

    /// A skipped draw consumes its dimension: what follows is the same as after a real one.
    #[test]
    fn skipped_draws_keep_the_dimensions_that_follow() {
        let kinds = [
            SamplerKind::Sobol,
            SamplerKind::Independent,
            SamplerKind::Halton {
                randomization: radiant_scene::DigitRandomization::PermuteDigits,
            },
            SamplerKind::Stratified {
                x: 4,
                y: 4,
                jitter: true,
            },
        ];
        for kind in kinds {
            let mut drawn = PixelSample::new(kind, 3, 4, 5, 6);
            let mut skipped = drawn.clone();
            let (a, b) = (drawn.get_2d(), drawn.get_1d());
            assert_eq!(skipped.get_2d_if(false), Vec2::ZERO);
            assert_eq!(skipped.get_1d_if(false), 0.0);
            assert_ne!((a, b), (Vec2::ZERO, 0.0));
            assert_eq!(drawn.get_2d(), skipped.get_2d(), "{kind:?}");
            assert_eq!(drawn.get_1d_if(true), skipped.get_1d(), "{kind:?}");
            assert_eq!(drawn.get_2d_if(true), skipped.get_2d(), "{kind:?}");
        }
    }

    /// The t of a (t, m, s)-net of 2^m points in [0, 1)^s: the smallest t for which every
    /// elementary box of volume 2^(t−m) holds exactly 2^t points (Niederreiter 1992).
    fn t_value(points: &[Vec<f32>]) -> u32 {
        let m = points.len().trailing_zeros();
        let s = points[0].len();
        // Every split of `bits` binary digits among the s coordinates.
        fn splits(bits: u32, s: usize) -> Vec<Vec<u32>> {
            if s == 1 {
                return vec![vec![bits]];
            }
            (0..=bits)
                .flat_map(|first| {
                    splits(bits - first, s - 1)
                        .into_iter()
                        .map(move |mut rest| {
                            rest.insert(0, first);
                            rest
                        })
                })
                .collect()
        }
        (0..=m)
            .find(|&t| {
                splits(m - t, s).iter().all(|digits| {
                    let mut count = std::collections::HashMap::new();
                    for p in points {
                        let cell: Vec<u32> = p
                            .iter()
                            .zip(digits)
                            .map(|(&x, &d)| (x * (1u64 << d) as f32) as u32)
                            .collect();
                        *count.entry(cell).or_insert(0u32) += 1;
                    }
                    count.values().all(|&c| c == 1 << t)
                })
            })
            .expect("t = m always holds")
    }

    /// The second vertex's draws of a path continue the first direction's point: over
    /// 2^m samples of a pixel the anchor and its continuations form nets of small t
    /// (those of the unscrambled Sobol dimensions 0–5, which Owen scrambling keeps).
    /// Padded pairs, each shuffled on its own, are hardly a net in 4D (t near m).
    #[test]
    fn continued_draws_are_stratified_jointly_with_their_anchor() {
        for &(seed, x, y) in &[(1u64, 0u32, 0u32), (7, 17, 3), (3, 255, 128)] {
            for m in [4u32, 6, 8] {
                let mut anchor_pair = Vec::new();
                let mut second = Vec::new();
                let mut third = Vec::new();
                let mut padded = Vec::new();
                for i in 0..1u32 << m {
                    let mut s = PixelSample::new(SamplerKind::Sobol, seed, x, y, i);
                    s.get_2d();
                    let (a, anchor) = s.get_2d_as_anchor();
                    s.get_1d();
                    let c3 = s.get_2d_continuing(anchor, ContinuedPair::Third);
                    let c2 = s.get_2d_continuing(anchor, ContinuedPair::Second);
                    let p = s.get_2d();
                    anchor_pair.push(a);
                    second.push(c2);
                    third.push(c3);
                    padded.push(p);
                }
                let joint = |parts: &[&[Vec2]]| -> Vec<Vec<f32>> {
                    (0..anchor_pair.len())
                        .map(|i| parts.iter().flat_map(|q| [q[i].x, q[i].y]).collect())
                        .collect()
                };
                let ctx = format!("seed {seed} pixel ({x}, {y}), 2^{m} samples");
                assert_eq!(t_value(&joint(&[&anchor_pair])), 0, "{ctx}");
                assert!(t_value(&joint(&[&second])) <= 1, "{ctx}");
                assert!(t_value(&joint(&[&third])) <= 3, "{ctx}");
                assert!(t_value(&joint(&[&anchor_pair, &second])) <= 3, "{ctx}");
                assert!(
                    t_value(&joint(&[&anchor_pair, &second, &third])) <= 4,
                    "{ctx}"
                );
                if m >= 6 {
                    assert!(t_value(&joint(&[&anchor_pair, &padded])) >= m - 2, "{ctx}");
                }
            }
        }
    }

    /// Branch j of k taken from sample i at dimension d draws there what sample i·k + j
    /// draws: the k branches of a pixel's n samples are its first n·k samples in the
    /// dimensions after the split, so their pairs are a (0, 2)-net as those samples'
    /// are, and a branch's continued draws continue its own anchor. A stratified
    /// sampler's strata are the n camera samples', so its branches draw independent
    /// numbers instead, different from branch to branch.
    #[test]
    fn branches_draw_as_further_samples_of_their_pixel() {
        let (n, k, d) = (16u32, 4u32, 5u32);
        let mut branched = Vec::new();
        for i in 0..n {
            let mut s = PixelSample::new(SamplerKind::Sobol, 9, 3, 4, i);
            s.set_dimension(d);
            for j in 0..k {
                let mut b = s.branch(k, j);
                let (u, anchor) = b.get_2d_as_anchor();
                let c = b.get_2d_continuing(anchor, ContinuedPair::Second);
                let mut plain = PixelSample::new(SamplerKind::Sobol, 9, 3, 4, i * k + j);
                plain.set_dimension(d);
                let (pu, panchor) = plain.get_2d_as_anchor();
                assert_eq!(
                    (u, c),
                    (pu, plain.get_2d_continuing(panchor, ContinuedPair::Second))
                );
                branched.push(vec![u.x, u.y]);
            }
        }
        assert_eq!(t_value(&branched), 0);

        let strata = SamplerKind::Stratified {
            x: 4,
            y: 4,
            jitter: true,
        };
        let s = PixelSample::new(strata, 9, 3, 4, 5);
        let draws: Vec<Vec2> = (0..k).map(|j| s.branch(k, j).get_2d()).collect();
        for (j, u) in draws.iter().enumerate() {
            assert!((0.0..1.0).contains(&u.x) && (0.0..1.0).contains(&u.y));
            assert!(draws[..j].iter().all(|v| v != u), "branch {j} repeats");
        }
    }

    #[test]
    fn continued_draws_consume_their_dimension_and_other_samplers_draw_plainly() {
        let mut plain = PixelSample::new(SamplerKind::Independent, 3, 4, 5, 6);
        let mut continued = plain.clone();
        let (a, anchor) = continued.get_2d_as_anchor();
        assert_eq!(a, plain.get_2d());
        assert_eq!(
            continued.get_2d_continuing(anchor, ContinuedPair::Second),
            plain.get_2d()
        );
        let mut sobol = PixelSample::new(SamplerKind::Sobol, 3, 4, 5, 6);
        let mut skipped = sobol.clone();
        let (a, anchor) = sobol.get_2d_as_anchor();
        assert_eq!(a, skipped.get_2d());
        let c = sobol.get_2d_continuing_if(true, anchor, ContinuedPair::Third);
        assert!((0.0..1.0).contains(&c.x) && (0.0..1.0).contains(&c.y));
        assert_eq!(
            skipped.get_2d_continuing_if(false, anchor, ContinuedPair::Third),
            Vec2::ZERO
        );
        assert_eq!(sobol.get_2d(), skipped.get_2d());
    }

    #[test]
    fn samples_are_pure_functions_of_their_coordinates() {
        let draw = |seed| {
            let mut s = PixelSample::new(SamplerKind::Sobol, seed, 5, 9, 3);
            (s.get_1d(), s.get_2d(), s.get_1d())
        };
        assert_eq!(draw(1), draw(1));
        assert_ne!(draw(1), draw(2));
    }

    #[test]
    fn independent_and_sobol_means_are_unbiased() {
        for kind in [SamplerKind::Independent, SamplerKind::Sobol] {
            let mut sum = 0.0f64;
            let n = 4096;
            for i in 0..n {
                let mut s = PixelSample::new(kind, 0, 1, 2, i);
                s.set_dimension(3);
                let u = s.get_2d();
                assert!((0.0..1.0).contains(&u.x) && (0.0..1.0).contains(&u.y));
                sum += (u.x * u.y) as f64;
            }
            // E[xy] = 1/4; Monte Carlo std of xy is ~0.22/sqrt(n) = 0.0034 for independent.
            assert!((sum / n as f64 - 0.25).abs() < 0.012, "{kind:?}");
        }
    }
}
