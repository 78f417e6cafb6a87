//! Checkpoints: a render's (or a progressive radiosity solve's) accumulated state on
//! disk, so that a run stopped by a signal or a time limit continues where it stopped
//! and ends with the image an uninterrupted run makes, bit for bit.
//!
//! # Format (version 3)
//!
//! All numbers little-endian; floats are IEEE 754 bit patterns, so nothing is rounded.
//!
//! | bytes | content |
//! |-------|---------|
//! | 8     | magic `RADCKPT\n` |
//! | 4     | format version, u32 (3) |
//! | 4     | header length H, u32 |
//! | H     | header: UTF-8 text, one `key: value` per line |
//! | 8     | payload length P, u64 |
//! | P     | payload, laid out by the header's `kind` |
//! | 8     | checksum: FNV-1a (64 bit) of every byte before it |
//!
//! Header keys (readers ignore keys they do not know, so fields can be added):
//! `kind` (`film`, `adaptive-film`, `sppm` or `radiosity`), `software`, `scene` (16 hex digits: hash of
//! the scene description, source locations left out), `integrator` (name),
//! `settings` (hash of the integrator's parameters), `seed`, `spp`, `resolution`
//! (`WxH`), `adaptive` (`yes` for a render with `--adaptive`, else `no`),
//! `pixel-bounds` (`x0,x1,y0,y1`, half-open; the whole image), `done` (samples per
//! pixel, iterations or shots complete, for people reading the file).
//!
//! Payloads:
//! - `film`: width u32, height u32, non-finite sample count u64, first non-finite pixel
//!   x u32 and y u32 (`u32::MAX` for none); then per pixel in row-major order the
//!   weighted sums r, g, b (f64), the weight sum (f64) and the samples taken (u32) —
//!   36 bytes a pixel. The samples are those of indices `0..samples`. Then a u32, 1
//!   when the film keeps second moments (for a variance channel or an adaptive
//!   render's pilot), followed by each pixel's weighted sums of squares r, g, b (3 f64),
//!   or 0. (Version 2 had no moments.)
//! - `adaptive-film`: a `film` payload, then the rays each pixel's pilot samples traced
//!   (u32 a pixel), then a u32, 1 when the pilot is done and each pixel's target count
//!   follows (u32 a pixel), or 0.
//! - `sppm`: iterations u32, width u32, height u32; then per pixel the direct-light
//!   sums (3 f64), then the global and the caustic estimate, each τ (3 f64), N (f64)
//!   and R² (f64) — 104 bytes a pixel. (Version 1 had one estimate, 64 bytes.)
//! - `radiosity`: shots u64, patches u64, then emitted, absorbed, escaped, unshot power
//!   and unshot magnitude per band (5 × 3 f64); then per patch the radiosity B, the
//!   unshot radiosity ΔB and the irradiance H (3 × 3 f64).
//!
//! Files are written through [`radiant_image::atomic`]: a temporary file beside the
//! target, renamed when complete, so a checkpoint on disk is always a whole one.

use std::fmt::Write as _;
use std::io::{self, Write};
use std::path::Path;

use radiant_image::atomic::atomic_write;
use radiant_image::{Film, FilmPixel, NonFinite};
use radiant_radiosity::ProgressiveState;
use radiant_render::RenderContext;
use radiant_render::integrator::{AdaptivePlan, IntegratorState, PhotonEstimate, SppmPixel};
use radiant_scene::{IntegratorDesc, SceneDesc};
use thiserror::Error;

const MAGIC: &[u8; 8] = b"RADCKPT\n";
pub const VERSION: u32 = 3;
/// Bytes of one SPPM pixel in the payload.
const SPPM_PIXEL_BYTES: usize = 104;

