//! OpenEXR files through the `exr` crate: linear float32 RGB out, R/G/B (f16, f32 or u32,
//! bare or `<layer>.R`) or Y in.
//!
//! Output is deterministic: the same image and meta always give the same bytes. The
//! encoding writes scan-line blocks in increasing order (the crate sorts blocks compressed
//! in parallel), no date or host attribute is written, and each of the two custom
//! attributes sits alone in its own attribute map — the crate keeps custom attributes in a
//! `HashMap`, whose iteration order (and hence byte order in the header) is randomised per
//! process when it holds more than one entry.

use std::path::Path;

use ::exr::meta::attribute::{AttributeValue, Chromaticities, Text};
use ::exr::prelude as x;
use ::exr::prelude::{ReadChannels, ReadLayers, WritableImage};

use super::{Image, ImageError, ImageMeta, MAX_READ_SAMPLES};

/// EXR attribute holding the samples per pixel of a render (type `int`).
pub const ATTR_SAMPLES_PER_PIXEL: &str = "samplesPerPixel";
/// EXR attribute holding the wall-clock render time in seconds (type `float`).
pub const ATTR_RENDER_TIME: &str = "renderTimeSeconds";

/// Rec. ITU-R BT.709-6 primaries and D65 white point (the same as sRGB, IEC 61966-2-1),
/// as CIE 1931 xy chromaticities.
pub fn rec709_chromaticities() -> Chromaticities {
    Chromaticities {
        red: x::Vec2(0.64, 0.33),
        green: x::Vec2(0.30, 0.60),
        blue: x::Vec2(0.15, 0.06),
        white: x::Vec2(0.3127, 0.3290),
    }
}

/// Writes `image` as a single-part scan-line EXR with float32 channels R, G, B and ZIP
/// compression (16 lines per block), plus the attributes in `meta` and Rec.709
/// chromaticities. An empty `meta.software` becomes `radiant <version>`.
pub fn write_exr(
    path: impl AsRef<Path>,
    image: &Image,
    meta: &ImageMeta,
) -> Result<(), ImageError> {
    let path = path.as_ref();
    image.validate(path)?;

    let (layer_attributes, encoding) = (layer_attributes(meta), ENCODING);
    let width = image.width;
    let pixels = &image.pixels;
    let channels = x::SpecificChannels::rgb(|pos: x::Vec2<usize>| {
        let p = pixels[pos.y() * width + pos.x()];
        (p.r, p.g, p.b)
    });
    let layer = x::Layer::new(
        (image.width, image.height),
        layer_attributes,
        encoding,
        channels,
    );
    let mut exr_image = x::Image::from_layer(layer);
    image_attributes(&mut exr_image.attributes, meta);
    super::write_atomically(path, |file| {
        exr_image
            .write()
            .to_buffered(file)
            .map_err(|error| write_error(path, error))
    })
}

/// Writes `image` as [`write_exr`] does, with `extra` channels beside R, G and B: named
/// as OpenEXR layers (`Albedo.R`, `N.X`) or bare (`Z`), each `width * height` float32
/// values in row order. Channels are stored sorted by name, as the format requires.
pub fn write_exr_channels(
    path: impl AsRef<Path>,
    image: &Image,
    meta: &ImageMeta,
    extra: &[(String, Vec<f32>)],
) -> Result<(), ImageError> {
    let path = path.as_ref();
    if extra.is_empty() {
        return write_exr(path, image, meta);
    }
    image.validate(path)?;
    let n = image.width * image.height;
    let mut names = std::collections::HashSet::new();
    for (name, values) in extra {
        if values.len() != n || matches!(name.as_str(), "R" | "G" | "B") || !names.insert(name) {
            return Err(ImageError::Channels {
                path: path.to_path_buf(),
                message: format!(
                    "channel {name}: {} values for a {}x{} image, or a repeated name",
                    values.len(),
                    image.width,
                    image.height
                ),
            });
        }
    }
    let (layer_attributes, encoding) = (layer_attributes(meta), ENCODING);
    let mut channels: Vec<x::AnyChannel<x::FlatSamples>> = Vec::with_capacity(3 + extra.len());
    for (k, name) in ["R", "G", "B"].into_iter().enumerate() {
        let values = image.pixels.iter().map(|p| p.to_array()[k]).collect();
        channels.push(x::AnyChannel::new(name, x::FlatSamples::F32(values)));
    }
    for (name, values) in extra {
        let text = Text::new_or_none(name.as_str()).ok_or_else(|| ImageError::Channels {
            path: path.to_path_buf(),
            message: format!("channel name {name:?} is not Latin-1 text"),
        })?;
        channels.push(x::AnyChannel::new(
            text,
            x::FlatSamples::F32(values.clone()),
        ));
    }
    let layer = x::Layer::new(
        (image.width, image.height),
        layer_attributes,
        encoding,
        x::AnyChannels::sort(channels.into()),
    );
    let mut exr_image = x::Image::from_layer(layer);
    image_attributes(&mut exr_image.attributes, meta);
    super::write_atomically(path, |file| {
        exr_image
            .write()
            .to_buffered(file)
            .map_err(|error| write_error(path, error))
    })
}

