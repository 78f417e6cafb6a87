//! Distributed renders: work units, partial files and their exact merge.
//!
//! A render is split into units — a pixel rectangle and, of each of its pixels, a range
//! of sample indices ([`WorkUnit`]). Every sample is a pure function of (pixel, sample
//! index, seed), and photon maps are traced whole by every unit, so a unit computes
//! exactly what the full render computes there. What makes the merge *bit-identical*
//! is the film's fixed grouping of sums ([`SAMPLE_BLOCK`]): a unit whose samples start
//! at 0 stores its pixels as the full render holds them after its last sample; a unit
//! that starts later stores the sums of each block it covers, and the merge adds them
//! to the pixel in block order with [`fold`] — the very additions one machine makes.
//!
//! A partial file (`RADPART`) is a text header (scene and settings hashes, seed, spp,
//! resolution, the sensor — imaging ratio, sample clamp, white balance —, the unit, the
//! part label) and a binary payload of layers, each a sample
//! range and, per pixel of the unit, the weighted sums (3 × f64), the weight (f64) and
//! the sample count (u32, dropped non-finite samples included), with the layer's
//! non-finite sample count and first such pixel; an FNV-1a checksum closes it. It is
//! written atomically, so a unit that is run again replaces its file whole.

use std::fmt::Write as _;
use std::io::{self, Write};
use std::path::Path;

use radiant_image::atomic::atomic_write;
use radiant_image::{Film, FilmPixel, NonFinite, Sensor};
use radiant_render::integrator::fold;
use radiant_render::{PixelBounds, RenderOutput, SAMPLE_BLOCK, WorkUnit};
use thiserror::Error;

use crate::checkpoint::{RunKey, fnv1a};

const MAGIC: &[u8; 8] = b"RADPART\n";
pub const VERSION: u32 = 1;

#[derive(Debug, Error)]
pub enum PartialError {
    #[error("{0}")]
    Io(#[from] io::Error),
    #[error("not a radiant partial file (no RADPART signature)")]
    NotAPartial,
    #[error("partial format version {0}; this radiant reads version {VERSION}")]
    Version(u32),
    #[error("corrupt partial file: {0}")]
    Corrupt(String),
    #[error("{0}")]
    Unit(String),
    #[error("the parts are of different renders: {0}")]
    Mismatch(String),
    #[error("the parts do not cover the image exactly once: {0}")]
    Coverage(String),
}

/// How `--part K/N` divides a render.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Split {
    /// N bands of whole rows, band K rows `[K·H/N, (K+1)·H/N)` (every integrator).
    Tiles,
    /// All pixels, the sample blocks divided into N runs, run K blocks
    /// `[K·B/N, (K+1)·B/N)` of the B = ⌈spp / 64⌉ (per-pixel integrators only).
    Samples,
}

/// The `k`-th (from 0) of `n` units of a `resolution` render of `spp` samples.
pub fn part_unit(
    resolution: (u32, u32),
    spp: u32,
    k: u32,
    n: u32,
    split: Split,
) -> Result<WorkUnit, PartialError> {
    if n == 0 || k >= n {
        return Err(PartialError::Unit(format!(
            "part {k}/{n}: K must be in 0..N"
        )));
    }
    let cut = |total: u32, i: u32| (total as u64 * i as u64 / n as u64) as u32;
    let mut unit = WorkUnit::full(resolution, spp);
    match split {
        Split::Tiles => {
            if n > resolution.1 {
                return Err(PartialError::Unit(format!(
                    "{n} parts by rows, but the image has {} rows",
                    resolution.1
                )));
            }
            unit.pixels.y0 = cut(resolution.1, k);
            unit.pixels.y1 = cut(resolution.1, k + 1);
        }
        Split::Samples => {
            let blocks = spp.div_ceil(SAMPLE_BLOCK);
            if n > blocks {
                return Err(PartialError::Unit(format!(
                    "{n} parts by samples, but {spp} spp make {blocks} block(s) of {SAMPLE_BLOCK}"
                )));
            }
            unit.samples = (
                (cut(blocks, k) * SAMPLE_BLOCK).min(spp),
                (cut(blocks, k + 1) * SAMPLE_BLOCK).min(spp),
            );
        }
    }
    Ok(unit)
}

