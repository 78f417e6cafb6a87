//! 8-bit sRGB PNG output for viewing (and input, for documentation images and tests).
//!
//! Display encoding: scale linear radiance by 2^exposure, apply the sRGB opto-electronic
//! transfer function of IEC 61966-2-1:1999 (the exact piecewise curve, linear toe below
//! 0.0031308), clamp to 0..=1 only then, and round to the nearest of 256 levels. No tone
//! curve: values above 1 after exposure clip to white.

use std::io::BufWriter;
use std::path::Path;

use super::{Image, ImageError};
use radiant_math::color::Rgb;

/// sRGB encoding of a linear value (IEC 61966-2-1), unclamped: negative input stays on the
/// linear toe, input above 1 goes above 1.
pub fn srgb_oetf(linear: f32) -> f32 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// Inverse of [`srgb_oetf`]: sRGB-encoded value to linear.
pub fn srgb_eotf(encoded: f32) -> f32 {
    if encoded <= 0.040_45 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

/// One linear channel value (already multiplied by the exposure) as an 8-bit sRGB code.
/// NaN maps to 0, +inf to 255.
pub fn encode_srgb8(linear: f32) -> u8 {
    let v = srgb_oetf(linear);
    if v.is_nan() {
        0
    } else {
        (v.clamp(0.0, 1.0) * 255.0).round() as u8
    }
}

/// The 8-bit sRGB RGB bytes (row 0 first) of `image` scaled by 2^`exposure_stops`.
pub fn to_srgb8(image: &Image, exposure_stops: f32) -> Vec<u8> {
    let scale = exposure_stops.exp2();
    let mut out = Vec::with_capacity(image.pixels.len() * 3);
    for p in &image.pixels {
        for v in p.to_array() {
            out.push(encode_srgb8(v * scale));
        }
    }
    out
}

/// Writes `image` as an 8-bit sRGB PNG after scaling by 2^`exposure_stops`. The file
/// carries an sRGB chunk so viewers do not apply a second transfer function.
pub fn write_png(
    path: impl AsRef<Path>,
    image: &Image,
    exposure_stops: f32,
) -> Result<(), ImageError> {
    let path = path.as_ref();
    image.validate(path)?;
    let png_error = |e: ::png::EncodingError| match e {
        // The operating system's reason (disk full, permission) as it stands.
        ::png::EncodingError::IoError(e) => ImageError::io(path, e),
        e => ImageError::Png {
            path: path.to_path_buf(),
            message: e.to_string(),
        },
    };
    let (w, h) = match (u32::try_from(image.width), u32::try_from(image.height)) {
        (Ok(w), Ok(h)) => (w, h),
        _ => {
            return Err(ImageError::InvalidImage {
                path: path.to_path_buf(),
                message: format!("{}x{} is too large for PNG", image.width, image.height),
            });
        }
    };
    let bytes = to_srgb8(image, exposure_stops);
    super::write_atomically(path, |file: &mut BufWriter<std::fs::File>| {
        let mut encoder = ::png::Encoder::new(file, w, h);
        encoder.set_color(::png::ColorType::Rgb);
        encoder.set_depth(::png::BitDepth::Eight);
        encoder.set_source_srgb(::png::SrgbRenderingIntent::Perceptual);
        let mut writer = encoder.write_header().map_err(png_error)?;
        writer.write_image_data(&bytes).map_err(png_error)?;
        writer.finish().map_err(png_error)
    })
}

/// Reads a PNG (any colour type, 8 or 16 bit) as linear RGB, assuming sRGB encoding.
/// Grey is replicated into all channels; alpha is ignored.
pub fn read_png(path: impl AsRef<Path>) -> Result<Image, ImageError> {
    let path = path.as_ref();
    let png_error = |e: ::png::DecodingError| ImageError::Png {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let file = std::fs::File::open(path).map_err(|e| ImageError::io(path, e))?;
    let mut decoder = ::png::Decoder::new(std::io::BufReader::new(file));
    // Expand palettes and low bit depths to 8 bit; 16-bit stays 16-bit.
    decoder.set_transformations(::png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(png_error)?;
    // The frame buffer is allocated from the header's size before any pixel is read:
    // check it first (a damaged header must not ask for gigabytes).
    let (w, h) = (reader.info().width as u64, reader.info().height as u64);
    if w.saturating_mul(h).saturating_mul(4) > crate::MAX_READ_SAMPLES {
        return Err(ImageError::TooLarge {
            path: path.to_path_buf(),
            what: "PNG",
            width: w,
            height: h,
            limit: crate::MAX_READ_SAMPLES / 4,
        });
    }
    let size = reader.output_buffer_size().ok_or_else(|| ImageError::Png {
        path: path.to_path_buf(),
        message: "image too large".to_string(),
    })?;
    let mut buf = vec![0u8; size];
    let info = reader.next_frame(&mut buf).map_err(png_error)?;
    let (width, height) = (info.width as usize, info.height as usize);
    let channels = info.color_type.samples();
    let sixteen = info.bit_depth == ::png::BitDepth::Sixteen;
    let bytes_per_sample = if sixteen { 2 } else { 1 };
    let max = if sixteen { 65535.0 } else { 255.0 };
    let sample = |row: &[u8], i: usize| -> f32 {
        let code = if sixteen {
            u16::from_be_bytes([row[2 * i], row[2 * i + 1]]) as f32
        } else {
            row[i] as f32
        };
        srgb_eotf(code / max)
    };

    let mut image = Image::new(width, height);
    for y in 0..height {
        let row =
            &buf[y * info.line_size..y * info.line_size + width * channels * bytes_per_sample];
        for x in 0..width {
            let i = x * channels;
            let c = if channels >= 3 {
                Rgb::new(sample(row, i), sample(row, i + 1), sample(row, i + 2))
            } else {
                Rgb::splat(sample(row, i))
            };
            image.set(x, y, c);
        }
    }
    image.validate(path)?;
    Ok(image)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn oetf_matches_hand_values_and_inverts() {
        // 0.5 → 1.055 * 0.5^(1/2.4) - 0.055 = 0.735357 → 187.52 → 188.
        assert!((srgb_oetf(0.5) - 0.735_357).abs() < 1e-5);
        assert_eq!(encode_srgb8(0.5), 188);
        // 0.18 (mid grey) → 0.461356 → 117.65 → 118.
        assert_eq!(encode_srgb8(0.18), 118);
        // On the toe: 0.001 → 0.01292 → 3.29 → 3.
        assert_eq!(encode_srgb8(0.001), 3);
        // The two branches meet: the curve is continuous at the break point to 1e-6.
        let b = 0.003_130_8f32;
        assert!((12.92 * b - (1.055 * b.powf(1.0 / 2.4) - 0.055)).abs() < 1e-6);
        for i in 0..=1000 {
            let v = i as f32 / 1000.0;
            assert!((srgb_eotf(srgb_oetf(v)) - v).abs() < 2e-6, "{v}");
        }
        assert_eq!(encode_srgb8(f32::NAN), 0);
        assert_eq!(encode_srgb8(f32::INFINITY), 255);
        assert_eq!(encode_srgb8(-1.0), 0);
    }

    #[test]
    fn exposure_applies_before_the_clamp() {
        let mut img = Image::new(3, 1);
        img.set(0, 0, Rgb::splat(4.0));
        img.set(1, 0, Rgb::splat(2.0));
        img.set(2, 0, Rgb::splat(0.25));
        // -2 stops: 4 → 1 (white), 2 → 0.5 (188), 0.25 → 0.0625 (→ 0.2801 → 71.4 → 71).
        let bytes = to_srgb8(&img, -2.0);
        assert_eq!(&bytes[0..3], &[255, 255, 255]);
        assert_eq!(&bytes[3..6], &[188, 188, 188]);
        assert_eq!(bytes[6], 71);
    }

    #[test]
    fn round_trip_within_quantisation() {
        let (w, h) = (16usize, 9usize);
        let mut img = Image::new(w, h);
        for y in 0..h {
            for x in 0..w {
                let t = (y * w + x) as f32 / (w * h) as f32;
                img.set(x, y, Rgb::new(t, t * t, 1.0 - t));
            }
        }
        let dir = std::env::temp_dir().join(format!("radiant-png-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("roundtrip.png");
        write_png(&path, &img, 0.0).unwrap();
        let back = read_png(&path).unwrap();
        std::fs::remove_file(&path).ok();
        assert_eq!((back.width, back.height), (w, h));
        for (a, b) in img.pixels.iter().zip(&back.pixels) {
            for c in 0..3 {
                // Rounding to 8 bits moves the encoded value by at most half a code.
                let err = (srgb_oetf(a[c]) - srgb_oetf(b[c])).abs();
                assert!(err <= 0.5 / 255.0 + 1e-6, "{a:?} vs {b:?}");
            }
        }
        // Row 0 is the top in both directions: the first pixel is t = 0 → (0, 0, 1).
        assert_eq!(back.get(0, 0), Rgb::new(0.0, 0.0, 1.0));
    }
}
