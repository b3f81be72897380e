//! A JPEG submission's encoding, read from its file, and Glint's renders
//! passed through the same encoding.
//!
//! JPEG changes a render before the grader sees it: it rounds each 8 × 8
//! block's cosine coefficients to the steps of its quantisation tables, after
//! averaging the chroma of 2 × 2 pixels (4:2:0) or not (4:4:4), in the sRGB
//! domain. The grader's question is whether the submission's expected value
//! is Glint's, and so with JPEG whether it is the expected value of Glint's
//! render *after the same encoding*: the tables and the subsampling are in
//! the file (read by `gufo-jpeg`), and Glint's renders are encoded with them
//! (by `jpeg-encoder`: the same tables, sampling factors, box-averaged chroma,
//! as libjpeg does) and decoded by the same decoder as the submission (the
//! `image` crate's). For files written by libjpeg (Pillow, OpenCV, most
//! programs) this reproduces the submission's codes bit for bit on nearly
//! every pixel, and the rest within a code or two
//! (`docs/grading-formats.md#jpeg-judged-through-its-own-encoding`).

use glam::Vec3;
use glint_camera::{linear_to_srgb8, srgb_to_linear};
use jpeg_encoder::{ChromaSubsamplingMethod, ColorType, QuantizationTableType, SamplingFactor};
use std::path::Path;

/// The lowest quality (on libjpeg's scale) a JPEG may have to be graded:
/// below it the loss drowns the mistakes a grader looks for, and the grade
/// says so instead of passing or failing.
pub const MIN_QUALITY: u32 = 50;

/// How a JPEG file was encoded: what Glint's renders are encoded with.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct JpegEncoding {
    /// The luma and chroma quantisation tables, in natural (row) order.
    pub luma: [u16; 64],
    pub chroma: [u16; 64],
    /// The luma's horizontal and vertical sampling factors against the
    /// chroma's: (2, 2) is 4:2:0, (1, 1) 4:4:4.
    pub sampling: (u8, u8),
    /// 1 (gray) or 3 (YCbCr).
    pub components: u8,
    pub progressive: bool,
    /// Its segments are laid out as libjpeg writes them (one table a DQT
    /// and a DHT segment): libjpeg and what is built on it (Pillow, OpenCV,
    /// ImageMagick, GIMP), whose arithmetic Glint's re-encoding repeats.
    /// Other encoders (stb_image_write's one DQT for both tables) round
    /// otherwise, by up to a code.
    pub libjpeg_layout: bool,
}

impl JpegEncoding {
    /// The encoding of the JPEG file at `path`, or why Glint cannot encode
    /// its renders the same way.
    pub fn from_file(path: &Path) -> Result<JpegEncoding, String> {
        let data = std::fs::read(path).map_err(|e| e.to_string())?;
        let jpeg = gufo_jpeg::Jpeg::new(data).map_err(|e| e.to_string())?;
        let unsupported =
            |what: String| format!("a JPEG Glint cannot encode its renders as: {what}");
        let sof = jpeg
            .sof()
            .map_err(|_| unsupported("not a Huffman-coded baseline or progressive JPEG".into()))?;
        if sof.p != 8 {
            return Err(unsupported(format!("{}-bit samples", sof.p)));
        }
        let model = jpeg.color_model().map_err(|e| unsupported(e.to_string()))?;
        let components = match model {
            gufo_jpeg::ColorModel::Grayscale => 1,
            gufo_jpeg::ColorModel::YCbCr => 3,
            other => return Err(unsupported(format!("{other:?} colour"))),
        };
        let (luma, chroma) = jpeg
            .quantization_tables()
            .map_err(|e| unsupported(e.to_string()))?;
        let table = |t: QuantizationTableType| match t {
            QuantizationTableType::Custom(table) => Ok(*table),
            _ => Err(unsupported("no quantisation table".into())),
        };
        let sampling = match components {
            1 => (1, 1),
            _ => {
                let luma = jpeg
                    .components_specification_parameters(0)
                    .map_err(|e| unsupported(e.to_string()))?;
                SamplingFactor::from_factors(luma.h, luma.v).ok_or_else(|| {
                    unsupported(format!("sampling factors {}×{}", luma.h, luma.v))
                })?;
                (luma.h, luma.v)
            }
        };
        Ok(JpegEncoding {
            luma: table(luma)?,
            chroma: table(chroma)?,
            sampling,
            components,
            progressive: jpeg.is_progressive().unwrap_or(false),
            libjpeg_layout: one_table_a_segment(&jpeg),
        })
    }

