//! Piecewise-constant distributions for importance sampling (pbrt-v4 section
//! A.5 and 12.5): sample a bin in proportion to its weight, then uniformly inside it.

use glam::Vec2;
use glint_geometry::prefetch;

/// A piecewise-constant density over [0, 1] with `n` equal bins.
#[derive(Clone, Debug)]
pub struct PiecewiseConstant1D {
    /// Entry `i` holds CDF value `i`, bin `i`'s density (0 past the last bin)
    /// and guide entry `i`: what a sample near `i/n` reads, in one place, so
    /// that a sample's search touches one or two cache lines, not one in
    /// each of three arrays.
    entries: Vec<Entry>,
    /// Integral of the weights over [0, 1] (their mean).
    integral: f32,
}

/// One index of a [`PiecewiseConstant1D`].
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(16))]
struct Entry {
    /// The probability of the bins before this one; 1 at `n`. In f64, so that
    /// bins a million times lighter than the total keep a non-zero width (and
    /// so are sampled with the density `pdf` reports).
    cdf: f64,
    /// The bin's density, its weight over the integral (made once here, not
    /// divided on every sample).
    density: f32,
    /// A guide table (Chen and Asau, "On generating random variates from an
    /// empirical distribution", AIIE Transactions 6(2), 1974): entry `j` is
    /// the number of CDF values in buckets before `j`, bucket
    /// [`bucket`]`(c, n)` holding value `c`. The values of `u`'s own bucket
    /// are the only ones the search compares with `u`; where a bucket holds
    /// none (a bin wider than a bucket), the guide is the answer. The bucket
    /// function is monotone, so the count is the full search's.
    guide: u32,
}

impl PiecewiseConstant1D {
    /// Weights must be finite and non-negative; all zero gives the uniform density.
    pub fn new(weights: Vec<f32>) -> Self {
        let n = weights.len().max(1);
        let mut weights = weights;
        if weights.is_empty() {
            weights.push(1.0);
        }
        let total: f64 = weights.iter().map(|&w| w.max(0.0) as f64).sum();
        let uniform = total.is_nan() || total <= 0.0;
        let mut cdf = Vec::with_capacity(n + 1);
        let mut running = 0.0f64;
        cdf.push(0.0);
        for &w in &weights {
            running += if uniform { 1.0 } else { w.max(0.0) as f64 };
            cdf.push(running / if uniform { n as f64 } else { total });
        }
        cdf[n] = 1.0;
        if uniform {
            weights.iter_mut().for_each(|w| *w = 1.0);
        }
        let integral = if uniform {
            1.0
        } else {
            (total / n as f64) as f32
        };
        let entries = (0..=n)
            .map(|i| Entry {
                cdf: cdf[i],
                density: weights.get(i).map_or(0.0, |&w| w.max(0.0) / integral),
                guide: cdf.partition_point(|&c| bucket(c, n) < i) as u32,
            })
            .collect();
        Self { entries, integral }
    }

    /// The number of CDF values at most `u`: those of the buckets before
    /// `u`'s, plus those of its own bucket at most `u` (most buckets hold none
    /// or one, counted without a branch).
    #[inline(always)]
    fn values_at_most(&self, u: f64) -> usize {
        let n = self.len();
        if !(0.0..1.0).contains(&u) {
            return self.entries.partition_point(|e| e.cdf <= u);
        }
        let j = bucket(u, n);
        let (lo, hi) = (
            self.entries[j].guide as usize,
            self.entries[j + 1].guide as usize,
        );
        let own = &self.entries[lo..hi];
        lo + if own.len() <= 4 {
            own.iter().map(|e| usize::from(e.cdf <= u)).sum::<usize>()
        } else {
            own.partition_point(|e| e.cdf <= u)
        }
    }

    pub fn len(&self) -> usize {
        self.entries.len() - 1
    }