/// Refuses a unit outside the image, empty, or with a sample range off the blocks.
pub fn check_unit(unit: &WorkUnit, resolution: (u32, u32), spp: u32) -> Result<(), PartialError> {
    let p = unit.pixels;
    if p.is_empty() || p.x1 > resolution.0 || p.y1 > resolution.1 {
        return Err(PartialError::Unit(format!(
            "pixel bounds {p} must be a non-empty rectangle inside the {}x{} image",
            resolution.0, resolution.1
        )));
    }
    let (a, b) = unit.samples;
    if a >= b || b > spp {
        return Err(PartialError::Unit(format!(
            "sample range {a}..{b} must be non-empty and within 0..{spp}"
        )));
    }
    let on_block = |s: u32| s.is_multiple_of(SAMPLE_BLOCK) || s == spp;
    if !on_block(a) || !on_block(b) {
        return Err(PartialError::Unit(format!(
            "sample range {a}..{b}: both ends must be multiples of {SAMPLE_BLOCK} (or {spp}, \
             the spp), the blocks the film sums by"
        )));
    }
    Ok(())
}

/// pbrt-v4's crop window (fractions of the image, x0 x1 y0 y1) as pixel bounds: each
/// edge at the pixel index ⌈resolution × fraction⌉.
pub fn crop_window_bounds(resolution: (u32, u32), crop: [f32; 4]) -> PixelBounds {
    let at = |size: u32, f: f32| ((size as f64 * f.clamp(0.0, 1.0) as f64).ceil() as u32).min(size);
    PixelBounds {
        x0: at(resolution.0, crop[0]),
        x1: at(resolution.0, crop[1]),
        y0: at(resolution.1, crop[2]),
        y1: at(resolution.1, crop[3]),
    }
}

/// One layer of a partial: the film of samples `[samples.0, samples.1)` over the unit's
/// pixels (a fresh accumulation; see the module's notes).
#[derive(Clone, Debug)]
pub struct Layer {
    pub samples: (u32, u32),
    pub film: Film,
}

/// A unit's result, as written to and read from a partial file.
#[derive(Clone, Debug)]
pub struct Partial {
    pub key: RunKey,
    pub sensor: Sensor,
    pub unit: WorkUnit,
    /// `--part K/N`, when the unit was chosen so.
    pub part: Option<(u32, u32)>,
    pub layers: Vec<Layer>,
}

impl Partial {
    /// The partial of a finished render of `unit`.
    pub fn from_output(
        key: RunKey,
        unit: WorkUnit,
        part: Option<(u32, u32)>,
        out: RenderOutput,
    ) -> Partial {
        let sensor = out.film.sensor;
        let (a, b) = unit.samples;
        let layers = if a == 0 {
            vec![Layer {
                samples: (0, b),
                film: out.film,
            }]
        } else {
            let mut s = a;
            out.blocks
                .into_iter()
                .map(|film| {
                    let e = (s + SAMPLE_BLOCK).min(b);
                    let layer = Layer {
                        samples: (s, e),
                        film,
                    };
                    s = e;
                    layer
                })
                .collect()
        };
        Partial {
            key,
            sensor,
            unit,
            part,
            layers,
        }
    }

    /// A name for messages: the part label, else the unit.
    pub fn label(&self) -> String {
        match self.part {
            Some((k, n)) => format!("part {k}/{n}"),
            None => format!(
                "pixels {} samples {}..{}",
                self.unit.pixels, self.unit.samples.0, self.unit.samples.1
            ),
        }
    }