    /// libjpeg's baseline encoding at `quality` with the luma sampled
    /// `sampling` times as densely as the chroma ((2, 2): 4:2:0), in colour.
    pub fn libjpeg(quality: u32, sampling: (u8, u8)) -> JpegEncoding {
        let (luma, chroma) = ijg_tables(quality.clamp(1, 100));
        JpegEncoding {
            luma,
            chroma,
            sampling,
            components: 3,
            progressive: false,
            libjpeg_layout: true,
        }
    }

    /// The libjpeg quality whose tables these are (`Exact`), or the nearest
    /// one (`Near`) for tables of other encoders.
    pub fn quality(&self) -> Quality {
        let distance = |q: u32| -> f64 {
            let (luma, chroma) = ijg_tables(q);
            let mut d: f64 = self
                .luma
                .iter()
                .zip(luma)
                .map(|(&a, b)| (a as f64 / b as f64).ln().abs())
                .sum();
            if self.components == 3 {
                d += self
                    .chroma
                    .iter()
                    .zip(chroma)
                    .map(|(&a, b)| (a as f64 / b as f64).ln().abs())
                    .sum::<f64>();
            }
            d
        };
        let (best, d) = (1..=100)
            .map(|q| (q, distance(q)))
            .min_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)))
            .expect("qualities");
        if d == 0.0 {
            Quality::Exact(best)
        } else {
            Quality::Near(best)
        }
    }

    /// What the file's description adds for its encoding: ["quality 75",
    /// "4:2:0"], ["progressive", "tables near quality 90", "4:4:4"] (a gray
    /// file says so itself).
    pub fn details(&self) -> Vec<String> {
        let mut parts = Vec::new();
        if self.progressive {
            parts.push("progressive".to_string());
        }
        parts.push(match self.quality() {
            Quality::Exact(q) => format!("quality {q}"),
            Quality::Near(q) => format!("tables near quality {q}"),
        });
        if self.components == 3 {
            parts.push(
                match self.sampling {
                    (1, 1) => "4:4:4",
                    (2, 1) => "4:2:2",
                    (2, 2) => "4:2:0",
                    (1, 2) => "4:4:0",
                    (4, 1) => "4:1:1",
                    _ => "subsampled",
                }
                .into(),
            );
        }
        parts
    }

    /// Why the encoding is too lossy to grade through, if it is.
    pub fn too_lossy(&self) -> Option<String> {
        let q = self.quality().value();
        (q < MIN_QUALITY).then(|| {
            format!(
                "a JPEG of quality {q} (on libjpeg's scale) loses more than the test can see through; grading needs quality {MIN_QUALITY} or more, or a lossless format (PNG)"
            )
        })
    }

    /// A short stable name for the cache: the tables and sampling, hashed.
    pub fn key(&self) -> String {
        let mut hasher = blake3::Hasher::new();
        for v in self.luma.iter().chain(&self.chroma) {
            hasher.update(&v.to_le_bytes());
        }
        hasher.update(&[self.sampling.0, self.sampling.1, self.components]);
        hasher.finalize().to_hex()[..16].to_string()
    }

    /// The side of the pixel blocks whose means the encoding keeps (up to
    /// the DC coefficient's rounding): 8, or 16 where chroma is halved.
    pub fn block(&self) -> u32 {
        8 * self.sampling.0.max(self.sampling.1) as u32
    }

    /// What the rounding of each block's DC coefficient may do to a file of
    /// this encoding of a render whose noiseless 8-bit image is `rgb` (row by
    /// row, `width × height`) and whose pixels have the variance `noise`
    /// (per channel, in 8-bit codes squared): per pixel, in codes of R, G
    /// and B, the band it adds and the variance it adds ([`DcRounding`]).
    ///
    /// A block's DC coefficient is the sum of its 64 samples less 128 each,
    /// divided by `8 Q₀` and rounded (libjpeg's integer DCT; its
    /// fixed-point YCbCr; its chroma averages with alternating rounding), so
    /// its mean moves in steps of `Q₀ / 8` codes. Two encoders whose
    /// arithmetic differs in a sample's last rounding may round a sum that
    /// lies within [`TIE_WINDOW`] of a half step apart: the band spans both
    /// roundings there. A submission's sum differs from this one by its
    /// noise and the reference's, `σ` (of the 64 samples' noise, the
    /// channels taken as fully correlated, the largest it can be); one lying
    /// `δ` from the nearest half step comes within the window with chance
    /// `p = Φ(−(δ − window)/σ)`, which grows with `σ`, so no submission less
    /// noisy than the one `noise` describes has a larger one; its block mean
    /// then varies by `p (1 − p)` steps squared from the rounding (at most a
    /// fair coin's, whatever the encoder does there). Blocks past the
    /// image's edge, padded by the encoder, count as ties.
    pub fn dc_rounding(&self, rgb: &[u8], noise: &[Vec3], width: u32, height: u32) -> DcRounding {
        let (w, h) = (width as usize, height as usize);
        let ycc: Vec<[i32; 3]> = rgb.chunks_exact(3).map(ycbcr).collect();
        let deviation: Vec<[f32; 3]> = noise.iter().map(|v| component_deviations(*v)).collect();
        let mut out = DcRounding {
            band: vec![Vec3::ZERO; w * h],
            variance: vec![Vec3::ZERO; w * h],
        };
        let image = Samples {
            ycc: &ycc,
            deviation: &deviation,
            w,
            h,
        };
        let luma_step = self.luma[0] as f32 / 8.0;
        self.add_component(&image, 0, (1, 1), Vec3::ONE * luma_step, &mut out);
        if self.components == 3 {
            let chroma_step = self.chroma[0] as f32 / 8.0;
            let factors = (self.sampling.0 as usize, self.sampling.1 as usize);
            self.add_component(&image, 1, factors, CB_SHARE * chroma_step, &mut out);
            self.add_component(&image, 2, factors, CR_SHARE * chroma_step, &mut out);
        }
        out
    }

    /// [`JpegEncoding::dc_rounding`] of component `c` (sampled once per
    /// `sx × sy` pixels), whose DC step moves R, G and B by `step` codes.
    fn add_component(
        &self,
        image: &Samples,
        c: usize,
        (sx, sy): (usize, usize),
        step: Vec3,
        out: &mut DcRounding,
    ) {
        let q = if c == 0 { self.luma[0] } else { self.chroma[0] } as i64;
        let (bw, bh) = (8 * sx, 8 * sy);
        let n = (sx * sy) as i32;
        for by in 0..image.h.div_ceil(bh) {
            for bx in 0..image.w.div_ceil(bw) {
                let whole = (bx + 1) * bw <= image.w && (by + 1) * bh <= image.h;
                let (band, chance) = if whole {
                    let (sum, variance) = image.block_sum(c, (bx * bw, by * bh), (sx, sy), n);
                    // How far the sum lies from the nearest half step, and
                    // from where encoders may round it apart.
                    let from_tie = (sum.rem_euclid(8 * q) - 4 * q).abs();
                    let beyond = (from_tie - TIE_WINDOW) as f64;
                    let sigma = variance.sqrt();
                    let apart = match sigma > 0.0 {
                        true => normal_tail(beyond / sigma),
                        false => 0.0,
                    };
                    (beyond <= 0.0, apart.max(FLIP_CHANCE as f64) as f32)
                } else {
                    (true, 0.5)
                };
                let band = if band { step } else { Vec3::ZERO };
                let variance = step * step * chance * (1.0 - chance) * (bw * bh) as f32;
                for y in by * bh..((by + 1) * bh).min(image.h) {
                    for x in bx * bw..((bx + 1) * bw).min(image.w) {
                        out.band[y * image.w + x] += band;
                        out.variance[y * image.w + x] += variance;
                    }
                }
            }
        }
    }

    /// `pixels` (linear, `width × height`, from the top left) as a file of
    /// this encoding would hold them: sRGB-encoded to 8 bits
    /// ([`linear_to_srgb8`]), encoded with these tables and subsampling,
    /// decoded by the `image` crate, linear again.
    pub fn round_trip(
        &self,
        pixels: &[Vec3],
        width: u32,
        height: u32,
    ) -> Result<Vec<Vec3>, String> {
        let rgb: Vec<u8> = pixels
            .iter()
            .flat_map(|p| p.to_array())
            .map(linear_to_srgb8)
            .collect();
        let (data, color) = match self.components {
            1 => (
                rgb.chunks_exact(3).map(luma).collect::<Vec<u8>>(),
                ColorType::Luma,
            ),
            _ => (rgb, ColorType::Rgb),
        };
        let (w, h) = (
            u16::try_from(width).map_err(|_| "wider than 65535 pixels".to_string())?,
            u16::try_from(height).map_err(|_| "taller than 65535 pixels".to_string())?,
        );
        let mut bytes = Vec::new();
        let mut encoder = jpeg_encoder::Encoder::new(&mut bytes, 100);
        encoder.set_quantization_tables(
            QuantizationTableType::Custom(Box::new(self.luma)),
            QuantizationTableType::Custom(Box::new(self.chroma)),
        );
        let sampling = SamplingFactor::from_factors(self.sampling.0, self.sampling.1)
            .expect("checked when read");
        encoder.set_sampling_factor(sampling);
        encoder.set_chroma_subsampling_method(ChromaSubsamplingMethod::Average);
        encoder
            .encode(&data, w, h, color)
            .map_err(|e| format!("encoding Glint's render as the JPEG: {e}"))?;
        let decoded = image::load_from_memory_with_format(&bytes, image::ImageFormat::Jpeg)
            .map_err(|e| format!("decoding Glint's render as the JPEG: {e}"))?
            .into_rgb8();
        let table: Vec<f32> = (0..256).map(|c| srgb_to_linear(c as f32 / 255.0)).collect();
        Ok(decoded
            .pixels()
            .map(|p| Vec3::from_array(p.0.map(|c| table[c as usize])))
            .collect())
    }
}