/// Scan lines of 16 rows, ZIP-compressed, top row first.
const ENCODING: x::Encoding = x::Encoding {
    compression: x::Compression::ZIP16,
    blocks: x::Blocks::ScanLines,
    line_order: x::LineOrder::Increasing,
};

/// The layer's software name and sample count.
fn layer_attributes(meta: &ImageMeta) -> x::LayerAttributes {
    let software = if meta.software.is_empty() {
        concat!("radiant ", env!("CARGO_PKG_VERSION")).to_string()
    } else {
        meta.software.clone()
    };
    let mut layer_attributes = x::LayerAttributes::default();
    // EXR text attributes are Latin-1; anything beyond it becomes '?'.
    let latin1: String = software
        .chars()
        .map(|c| if (c as u32) < 256 { c } else { '?' })
        .collect();
    layer_attributes.software_name = Text::new_or_none(latin1);
    if let Some(spp) = meta.samples_per_pixel {
        // EXR has no unsigned int attribute; more than 2^31 samples per pixel would be absurd.
        let spp = i32::try_from(spp).unwrap_or(i32::MAX);
        layer_attributes
            .other
            .insert(Text::from(ATTR_SAMPLES_PER_PIXEL), AttributeValue::I32(spp));
    }
    layer_attributes
}

/// The image's chromaticities (Rec. 709 primaries) and render time.
fn image_attributes(attributes: &mut x::ImageAttributes, meta: &ImageMeta) {
    attributes.chromaticities = Some(rec709_chromaticities());
    if let Some(t) = meta.render_time_seconds {
        attributes
            .other
            .insert(Text::from(ATTR_RENDER_TIME), AttributeValue::F32(t as f32));
    }
}

/// The operating system's reason (disk full, permission) as it stands, else the
/// encoder's.
fn write_error(path: &Path, error: ::exr::error::Error) -> ImageError {
    match error {
        ::exr::error::Error::Io(e) => ImageError::io(path, e),
        error => ImageError::Exr {
            path: path.to_path_buf(),
            error,
        },
    }
}