    pub fn encode(&self) -> Vec<u8> {
        let key = &self.key;
        let mut header = String::new();
        let _ = writeln!(header, "kind: partial");
        let _ = writeln!(header, "software: radiant {}", env!("CARGO_PKG_VERSION"));
        let _ = writeln!(header, "scene: {:016x}", key.scene);
        let _ = writeln!(header, "integrator: {}", key.integrator);
        let _ = writeln!(header, "settings: {:016x}", key.settings);
        let _ = writeln!(header, "seed: {}", key.seed);
        let _ = writeln!(header, "spp: {}", key.spp);
        let _ = writeln!(
            header,
            "resolution: {}x{}",
            key.resolution.0, key.resolution.1
        );
        let _ = writeln!(
            header,
            "imaging-ratio: {:08x}",
            self.sensor.imaging_ratio.to_bits()
        );
        let _ = writeln!(
            header,
            "max-component: {:08x}",
            self.sensor.max_component.to_bits()
        );
        let balance = match &self.sensor.white_balance {
            None => "none".to_string(),
            Some(m) => m
                .iter()
                .flatten()
                .map(|v| format!("{:08x}", v.to_bits()))
                .collect::<Vec<_>>()
                .join(","),
        };
        let _ = writeln!(header, "white-balance: {balance}");
        let _ = writeln!(header, "pixel-bounds: {}", self.unit.pixels);
        let _ = writeln!(
            header,
            "sample-range: {}..{}",
            self.unit.samples.0, self.unit.samples.1
        );
        match self.part {
            Some((k, n)) => {
                let _ = writeln!(header, "part: {k}/{n}");
            }
            None => {
                let _ = writeln!(header, "part: none");
            }
        }
        let _ = writeln!(header, "layers: {}", self.layers.len());
        let mut out = Vec::new();
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.extend_from_slice(&(header.len() as u32).to_le_bytes());
        out.extend_from_slice(header.as_bytes());
        for layer in &self.layers {
            out.extend_from_slice(&layer.samples.0.to_le_bytes());
            out.extend_from_slice(&layer.samples.1.to_le_bytes());
            let nf = layer.film.nonfinite;
            out.extend_from_slice(&nf.count.to_le_bytes());
            let (fx, fy) = nf.first_pixel.unwrap_or((u32::MAX, u32::MAX));
            out.extend_from_slice(&fx.to_le_bytes());
            out.extend_from_slice(&fy.to_le_bytes());
            for p in &layer.film.pixels {
                for v in p.sum {
                    out.extend_from_slice(&v.to_le_bytes());
                }
                out.extend_from_slice(&p.weight.to_le_bytes());
                out.extend_from_slice(&p.samples.to_le_bytes());
            }
        }
        let sum = fnv1a(&out);
        out.extend_from_slice(&sum.to_le_bytes());
        out
    }

    pub fn decode(bytes: &[u8]) -> Result<Partial, PartialError> {
        if bytes.len() < 8 || &bytes[..8] != MAGIC {
            return Err(PartialError::NotAPartial);
        }
        let corrupt = |m: &str| PartialError::Corrupt(m.to_string());
        if bytes.len() < 24 {
            return Err(corrupt("truncated"));
        }
        let (body, tail) = bytes.split_at(bytes.len() - 8);
        let mut r = Reader { bytes: body, at: 8 };
        let version = r.u32()?;
        if version != VERSION {
            return Err(PartialError::Version(version));
        }
        let header_len = r.u32()? as usize;
        let header =
            std::str::from_utf8(r.take(header_len)?).map_err(|_| corrupt("header is not UTF-8"))?;
        if fnv1a(body).to_le_bytes() != tail {
            return Err(corrupt("the checksum does not match the contents"));
        }
        let field = |name: &str| -> Result<&str, PartialError> {
            header
                .lines()
                .find_map(|l| l.strip_prefix(name)?.strip_prefix(": "))
                .ok_or_else(|| PartialError::Corrupt(format!("no {name} in the header")))
        };
        let bad = |name: &str| PartialError::Corrupt(format!("bad {name} in the header"));
        let hex = |name: &str| u64::from_str_radix(field(name)?, 16).map_err(|_| bad(name));
        let num = |name: &str| field(name)?.parse::<u64>().map_err(|_| bad(name));
        let (w, h) = field("resolution")?
            .split_once('x')
            .and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)))
            .ok_or_else(|| bad("resolution"))?;
        let key = RunKey {
            scene: hex("scene")?,
            integrator: field("integrator")?.to_string(),
            settings: hex("settings")?,
            seed: num("seed")?,
            spp: num("spp")? as u32,
            resolution: (w, h),
            // Units of a distributed render sample uniformly.
            adaptive: false,
        };
        let white_balance = match field("white-balance")? {
            "none" => None,
            list => {
                let values: Vec<f32> = list
                    .split(',')
                    .map(|v| u32::from_str_radix(v, 16).map(f32::from_bits))
                    .collect::<Result<_, _>>()
                    .map_err(|_| bad("white-balance"))?;
                let [a, b, c, d, e, f, g, h, i] = values[..] else {
                    return Err(bad("white-balance"));
                };
                Some([[a, b, c], [d, e, f], [g, h, i]])
            }
        };
        let sensor = Sensor {
            imaging_ratio: f32::from_bits(hex("imaging-ratio")? as u32),
            max_component: f32::from_bits(hex("max-component")? as u32),
            white_balance,
        };
        let pixels = parse_pixel_bounds(field("pixel-bounds")?).map_err(|_| bad("pixel-bounds"))?;
        let samples =
            parse_sample_range(field("sample-range")?).map_err(|_| bad("sample-range"))?;
        let part = match field("part")? {
            "none" => None,
            s => Some(parse_part(s).map_err(|_| bad("part"))?),
        };
        let unit = WorkUnit { pixels, samples };
        check_unit(&unit, key.resolution, key.spp)
            .map_err(|e| PartialError::Corrupt(format!("{e}")))?;
        let n_layers = num("layers")? as usize;
        let (fw, fh) = (pixels.width() as usize, pixels.height() as usize);
        let mut layers = Vec::new();
        for _ in 0..n_layers {
            let s = (r.u32()?, r.u32()?);
            let count = r.u64()?;
            let first = (r.u32()?, r.u32()?);
            let mut film = Film::new(fw, fh, sensor);
            film.nonfinite = NonFinite {
                count,
                first_pixel: (first != (u32::MAX, u32::MAX)).then_some(first),
            };
            if r.bytes.len() - r.at < fw * fh * 36 {
                return Err(corrupt("truncated layer"));
            }
            for p in &mut film.pixels {
                *p = FilmPixel {
                    sum: [r.f64()?, r.f64()?, r.f64()?],
                    weight: r.f64()?,
                    samples: r.u32()?,
                };
            }
            layers.push(Layer { samples: s, film });
        }
        if r.at != body.len() {
            return Err(corrupt("bytes after the last layer"));
        }
        Ok(Partial {
            key,
            sensor,
            unit,
            part,
            layers,
        })
    }

    /// Writes the partial atomically (a rerun unit replaces its file whole).
    pub fn write(&self, path: &Path) -> Result<(), PartialError> {
        let bytes = self.encode();
        atomic_write(path, |w| w.write_all(&bytes))?;
        Ok(())
    }

    pub fn read(path: &Path) -> Result<Partial, PartialError> {
        Partial::decode(&std::fs::read(path)?)
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], PartialError> {
        if self.bytes.len() - self.at < n {
            return Err(PartialError::Corrupt("truncated".into()));
        }
        let s = &self.bytes[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }
    fn u32(&mut self) -> Result<u32, PartialError> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }
    fn u64(&mut self) -> Result<u64, PartialError> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    fn f64(&mut self) -> Result<f64, PartialError> {
        Ok(f64::from_bits(self.u64()?))
    }
}