#[derive(Debug, Error)]
pub enum CheckpointError {
    #[error("{0}")]
    Io(#[from] io::Error),
    #[error("not a radiant checkpoint (no RADCKPT signature)")]
    NotACheckpoint,
    #[error("checkpoint format version {0}; this radiant reads version {VERSION}")]
    Version(u32),
    #[error("truncated: {0}")]
    Truncated(String),
    #[error("corrupt: the checksum does not match the contents")]
    Checksum,
    #[error("corrupt header: {0}")]
    Header(String),
    #[error("corrupt contents: {0}")]
    Payload(String),
    #[error("the checkpoint holds {found} state, but this run needs {wanted} state")]
    Kind {
        found: &'static str,
        wanted: &'static str,
    },
    #[error("the checkpoint is of a different run: {}", .0.join("; "))]
    Mismatch(Vec<String>),
}

/// What identifies a run: resuming is refused unless every field matches.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunKey {
    /// Hash of the scene description (camera, film, sampler, filter, materials, shapes,
    /// instances, lights), without source locations: editing comments keeps it.
    pub scene: u64,
    pub integrator: String,
    /// Hash of the integrator's parameters.
    pub settings: u64,
    pub seed: u64,
    pub spp: u32,
    pub resolution: (u32, u32),
    /// Whether samples are spread by the pilot's error (`--adaptive`).
    pub adaptive: bool,
}

impl RunKey {
    /// The key of rendering `desc` with `integrator` (the integrator description in
    /// effect: the scene's, with a name from the command line put in) in `ctx`.
    pub fn new(desc: &SceneDesc, integrator: &IntegratorDesc, ctx: &RenderContext) -> RunKey {
        RunKey {
            scene: scene_hash(desc),
            integrator: integrator.name.clone(),
            settings: settings_hash(integrator),
            seed: ctx.seed,
            spp: ctx.spp,
            resolution: ctx.resolution,
            adaptive: ctx.adaptive,
        }
    }

    /// One message per field that differs from `now`'s.
    fn differences(&self, now: &RunKey) -> Vec<String> {
        let mut out = Vec::new();
        if self.scene != now.scene {
            out.push(format!(
                "the scene differs (description hash {:016x} in the checkpoint, {:016x} now)",
                self.scene, now.scene
            ));
        }
        if self.integrator != now.integrator {
            out.push(format!(
                "integrator \"{}\" in the checkpoint, \"{}\" now",
                self.integrator, now.integrator
            ));
        }
        if self.settings != now.settings {
            out.push(format!(
                "the integrator's parameters differ (hash {:016x} in the checkpoint, {:016x} now)",
                self.settings, now.settings
            ));
        }
        if self.seed != now.seed {
            out.push(format!(
                "seed {} in the checkpoint, {} now",
                self.seed, now.seed
            ));
        }
        if self.spp != now.spp {
            out.push(format!(
                "spp {} in the checkpoint, {} now",
                self.spp, now.spp
            ));
        }
        if self.resolution != now.resolution {
            out.push(format!(
                "resolution {}x{} in the checkpoint, {}x{} now",
                self.resolution.0, self.resolution.1, now.resolution.0, now.resolution.1
            ));
        }
        if self.adaptive != now.adaptive {
            let says = |a: bool| if a { "adaptive" } else { "uniform" };
            out.push(format!(
                "{} sampling in the checkpoint, {} now (--adaptive)",
                says(self.adaptive),
                says(now.adaptive)
            ));
        }
        out
    }

    /// Refuses a checkpoint of another run, naming every field that differs.
    pub fn check(&self, now: &RunKey) -> Result<(), CheckpointError> {
        let d = self.differences(now);
        if d.is_empty() {
            Ok(())
        } else {
            Err(CheckpointError::Mismatch(d))
        }
    }
}

