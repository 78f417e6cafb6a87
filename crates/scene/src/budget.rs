//! The memory budget: large allocations (the film, radiosity patches and form-factor
//! matrices, subdivided meshes) are estimated before they are made and refused, with the parameter that
//! asked for them, when the estimate exceeds the budget. Without a budget a request of
//! 400 GB ends the process with "memory allocation failed" and a backtrace instead of a
//! message.
//!
//! The budget is process-wide (the command line sets it once): by default a fraction of
//! the physical memory, where the platform reports it.

use std::sync::atomic::{AtomicU64, Ordering};

/// The fraction of physical memory allowed by default: the rest is for the scene, the
/// BVH, the operating system and other programs.
const DEFAULT_FRACTION: f64 = 0.75;

/// 0: not set, use the default.
static LIMIT: AtomicU64 = AtomicU64::new(0);

/// Sets the budget in bytes (0 restores the default).
pub fn set_limit(bytes: u64) {
    LIMIT.store(bytes, Ordering::Relaxed);
}

/// The budget in bytes: the one set, else [`DEFAULT_FRACTION`] of physical memory,
/// else unlimited.
pub fn limit() -> u64 {
    match LIMIT.load(Ordering::Relaxed) {
        0 => physical_memory().map_or(u64::MAX, |m| (m as f64 * DEFAULT_FRACTION) as u64),
        n => n,
    }
}

/// Total physical memory from `/proc/meminfo` (Linux); `None` elsewhere.
pub fn physical_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Bytes for a message: "4.0 TB", "19 GB", "512 MB" (decimal units, two significant
/// figures — an estimate, not an accounting).
pub fn format_bytes(bytes: f64) -> String {
    let units = ["bytes", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut v = bytes;
    let mut u = 0;
    while v >= 1000.0 && u + 1 < units.len() {
        v /= 1000.0;
        u += 1;
    }
    if u == 0 {
        format!("{v:.0} bytes")
    } else if v < 10.0 {
        format!("{v:.1} {}", units[u])
    } else {
        format!("{v:.0} {}", units[u])
    }
}

/// `Ok` when `bytes` fits the budget; otherwise the end of a message,
/// "≈ 4.0 TB; the memory limit is 19 GB", for the caller to put after what asked.
pub fn check(bytes: f64) -> Result<(), String> {
    let limit = limit();
    if bytes <= limit as f64 {
        Ok(())
    } else {
        Err(format!(
            "≈ {}; the memory limit is {}",
            format_bytes(bytes),
            format_bytes(limit as f64)
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_read_as_people_write_them() {
        assert_eq!(format_bytes(512.0), "512 bytes");
        assert_eq!(format_bytes(4.0e12), "4.0 TB");
        assert_eq!(format_bytes(19.3e9), "19 GB");
        assert_eq!(format_bytes(1.05e11), "105 GB");
    }
}
