//! A TCP client for a running tev, and a live view that gives up quietly when tev goes.

use std::io::{self, Read, Write};
use std::net::{TcpStream, ToSocketAddrs};
use std::time::Duration;

use super::TevError;
use super::packet::{
    Layout, Tile, encode_close_image, encode_create_image, encode_open_image, encode_reload_image,
    encode_update_image,
};

/// Where tev listens unless started with `--hostname`.
pub const DEFAULT_ADDRESS: &str = "127.0.0.1:14158";

/// Tiles sent by [`TevClient::update_rgb`] are at most this many pixels on a side, so
/// each packet stays small (tev's receive buffer starts at 1 MiB).
pub const TILE_SIZE: u32 = 128;

/// How long connecting, or one blocked write, may take before it counts as a failure:
/// a viewer that stops reading must not stall a render for longer.
pub const TIMEOUT: Duration = Duration::from_secs(5);

/// An open connection to tev. Every call returns an error rather than panicking; after
/// an error the connection should be dropped (see [`TevLiveView`]).
#[derive(Debug)]
pub struct TevClient {
    stream: TcpStream,
    /// Packet buffer, reused by every call.
    packet: Vec<u8>,
    /// Tile staging buffer for [`TevClient::update_rgb`].
    tile: Vec<f32>,
}

impl TevClient {
    /// Connects to tev at `addr` (e.g. [`DEFAULT_ADDRESS`]), trying each resolved address.
    pub fn connect(addr: impl ToSocketAddrs) -> Result<TevClient, TevError> {
        let mut last = io::Error::new(io::ErrorKind::NotFound, "address resolved to nothing");
        for a in addr.to_socket_addrs()? {
            match TcpStream::connect_timeout(&a, TIMEOUT) {
                Ok(stream) => {
                    stream.set_write_timeout(Some(TIMEOUT))?;
                    // Small packets (create, close) should not wait for Nagle's algorithm.
                    stream.set_nodelay(true)?;
                    return Ok(TevClient {
                        stream,
                        packet: Vec::new(),
                        tile: Vec::new(),
                    });
                }
                Err(e) => last = e,
            }
        }
        Err(TevError::Io(last))
    }

    fn send_packet(&mut self) -> Result<(), TevError> {
        self.stream.write_all(&self.packet)?;
        Ok(())
    }

    /// A blank image `name` with the given channels (e.g. `["R", "G", "B"]`), replacing
    /// any image of that name, and shown at once.
    pub fn create_image(
        &mut self,
        name: &str,
        width: u32,
        height: u32,
        channels: &[&str],
    ) -> Result<(), TevError> {
        encode_create_image(&mut self.packet, name, width, height, channels, true)?;
        self.send_packet()
    }

    /// New values for one tile of image `name`.
    pub fn update_tile(&mut self, name: &str, tile: &Tile) -> Result<(), TevError> {
        encode_update_image(&mut self.packet, name, tile, false)?;
        self.send_packet()
    }

    /// The whole of an RGB image (`width * height` pixels, row major) as R, G, B
    /// channels, in tiles of at most [`TILE_SIZE`]².
    pub fn update_rgb(
        &mut self,
        name: &str,
        width: u32,
        height: u32,
        pixels: &[[f32; 3]],
    ) -> Result<(), TevError> {
        let expected = width as usize * height as usize;
        if pixels.len() != expected {
            return Err(TevError::DataSize {
                expected: 3 * expected,
                got: 3 * pixels.len(),
            });
        }
        let mut tile = std::mem::take(&mut self.tile);
        let result = (|| {
            for y0 in (0..height).step_by(TILE_SIZE as usize) {
                for x0 in (0..width).step_by(TILE_SIZE as usize) {
                    let (tw, th) = (TILE_SIZE.min(width - x0), TILE_SIZE.min(height - y0));
                    tile.clear();
                    for y in y0..y0 + th {
                        let row = y as usize * width as usize;
                        let span = &pixels[row + x0 as usize..row + (x0 + tw) as usize];
                        tile.extend(span.iter().flatten());
                    }
                    let t = Tile {
                        x: x0,
                        y: y0,
                        width: tw,
                        height: th,
                        channels: &["R", "G", "B"],
                        data: &tile,
                        layout: Layout::Interleaved,
                    };
                    self.update_tile(name, &t)?;
                }
            }
            Ok(())
        })();
        self.tile = tile;
        result
    }