/// Hash of what a scene describes (camera, film, sampler, filter, materials, shapes,
/// instances, lights; not its integrator, not where in the files things are said).
pub fn scene_hash(desc: &SceneDesc) -> u64 {
    let scene = format!(
        "{:?}{:?}{:?}{:?}{:?}{:?}{:?}{:?}{:?}",
        desc.camera,
        desc.film,
        desc.sampler,
        desc.filter,
        desc.materials,
        desc.shapes,
        desc.objects,
        desc.instances,
        desc.lights
    );
    fnv1a(strip_locations(&scene).as_bytes())
}

/// Hash of an integrator's parameters (values only, not their locations).
pub fn settings_hash(integrator: &IntegratorDesc) -> u64 {
    fnv1a(strip_locations(&format!("{:?}", integrator.params)).as_bytes())
}

/// A checkpoint's contents.
#[derive(Clone, Debug)]
pub enum State {
    Render(IntegratorState),
    Radiosity(ProgressiveState),
}

impl State {
    pub fn kind(&self) -> &'static str {
        match self {
            State::Render(IntegratorState::AdaptiveFilm { .. }) => "adaptive-film",
            State::Render(s) => s.kind().name(),
            State::Radiosity(_) => "radiosity",
        }
    }

    fn done(&self) -> u64 {
        match self {
            State::Render(s) => s.done() as u64,
            State::Radiosity(s) => s.shots as u64,
        }
    }
}

/// A checkpoint read back: the run it belongs to and its state.
#[derive(Clone, Debug)]
pub struct Checkpoint {
    pub key: RunKey,
    pub state: State,
}

/// Removes every `FileLoc { … }` (file, line and column of a directive) and `Cell { … }`
/// (whether a parameter was read yet) from a Debug rendering, so that the hash follows
/// what the scene says, not where it says it or what has looked at it.
fn strip_locations(text: &str) -> String {
    const TAGS: [&str; 2] = ["FileLoc {", "Cell {"];
    let bytes = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut copied = 0;
    let mut i = 0;
    while i < bytes.len() {
        let Some(tag) = TAGS.iter().find(|t| bytes[i..].starts_with(t.as_bytes())) else {
            i += 1;
            continue;
        };
        out.push_str(&text[copied..i]);
        // Skip to the brace that closes it, minding braces inside a quoted file name.
        let mut k = i + tag.len();
        let (mut in_string, mut escaped) = (false, false);
        while k < bytes.len() {
            let c = bytes[k];
            k += 1;
            match c {
                _ if escaped => escaped = false,
                b'\\' if in_string => escaped = true,
                b'"' => in_string = !in_string,
                b'}' if !in_string => break,
                _ => {}
            }
        }
        i = k;
        copied = k;
    }
    out.push_str(&text[copied..]);
    out
}