/// `x0,x1,y0,y1`.
pub fn parse_pixel_bounds(s: &str) -> Result<PixelBounds, String> {
    let v: Vec<u32> = s
        .split(',')
        .map(|t| t.trim().parse::<u32>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("expected x0,x1,y0,y1 (pixel indices), got \"{s}\""))?;
    match v[..] {
        [x0, x1, y0, y1] if x0 < x1 && y0 < y1 => Ok(PixelBounds { x0, x1, y0, y1 }),
        [_, _, _, _] => Err(format!("pixel bounds \"{s}\": need x0 < x1 and y0 < y1")),
        _ => Err(format!("expected x0,x1,y0,y1 (four numbers), got \"{s}\"")),
    }
}

/// `a..b`: samples a to b − 1 of every pixel.
pub fn parse_sample_range(s: &str) -> Result<(u32, u32), String> {
    let (a, b) = s
        .split_once("..")
        .ok_or_else(|| format!("expected a..b, got \"{s}\""))?;
    match (a.trim().parse::<u32>(), b.trim().parse::<u32>()) {
        (Ok(a), Ok(b)) if a < b => Ok((a, b)),
        (Ok(_), Ok(_)) => Err(format!("sample range \"{s}\": need a < b")),
        _ => Err(format!("expected a..b (sample indices), got \"{s}\"")),
    }
}

/// `K/N`, K counted from 0.
pub fn parse_part(s: &str) -> Result<(u32, u32), String> {
    let (k, n) = s
        .split_once('/')
        .ok_or_else(|| format!("expected K/N, got \"{s}\""))?;
    match (k.trim().parse::<u32>(), n.trim().parse::<u32>()) {
        (Ok(k), Ok(n)) if k < n => Ok((k, n)),
        (Ok(_), Ok(_)) => Err(format!("part \"{s}\": need 0 <= K < N")),
        _ => Err(format!("expected K/N (numbers), got \"{s}\"")),
    }
}

