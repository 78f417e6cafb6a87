//! tev's IPC packets, as tev's own `Ipc.cpp`/`Ipc.h` and its Python client define them:
//!
//! - every packet starts with a `u32` byte count of the *whole* packet (these four bytes
//!   included), then a one-byte packet type;
//! - integers little endian, `bool` one byte (0 or 1), strings UTF-8 terminated by NUL,
//!   lists with no length prefix (their count comes earlier in the packet);
//! - types: OpenImage 0, ReloadImage 1, CloseImage 2, UpdateImage 3, CreateImage 4,
//!   UpdateImage v2 5, UpdateImage v3 6, OpenImage v2 7, VectorGraphics 8.
//!
//! Layouts written here (after length and type):
//! - OpenImage v2: grab_focus, path, channel selector
//! - ReloadImage: grab_focus, name
//! - CloseImage: name
//! - CreateImage: grab_focus, name, i32 width, i32 height, i32 channel count, names
//! - UpdateImage v3: grab_focus, name, i32 channel count, names, i32 x, y, width, height,
//!   i64 offset per channel, i64 stride per channel, f32 data; channel c of pixel p (row
//!   major within the tile) is `data[offset[c] + p * stride[c]]`.

use super::TevError;

/// Packet type bytes.
pub mod kind {
    pub const OPEN_IMAGE: u8 = 0;
    pub const RELOAD_IMAGE: u8 = 1;
    pub const CLOSE_IMAGE: u8 = 2;
    pub const UPDATE_IMAGE: u8 = 3;
    pub const CREATE_IMAGE: u8 = 4;
    pub const UPDATE_IMAGE_V2: u8 = 5;
    pub const UPDATE_IMAGE_V3: u8 = 6;
    pub const OPEN_IMAGE_V2: u8 = 7;
}

/// How a tile's floats are laid out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// Channel-major: all of channel 0, then all of channel 1, …
    Planar,
    /// Pixel-major: all channels of pixel 0, then pixel 1, … (e.g. RGBRGB…).
    Interleaved,
}

/// A rectangle of pixel data for an UpdateImage packet.
#[derive(Clone, Copy, Debug)]
pub struct Tile<'a> {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
    /// Channel names, e.g. `["R", "G", "B"]`.
    pub channels: &'a [&'a str],
    /// `channels.len() * width * height` floats in `layout`.
    pub data: &'a [f32],
    pub layout: Layout,
}

/// A decoded packet (owned), as a tev instance would interpret it.
#[derive(Clone, Debug, PartialEq)]
pub enum Packet {
    OpenImage {
        grab_focus: bool,
        path: String,
        channel_selector: String,
    },
    ReloadImage {
        grab_focus: bool,
        name: String,
    },
    CloseImage {
        name: String,
    },
    CreateImage {
        grab_focus: bool,
        name: String,
        width: i32,
        height: i32,
        channels: Vec<String>,
    },
    UpdateImage {
        grab_focus: bool,
        name: String,
        channels: Vec<String>,
        x: i32,
        y: i32,
        width: i32,
        height: i32,
        /// One row-major array of `width * height` values per channel.
        data: Vec<Vec<f32>>,
    },
}

/// Appends the fields of one packet to a buffer and patches in the length at the end.
struct Writer<'b> {
    out: &'b mut Vec<u8>,
}