    /// Asks for the memory a [`Self::sample`] at `u` reads: the entry of
    /// `u`'s bucket, with the CDF values and weights there, which an even
    /// density's search finds.
    #[inline]
    fn prefetch_around(&self, u: f32) {
        prefetch(&self.entries[bucket(u as f64, self.len())]);
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Integral of the weights over [0, 1].
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// `(x, pdf(x), bin)` for a uniform `u` ∈ [0, 1).
    // Inlined into `PiecewiseConstant2D::sample_each`'s stages, the samples of
    // different points overlap better than as calls (`physical-environment`
    // 0.975× its time, 11 pairs).
    #[inline(always)]
    pub fn sample(&self, u: f32) -> (f32, f32, usize) {
        let u = u as f64;
        // The last bin whose cdf is ≤ u, skipping empty bins.
        let bin = self.values_at_most(u).saturating_sub(1).min(self.len() - 1);
        let (lo, hi) = (self.entries[bin].cdf, self.entries[bin + 1].cdf);
        let within = if hi > lo {
            ((u - lo) / (hi - lo)).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let n = self.len() as f32;
        // Stay inside the bin: rounding must not carry x into the next one.
        let x = (((bin as f64 + within) / self.len() as f64) as f32)
            .clamp(bin as f32 / n, ((bin + 1) as f32 / n).next_down());
        (x, self.pdf_of_bin(bin), bin)
    }

    /// The density at `x` ∈ [0, 1].
    #[inline]
    pub fn pdf(&self, x: f32) -> f32 {
        let bin = ((x * self.len() as f32) as usize).min(self.len() - 1);
        self.pdf_of_bin(bin)
    }

    #[inline]
    fn pdf_of_bin(&self, bin: usize) -> f32 {
        self.entries[bin].density
    }
}

/// The guide bucket of `x` among `n`: `⌊x·n⌋` as rounded, within `0..n`.
/// Monotone in `x`, which is all the guide table needs of it.
#[inline]
fn bucket(x: f64, n: usize) -> usize {
    ((x * n as f64) as usize).min(n - 1)
}

/// A piecewise-constant density over [0, 1]² on a `width × height` grid of bins:
/// a marginal density over rows and a conditional density within each row.
#[derive(Clone, Debug)]
pub struct PiecewiseConstant2D {
    rows: Vec<PiecewiseConstant1D>,
    marginal: PiecewiseConstant1D,
}

impl PiecewiseConstant2D {
    /// `weights` row-major, `width` per row, the first row at v = 0.
    pub fn new(weights: &[f32], width: usize) -> Self {
        let weights = if weights.is_empty() {
            &[1.0][..]
        } else {
            weights
        };
        let rows: Vec<PiecewiseConstant1D> = weights
            .chunks(width.max(1))
            .map(|row| PiecewiseConstant1D::new(row.to_vec()))
            .collect();
        let marginal = PiecewiseConstant1D::new(rows.iter().map(|r| r.integral()).collect());
        Self { rows, marginal }
    }

    /// `(uv, pdf(uv))` for uniform `u` ∈ [0, 1)²; the pdf is per unit area of [0, 1]².
    #[inline]
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (v, pdf_v, row) = self.marginal.sample(u.y);
        let (x, pdf_u, _) = self.rows[row].sample(u.x);
        (Vec2::new(x, v), pdf_v * pdf_u)
    }

    /// [`Self::sample`] at each of the first `len` points of `u`, bit for bit,
    /// stage by stage: every point's row, then every point's column. The
    /// searches of different points are independent, so their loads overlap
    /// where one point's would each wait for the one before.
    #[inline]
    pub fn sample_each<const N: usize>(&self, u: &[Vec2; N], len: usize) -> [(Vec2, f32); N] {
        let mut out = [(Vec2::ZERO, 0.0); N];
        let mut rows = [0usize; N];
        for k in 0..len.min(N) {
            let (v, pdf_v, row) = self.marginal.sample(u[k].y);
            (out[k], rows[k]) = ((Vec2::new(0.0, v), pdf_v), row);
        }
        // Each row's guide entry, CDF values and weights around the bucket of
        // its point: the searches below find them in the cache.
        for k in 0..len.min(N) {
            self.rows[rows[k]].prefetch_around(u[k].x);
        }
        for k in 0..len.min(N) {
            let (x, pdf_u, _) = self.rows[rows[k]].sample(u[k].x);
            out[k].0.x = x;
            out[k].1 *= pdf_u;
        }
        out
    }

    /// The density at `uv` ∈ [0, 1]².
    #[inline]
    pub fn pdf(&self, uv: Vec2) -> f32 {
        let row = ((uv.y * self.rows.len() as f32) as usize).min(self.rows.len() - 1);
        self.marginal.pdf(uv.y) * self.rows[row].pdf(uv.x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_follow_the_weights_and_pdf_integrates_to_one() {
        let d = PiecewiseConstant1D::new(vec![1.0, 0.0, 3.0, 4.0]);
        assert!((d.integral() - 2.0).abs() < 1e-6);
        let mut counts = [0usize; 4];
        let n = 80_000;
        for i in 0..n {
            let u = (i as f32 + 0.5) / n as f32;
            let (x, pdf, bin) = d.sample(u);
            assert!((0.0..1.0).contains(&x));
            assert_eq!(((x * 4.0) as usize), bin);
            assert!((pdf - d.pdf(x)).abs() < 1e-6);
            counts[bin] += 1;
        }
        assert_eq!(counts[1], 0, "an empty bin is never sampled");
        for (bin, expected) in [(0, 0.125), (2, 0.375), (3, 0.5)] {
            assert!((counts[bin] as f32 / n as f32 - expected).abs() < 1e-3);
        }
        let integral: f32 = (0..1000)
            .map(|i| d.pdf((i as f32 + 0.5) / 1000.0) / 1000.0)
            .sum();
        assert!((integral - 1.0).abs() < 1e-4);
    }

    /// The guide table only narrows the search: every `u` finds the bin of the
    /// full binary search, on uneven, zero-filled and peaked weights, at bucket
    /// edges, CDF values and their neighbours.
    #[test]
    fn the_guided_search_finds_the_full_searchs_bin() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let weights: [Vec<f32>; 4] = [
            (0..1000).map(|_| next().powi(8)).collect(),
            (0..257)
                .map(|k| if k % 7 == 0 { 1.0 } else { 0.0 })
                .collect(),
            (0..64).map(|k| if k == 40 { 1e6 } else { 1e-3 }).collect(),
            vec![0.0; 9],
        ];
        for w in weights {
            let d = PiecewiseConstant1D::new(w);
            let n = d.len();
            let mut us: Vec<f64> = (0..=4 * n).map(|j| j as f64 / (4 * n) as f64).collect();
            let cdf: Vec<f64> = d.entries.iter().map(|e| e.cdf).collect();
            for &c in &cdf {
                us.extend([
                    c,
                    f64::from_bits(c.to_bits().saturating_sub(1)),
                    c.next_up(),
                ]);
            }
            us.extend((0..2000).map(|_| next() as f64));
            for u in us.into_iter().filter(|u| (0.0..1.0).contains(u)) {
                let full = cdf.partition_point(|&c| c <= u);
                assert_eq!(d.values_at_most(u), full, "u = {u}, n = {n}");
            }
        }
    }

    #[test]
    fn all_zero_weights_give_the_uniform_density() {
        let d = PiecewiseConstant1D::new(vec![0.0; 5]);
        assert_eq!(d.pdf(0.3), 1.0);
        assert!((d.sample(0.5).0 - 0.5).abs() < 1e-6);
    }

    #[test]
    fn two_dimensional_pdf_matches_sampling() {
        let weights = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        let d = PiecewiseConstant2D::new(&weights, 3);
        let mut total = 0.0f64;
        let n = 300;
        for j in 0..n {
            for i in 0..n {
                let uv = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                total += d.pdf(uv) as f64 / (n * n) as f64;
                let (s, pdf) = d.sample(uv);
                assert!((pdf - d.pdf(s)).abs() < 1e-4 * pdf.max(1.0));
            }
        }
        assert!((total - 1.0).abs() < 1e-4, "{total}");
        // Bin (1, 1) has weight 4 of 15 in total over 6 bins: pdf = 4 / (15/6).
        assert!((d.pdf(Vec2::new(0.4, 0.8)) - 4.0 / 2.5).abs() < 1e-5);
    }
}