/// Merges partials (each with a name for messages, e.g. its file) into the film of the
/// whole render: refuses parts of different renders, and coverage that is not exactly
/// once per pixel and sample.
pub fn merge(parts: &[(String, Partial)]) -> Result<Film, PartialError> {
    let Some((first_name, first)) = parts.first() else {
        return Err(PartialError::Coverage("no parts given".into()));
    };
    for (name, p) in &parts[1..] {
        if let Err(e) = p.key.check(&first.key) {
            let why = match e {
                crate::checkpoint::CheckpointError::Mismatch(d) => d.join("; "),
                other => other.to_string(),
            };
            return Err(PartialError::Mismatch(format!(
                "{name} against {first_name}: {}",
                why.replace("in the checkpoint", "in the first")
                    .replace(" now", " here")
            )));
        }
        if p.sensor != first.sensor {
            return Err(PartialError::Mismatch(format!(
                "{name} against {first_name}: the sensor differs"
            )));
        }
    }
    for (i, (a_name, a)) in parts.iter().enumerate() {
        for (b_name, b) in &parts[i + 1..] {
            if a.unit == b.unit {
                return Err(PartialError::Coverage(format!(
                    "duplicate: {a_name} and {b_name} are the same unit ({})",
                    a.label()
                )));
            }
        }
    }
    let (w, h) = first.key.resolution;
    let spp = first.key.spp;
    let mut film = Film::new(w as usize, h as usize, first.sensor);
    // Per pixel: samples covered so far, and the part that covered the last of them.
    let mut covered = vec![0u32; w as usize * h as usize];
    let mut owner = vec![usize::MAX; covered.len()];
    let mut layers: Vec<(usize, &Layer)> = parts
        .iter()
        .enumerate()
        .flat_map(|(i, (_, p))| p.layers.iter().map(move |l| (i, l)))
        .collect();
    layers.sort_by_key(|(i, l)| (l.samples.0, *i));
    for &(i, layer) in &layers {
        let (name, part) = &parts[i];
        let (s, e) = layer.samples;
        let block_ok =
            s == 0 || (s.is_multiple_of(SAMPLE_BLOCK) && e == (s + SAMPLE_BLOCK).min(spp));
        if !block_ok || e > spp || s >= e {
            return Err(PartialError::Corrupt(format!(
                "{name}: a layer of samples {s}..{e} is not a sample block"
            )));
        }
        let b = part.unit.pixels;
        for y in b.y0..b.y1 {
            for x in b.x0..b.x1 {
                let at = (y * w + x) as usize;
                if covered[at] != s {
                    let other = parts.get(owner[at]).map_or("no part", |(n, _)| n.as_str());
                    return Err(PartialError::Coverage(if covered[at] > s {
                        format!(
                            "overlap: {name} ({}) and {other} both hold samples {s}..{} of pixel {x},{y}",
                            part.label(),
                            covered[at].min(e)
                        )
                    } else {
                        format!(
                            "gap: samples {}..{s} of pixel {x},{y} are in no part (before {name}, {})",
                            covered[at],
                            part.label()
                        )
                    }));
                }
                let src = &layer.film.pixels[((y - b.y0) * b.width() + (x - b.x0)) as usize];
                let dst = &mut film.pixels[at];
                if s == 0 {
                    *dst = *src;
                } else {
                    fold(dst, src);
                }
                covered[at] = e;
                owner[at] = i;
            }
        }
        film.nonfinite.merge(layer.film.nonfinite);
    }
    // What is missing, as a rectangle and by part label where the parts have them.
    let missing: Vec<usize> = (0..covered.len()).filter(|&i| covered[i] != spp).collect();
    if !missing.is_empty() {
        let (mut x0, mut x1, mut y0, mut y1) = (u32::MAX, 0, u32::MAX, 0);
        for &i in &missing {
            let (x, y) = (i as u32 % w, i as u32 / w);
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x + 1), y0.min(y), y1.max(y + 1));
        }
        let mut text = format!(
            "gap: {} pixel(s) in bounds {x0},{x1},{y0},{y1} lack samples (e.g. pixel {},{} has {} of {spp})",
            missing.len(),
            missing[0] as u32 % w,
            missing[0] as u32 / w,
            covered[missing[0]]
        );
        if let Some((_, n)) = first.part
            && parts
                .iter()
                .all(|(_, p)| p.part.is_some_and(|(_, m)| m == n))
        {
            let absent: Vec<String> = (0..n)
                .filter(|k| !parts.iter().any(|(_, p)| p.part == Some((*k, n))))
                .map(|k| format!("{k}/{n}"))
                .collect();
            if !absent.is_empty() {
                let _ = write!(text, "; missing part(s) {}", absent.join(", "));
            }
        }
        return Err(PartialError::Coverage(text));
    }
    Ok(film)
}