/// Reads the first layer of an EXR that has R, G and B channels (bare or as `<layer>.R`,
/// preferring the shortest name, as `compare.py` does) or else a Y channel (grey).
/// Samples may be f16, f32 or u32; they are converted to f32.
pub fn read_exr(path: impl AsRef<Path>) -> Result<Image, ImageError> {
    let path = path.as_ref();
    let exr_error = |error| ImageError::Exr {
        path: path.to_path_buf(),
        error,
    };
    // Open the file ourselves so that a missing file reads as an I/O error, not an EXR one.
    let reader = std::fs::File::open(path).map_err(|e| ImageError::io(path, e))?;
    // The reader allocates every layer's samples from the header's sizes before reading
    // them: check those first.
    let meta = x::MetaData::read_from_file(path, false).map_err(exr_error)?;
    let mut samples = 0u64;
    for header in meta.headers.iter() {
        let size = header.layer_size;
        let (w, h) = (size.width() as u64, size.height() as u64);
        let channels = header.channels.list.len() as u64;
        samples = samples.saturating_add(w.saturating_mul(h).saturating_mul(channels));
        if samples > MAX_READ_SAMPLES {
            return Err(ImageError::TooLarge {
                path: path.to_path_buf(),
                what: "EXR data window",
                width: w,
                height: h,
                limit: MAX_READ_SAMPLES / channels.max(1),
            });
        }
    }
    let file = x::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_buffered(std::io::BufReader::new(reader))
        .map_err(exr_error)?;

    let mut found = Vec::new();
    for layer in &file.layer_data {
        let names: Vec<String> = layer
            .channel_data
            .list
            .iter()
            .map(|c| c.name.to_string())
            .collect();
        // Subsampled channels (chroma-style) would need resampling; treat them as absent.
        let usable = |i: usize| layer.channel_data.list[i].sampling == x::Vec2(1, 1);
        let pick = |c: &str| {
            let suffix = format!(".{c}");
            (0..names.len())
                .filter(|&i| usable(i) && (names[i] == c || names[i].ends_with(&suffix)))
                .min_by_key(|&i| names[i].len())
        };
        let rgb = match (pick("R"), pick("G"), pick("B")) {
            (Some(r), Some(g), Some(b)) => Some([r, g, b]),
            _ => (0..names.len())
                .find(|&i| usable(i) && names[i] == "Y")
                .map(|y| [y, y, y]),
        };
        let Some(rgb) = rgb else {
            found.extend(names);
            continue;
        };
        let (width, height) = (layer.size.x(), layer.size.y());
        let mut image = Image::new(width, height);
        for (k, &ci) in rgb.iter().enumerate() {
            let samples = &layer.channel_data.list[ci].sample_data;
            if samples.len() != width * height {
                return Err(ImageError::InvalidImage {
                    path: path.to_path_buf(),
                    message: format!(
                        "channel {} has {} samples for {width}x{height} pixels",
                        names[ci],
                        samples.len()
                    ),
                });
            }
            for (p, v) in image.pixels.iter_mut().zip(samples.values_as_f32()) {
                match k {
                    0 => p.r = v,
                    1 => p.g = v,
                    _ => p.b = v,
                }
            }
        }
        image.validate(path)?;
        return Ok(image);
    }
    Err(ImageError::ExrChannels {
        path: path.to_path_buf(),
        found: if found.is_empty() {
            "none".to_string()
        } else {
            found.join(", ")
        },
    })
}

/// Header attributes radiant writes, as read back from a file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExrAttributes {
    pub samples_per_pixel: Option<i32>,
    pub render_time_seconds: Option<f32>,
    pub software: Option<String>,
    pub chromaticities: Option<[f32; 8]>,
    pub compression: Option<String>,
}

