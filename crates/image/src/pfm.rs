//! Portable Float Map (PFM): a text header and raw f32 samples.
//!
//! Header: `PF` (RGB) or `Pf` (grey), then width and height, then a scale whose sign gives
//! the byte order (negative = little-endian) and whose magnitude we ignore, each followed by
//! whitespace; exactly one whitespace byte ends the header. Rows are stored bottom to top
//! (the format's origin is the lower-left corner); this module flips them so that row 0 of
//! an [`Image`] is the top row.

use std::path::Path;

use super::{Image, ImageError};
use radiant_math::color::Rgb;

/// Writes `image` as a little-endian RGB PFM (`PF`, scale -1.0).
pub fn write_pfm(path: impl AsRef<Path>, image: &Image) -> Result<(), ImageError> {
    let path = path.as_ref();
    image.validate(path)?;
    let bytes = encode_pfm(image);
    super::write_atomically(path, |w| {
        std::io::Write::write_all(w, &bytes).map_err(|e| ImageError::io(path, e))
    })
}

/// The bytes of the little-endian RGB PFM file for `image`.
pub fn encode_pfm(image: &Image) -> Vec<u8> {
    let header = format!("PF\n{} {}\n-1.0\n", image.width, image.height);
    let mut bytes = Vec::with_capacity(header.len() + image.pixels.len() * 12);
    bytes.extend_from_slice(header.as_bytes());
    for row in image.pixels.chunks_exact(image.width.max(1)).rev() {
        for p in row {
            for v in p.to_array() {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    bytes
}

/// Reads a PFM file (`PF` or `Pf`, either byte order). Grey images are replicated into
/// all three channels.
pub fn read_pfm(path: impl AsRef<Path>) -> Result<Image, ImageError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| ImageError::io(path, e))?;
    decode_pfm(&bytes).map_err(|(line, message)| ImageError::Pfm {
        path: path.to_path_buf(),
        line,
        message,
    })
}

/// Decodes PFM bytes; errors are (1-based header line, message).
pub fn decode_pfm(bytes: &[u8]) -> Result<Image, (usize, String)> {
    let mut header = HeaderReader {
        bytes,
        pos: 0,
        line: 1,
    };
    let (_, magic) = header.token()?;
    let channels = match magic {
        b"PF" => 3,
        b"Pf" => 1,
        other => {
            return Err((
                1,
                format!(
                    "not a PFM file (magic `{}`, expected `PF` or `Pf`)",
                    String::from_utf8_lossy(&other[..other.len().min(16)])
                ),
            ));
        }
    };
    let width = header.dimension("width")?;
    let height = header.dimension("height")?;
    let (scale_line, scale_tok) = header.token()?;
    let scale: f64 = std::str::from_utf8(scale_tok)
        .ok()
        .and_then(|s| s.parse().ok())
        .filter(|s: &f64| s.is_finite() && *s != 0.0)
        .ok_or_else(|| {
            (
                scale_line,
                format!(
                    "scale `{}` is not a finite non-zero number",
                    String::from_utf8_lossy(scale_tok)
                ),
            )
        })?;
    // Exactly one whitespace byte separates the header from the samples.
    header.pos += 1;
    let little_endian = scale < 0.0;

    let n_floats = width
        .checked_mul(height)
        .and_then(|n| n.checked_mul(channels))
        .ok_or_else(|| (scale_line, format!("size {width}x{height} overflows")))?;
    let data = bytes.get(header.pos..).unwrap_or(&[]);
    let expected = n_floats.saturating_mul(4);
    if data.len() < expected {
        return Err((
            scale_line,
            format!(
                "truncated: {width}x{height}x{channels} floats need {expected} bytes of data, file has {}",
                data.len()
            ),
        ));
    }

    let sample = |i: usize| {
        let b = [
            data[4 * i],
            data[4 * i + 1],
            data[4 * i + 2],
            data[4 * i + 3],
        ];
        if little_endian {
            f32::from_le_bytes(b)
        } else {
            f32::from_be_bytes(b)
        }
    };
    let mut image = Image::new(width, height);
    for y in 0..height {
        // File row 0 is the bottom of the picture.
        let file_row = height - 1 - y;
        for x in 0..width {
            let i = (file_row * width + x) * channels;
            let c = if channels == 3 {
                Rgb::new(sample(i), sample(i + 1), sample(i + 2))
            } else {
                Rgb::splat(sample(i))
            };
            image.set(x, y, c);
        }
    }
    Ok(image)
}

/// Splits the PFM header into whitespace-separated tokens, tracking the line number and
/// skipping `#` comments (which some writers put between the magic and the size).
struct HeaderReader<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> HeaderReader<'a> {
    /// The next token and the line it is on.
    fn token(&mut self) -> Result<(usize, &'a [u8]), (usize, String)> {
        loop {
            match self.bytes.get(self.pos) {
                None => return Err((self.line, "truncated header".to_string())),
                Some(b'\n') => {
                    self.line += 1;
                    self.pos += 1;
                }
                Some(c) if c.is_ascii_whitespace() => self.pos += 1,
                Some(b'#') => {
                    while self.bytes.get(self.pos).is_some_and(|&c| c != b'\n') {
                        self.pos += 1;
                    }
                }
                Some(_) => break,
            }
        }
        let start = self.pos;
        // A header token is short; a long run without whitespace means binary garbage.
        while self
            .bytes
            .get(self.pos)
            .is_some_and(|c| !c.is_ascii_whitespace())
        {
            self.pos += 1;
            if self.pos - start > 64 {
                return Err((self.line, "malformed header (token too long)".to_string()));
            }
        }
        if self.pos == self.bytes.len() {
            return Err((self.line, "truncated header".to_string()));
        }
        Ok((self.line, &self.bytes[start..self.pos]))
    }

    fn dimension(&mut self, what: &str) -> Result<usize, (usize, String)> {
        let (line, tok) = self.token()?;
        std::str::from_utf8(tok)
            .ok()
            .and_then(|s| s.parse::<usize>().ok())
            .filter(|&n| n > 0)
            .ok_or_else(|| {
                (
                    line,
                    format!(
                        "{what} `{}` is not a positive integer",
                        String::from_utf8_lossy(tok)
                    ),
                )
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_by_one_byte_layout() {
        let mut img = Image::new(2, 1);
        img.set(0, 0, Rgb::new(1.0, 2.0, 3.0));
        img.set(1, 0, Rgb::new(-0.5, 0.25, 1e-3));
        let bytes = encode_pfm(&img);
        let mut expected = b"PF\n2 1\n-1.0\n".to_vec();
        for v in [1.0f32, 2.0, 3.0, -0.5, 0.25, 1e-3] {
            expected.extend_from_slice(&v.to_le_bytes());
        }
        assert_eq!(bytes, expected);
        // 1.0f32 little-endian is 00 00 80 3f: check one by hand so the test does not
        // only compare the encoder with itself.
        assert_eq!(&bytes[12..16], &[0x00, 0x00, 0x80, 0x3f]);
        assert_eq!(decode_pfm(&bytes).unwrap(), img);
    }

    #[test]
    fn rows_are_stored_bottom_to_top() {
        // 1x2 image: top pixel bright. The file's first row must be the bottom (dark) one.
        let mut img = Image::new(1, 2);
        img.set(0, 0, Rgb::splat(5.0));
        let bytes = encode_pfm(&img);
        let data = &bytes[b"PF\n1 2\n-1.0\n".len()..];
        assert_eq!(&data[0..4], &0.0f32.to_le_bytes());
        assert_eq!(&data[12..16], &5.0f32.to_le_bytes());
    }

    #[test]
    fn top_left_stays_top_left() {
        let mut img = Image::new(4, 3);
        img.set(0, 0, Rgb::new(10.0, 20.0, 30.0));
        let dir = std::env::temp_dir().join(format!("radiant-pfm-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("topleft.pfm");
        write_pfm(&path, &img).unwrap();
        let back = read_pfm(&path).unwrap();
        std::fs::remove_file(&path).ok();
        assert_eq!(back.get(0, 0), Rgb::new(10.0, 20.0, 30.0));
        let lit: usize = back.pixels.iter().filter(|p| !p.is_black()).count();
        assert_eq!(lit, 1);
        assert_eq!(back, img);
    }

    #[test]
    fn big_endian_grey_with_comment() {
        let mut bytes = b"Pf\n# made by hand\n2 2\n1.0\n".to_vec();
        // Bottom row first: bottom-left, bottom-right, top-left, top-right.
        for v in [1.0f32, 2.0, 3.0, 4.0] {
            bytes.extend_from_slice(&v.to_be_bytes());
        }
        let img = decode_pfm(&bytes).unwrap();
        assert_eq!(img.get(0, 0), Rgb::splat(3.0));
        assert_eq!(img.get(1, 0), Rgb::splat(4.0));
        assert_eq!(img.get(0, 1), Rgb::splat(1.0));
        assert_eq!(img.get(1, 1), Rgb::splat(2.0));
    }

    #[test]
    fn malformed_files_give_errors_with_lines() {
        let good = encode_pfm(&Image::new(3, 2));
        // Truncated data: one byte short.
        let (line, msg) = decode_pfm(&good[..good.len() - 1]).unwrap_err();
        assert!(msg.contains("truncated") && line == 3, "{line}: {msg}");
        // Truncated header.
        let (_, msg) = decode_pfm(b"PF\n3 ").unwrap_err();
        assert!(msg.contains("truncated header"), "{msg}");
        // Wrong magic.
        let (line, msg) = decode_pfm(b"P6\n3 2\n255\n").unwrap_err();
        assert!(msg.contains("not a PFM") && line == 1, "{msg}");
        // Bad size.
        let (line, msg) = decode_pfm(b"PF\n3 x\n-1.0\n").unwrap_err();
        assert!(msg.contains("height") && line == 2, "{msg}");
        let (line, msg) = decode_pfm(b"PF\n# comment\n\n-3 2\n-1.0\n").unwrap_err();
        assert!(msg.contains("width") && line == 4, "{line}: {msg}");
        let (_, msg) = decode_pfm(b"PF\n0 2\n-1.0\n").unwrap_err();
        assert!(msg.contains("width"), "{msg}");
        // Zero / non-numeric scale.
        let (line, msg) = decode_pfm(b"PF\n1 1\n0.0\n............").unwrap_err();
        assert!(msg.contains("scale") && line == 3, "{msg}");
        // Size so large it overflows usize arithmetic.
        let (_, msg) = decode_pfm(b"PF\n18446744073709551615 3\n-1\n").unwrap_err();
        assert!(msg.contains("overflow"), "{msg}");
        // Empty file.
        assert!(decode_pfm(b"").is_err());
        // The file-level error names the path and line.
        let path = std::env::temp_dir().join(format!("radiant-bad-{}.pfm", std::process::id()));
        std::fs::write(&path, b"PF\n2 2\n-1.0\n\0\0").unwrap();
        let err = read_pfm(&path).unwrap_err().to_string();
        std::fs::remove_file(&path).ok();
        assert!(err.contains("radiant-bad-") && err.contains(":3:"), "{err}");
    }
}
