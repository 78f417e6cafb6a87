//! Errors from reading, writing and comparing images. Every variant that concerns a file
//! carries its path so that a message can be shown to the user as it stands. The
//! underlying I/O or decoder error is part of the message (not a `source()`), so that
//! printing the error chain does not repeat it.

use std::path::PathBuf;

/// Anything that can go wrong in the `image` module.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The operating system refused to open, read or write the file.
    #[error("{path}: {error}", path = path.display())]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },

    /// The `exr` crate rejected the file (corrupt, unsupported feature) or could not write it.
    #[error("{path}: OpenEXR: {error}", path = path.display())]
    Exr {
        path: PathBuf,
        error: ::exr::error::Error,
    },

    /// The file is an EXR without the channels we need (R,G,B or Y).
    #[error("{path}: no usable colour channels (need R,G,B or Y; found {found})", path = path.display())]
    ExrChannels { path: PathBuf, found: String },

    /// PNG decoding or encoding failed.
    #[error("{path}: PNG: {message}", path = path.display())]
    Png { path: PathBuf, message: String },

    /// A PFM file is malformed; `line` is the 1-based header line where the problem was seen.
    #[error("{path}:{line}: PFM: {message}", path = path.display())]
    Pfm {
        path: PathBuf,
        line: usize,
        message: String,
    },

    /// The image declares more pixels than radiant reads (a damaged or hostile header
    /// would otherwise make the reader allocate gigabytes before failing).
    #[error("{path}: {width}x{height} pixels ({what}) is more than the {limit} pixels radiant reads", path = path.display())]
    TooLarge {
        path: PathBuf,
        what: &'static str,
        width: u64,
        height: u64,
        limit: u64,
    },

    /// Extra channels that cannot be written (wrong length, repeated or bad name).
    #[error("{path}: {message}", path = path.display())]
    Channels { path: PathBuf, message: String },

    /// The file name does not end in a known image extension.
    #[error("{path}: unknown image format (expected .exr, .pfm or .png)", path = path.display())]
    UnknownFormat { path: PathBuf },

    /// Two images that must have the same size do not.
    #[error("image size mismatch: {test_w}x{test_h} vs reference {ref_w}x{ref_h}")]
    SizeMismatch {
        test_w: usize,
        test_h: usize,
        ref_w: usize,
        ref_h: usize,
    },

    /// A crop rectangle is empty or does not lie inside the image.
    #[error("crop {x0},{y0},{x1},{y1} is empty or outside the {width}x{height} image")]
    BadCrop {
        x0: usize,
        y0: usize,
        x1: usize,
        y1: usize,
        width: usize,
        height: usize,
    },

    /// A noise estimate from independent passes needs at least two.
    #[error("{got} pass(es) given; the spread between passes needs at least 2")]
    TooFewPasses { got: usize },

    /// Tile statistics on different tile grids cannot be compared.
    #[error("tile grids differ: {a} px tiles vs {b} px tiles")]
    TileMismatch { a: usize, b: usize },

    /// An image with zero width or height, or with a pixel buffer of the wrong length.
    #[error("{path}: invalid image: {message}", path = path.display())]
    InvalidImage { path: PathBuf, message: String },
}

impl ImageError {
    pub(crate) fn io(path: &std::path::Path, error: std::io::Error) -> ImageError {
        ImageError::Io {
            path: path.to_path_buf(),
            error,
        }
    }
}
