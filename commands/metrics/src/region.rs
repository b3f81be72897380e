//! [`Region`]: the rectangle of pixels a measurement covers.

use crate::MetricsError;

/// A rectangle of pixels, half-open: columns `x0..x1`, rows `y0..y1` (rows from
/// the top). Every measurement over a region averages (or takes the largest)
/// over exactly these pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Region {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl Region {
    /// The whole `width × height` image.
    pub fn full(width: u32, height: u32) -> Region {
        Region {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }

    /// Parses `"x0,y0,x1,y1"` (four whole numbers, spaces around them allowed)
    /// into a non-empty region: `x1 > x0` and `y1 > y0`. Whether it fits an image
    /// is [`Region::check`]'s job.
    pub fn parse(text: &str) -> Result<Region, String> {
        let shape = || format!("expected x0,y0,x1,y1 (four whole numbers), got {text:?}");
        let parts: Vec<&str> = text.split(',').map(str::trim).collect();
        let [x0, y0, x1, y1] = parts[..] else {
            return Err(shape());
        };
        let number = |name: &str, s: &str| {
            s.parse::<u32>()
                .map_err(|_| format!("{name} is {s:?}, not a whole number from 0 to {}", u32::MAX))
        };
        let region = Region {
            x0: number("x0", x0)?,
            y0: number("y0", y0)?,
            x1: number("x1", x1)?,
            y1: number("y1", y1)?,
        };
        region.check_non_empty()?;
        Ok(region)
    }

    fn check_non_empty(&self) -> Result<(), String> {
        if self.x1 <= self.x0 {
            return Err(format!(
                "the region {self} is empty: x1 ({}) must be greater than x0 ({})",
                self.x1, self.x0
            ));
        }
        if self.y1 <= self.y0 {
            return Err(format!(
                "the region {self} is empty: y1 ({}) must be greater than y0 ({})",
                self.y1, self.y0
            ));
        }
        Ok(())
    }

    /// Checks that the region is non-empty and lies inside a `width × height`
    /// image (`x1 ≤ width`, `y1 ≤ height`). Every measurement refuses a region
    /// that fails this check ([`MetricsError::Region`]).
    pub fn check(&self, width: u32, height: u32) -> Result<(), String> {
        self.check_non_empty()?;
        if self.x1 > width || self.y1 > height {
            return Err(format!(
                "the region {self} reaches outside the {width}x{height} image"
            ));
        }
        Ok(())
    }

    /// The number of pixels in the region (0 if it is empty).
    pub fn pixel_count(&self) -> u64 {
        self.x1.saturating_sub(self.x0) as u64 * self.y1.saturating_sub(self.y0) as u64
    }

    /// The same part of the picture at another resolution: each edge is scaled by
    /// `to / from` along its axis and rounded to the nearest pixel edge (halves
    /// up), then the region is widened to at least one pixel on each axis, staying
    /// inside `to`. Scaling to the same resolution returns the region unchanged.
    ///
    /// # Panics
    /// If a side of `from` or `to` is 0.
    pub fn scaled(&self, from: (u32, u32), to: (u32, u32)) -> Region {
        assert!(
            from.0 > 0 && from.1 > 0 && to.0 > 0 && to.1 > 0,
            "Region::scaled needs non-empty resolutions, got {from:?} -> {to:?}"
        );
        let edge = |v: u32, from: u32, to: u32| -> u32 {
            // round(v · to / from) in integers; halves round up.
            let scaled = (2 * v as u64 * to as u64 + from as u64) / (2 * from as u64);
            scaled.min(to as u64) as u32
        };
        let axis = |a: u32, b: u32, from: u32, to: u32| -> (u32, u32) {
            let (mut lo, mut hi) = (edge(a, from, to), edge(b, from, to));
            if hi <= lo {
                hi = lo + 1;
            }
            if hi > to {
                lo = to - 1;
                hi = to;
            }
            (lo, hi)
        };
        let (x0, x1) = axis(self.x0, self.x1, from.0, to.0);
        let (y0, y1) = axis(self.y0, self.y1, from.1, to.1);
        Region { x0, y0, x1, y1 }
    }

    /// [`Region::check`] as a [`MetricsError`].
    pub(crate) fn inside(&self, width: u32, height: u32) -> Result<(), MetricsError> {
        self.check(width, height).map_err(MetricsError::Region)
    }

    /// The rows of the region.
    pub(crate) fn rows(&self) -> std::ops::Range<u32> {
        self.y0..self.y1
    }

    /// The columns of the region, as indices into a row.
    pub(crate) fn columns(&self) -> std::ops::Range<usize> {
        self.x0 as usize..self.x1 as usize
    }
}

