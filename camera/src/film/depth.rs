//! The quantisation an integer image shows in its data, not in its header.
//!
//! A file's header gives the largest code it can store (255, 65535, a PPM's
//! maxval), but what was written may be coarser: 8-bit values converted to 16
//! bits (each code × 257), a 5-bit TGA channel widened to 8 bits, a PPM of
//! maxval 1023 holding 8-bit data. What a grader may allow for is the step the
//! values were rounded to, so each channel's depth is found from the codes it
//! holds: the fewest levels `m` of the form `2ⁿ − 1` whose grid `j · max / m`
//! every code lies within one code of, where that cannot be chance.
//!
//! Chance: a code drawn from a finer encoding lands within one code of the
//! grid with probability `p` (the share of codes that do), so `d` distinct
//! codes all do with probability `pᵈ`; a coarser depth is taken only where that
//! is below [`CHANCE`]. An image of few distinct codes (all black, say) keeps
//! its header's depth. The channels of one file were most likely written
//! alike, so one depth for all three is tried first, on the evidence of all
//! their codes ([`levels`]): a channel that shows few codes of its own (the
//! blue of a red and yellow scene) takes the depth the others show.

/// The largest chance of taking a finer encoding for a coarser one.
pub const CHANCE: f64 = 1e-6;

/// Which codes `0..=max` occur in one channel.
#[derive(Clone, Debug)]
pub struct CodeSet {
    max: u32,
    seen: Vec<bool>,
}

impl CodeSet {
    pub fn new(max: u32) -> CodeSet {
        CodeSet {
            max,
            seen: vec![false; max as usize + 1],
        }
    }

    /// The largest code the file can store.
    pub fn max(&self) -> u32 {
        self.max
    }

    pub fn insert(&mut self, code: u32) {
        self.seen[code.min(self.max) as usize] = true;
    }

    fn codes(&self) -> impl Iterator<Item = u32> + '_ {
        self.seen
            .iter()
            .enumerate()
            .filter(|(_, &s)| s)
            .map(|(c, _)| c as u32)
    }

    /// The number of levels this channel alone shows it was quantised to:
    /// the coarsest depth `2ⁿ − 1` below the header's `max` that every code
    /// fits and chance cannot explain; else `max`.
    pub fn levels(&self) -> u32 {
        common_levels(std::slice::from_ref(self))
    }
}

/// The levels of each of a file's channels (which share its `max`): one
/// depth for all where their codes together show it, else each channel's
/// own ([`CodeSet::levels`]).
pub fn levels(channels: &[CodeSet; 3]) -> [u32; 3] {
    match common_levels(channels) {
        m if m < channels[0].max => [m; 3],
        _ => std::array::from_fn(|c| channels[c].levels()),
    }
}

/// The coarsest depth `2ⁿ − 1` below `max` that every code of every one of
/// `channels` fits, on the evidence of all their distinct codes; else `max`.
fn common_levels(channels: &[CodeSet]) -> u32 {
    let max = channels[0].max;
    let distinct: i32 = channels.iter().map(|c| c.codes().count() as i32).sum();
    (1..32)
        .map(|n| (1u64 << n) - 1)
        .take_while(|&m| m < max as u64)
        .map(|m| m as u32)
        .find(|&m| {
            let grid = Grid::new(max, m);
            grid.chance().powi(distinct) < CHANCE
                && channels
                    .iter()
                    .all(|c| c.codes().all(|code| grid.fits(code)))
        })
        .unwrap_or(max)
}

/// The codes `j · max / m` of `m` levels stored in codes of `max`.
struct Grid {
    max: f64,
    levels: f64,
}

impl Grid {
    fn new(max: u32, levels: u32) -> Grid {
        Grid {
            max: max as f64,
            levels: levels as f64,
        }
    }

    fn point(&self, j: f64) -> f64 {
        j * self.max / self.levels
    }

    /// Within one code of a grid point: rounded, truncated and bit-replicated
    /// widenings all are.
    fn fits(&self, code: u32) -> bool {
        let code = code as f64;
        let j = (code * self.levels / self.max).round();
        (code - self.point(j)).abs() < 1.0
    }

    /// The share of all codes `0..=max` that fit.
    fn chance(&self) -> f64 {
        let fitting: f64 = (0..=self.levels as u32)
            .map(|j| {
                let point = self.point(j as f64);
                if point.fract() == 0.0 {
                    1.0
                } else {
                    2.0
                }
            })
            .sum();
        (fitting / (self.max + 1.0)).min(1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(max: u32, codes: impl IntoIterator<Item = u32>) -> CodeSet {
        let mut set = CodeSet::new(max);
        codes.into_iter().for_each(|c| set.insert(c));
        set
    }

    #[test]
    fn eight_bit_data_in_sixteen_bits_is_found() {
        // Every 8-bit code × 257, as any 8-to-16-bit conversion writes.
        assert_eq!(set(65535, (0..256).map(|c| c * 257)).levels(), 255);
        // A handful of codes is still far beyond chance (1/256 each).
        assert_eq!(set(65535, [0, 257 * 3, 257 * 100, 65535]).levels(), 255);
        // One code off the grid: genuine 16-bit data.
        assert_eq!(
            set(65535, (0..256).map(|c| c * 257).chain([1000])).levels(),
            65535
        );
    }

    #[test]
    fn five_bit_channels_widened_any_way_are_found() {
        let rounded = (0..32).map(|x| (x as f64 * 255.0 / 31.0).round() as u32);
        let truncated = (0..32).map(|x| x * 255 / 31);
        let replicated = (0..32).map(|x| (x << 3) | (x >> 2));
        assert_eq!(set(255, rounded).levels(), 31);
        assert_eq!(set(255, truncated).levels(), 31);
        assert_eq!(set(255, replicated).levels(), 31);
    }

    #[test]
    fn a_channel_of_few_codes_takes_the_depth_the_others_show() {
        let five = |x: u32| x * 255 / 31;
        // Red and green use every 5-bit level, blue only five of them: alone,
        // blue would keep its 8 bits.
        let blue = set(255, [0, 3, 9, 20, 31].map(five));
        assert_eq!(blue.levels(), 255);
        let full = set(255, (0..32).map(five));
        assert_eq!(levels(&[full.clone(), full.clone(), blue]), [31; 3]);
        // 5-6-5: no common depth, each channel its own.
        let six = set(255, (0..64).map(|x| x * 255 / 63));
        assert_eq!(levels(&[full.clone(), six, full]), [31, 63, 31]);
    }

    #[test]
    fn few_distinct_codes_keep_the_header_depth() {
        // All black, or black and white: nothing says the data is coarse.
        assert_eq!(set(65535, [0]).levels(), 65535);
        assert_eq!(set(255, [0, 255]).levels(), 255);
        // Ten 5-bit codes in 8 bits are 4⁻¹⁰ < 1e-6 by chance; five are not.
        let five = (0..32).step_by(7).map(|x| x * 255 / 31);
        assert_eq!(set(255, five).levels(), 255);
    }
}
