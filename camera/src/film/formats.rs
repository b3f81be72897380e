//! The image file formats [`Film::read`](super::Film::read) reads, told
//! apart by their content (the magic bytes every format but TGA starts with),
//! not by the file's name; and what their headers say of how they store
//! pixels, in words.

use std::path::Path;

/// An image file format, as the file's content shows it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FileFormat {
    Png,
    Jpeg,
    Bmp,
    /// Truevision TGA: no magic bytes, so known by its `.tga` name (or a TGA
    /// 2.0 footer).
    Tga,
    /// Netpbm: PBM, PGM, PPM and PAM, binary or ASCII.
    Pnm,
    /// Radiance RGBE (`.hdr`, `.pic`).
    RadianceHdr,
    OpenExr,
    /// Portable Float Map.
    Pfm,
}

impl FileFormat {
    pub fn name(self) -> &'static str {
        match self {
            FileFormat::Png => "PNG",
            FileFormat::Jpeg => "JPEG",
            FileFormat::Bmp => "BMP",
            FileFormat::Tga => "TGA",
            FileFormat::Pnm => "Netpbm",
            FileFormat::RadianceHdr => "Radiance HDR",
            FileFormat::OpenExr => "OpenEXR",
            FileFormat::Pfm => "PFM",
        }
    }

    /// The `image` crate's decoder for it (PFM has none).
    pub(super) fn image_crate(self) -> Option<image::ImageFormat> {
        use image::ImageFormat as I;
        Some(match self {
            FileFormat::Png => I::Png,
            FileFormat::Jpeg => I::Jpeg,
            FileFormat::Bmp => I::Bmp,
            FileFormat::Tga => I::Tga,
            FileFormat::Pnm => I::Pnm,
            FileFormat::RadianceHdr => I::Hdr,
            FileFormat::OpenExr => I::OpenExr,
            FileFormat::Pfm => return None,
        })
    }

    /// The format a file name's extension suggests.
    pub fn from_extension(path: &Path) -> Option<FileFormat> {
        Some(match super::lowercase_extension(path)?.as_str() {
            "png" => FileFormat::Png,
            "jpg" | "jpeg" | "jpe" | "jfif" => FileFormat::Jpeg,
            "bmp" | "dib" => FileFormat::Bmp,
            "tga" | "icb" | "vda" | "vst" => FileFormat::Tga,
            "ppm" | "pgm" | "pbm" | "pnm" | "pam" => FileFormat::Pnm,
            "hdr" | "pic" | "rgbe" => FileFormat::RadianceHdr,
            "exr" => FileFormat::OpenExr,
            "pfm" => FileFormat::Pfm,
            _ => return None,
        })
    }

    /// The format `head` (the file's first bytes) starts like, and `tail` (its
    /// last bytes, for TGA 2.0's footer) ends like.
    pub fn sniff(head: &[u8], tail: &[u8]) -> Result<FileFormat, String> {
        let starts = |magic: &[u8]| head.starts_with(magic);
        let whitespace_at = |i: usize| head.get(i).is_some_and(u8::is_ascii_whitespace);
        if starts(b"\x89PNG\r\n\x1a\n") {
            Ok(FileFormat::Png)
        } else if starts(&[0xff, 0xd8, 0xff]) {
            Ok(FileFormat::Jpeg)
        } else if starts(b"BM") {
            Ok(FileFormat::Bmp)
        } else if starts(b"#?RADIANCE") || starts(b"#?RGBE") {
            Ok(FileFormat::RadianceHdr)
        } else if starts(&[0x76, 0x2f, 0x31, 0x01]) {
            Ok(FileFormat::OpenExr)
        } else if (starts(b"PF") || starts(b"Pf")) && whitespace_at(2) {
            Ok(FileFormat::Pfm)
        } else if head.first() == Some(&b'P')
            && head.get(1).is_some_and(|d| (b'1'..=b'7').contains(d))
            && whitespace_at(2)
        {
            Ok(FileFormat::Pnm)
        } else if tail.ends_with(b"TRUEVISION-XFILE.\0") {
            Ok(FileFormat::Tga)
        } else {
            Err(unknown_content(head))
        }
    }
}

/// Why `head` is not an image Glint reads: the format it is, where known.
fn unknown_content(head: &[u8]) -> String {
    if head.is_empty() {
        return "the file is empty".into();
    }
    let other = [
        (&b"GIF8"[..], "a GIF image"),
        (b"II*\0", "a TIFF image"),
        (b"MM\0*", "a TIFF image"),
        (b"qoif", "a QOI image"),
        (b"\0\0\0\x0cjP", "a JPEG 2000 image"),
    ]
    .into_iter()
    .find(|(magic, _)| head.starts_with(magic))
    .map(|(_, what)| what.to_string())
    .or_else(|| {
        (head.starts_with(b"RIFF") && head.get(8..12) == Some(b"WEBP"))
            .then(|| "a WebP image".into())
    });
    let what = other.unwrap_or_else(|| {
        let shown: String = head
            .iter()
            .take(8)
            .map(|&b| match b {
                b' '..=b'~' => (b as char).to_string(),
                _ => format!("\\x{b:02x}"),
            })
            .collect();
        format!("not an image Glint knows (it starts with \"{shown}\")")
    });
    format!("{what}; Glint reads PNG, JPEG, BMP, TGA, PPM/PGM, Radiance HDR, OpenEXR and PFM")
}