    /// Closes image `name` in tev.
    pub fn close_image(&mut self, name: &str) -> Result<(), TevError> {
        encode_close_image(&mut self.packet, name)?;
        self.send_packet()
    }

    /// Asks tev to open a file from its own disk, with an optional channel selector.
    pub fn open_image(
        &mut self,
        path: &str,
        channel_selector: &str,
        grab_focus: bool,
    ) -> Result<(), TevError> {
        encode_open_image(&mut self.packet, path, channel_selector, grab_focus)?;
        self.send_packet()
    }

    /// Asks tev to reload an image it opened from disk.
    pub fn reload_image(&mut self, name: &str, grab_focus: bool) -> Result<(), TevError> {
        encode_reload_image(&mut self.packet, name, grab_focus)?;
        self.send_packet()
    }

    /// True while the peer has not closed the connection, as far as can be seen without
    /// blocking. tev never sends anything, so any readable byte or EOF means it is gone
    /// or is not tev.
    pub fn peer_open(&mut self) -> bool {
        if self.stream.set_nonblocking(true).is_err() {
            return false;
        }
        let mut byte = [0u8; 1];
        let open = match self.stream.read(&mut byte) {
            Ok(_) => false,
            Err(e) => e.kind() == io::ErrorKind::WouldBlock,
        };
        // Writes must block again (up to TIMEOUT) whatever the answer.
        let restored = self.stream.set_nonblocking(false).is_ok();
        open && restored
    }
}

/// A live view of a render in tev that never interrupts the render: the first failure
/// (no tev running, tev closed, a write timed out) is remembered, the connection is
/// dropped, and every later call does nothing.
#[derive(Debug)]
pub struct TevLiveView {
    client: Option<TevClient>,
    failure: Option<TevError>,
    name: String,
    width: u32,
    height: u32,
}

impl TevLiveView {
    /// Connects to tev at `addr` and creates an RGB image `name` of the given size.
    /// Failing here only makes the view inactive.
    pub fn start(addr: impl ToSocketAddrs, name: &str, width: u32, height: u32) -> TevLiveView {
        let mut view = TevLiveView {
            client: None,
            failure: None,
            name: name.to_string(),
            width,
            height,
        };
        match TevClient::connect(addr) {
            Ok(client) => view.client = Some(client),
            Err(e) => view.failure = Some(e),
        }
        view.attempt(|c, name, w, h| c.create_image(name, w, h, &["R", "G", "B"]));
        view
    }

    /// Runs `f` on the client unless an earlier call failed; a failure ends the view.
    fn attempt(&mut self, f: impl FnOnce(&mut TevClient, &str, u32, u32) -> Result<(), TevError>) {
        if let Some(client) = self.client.as_mut()
            && let Err(e) = f(client, &self.name, self.width, self.height)
        {
            self.client = None;
            self.failure = Some(e);
        }
    }

    /// Sends the current image (`width * height` RGB pixels) to tev.
    pub fn update(&mut self, pixels: &[[f32; 3]]) {
        self.attempt(|c, name, w, h| c.update_rgb(name, w, h, pixels));
    }

    /// Sends one tile of the image.
    pub fn update_tile(&mut self, tile: &Tile) {
        self.attempt(|c, name, _, _| c.update_tile(name, tile));
    }

    /// Closes the image in tev and ends the view.
    pub fn close(&mut self) {
        self.attempt(|c, name, _, _| c.close_image(name));
        self.client = None;
    }

    /// True while updates are still being sent.
    pub fn is_active(&self) -> bool {
        self.client.is_some()
    }

    /// The failure that ended the view, if one did.
    pub fn failure(&self) -> Option<&TevError> {
        self.failure.as_ref()
    }
}