impl<'b> Writer<'b> {
    /// Starts a packet of type `kind` in `out` (which is cleared).
    fn start(out: &'b mut Vec<u8>, kind: u8) -> Writer<'b> {
        out.clear();
        out.extend_from_slice(&[0; 4]);
        out.push(kind);
        Writer { out }
    }

    fn bool(&mut self, v: bool) {
        self.out.push(u8::from(v));
    }

    fn i32(&mut self, v: i32) {
        self.out.extend_from_slice(&v.to_le_bytes());
    }

    fn i64(&mut self, v: i64) {
        self.out.extend_from_slice(&v.to_le_bytes());
    }

    fn string(&mut self, s: &str) -> Result<(), TevError> {
        if s.contains('\0') {
            return Err(TevError::InvalidString(s.to_string()));
        }
        self.out.extend_from_slice(s.as_bytes());
        self.out.push(0);
        Ok(())
    }

    fn finish(self) -> Result<(), TevError> {
        let len = u32::try_from(self.out.len()).map_err(|_| TevError::TooLarge(self.out.len()))?;
        self.out[..4].copy_from_slice(&len.to_le_bytes());
        Ok(())
    }
}

fn dimension(v: u32) -> Result<i32, TevError> {
    i32::try_from(v).map_err(|_| TevError::TooLarge(v as usize))
}

fn count(n: usize) -> Result<i32, TevError> {
    i32::try_from(n).map_err(|_| TevError::TooLarge(n))
}

/// OpenImage v2: asks tev to load a file from its own disk.
pub fn encode_open_image(
    out: &mut Vec<u8>,
    path: &str,
    channel_selector: &str,
    grab_focus: bool,
) -> Result<(), TevError> {
    let mut w = Writer::start(out, kind::OPEN_IMAGE_V2);
    w.bool(grab_focus);
    w.string(path)?;
    w.string(channel_selector)?;
    w.finish()
}

/// ReloadImage: re-reads an image tev opened from disk.
pub fn encode_reload_image(
    out: &mut Vec<u8>,
    name: &str,
    grab_focus: bool,
) -> Result<(), TevError> {
    let mut w = Writer::start(out, kind::RELOAD_IMAGE);
    w.bool(grab_focus);
    w.string(name)?;
    w.finish()
}

/// CloseImage.
pub fn encode_close_image(out: &mut Vec<u8>, name: &str) -> Result<(), TevError> {
    let mut w = Writer::start(out, kind::CLOSE_IMAGE);
    w.string(name)?;
    w.finish()
}

/// CreateImage: a blank image of the given size and channels (replacing one of that name).
pub fn encode_create_image(
    out: &mut Vec<u8>,
    name: &str,
    width: u32,
    height: u32,
    channels: &[&str],
    grab_focus: bool,
) -> Result<(), TevError> {
    if channels.is_empty() {
        return Err(TevError::NoChannels);
    }
    let mut w = Writer::start(out, kind::CREATE_IMAGE);
    w.bool(grab_focus);
    w.string(name)?;
    w.i32(dimension(width)?);
    w.i32(dimension(height)?);
    w.i32(count(channels.len())?);
    for c in channels {
        w.string(c)?;
    }
    w.finish()
}

/// UpdateImage v3: new values for a tile of an image created before.
pub fn encode_update_image(
    out: &mut Vec<u8>,
    name: &str,
    tile: &Tile,
    grab_focus: bool,
) -> Result<(), TevError> {
    let n_channels = tile.channels.len();
    if n_channels == 0 {
        return Err(TevError::NoChannels);
    }
    let pixels = tile.width as usize * tile.height as usize;
    let expected = pixels * n_channels;
    if tile.data.len() != expected {
        return Err(TevError::DataSize {
            expected,
            got: tile.data.len(),
        });
    }
    let mut w = Writer::start(out, kind::UPDATE_IMAGE_V3);
    w.bool(grab_focus);
    w.string(name)?;
    w.i32(count(n_channels)?);
    for c in tile.channels {
        w.string(c)?;
    }
    for v in [tile.x, tile.y, tile.width, tile.height] {
        w.i32(dimension(v)?);
    }
    let (offset, stride) = match tile.layout {
        Layout::Planar => (pixels, 1),
        Layout::Interleaved => (1, n_channels),
    };
    for c in 0..n_channels {
        w.i64((c * offset) as i64);
    }
    for _ in 0..n_channels {
        w.i64(stride as i64);
    }
    w.out.reserve(4 * tile.data.len());
    for v in tile.data {
        w.out.extend_from_slice(&v.to_le_bytes());
    }
    w.finish()
}

/// Reads fields of one packet, failing on any read past its end.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], TevError> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or(TevError::Malformed("field runs past the end of the packet"))?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn u8(&mut self) -> Result<u8, TevError> {
        Ok(self.take(1)?[0])
    }

    fn bool(&mut self) -> Result<bool, TevError> {
        Ok(self.u8()? == 1)
    }

    fn i32(&mut self) -> Result<i32, TevError> {
        Ok(i32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }

    fn i64(&mut self) -> Result<i64, TevError> {
        Ok(i64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }

    fn string(&mut self) -> Result<String, TevError> {
        let rest = &self.bytes[self.at..];
        let len = rest
            .iter()
            .position(|&b| b == 0)
            .ok_or(TevError::Malformed("string without NUL terminator"))?;
        let s = String::from_utf8(rest[..len].to_vec())
            .map_err(|_| TevError::Malformed("string is not UTF-8"))?;
        self.at += len + 1;
        Ok(s)
    }

    fn strings(&mut self, n: i32) -> Result<Vec<String>, TevError> {
        (0..n).map(|_| self.string()).collect()
    }
}

impl Packet {
    /// Encodes the packet (tev's newest variant of each type).
    pub fn encode(&self) -> Result<Vec<u8>, TevError> {
        let mut out = Vec::new();
        match self {
            Packet::OpenImage {
                grab_focus,
                path,
                channel_selector,
            } => encode_open_image(&mut out, path, channel_selector, *grab_focus)?,
            Packet::ReloadImage { grab_focus, name } => {
                encode_reload_image(&mut out, name, *grab_focus)?
            }
            Packet::CloseImage { name } => encode_close_image(&mut out, name)?,
            Packet::CreateImage {
                grab_focus,
                name,
                width,
                height,
                channels,
            } => {
                let names: Vec<&str> = channels.iter().map(String::as_str).collect();
                let (w, h) = (non_negative(*width)?, non_negative(*height)?);
                encode_create_image(&mut out, name, w, h, &names, *grab_focus)?
            }
            Packet::UpdateImage {
                grab_focus,
                name,
                channels,
                x,
                y,
                width,
                height,
                data,
            } => {
                let names: Vec<&str> = channels.iter().map(String::as_str).collect();
                let flat: Vec<f32> = data.iter().flatten().copied().collect();
                let tile = Tile {
                    x: non_negative(*x)?,
                    y: non_negative(*y)?,
                    width: non_negative(*width)?,
                    height: non_negative(*height)?,
                    channels: &names,
                    data: &flat,
                    layout: Layout::Planar,
                };
                encode_update_image(&mut out, name, &tile, *grab_focus)?
            }
        }
        Ok(out)
    }

    /// Decodes one whole packet the way tev does; the length field must equal
    /// `bytes.len()`. Reads the types [`Packet`] covers, old variants included.
    pub fn decode(bytes: &[u8]) -> Result<Packet, TevError> {
        let mut r = Reader { bytes, at: 0 };
        let len = u32::from_le_bytes(r.take(4)?.try_into().expect("4 bytes"));
        if len as usize != bytes.len() {
            return Err(TevError::Malformed("length field differs from packet size"));
        }
        let packet = match r.u8()? {
            kind::OPEN_IMAGE_V2 => Packet::OpenImage {
                grab_focus: r.bool()?,
                path: r.string()?,
                channel_selector: r.string()?,
            },
            kind::RELOAD_IMAGE => Packet::ReloadImage {
                grab_focus: r.bool()?,
                name: r.string()?,
            },
            kind::CLOSE_IMAGE => Packet::CloseImage { name: r.string()? },
            kind::CREATE_IMAGE => {
                let grab_focus = r.bool()?;
                let name = r.string()?;
                let (width, height, n) = (r.i32()?, r.i32()?, r.i32()?);
                Packet::CreateImage {
                    grab_focus,
                    name,
                    width,
                    height,
                    channels: r.strings(n)?,
                }
            }
            k @ (kind::UPDATE_IMAGE | kind::UPDATE_IMAGE_V2 | kind::UPDATE_IMAGE_V3) => {
                decode_update(&mut r, k)?
            }
            _ => return Err(TevError::Malformed("unsupported packet type")),
        };
        Ok(packet)
    }
}

fn non_negative(v: i32) -> Result<u32, TevError> {
    u32::try_from(v).map_err(|_| TevError::Malformed("negative size or position"))
}

/// UpdateImage, all three versions: v1 has one channel, v1 and v2 are planar.
fn decode_update(r: &mut Reader, k: u8) -> Result<Packet, TevError> {
    let grab_focus = r.bool()?;
    let name = r.string()?;
    let n = if k == kind::UPDATE_IMAGE { 1 } else { r.i32()? };
    let channels = r.strings(n)?;
    let (x, y, width, height) = (r.i32()?, r.i32()?, r.i32()?, r.i32()?);
    let pixels = non_negative(width)? as usize * non_negative(height)? as usize;
    let (offsets, strides): (Vec<i64>, Vec<i64>) = if k == kind::UPDATE_IMAGE_V3 {
        let offsets = (0..n).map(|_| r.i64()).collect::<Result<_, _>>()?;
        let strides = (0..n).map(|_| r.i64()).collect::<Result<_, _>>()?;
        (offsets, strides)
    } else {
        (
            (0..n as i64).map(|c| c * pixels as i64).collect(),
            vec![1; n as usize],
        )
    };
    let floats: Vec<f32> = r.bytes[r.at..]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().expect("4 bytes")))
        .collect();
    let mut data = Vec::with_capacity(n as usize);
    for (&offset, &stride) in offsets.iter().zip(&strides) {
        let index = |p: usize| -> Option<usize> {
            let i = offset.checked_add((p as i64).checked_mul(stride)?)?;
            usize::try_from(i).ok().filter(|&i| i < floats.len())
        };
        let channel: Option<Vec<f32>> = (0..pixels).map(|p| index(p).map(|i| floats[i])).collect();
        data.push(channel.ok_or(TevError::Malformed("image data shorter than its layout"))?);
    }
    Ok(Packet::UpdateImage {
        grab_focus,
        name,
        channels,
        x,
        y,
        width,
        height,
        data,
    })
}