/// What the rounding of DC coefficients may do to a JPEG's pixels
/// ([`JpegEncoding::dc_rounding`]), in 8-bit codes of R, G and B.
#[derive(Clone, Debug, PartialEq)]
pub struct DcRounding {
    /// How far a pixel's block mean may lie either way from the re-encoded
    /// one, where its DC coefficient lies at a tie.
    pub band: Vec<Vec3>,
    /// The variance the rounding adds to the pixel's block mean, times the
    /// block's pixels: summed over a region of `n` pixels and divided by
    /// `n²`, at least the variance it adds to the region's mean (blocks
    /// round independently).
    pub variance: Vec<Vec3>,
}

/// A noiseless image's YCbCr and each component's noise (standard
/// deviation, codes), per pixel.
struct Samples<'a> {
    ycc: &'a [[i32; 3]],
    deviation: &'a [[f32; 3]],
    w: usize,
    h: usize,
}

impl Samples<'_> {
    /// The sum of a block's 64 samples of component `c` less 128 each (the
    /// block from pixel `(x0, y0)`, each sample the rounded average of `n =
    /// sx × sy` pixels, as libjpeg's h2v2 and h2v1 averages round,
    /// alternately down and up), and the variance of that sum in codes².
    fn block_sum(
        &self,
        c: usize,
        (x0, y0): (usize, usize),
        (sx, sy): (usize, usize),
        n: i32,
    ) -> (i64, f64) {
        let (mut sum, mut variance) = (0i64, 0f64);
        for v in 0..8 {
            for u in 0..8 {
                let (mut s, mut spread) = (0, 0f64);
                for dy in 0..sy {
                    for dx in 0..sx {
                        let i = (y0 + v * sy + dy) * self.w + x0 + u * sx + dx;
                        s += self.ycc[i][c];
                        spread += (self.deviation[i][c] as f64).powi(2);
                    }
                }
                let bias = if u % 2 == 0 { (n - 1) / 2 } else { n / 2 };
                sum += ((s + bias) / n - 128) as i64;
                variance += spread / (n * n) as f64;
            }
        }
        (sum, variance)
    }
}