/// FNV-1a, 64 bit (Fowler, Noll & Vo): a checksum against truncation and bit rot, and
/// the hash of the run's description.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// The checkpoint file's bytes.
pub fn encode(key: &RunKey, state: &State) -> Vec<u8> {
    let mut header = String::new();
    let _ = writeln!(header, "kind: {}", state.kind());
    let _ = writeln!(header, "software: radiant {}", env!("CARGO_PKG_VERSION"));
    let _ = writeln!(header, "scene: {:016x}", key.scene);
    let _ = writeln!(header, "integrator: {}", key.integrator);
    let _ = writeln!(header, "settings: {:016x}", key.settings);
    let _ = writeln!(header, "seed: {}", key.seed);
    let _ = writeln!(header, "spp: {}", key.spp);
    let (w, h) = key.resolution;
    let _ = writeln!(header, "resolution: {w}x{h}");
    let _ = writeln!(
        header,
        "adaptive: {}",
        if key.adaptive { "yes" } else { "no" }
    );
    let _ = writeln!(header, "pixel-bounds: 0,{w},0,{h}");
    let _ = writeln!(header, "done: {}", state.done());
    let payload = encode_payload(state);
    let mut out = Vec::with_capacity(32 + header.len() + payload.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&(header.len() as u32).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&payload);
    let sum = fnv1a(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}

fn put_f64s(out: &mut Vec<u8>, values: &[f64]) {
    for v in values {
        out.extend_from_slice(&v.to_le_bytes());
    }
}

fn put_u32s(out: &mut Vec<u8>, values: &[u32]) {
    for v in values {
        out.extend_from_slice(&v.to_le_bytes());
    }
}

fn put_film(out: &mut Vec<u8>, film: &Film) {
    out.reserve(28 + 60 * film.pixels.len());
    out.extend_from_slice(&(film.width as u32).to_le_bytes());
    out.extend_from_slice(&(film.height as u32).to_le_bytes());
    out.extend_from_slice(&film.nonfinite.count.to_le_bytes());
    let (x, y) = film.nonfinite.first_pixel.unwrap_or((u32::MAX, u32::MAX));
    out.extend_from_slice(&x.to_le_bytes());
    out.extend_from_slice(&y.to_le_bytes());
    for p in &film.pixels {
        put_f64s(out, &p.sum);
        put_f64s(out, &[p.weight]);
        out.extend_from_slice(&p.samples.to_le_bytes());
    }
    match &film.moments {
        Some(moments) => {
            out.extend_from_slice(&1u32.to_le_bytes());
            for m in moments {
                put_f64s(out, m);
            }
        }
        None => out.extend_from_slice(&0u32.to_le_bytes()),
    }
}

fn encode_payload(state: &State) -> Vec<u8> {
    let mut out = Vec::new();
    match state {
        State::Render(IntegratorState::Film(film)) => put_film(&mut out, film),
        State::Render(IntegratorState::AdaptiveFilm { film, plan }) => {
            put_film(&mut out, film);
            out.reserve(8 * plan.pilot_rays.len() + 4);
            put_u32s(&mut out, &plan.pilot_rays);
            match &plan.targets {
                Some(targets) => {
                    out.extend_from_slice(&1u32.to_le_bytes());
                    put_u32s(&mut out, targets);
                }
                None => out.extend_from_slice(&0u32.to_le_bytes()),
            }
        }
        State::Render(IntegratorState::Sppm {
            iterations,
            width,
            height,
            pixels,
        }) => {
            out.reserve(12 + SPPM_PIXEL_BYTES * pixels.len());
            for v in [*iterations, *width, *height] {
                out.extend_from_slice(&v.to_le_bytes());
            }
            for p in pixels {
                put_f64s(&mut out, &p.ld);
                for e in [&p.global, &p.caustic] {
                    put_f64s(&mut out, &e.tau);
                    put_f64s(&mut out, &[e.n, e.r2]);
                }
            }
        }
        State::Radiosity(s) => {
            out.reserve(136 + 72 * s.radiosity.len());
            out.extend_from_slice(&(s.shots as u64).to_le_bytes());
            out.extend_from_slice(&(s.radiosity.len() as u64).to_le_bytes());
            for v in [
                s.emitted,
                s.absorbed,
                s.escaped,
                s.unshot_power,
                s.unshot_magnitude,
            ] {
                put_f64s(&mut out, &v);
            }
            for ((b, db), h) in s.radiosity.iter().zip(&s.unshot).zip(&s.irradiance) {
                put_f64s(&mut out, b);
                put_f64s(&mut out, db);
                put_f64s(&mut out, h);
            }
        }
    }
    out
}

/// Writes the checkpoint atomically: the previous one stays whole until the new one is.
pub fn write(path: impl AsRef<Path>, key: &RunKey, state: &State) -> Result<(), CheckpointError> {
    let bytes = encode(key, state);
    atomic_write(path, |w| -> io::Result<()> { w.write_all(&bytes) })?;
    Ok(())
}

/// Reads a checkpoint; a truncated or corrupt file is an error, never a panic.
pub fn read(path: impl AsRef<Path>) -> Result<Checkpoint, CheckpointError> {
    decode(&std::fs::read(path)?)
}

/// A cursor over the file's bytes that reports what was cut off.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], CheckpointError> {
        let left = self.bytes.len() - self.at;
        if n > left {
            return Err(CheckpointError::Truncated(format!(
                "{what} needs {n} bytes at offset {}, the file has {left} more",
                self.at
            )));
        }
        let s = &self.bytes[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }

    fn u32(&mut self, what: &str) -> Result<u32, CheckpointError> {
        Ok(u32::from_le_bytes(self.take(4, what)?.try_into().unwrap()))
    }

    fn u64(&mut self, what: &str) -> Result<u64, CheckpointError> {
        Ok(u64::from_le_bytes(self.take(8, what)?.try_into().unwrap()))
    }

    fn f64(&mut self, what: &str) -> Result<f64, CheckpointError> {
        Ok(f64::from_bits(self.u64(what)?))
    }

    fn f64x3(&mut self, what: &str) -> Result<[f64; 3], CheckpointError> {
        Ok([self.f64(what)?, self.f64(what)?, self.f64(what)?])
    }
}

