//! Failure output: histograms as PFM images (grayscale "Pf", little-endian, rows stored
//! bottom to top, so row 0 — the lowest cos θ, r² or y — is at the bottom) and a text
//! summary.

use crate::chi2::report::{ChiSquareReport, residual};
use std::fmt;
use std::path::{Path, PathBuf};

/// Errors of the failure output.
#[derive(Debug, thiserror::Error)]
pub enum Chi2Error {
    #[error("cannot write {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

/// The files a failing test wrote.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct HistogramFiles {
    pub observed: PathBuf,
    pub expected: PathBuf,
    /// (O - E)/√E per cell; cells that expect nothing hold their raw count.
    pub residual: PathBuf,
    pub summary: PathBuf,
}

impl fmt::Display for HistogramFiles {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "  observed histogram: {}", self.observed.display())?;
        writeln!(f, "  expected histogram: {}", self.expected.display())?;
        writeln!(f, "  residuals:          {}", self.residual.display())?;
        writeln!(f, "  summary:            {}", self.summary.display())
    }
}

/// Base folder for failure output: `$RADIANT_CHI2_DIR`, else `chi2-failures/` in the
/// cargo target directory that holds the running test binary (recognised by the
/// `CACHEDIR.TAG` cargo puts there, which also works for workspace members), else
/// `target/chi2-failures` below the working directory.
pub(crate) fn default_failure_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("RADIANT_CHI2_DIR").filter(|d| !d.is_empty()) {
        return PathBuf::from(dir);
    }
    if let Ok(exe) = std::env::current_exe()
        && let Some(target) = exe
            .ancestors()
            .skip(1)
            .find(|dir| dir.join("CACHEDIR.TAG").is_file())
    {
        return target.join("chi2-failures");
    }
    PathBuf::from("target").join("chi2-failures")
}

fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> Chi2Error + '_ {
    move |source| Chi2Error::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Encodes a grayscale PFM image; `values` are row-major with row 0 at the bottom,
/// which is PFM's own storage order.
pub fn encode_pfm(width: usize, height: usize, values: &[f32]) -> Vec<u8> {
    assert_eq!(values.len(), width * height, "PFM size mismatch");
    let mut bytes = format!("Pf\n{width} {height}\n-1.0\n").into_bytes();
    bytes.reserve(values.len() * 4);
    for v in values {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes
}

fn write_file(path: &Path, bytes: &[u8]) -> Result<(), Chi2Error> {
    std::fs::write(path, bytes).map_err(io_error(path))
}

pub(crate) fn write_all(
    report: &ChiSquareReport,
    dir: &Path,
    summary: &str,
) -> Result<HistogramFiles, Chi2Error> {
    std::fs::create_dir_all(dir).map_err(io_error(dir))?;
    let [width, height] = report.resolution;
    let files = HistogramFiles {
        observed: dir.join("observed.pfm"),
        expected: dir.join("expected.pfm"),
        residual: dir.join("residual.pfm"),
        summary: dir.join("summary.txt"),
    };
    let observed: Vec<f32> = report.observed().iter().map(|&o| o as f32).collect();
    let expected: Vec<f32> = report.expected().iter().map(|&e| e as f32).collect();
    let residuals: Vec<f32> = report
        .observed()
        .iter()
        .zip(report.expected())
        .map(|(&o, &e)| {
            let r = residual(o, e);
            if r.is_finite() { r as f32 } else { o as f32 }
        })
        .collect();
    write_file(&files.observed, &encode_pfm(width, height, &observed))?;
    write_file(&files.expected, &encode_pfm(width, height, &expected))?;
    write_file(&files.residual, &encode_pfm(width, height, &residuals))?;
    write_file(&files.summary, summary.as_bytes())?;
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pfm_header_and_payload() {
        let bytes = encode_pfm(2, 1, &[1.0, -2.5]);
        let header = b"Pf\n2 1\n-1.0\n";
        assert_eq!(&bytes[..header.len()], header);
        let payload = &bytes[header.len()..];
        assert_eq!(payload.len(), 8);
        assert_eq!(f32::from_le_bytes(payload[4..8].try_into().unwrap()), -2.5);
    }
}