/// The standard deviation of Y, Cb and Cr from those of R, G and B (the
/// square roots of `variance`), the channels taken as fully correlated: the
/// largest they can be.
fn component_deviations(variance: Vec3) -> [f32; 3] {
    let sd = Vec3::new(variance.x.sqrt(), variance.y.sqrt(), variance.z.sqrt());
    [
        Vec3::new(0.299, 0.587, 0.114).dot(sd),
        Vec3::new(0.168_74, 0.331_26, 0.5).dot(sd),
        Vec3::new(0.5, 0.418_69, 0.081_31).dot(sd),
    ]
}

/// `P(Z > z)` for a standard normal `Z`.
fn normal_tail(z: f64) -> f64 {
    0.5 * statrs::function::erf::erfc(z / std::f64::consts::SQRT_2)
}

/// How close, in sums of a block's 64 samples, a DC coefficient may lie to
/// a half step and still be rounded apart by two encoders: libjpeg and
/// Glint's re-encoding round a sample's YCbCr apart now and then (by one),
/// which moves the sum by one; measured flips lay within 3 of a tie.
pub const TIE_WINDOW: i64 = 3;

/// The least chance taken that a block's DC coefficient is rounded the other
/// way than Glint's re-encoding rounds it, away from ties and noise: below
/// 1% of blocks measured for libjpeg on the same input; 3% leaves room for
/// what the model leaves out (clamping after a coefficient rounded apart).
pub const FLIP_CHANCE: f32 = 0.03;