pub fn decode(bytes: &[u8]) -> Result<Checkpoint, CheckpointError> {
    if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
        return Err(CheckpointError::NotACheckpoint);
    }
    let mut r = Reader {
        bytes,
        at: MAGIC.len(),
    };
    let version = r.u32("the version")?;
    if version != VERSION {
        return Err(CheckpointError::Version(version));
    }
    let header_len = r.u32("the header length")? as usize;
    let header = r.take(header_len, "the header")?;
    let payload_len = r.u64("the payload length")?;
    let payload_len = usize::try_from(payload_len)
        .map_err(|_| CheckpointError::Header(format!("payload of {payload_len} bytes")))?;
    let payload = r.take(payload_len, "the payload")?;
    let body_end = r.at;
    let sum = r.u64("the checksum")?;
    if r.at != bytes.len() {
        return Err(CheckpointError::Payload(format!(
            "{} bytes after the checksum",
            bytes.len() - r.at
        )));
    }
    if fnv1a(&bytes[..body_end]) != sum {
        return Err(CheckpointError::Checksum);
    }
    let header =
        std::str::from_utf8(header).map_err(|_| CheckpointError::Header("not UTF-8".into()))?;
    let field = |name: &str| -> Result<&str, CheckpointError> {
        header
            .lines()
            .find_map(|l| l.strip_prefix(name)?.strip_prefix(": "))
            .ok_or_else(|| CheckpointError::Header(format!("no \"{name}\"")))
    };
    let bad = |name: &str, v: &str| CheckpointError::Header(format!("{name}: \"{v}\""));
    let hex = |name: &str| -> Result<u64, CheckpointError> {
        let v = field(name)?;
        u64::from_str_radix(v, 16).map_err(|_| bad(name, v))
    };
    let num = |name: &str| -> Result<u64, CheckpointError> {
        let v = field(name)?;
        v.parse().map_err(|_| bad(name, v))
    };
    let resolution = {
        let v = field("resolution")?;
        v.split_once('x')
            .and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)))
            .ok_or_else(|| bad("resolution", v))?
    };
    let key = RunKey {
        scene: hex("scene")?,
        integrator: field("integrator")?.to_string(),
        settings: hex("settings")?,
        seed: num("seed")?,
        spp: u32::try_from(num("spp")?).map_err(|_| bad("spp", field("spp").unwrap_or("")))?,
        resolution,
        adaptive: match field("adaptive")? {
            "yes" => true,
            "no" => false,
            v => return Err(bad("adaptive", v)),
        },
    };
    let kind = field("kind")?;
    let mut p = Reader {
        bytes: payload,
        at: 0,
    };
    let state = match kind {
        "film" => State::Render(IntegratorState::Film(decode_film(&mut p, resolution)?)),
        "adaptive-film" => {
            let film = decode_film(&mut p, resolution)?;
            let plan = decode_plan(&mut p, film.pixels.len())?;
            State::Render(IntegratorState::AdaptiveFilm { film, plan })
        }
        "sppm" => State::Render(decode_sppm(&mut p, resolution)?),
        "radiosity" => State::Radiosity(decode_radiosity(&mut p)?),
        other => {
            return Err(CheckpointError::Header(format!("unknown kind \"{other}\"")));
        }
    };
    if p.at != payload.len() {
        return Err(CheckpointError::Payload(format!(
            "{} bytes left over",
            payload.len() - p.at
        )));
    }
    Ok(Checkpoint { key, state })
}

