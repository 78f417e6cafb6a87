//! Live view of a render in tev, Thomas Müller's HDR image viewer, through its TCP IPC
//! protocol (see [`packet`] for the wire format).

pub mod client;
pub mod packet;

pub use client::{DEFAULT_ADDRESS, TILE_SIZE, TevClient, TevLiveView};
pub use packet::{Layout, Packet, Tile};

/// What can go wrong talking to tev.
#[derive(Debug, thiserror::Error)]
pub enum TevError {
    /// Connecting or writing failed (no tev listening, tev closed, a write timed out).
    #[error("tev connection: {0}")]
    Io(#[from] std::io::Error),
    /// A name contained NUL, which ends strings in tev's protocol.
    #[error("tev names cannot contain NUL: {0:?}")]
    InvalidString(String),
    /// An image needs at least one channel.
    #[error("tev images need at least one channel")]
    NoChannels,
    /// Tile data did not match its size and channel count.
    #[error("tile data has {got} values, its size needs {expected}")]
    DataSize { expected: usize, got: usize },
    /// A size or packet too large for the protocol's 32-bit fields.
    #[error("{0} does not fit tev's 32-bit fields")]
    TooLarge(usize),
    /// Bytes that are not a packet tev would accept (only from decoding).
    #[error("malformed tev packet: {0}")]
    Malformed(&'static str),
}