/// What one code of Cb and of Cr adds to R, G and B (their magnitudes).
const CB_SHARE: Vec3 = Vec3::new(0.0, 0.344, 1.772);
const CR_SHARE: Vec3 = Vec3::new(1.402, 0.714, 0.0);

/// libjpeg's fixed-point YCbCr of an 8-bit RGB pixel (`jccolor.c`, as
/// `jpeg-encoder` repeats it).
fn ycbcr(p: &[u8]) -> [i32; 3] {
    let (r, g, b) = (p[0] as i32, p[1] as i32, p[2] as i32);
    let y = (19595 * r + 38470 * g + 7471 * b + 0x7FFF) >> 16;
    let cb = (-11059 * r - 21709 * g + 32768 * b + (128 << 16) + 0x7FFF) >> 16;
    let cr = (32768 * r - 27439 * g - 5329 * b + (128 << 16) + 0x7FFF) >> 16;
    [y, cb, cr]
}

/// Whether every DQT and DHT segment of `jpeg` holds one table, as libjpeg
/// writes them.
fn one_table_a_segment(jpeg: &gufo_jpeg::Jpeg) -> bool {
    let dqt_ok = jpeg
        .segments_marker(gufo_jpeg::Marker::DQT)
        .all(|s| gufo_jpeg::Dqt::from_data(s.data()).is_ok_and(|tables| tables.len() == 1));
    let dht_ok = jpeg
        .segments_marker(gufo_jpeg::Marker::DHT)
        .all(|s| huffman_tables(s.data()) == Some(1));
    dqt_ok && dht_ok
}

/// How many Huffman tables a DHT segment's data holds (each a class and id
/// byte, 16 counts, and as many values as they sum to).
fn huffman_tables(mut data: &[u8]) -> Option<usize> {
    let mut tables = 0;
    while !data.is_empty() {
        let counts = data.get(1..17)?;
        let values: usize = counts.iter().map(|&c| c as usize).sum();
        data = data.get(17 + values..)?;
        tables += 1;
    }
    Some(tables)
}