/// What `format`'s header (the file's first bytes, `head`) says of how it
/// stores pixels beyond what decoding shows: the format's variant, the bits a
/// pixel takes, compression, a colour map.
pub(super) fn header_layout(format: FileFormat, head: &[u8]) -> Layout {
    let byte = |i: usize| head.get(i).copied().unwrap_or(0);
    let u16_le = |i: usize| u16::from_le_bytes([byte(i), byte(i + 1)]);
    let mut layout = Layout {
        label: format.name().to_string(),
        ..Layout::default()
    };
    match format {
        // IHDR: bit depth at 24, colour type at 25 (3 = indexed).
        FileFormat::Png => {
            layout.bits = Some(byte(24) as u32);
            layout.indexed = byte(25) == 3;
        }
        // BITMAPINFOHEADER: bits per pixel at 28; 8 or fewer use a colour table.
        FileFormat::Bmp => {
            layout.bits = Some(u16_le(28) as u32);
            layout.indexed = u16_le(28) <= 8;
        }
        // Image type at 2 (1 indexed, 2 true colour, 3 gray; +8 RLE), pixel
        // depth at 16.
        FileFormat::Tga => {
            layout.bits = Some(byte(16) as u32);
            layout.indexed = byte(2) & 7 == 1;
            if byte(2) >= 8 {
                layout.extras.push("RLE".into());
            }
        }
        FileFormat::Pnm => {
            let kind = match byte(1) {
                b'1' | b'4' => "PBM",
                b'2' | b'5' => "PGM",
                b'3' | b'6' => "PPM",
                _ => "PAM",
            };
            layout.label = format!("{kind} (P{})", byte(1) as char);
        }
        _ => {}
    }
    layout
}

/// A header's account of a file's layout, for its description.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(super) struct Layout {
    /// The format's name, with its variant where it has several ("PPM (P3)").
    pub label: String,
    /// Bits a pixel takes in the file, where the header says.
    pub bits: Option<u32>,
    /// Pixels are indices into a colour map (a palette).
    pub indexed: bool,
    /// Compression and the like ("RLE").
    pub extras: Vec<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_are_told_by_their_first_bytes() {
        let sniff = |head: &[u8]| FileFormat::sniff(head, b"");
        assert_eq!(sniff(b"\x89PNG\r\n\x1a\n...."), Ok(FileFormat::Png));
        assert_eq!(sniff(&[0xff, 0xd8, 0xff, 0xe0]), Ok(FileFormat::Jpeg));
        assert_eq!(sniff(b"BM6\x00"), Ok(FileFormat::Bmp));
        assert_eq!(sniff(b"#?RADIANCE\n"), Ok(FileFormat::RadianceHdr));
        assert_eq!(sniff(b"#?RGBE\n"), Ok(FileFormat::RadianceHdr));
        assert_eq!(sniff(&[0x76, 0x2f, 0x31, 0x01, 2]), Ok(FileFormat::OpenExr));
        assert_eq!(sniff(b"PF\n2 2\n-1\n"), Ok(FileFormat::Pfm));
        assert_eq!(sniff(b"Pf 2 2 -1\n"), Ok(FileFormat::Pfm));
        assert_eq!(sniff(b"P6\n2 2\n255\n"), Ok(FileFormat::Pnm));
        assert_eq!(sniff(b"P2 2 2 255 "), Ok(FileFormat::Pnm));
        assert_eq!(
            FileFormat::sniff(b"\0\0\x02", b"....TRUEVISION-XFILE.\0"),
            Ok(FileFormat::Tga)
        );
        assert!(sniff(b"GIF89a").unwrap_err().starts_with("a GIF image; "));
        assert!(sniff(b"RIFF\0\0\0\0WEBPVP8 ")
            .unwrap_err()
            .starts_with("a WebP image"));
        let e = sniff(b"\x00\x01hello").unwrap_err();
        assert!(e.contains("starts with \"\\x00\\x01hello\""), "{e}");
    }

    #[test]
    fn extensions_name_formats_case_insensitively() {
        assert_eq!(
            FileFormat::from_extension(Path::new("a.TGA")),
            Some(FileFormat::Tga)
        );
        assert_eq!(
            FileFormat::from_extension(Path::new("a.pic")),
            Some(FileFormat::RadianceHdr)
        );
        assert_eq!(FileFormat::from_extension(Path::new("a.txt")), None);
    }
}