impl std::fmt::Display for Region {
    /// The form [`Region::parse`] reads: `x0,y0,x1,y1`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{},{},{},{}", self.x0, self.y0, self.x1, self.y1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_reads_four_numbers_and_refuses_everything_else() {
        assert_eq!(
            Region::parse("1, 2,30 ,40"),
            Ok(Region {
                x0: 1,
                y0: 2,
                x1: 30,
                y1: 40
            })
        );
        for (text, expected) in [
            ("", "expected x0,y0,x1,y1"),
            ("1,2,3", "expected x0,y0,x1,y1"),
            ("1,2,3,4,5", "expected x0,y0,x1,y1"),
            ("a,0,1,1", "x0 is \"a\", not a whole number"),
            ("0,-1,1,1", "y0 is \"-1\", not a whole number"),
            ("0,0,1.5,1", "x1 is \"1.5\""),
            ("0,0,1,", "y1 is \"\""),
            ("0,0,99999999999,1", "x1 is \"99999999999\""),
            (
                "5,0,5,1",
                "the region 5,0,5,1 is empty: x1 (5) must be greater than x0 (5)",
            ),
            ("0,4,1,2", "y1 (2) must be greater than y0 (4)"),
        ] {
            let error = Region::parse(text).unwrap_err();
            assert!(error.contains(expected), "{text:?}: {error}");
        }
    }

    #[test]
    fn check_needs_a_non_empty_region_inside_the_image() {
        assert!(Region::full(4, 3).check(4, 3).is_ok());
        assert!(Region::parse("1,1,4,3").unwrap().check(4, 3).is_ok());
        let outside = Region::parse("1,1,5,3").unwrap().check(4, 3).unwrap_err();
        assert_eq!(outside, "the region 1,1,5,3 reaches outside the 4x3 image");
        assert!(Region::full(0, 3).check(0, 3).is_err());
        assert!(Region::parse("0,0,4,4").unwrap().check(4, 3).is_err());
    }

    #[test]
    fn pixel_count_and_display() {
        let r = Region::parse("2,1,5,3").unwrap();
        assert_eq!(r.pixel_count(), 6);
        assert_eq!(r.to_string(), "2,1,5,3");
        assert_eq!(Region::full(16384, 16384).pixel_count(), 1 << 28);
    }

    #[test]
    fn scaled_keeps_proportions_and_at_least_one_pixel() {
        let r = Region::parse("10,20,30,40").unwrap();
        assert_eq!(r.scaled((100, 100), (100, 100)), r);
        assert_eq!(
            r.scaled((100, 100), (50, 200)),
            Region::parse("5,40,15,80").unwrap()
        );
        assert_eq!(
            Region::full(640, 480).scaled((640, 480), (7, 3)),
            Region::full(7, 3)
        );
        // A sliver still covers a pixel, inside the image.
        let sliver = Region::parse("99,0,100,1")
            .unwrap()
            .scaled((100, 100), (10, 10));
        assert_eq!(sliver, Region::parse("9,0,10,1").unwrap());
        let tiny = Region::parse("0,0,1,1")
            .unwrap()
            .scaled((1000, 1000), (10, 10));
        assert_eq!(tiny, Region::parse("0,0,1,1").unwrap());
        assert!(sliver.check(10, 10).is_ok() && tiny.check(10, 10).is_ok());
        // Halves round up: 15 · 10 / 100 = 1.5 -> 2.
        assert_eq!(
            Region::parse("15,15,25,25")
                .unwrap()
                .scaled((100, 100), (10, 10)),
            Region::parse("2,2,3,3").unwrap()
        );
    }
}