/// What [`JpegEncoding::round_trip`] computes, for the reference cache's
/// keys (which name a transform only by its place): change it with anything
/// that changes the round trip's result.
pub const ROUND_TRIP: &str = "jpeg-encoder 0.7, box-averaged chroma, image 0.25's decoder";

/// Rec. 601 luma of 8-bit codes, rounded, as libjpeg turns RGB into gray.
fn luma(p: &[u8]) -> u8 {
    let y = 0.299 * p[0] as f32 + 0.587 * p[1] as f32 + 0.114 * p[2] as f32;
    y.round().clamp(0.0, 255.0) as u8
}

/// A JPEG's quality on libjpeg's scale.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quality {
    /// Its tables are libjpeg's at this quality.
    Exact(u32),
    /// Its tables are others'; these are the nearest libjpeg's.
    Near(u32),
}

impl Quality {
    pub fn value(self) -> u32 {
        match self {
            Quality::Exact(q) | Quality::Near(q) => q,
        }
    }
}

/// The JPEG standard's example tables (ITU-T T.81 Annex K), natural order.
const ANNEX_K_LUMA: [u16; 64] = [
    16, 11, 10, 16, 24, 40, 51, 61, 12, 12, 14, 19, 26, 58, 60, 55, 14, 13, 16, 24, 40, 57, 69, 56,
    14, 17, 22, 29, 51, 87, 80, 62, 18, 22, 37, 56, 68, 109, 103, 77, 24, 35, 55, 64, 81, 104, 113,
    92, 49, 64, 78, 87, 103, 121, 120, 101, 72, 92, 95, 98, 112, 100, 103, 99,
];
const ANNEX_K_CHROMA: [u16; 64] = [
    17, 18, 24, 47, 99, 99, 99, 99, 18, 21, 26, 66, 99, 99, 99, 99, 24, 26, 56, 99, 99, 99, 99, 99,
    47, 66, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99,
    99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99,
];

/// libjpeg's tables at `quality` (`jpeg_quality_scaling`, baseline).
fn ijg_tables(quality: u32) -> ([u16; 64], [u16; 64]) {
    let scale = if quality < 50 {
        5000 / quality
    } else {
        200 - 2 * quality
    };
    let scaled = |t: &[u16; 64]| t.map(|v| ((v as u32 * scale + 50) / 100).clamp(1, 255) as u16);
    (scaled(&ANNEX_K_LUMA), scaled(&ANNEX_K_CHROMA))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn libjpeg_qualities_are_recognised_and_others_placed_near() {
        assert_eq!(
            JpegEncoding::libjpeg(75, (2, 2)).quality(),
            Quality::Exact(75)
        );
        assert_eq!(
            JpegEncoding::libjpeg(100, (1, 1)).quality(),
            Quality::Exact(100)
        );
        let mut custom = JpegEncoding::libjpeg(90, (2, 2));
        custom.luma[5] += 1;
        assert_eq!(custom.quality(), Quality::Near(90));
        assert_eq!(
            JpegEncoding::libjpeg(85, (2, 2)).details(),
            ["quality 85", "4:2:0"]
        );
        assert!(JpegEncoding::libjpeg(49, (2, 2))
            .too_lossy()
            .unwrap()
            .contains("quality 49"));
        assert!(JpegEncoding::libjpeg(50, (2, 2)).too_lossy().is_none());
        assert_ne!(
            JpegEncoding::libjpeg(75, (2, 2)).key(),
            JpegEncoding::libjpeg(75, (1, 1)).key()
        );
        assert_eq!(JpegEncoding::libjpeg(75, (2, 2)).block(), 16);
    }

    #[test]
    fn a_flat_image_survives_the_round_trip() {
        // A flat block has one DC coefficient, a multiple of its step here.
        let grey = Vec3::splat(srgb_to_linear(128.0 / 255.0));
        let out = JpegEncoding::libjpeg(90, (2, 2))
            .round_trip(&vec![grey; 24 * 16], 24, 16)
            .unwrap();
        assert!(out.iter().all(|p| (*p - grey).abs().max_element() < 0.01));
    }
}