/// Pixel count of a `width × height` payload that says `per_pixel` bytes a pixel, if
/// the payload can hold them.
fn pixel_count(
    p: &Reader<'_>,
    (width, height): (u32, u32),
    header: (u32, u32),
    per_pixel: usize,
) -> Result<usize, CheckpointError> {
    if (width, height) != header {
        return Err(CheckpointError::Payload(format!(
            "a {width}x{height} image in a {}x{} checkpoint",
            header.0, header.1
        )));
    }
    let n = width as usize * height as usize;
    let left = p.bytes.len() - p.at;
    if n.checked_mul(per_pixel).is_none_or(|b| b > left) {
        return Err(CheckpointError::Truncated(format!(
            "{n} pixels of {per_pixel} bytes, {left} bytes left"
        )));
    }
    Ok(n)
}

fn decode_film(p: &mut Reader<'_>, resolution: (u32, u32)) -> Result<Film, CheckpointError> {
    let width = p.u32("the width")?;
    let height = p.u32("the height")?;
    let count = p.u64("the non-finite count")?;
    let x = p.u32("the non-finite pixel")?;
    let y = p.u32("the non-finite pixel")?;
    let n = pixel_count(p, (width, height), resolution, 36)?;
    let mut film = Film::new(width as usize, height as usize, Default::default());
    film.nonfinite = NonFinite {
        count,
        first_pixel: (x != u32::MAX).then_some((x, y)),
    };
    for px in film.pixels.iter_mut().take(n) {
        *px = FilmPixel {
            sum: p.f64x3("a pixel")?,
            weight: p.f64("a pixel")?,
            samples: p.u32("a pixel")?,
        };
    }
    match p.u32("the moments flag")? {
        0 => {}
        1 => {
            let n = pixel_count(p, (width, height), resolution, 24)?;
            let mut moments = vec![[0.0; 3]; n];
            for m in &mut moments {
                *m = p.f64x3("a pixel's moments")?;
            }
            film.moments = Some(moments);
        }
        v => return Err(CheckpointError::Payload(format!("moments flag {v}"))),
    }
    Ok(film)
}

/// `n` u32 values.
fn u32s(p: &mut Reader<'_>, n: usize, what: &str) -> Result<Vec<u32>, CheckpointError> {
    let left = p.bytes.len() - p.at;
    if n.checked_mul(4).is_none_or(|b| b > left) {
        return Err(CheckpointError::Truncated(format!(
            "{n} values of {what}, {left} bytes left"
        )));
    }
    (0..n).map(|_| p.u32(what)).collect()
}

/// An adaptive render's plan for a film of `n` pixels.
fn decode_plan(p: &mut Reader<'_>, n: usize) -> Result<AdaptivePlan, CheckpointError> {
    let pilot_rays = u32s(p, n, "the pilot's rays")?;
    let targets = match p.u32("the targets flag")? {
        0 => None,
        1 => Some(u32s(p, n, "the targets")?),
        v => return Err(CheckpointError::Payload(format!("targets flag {v}"))),
    };
    Ok(AdaptivePlan {
        pilot_rays,
        targets,
    })
}