/// Reads only the header of `path` and returns the attributes radiant writes.
pub fn read_exr_attributes(path: impl AsRef<Path>) -> Result<ExrAttributes, ImageError> {
    let path = path.as_ref();
    let meta = x::MetaData::read_from_file(path, false).map_err(|error| ImageError::Exr {
        path: path.to_path_buf(),
        error,
    })?;
    let mut out = ExrAttributes::default();
    let Some(header) = meta.headers.first() else {
        return Ok(out);
    };
    let other = header
        .own_attributes
        .other
        .iter()
        .chain(header.shared_attributes.other.iter());
    for (name, value) in other {
        match (name.to_string().as_str(), value) {
            (ATTR_SAMPLES_PER_PIXEL, AttributeValue::I32(v)) => out.samples_per_pixel = Some(*v),
            (ATTR_RENDER_TIME, AttributeValue::F32(v)) => out.render_time_seconds = Some(*v),
            _ => {}
        }
    }
    out.software = header
        .own_attributes
        .software_name
        .as_ref()
        .map(|t| t.to_string());
    out.chromaticities = header.shared_attributes.chromaticities.map(|c| {
        [
            c.red.x(),
            c.red.y(),
            c.green.x(),
            c.green.y(),
            c.blue.x(),
            c.blue.y(),
            c.white.x(),
            c.white.y(),
        ]
    });
    out.compression = Some(format!("{:?}", header.compression));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::color::Rgb;
    use std::path::PathBuf;

    fn test_pixel(x: usize, y: usize) -> Rgb {
        Rgb::new(x as f32 * 0.25, y as f32 * 1.5e-3, (x * y) as f32 + 1e4)
    }

    fn temp_path(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("radiant-exr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    fn pattern(w: usize, h: usize) -> Image {
        let mut img = Image::new(w, h);
        for y in 0..h {
            for x in 0..w {
                img.set(x, y, test_pixel(x, y));
            }
        }
        // Values f16 could not hold: the file must keep full f32 precision.
        img.set(0, 0, Rgb::new(1.0 + 1e-6, -3.25e-7, 7.0e5));
        img
    }

    #[test]
    fn round_trip_is_exact_and_attributes_are_written() {
        let img = pattern(37, 21);
        let meta = ImageMeta {
            samples_per_pixel: Some(1024),
            render_time_seconds: Some(12.5),
            software: "radiant test".to_string(),
        };
        let path = temp_path("roundtrip.exr");
        write_exr(&path, &img, &meta).unwrap();
        let back = read_exr(&path).unwrap();
        assert_eq!(back, img);

        let attrs = read_exr_attributes(&path).unwrap();
        assert_eq!(attrs.samples_per_pixel, Some(1024));
        assert_eq!(attrs.render_time_seconds, Some(12.5));
        assert_eq!(attrs.software.as_deref(), Some("radiant test"));
        assert_eq!(
            attrs.chromaticities,
            Some([0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290])
        );
        assert_eq!(attrs.compression.as_deref(), Some("ZIP16"));
        std::fs::remove_file(&path).ok();
    }

    #[test]
    fn extra_channels_are_written_beside_rgb_and_read_back_by_name() {
        let img = pattern(9, 5);
        let n = 9 * 5;
        let extra = vec![
            (
                "Z".to_string(),
                (0..n).map(|i| i as f32 * 0.5).collect::<Vec<f32>>(),
            ),
            ("Albedo.R".to_string(), vec![0.25; n]),
            ("N.X".to_string(), vec![-1.0; n]),
        ];
        let path = temp_path("channels.exr");
        let meta = ImageMeta {
            samples_per_pixel: Some(4),
            ..ImageMeta::default()
        };
        write_exr_channels(&path, &img, &meta, &extra).unwrap();
        // The colour is read as before: the shortest R, G, B names.
        assert_eq!(read_exr(&path).unwrap(), img);
        let file = x::read_all_flat_layers_from_file(&path).unwrap();
        let list = &file.layer_data[0].channel_data.list;
        let names: Vec<String> = list.iter().map(|c| c.name.to_string()).collect();
        assert_eq!(names, ["Albedo.R", "B", "G", "N.X", "R", "Z"]);
        let z: Vec<f32> = list[5].sample_data.values_as_f32().collect();
        assert_eq!(z, extra[0].1);
        // Same bytes every time; a wrong length or a repeated name is refused.
        let again = temp_path("channels2.exr");
        write_exr_channels(&again, &img, &meta, &extra).unwrap();
        assert_eq!(
            std::fs::read(&path).unwrap(),
            std::fs::read(&again).unwrap()
        );
        let short = vec![("Z".to_string(), vec![0.0; n - 1])];
        assert!(write_exr_channels(&again, &img, &meta, &short).is_err());
        let twice = vec![
            ("Z".to_string(), vec![0.0; n]),
            ("Z".to_string(), vec![0.0; n]),
        ];
        assert!(write_exr_channels(&again, &img, &meta, &twice).is_err());
        std::fs::remove_file(&path).ok();
        std::fs::remove_file(&again).ok();
    }

    #[test]
    fn writing_is_deterministic_and_has_no_timestamp() {
        let img = pattern(64, 40);
        let meta = ImageMeta {
            samples_per_pixel: Some(16),
            render_time_seconds: Some(0.75),
            software: String::new(),
        };
        // Each write builds fresh attribute HashMaps with fresh random hash keys; were two
        // custom attributes to share a map, 4 writes would all agree with chance 1/8.
        let write = |i: usize| {
            let path = temp_path(&format!("det_{i}.exr"));
            write_exr(&path, &img, &meta).unwrap();
            let bytes = std::fs::read(&path).unwrap();
            std::fs::remove_file(&path).ok();
            bytes
        };
        let bytes_a = write(0);
        for i in 1..4 {
            assert!(write(i) == bytes_a, "write {i} differs from write 0");
        }
        // The header (everything before the first zero-padded pixel block) holds no date
        // attribute and no hostname-ish owner.
        let header = &bytes_a[..bytes_a.len().min(2048)];
        for forbidden in [&b"capDate"[..], b"utcOffset", b"owner"] {
            assert!(
                !header.windows(forbidden.len()).any(|w| w == forbidden),
                "header contains {}",
                String::from_utf8_lossy(forbidden)
            );
        }
        let version = concat!("radiant ", env!("CARGO_PKG_VERSION")).as_bytes();
        assert!(header.windows(version.len()).any(|w| w == version));
    }

    #[test]
    fn layer_prefixed_and_half_channels_are_read() {
        // Write "beauty.R/G/B" as f16 by hand with the exr crate.
        use ::exr::prelude::f16;
        let (w, h) = (5usize, 3usize);
        let value = |x: usize, y: usize, c: usize| (x + 10 * y + 100 * c) as f32 * 0.5;
        let channel = |name: &str, c: usize| {
            let data: Vec<f16> = (0..w * h)
                .map(|i| f16::from_f32(value(i % w, i / w, c)))
                .collect();
            x::AnyChannel::new(name, x::FlatSamples::F16(data))
        };
        let channels = x::AnyChannels::sort(smallvec_of(vec![
            channel("beauty.B", 2),
            channel("beauty.G", 1),
            channel("beauty.R", 0),
        ]));
        let layer = x::Layer::new(
            (w, h),
            x::LayerAttributes::default(),
            x::Encoding::SMALL_FAST_LOSSLESS,
            channels,
        );
        let path = temp_path("layered.exr");
        x::Image::from_layer(layer).write().to_file(&path).unwrap();
        let img = read_exr(&path).unwrap();
        std::fs::remove_file(&path).ok();
        for y in 0..h {
            for xx in 0..w {
                // These values are multiples of 0.5 below 2048: exact in f16.
                let want = Rgb::new(value(xx, y, 0), value(xx, y, 1), value(xx, y, 2));
                assert_eq!(img.get(xx, y), want);
            }
        }
    }

    #[test]
    fn grey_y_channel_is_replicated() {
        let (w, h) = (4usize, 2usize);
        let data: Vec<f32> = (0..w * h).map(|i| i as f32).collect();
        let channels = x::AnyChannels::sort(smallvec_of(vec![x::AnyChannel::new(
            "Y",
            x::FlatSamples::F32(data),
        )]));
        let layer = x::Layer::new(
            (w, h),
            x::LayerAttributes::default(),
            x::Encoding::UNCOMPRESSED,
            channels,
        );
        let path = temp_path("grey.exr");
        x::Image::from_layer(layer).write().to_file(&path).unwrap();
        let img = read_exr(&path).unwrap();
        std::fs::remove_file(&path).ok();
        assert_eq!(img.get(3, 1), Rgb::splat(7.0));
        assert_eq!(img.get(1, 0), Rgb::splat(1.0));
    }

    #[test]
    fn missing_file_and_wrong_channels_name_the_path() {
        let err = read_exr(temp_path("does-not-exist.exr"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("does-not-exist.exr"), "{err}");

        let channels = x::AnyChannels::sort(smallvec_of(vec![x::AnyChannel::new(
            "Z",
            x::FlatSamples::F32(vec![1.0; 4]),
        )]));
        let layer = x::Layer::new(
            (2, 2),
            x::LayerAttributes::default(),
            x::Encoding::UNCOMPRESSED,
            channels,
        );
        let path = temp_path("depth-only.exr");
        x::Image::from_layer(layer).write().to_file(&path).unwrap();
        let err = read_exr(&path).unwrap_err().to_string();
        std::fs::remove_file(&path).ok();
        assert!(err.contains("depth-only.exr") && err.contains("Z"), "{err}");
    }

    fn smallvec_of(
        v: Vec<x::AnyChannel<x::FlatSamples>>,
    ) -> ::exr::prelude::SmallVec<[x::AnyChannel<x::FlatSamples>; 4]> {
        v.into_iter().collect()
    }
}