fn decode_sppm(
    p: &mut Reader<'_>,
    resolution: (u32, u32),
) -> Result<IntegratorState, CheckpointError> {
    let iterations = p.u32("the iteration count")?;
    let width = p.u32("the width")?;
    let height = p.u32("the height")?;
    let n = pixel_count(p, (width, height), resolution, SPPM_PIXEL_BYTES)?;
    let mut pixels = Vec::with_capacity(n);
    let estimate = |p: &mut Reader<'_>| -> Result<PhotonEstimate, CheckpointError> {
        Ok(PhotonEstimate {
            tau: p.f64x3("a pixel")?,
            n: p.f64("a pixel")?,
            r2: p.f64("a pixel")?,
        })
    };
    for _ in 0..n {
        pixels.push(SppmPixel {
            ld: p.f64x3("a pixel")?,
            global: estimate(p)?,
            caustic: estimate(p)?,
        });
    }
    Ok(IntegratorState::Sppm {
        iterations,
        width,
        height,
        pixels,
    })
}

fn decode_radiosity(p: &mut Reader<'_>) -> Result<ProgressiveState, CheckpointError> {
    let shots = p.u64("the shot count")?;
    let patches = p.u64("the patch count")?;
    let emitted = p.f64x3("the power balance")?;
    let absorbed = p.f64x3("the power balance")?;
    let escaped = p.f64x3("the power balance")?;
    let unshot_power = p.f64x3("the power balance")?;
    let unshot_magnitude = p.f64x3("the power balance")?;
    let left = p.bytes.len() - p.at;
    let n = usize::try_from(patches)
        .ok()
        .filter(|n| n.checked_mul(72).is_some_and(|b| b <= left))
        .ok_or_else(|| {
            CheckpointError::Truncated(format!("{patches} patches of 72 bytes, {left} bytes left"))
        })?;
    let (mut radiosity, mut unshot, mut irradiance) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    for _ in 0..n {
        radiosity.push(p.f64x3("a patch")?);
        unshot.push(p.f64x3("a patch")?);
        irradiance.push(p.f64x3("a patch")?);
    }
    Ok(ProgressiveState {
        radiosity,
        unshot,
        irradiance,
        shots: usize::try_from(shots)
            .map_err(|_| CheckpointError::Payload(format!("{shots} shots")))?,
        emitted,
        absorbed,
        escaped,
        unshot_power,
        unshot_magnitude,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key() -> RunKey {
        RunKey {
            scene: 0x1234,
            integrator: "path".into(),
            settings: 0x99,
            seed: 7,
            spp: 16,
            resolution: (3, 2),
            adaptive: false,
        }
    }

    fn film() -> Film {
        let mut film = Film::new(3, 2, Default::default());
        for (i, p) in film.pixels.iter_mut().enumerate() {
            p.sum = [i as f64 * 0.1, -0.0, f64::MIN_POSITIVE];
            p.weight = 1.0 / 3.0 + i as f64;
            p.samples = i as u32;
        }
        film.nonfinite = NonFinite {
            count: 2,
            first_pixel: Some((1, 0)),
        };
        film
    }

    /// [`film`] with second moments.
    fn film_with_moments() -> Film {
        let mut film = film().with_moments();
        for (i, m) in film.moments.iter_mut().flatten().enumerate() {
            *m = [i as f64 * 0.3, 1e-300, f64::MAX];
        }
        film
    }

    fn adaptive_state(targets: Option<Vec<u32>>) -> State {
        State::Render(IntegratorState::AdaptiveFilm {
            film: film_with_moments(),
            plan: AdaptivePlan {
                pilot_rays: vec![7, 0, u32::MAX, 3, 9, 1],
                targets,
            },
        })
    }

    fn moment_bits(f: &Film) -> Option<Vec<[u64; 3]>> {
        f.moments
            .as_ref()
            .map(|m| m.iter().map(|v| v.map(f64::to_bits)).collect())
    }

    #[test]
    fn moments_and_adaptive_plans_round_trip_bit_for_bit() {
        let plain = encode(
            &key(),
            &State::Render(IntegratorState::Film(film_with_moments())),
        );
        let State::Render(IntegratorState::Film(f)) = decode(&plain).unwrap().state else {
            panic!("not a film");
        };
        assert_eq!(moment_bits(&f), moment_bits(&film_with_moments()));
        assert!(moment_bits(&f).is_some());
        let adaptive_key = RunKey {
            adaptive: true,
            ..key()
        };
        for targets in [None, Some(vec![16, 16, 128, 40, 16, 64])] {
            let state = adaptive_state(targets.clone());
            let back = decode(&encode(&adaptive_key, &state)).unwrap();
            assert_eq!(back.key, adaptive_key);
            assert_eq!(back.state.kind(), "adaptive-film");
            let State::Render(IntegratorState::AdaptiveFilm { film, plan }) = back.state else {
                panic!("not an adaptive film");
            };
            assert_eq!(moment_bits(&film), moment_bits(&film_with_moments()));
            assert_eq!(plan.pilot_rays, vec![7, 0, u32::MAX, 3, 9, 1]);
            assert_eq!(plan.targets, targets);
        }
    }

    #[test]
    fn film_round_trips_bit_for_bit() {
        let bytes = encode(&key(), &State::Render(IntegratorState::Film(film())));
        let back = decode(&bytes).unwrap();
        assert_eq!(back.key, key());
        let State::Render(IntegratorState::Film(f)) = back.state else {
            panic!("not a film");
        };
        let bits = |f: &Film| -> Vec<(u64, u64, u64, u64, u32)> {
            f.pixels
                .iter()
                .map(|p| {
                    (
                        p.sum[0].to_bits(),
                        p.sum[1].to_bits(),
                        p.sum[2].to_bits(),
                        p.weight.to_bits(),
                        p.samples,
                    )
                })
                .collect()
        };
        assert_eq!(bits(&f), bits(&film()));
        assert_eq!(f.nonfinite, film().nonfinite);
    }

    #[test]
    fn every_truncation_and_flipped_byte_is_an_error() {
        let states = [
            State::Render(IntegratorState::Film(film())),
            adaptive_state(Some(vec![1, 2, 3, 4, 5, 6])),
        ];
        for state in &states {
            let bytes = encode(&key(), state);
            for n in 0..bytes.len() {
                assert!(decode(&bytes[..n]).is_err(), "truncated to {n} bytes");
            }
            for i in 0..bytes.len() {
                let mut b = bytes.clone();
                b[i] ^= 0x40;
                assert!(decode(&b).is_err(), "byte {i} flipped");
            }
        }
    }

    #[test]
    fn mismatches_are_named() {
        let now = RunKey {
            seed: 8,
            resolution: (4, 2),
            ..key()
        };
        let e = key().check(&now).unwrap_err().to_string();
        assert!(e.contains("seed 7 in the checkpoint, 8 now"), "{e}");
        assert!(e.contains("resolution 3x2"), "{e}");
        assert!(!e.contains("scene"), "{e}");
        let adaptive = RunKey {
            adaptive: true,
            ..key()
        };
        let e = key().check(&adaptive).unwrap_err().to_string();
        assert!(
            e.contains("uniform sampling in the checkpoint, adaptive now"),
            "{e}"
        );
    }

    #[test]
    fn locations_do_not_count() {
        let a = r#"Shape { kind: Sphere, loc: FileLoc { file: "a}.pbrt", line: 3, column: 1 } }"#;
        let b = r#"Shape { kind: Sphere, loc: FileLoc { file: "b.pbrt", line: 9, column: 4 } }"#;
        assert_eq!(strip_locations(a), strip_locations(b));
        assert_eq!(strip_locations(a), "Shape { kind: Sphere, loc:  }");
        let read = "Param { name: \"radius\", used: Cell { value: true } }";
        let unread = "Param { name: \"radius\", used: Cell { value: false } }";
        assert_eq!(strip_locations(read), strip_locations(unread));
    }
}
