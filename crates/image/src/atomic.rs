//! Durable, all-or-nothing output files.
//!
//! A file is written to a temporary name in the folder of its destination, flushed and
//! synced to the disk, and only then renamed over the destination. A rename within one
//! file system replaces the name in a single step (POSIX `rename(2)`), so a reader — or
//! the user after a crash, a full disk or a signal — sees either the previous file whole
//! or the new one whole, never a truncated mix. A write that fails removes its temporary
//! file and leaves the previous file as it was.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// A file being written under a temporary name; [`AtomicFile::commit`] puts it in place.
/// Dropped without a commit, it removes the temporary file.
pub struct AtomicFile {
    target: PathBuf,
    temp: PathBuf,
    writer: Option<BufWriter<File>>,
}

/// Distinguishes the temporary files of several writes in one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// The temporary name for `target`: hidden, in the same folder (so the rename stays on
/// one file system), unique per process and write.
fn temp_path(target: &Path) -> PathBuf {
    let name = target
        .file_name()
        .map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    target.with_file_name(format!(".{name}.{}-{n}.tmp", std::process::id()))
}

impl AtomicFile {
    /// Creates the temporary file beside `target`.
    pub fn create(target: impl AsRef<Path>) -> io::Result<AtomicFile> {
        let target = target.as_ref().to_path_buf();
        let temp = temp_path(&target);
        let file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&temp)?;
        Ok(AtomicFile {
            target,
            temp,
            writer: Some(BufWriter::with_capacity(1 << 16, file)),
        })
    }

    /// The buffered writer of the temporary file (it also seeks, for formats that need it).
    pub fn writer(&mut self) -> &mut BufWriter<File> {
        self.writer.as_mut().expect("writer present until commit")
    }

    /// Flushes and syncs the temporary file, renames it over the target and syncs the
    /// folder so the rename itself survives a crash.
    pub fn commit(mut self) -> io::Result<()> {
        let writer = self.writer.take().expect("writer present until commit");
        let file = writer.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        drop(file);
        std::fs::rename(&self.temp, &self.target)?;
        // The temporary name is gone now: nothing for Drop to remove.
        self.temp = PathBuf::new();
        sync_parent(&self.target);
        Ok(())
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if !self.temp.as_os_str().is_empty() {
            self.writer = None;
            let _ = std::fs::remove_file(&self.temp);
        }
    }
}

/// Syncs the folder holding `path` (where the platform allows opening a folder; a
/// failure only weakens durability across a power cut, not atomicity).
fn sync_parent(path: &Path) {
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if let Ok(dir) = File::open(parent) {
        let _ = dir.sync_all();
    }
}

/// Writes `path` all or nothing: `write` fills a temporary file beside it, which then
/// replaces `path`. On any error the temporary file is removed, `path` is untouched and
/// the error (e.g. "No space left on device") is returned.
pub fn atomic_write<E: From<io::Error>>(
    path: impl AsRef<Path>,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), E>,
) -> Result<(), E> {
    let mut file = AtomicFile::create(path)?;
    write(file.writer())?;
    file.commit()?;
    Ok(())
}

/// [`atomic_write`] of a byte buffer.
pub fn atomic_write_bytes(path: impl AsRef<Path>, bytes: &[u8]) -> io::Result<()> {
    atomic_write(path, |w| w.write_all(bytes))
}

/// Checks, before any work, that a file can be created at `path`: its folder exists, is a
/// folder and accepts a new file (a probe file is created and removed), and `path` is not
/// itself a folder.
pub fn check_writable(path: impl AsRef<Path>) -> io::Result<()> {
    let path = path.as_ref();
    if path.is_dir() {
        return Err(io::Error::new(
            io::ErrorKind::IsADirectory,
            "is a folder, not a file",
        ));
    }
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    match std::fs::metadata(parent) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => {
            return Err(io::Error::new(
                io::ErrorKind::NotADirectory,
                format!("{} is not a folder", parent.display()),
            ));
        }
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            return Err(io::Error::new(
                io::ErrorKind::NotFound,
                format!("folder {} does not exist", parent.display()),
            ));
        }
        Err(e) => return Err(e),
    }
    // Only a real attempt answers for permissions, read-only mounts and ACLs alike.
    drop(AtomicFile::create(path)?);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("radiant-atomic-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn entries(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn replaces_the_file_whole() {
        let d = dir("replace");
        let path = d.join("out.bin");
        atomic_write_bytes(&path, b"first").unwrap();
        atomic_write_bytes(&path, b"second, longer").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second, longer");
        assert_eq!(entries(&d), ["out.bin"]);
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn a_failed_write_leaves_the_previous_file_and_no_temporary() {
        let d = dir("fail");
        let path = d.join("out.bin");
        atomic_write_bytes(&path, b"previous").unwrap();
        let err = atomic_write(&path, |w| {
            w.write_all(&[7u8; 100_000])?;
            Err(io::Error::new(io::ErrorKind::StorageFull, "disk full"))
        })
        .unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::StorageFull);
        assert_eq!(std::fs::read(&path).unwrap(), b"previous");
        assert_eq!(entries(&d), ["out.bin"]);
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn checks_name_the_problem() {
        let d = dir("check");
        assert!(check_writable(d.join("ok.exr")).is_ok());
        assert_eq!(entries(&d), Vec::<String>::new(), "probe removed");
        let err = check_writable(d.join("missing/out.exr")).unwrap_err();
        assert!(err.to_string().contains("does not exist"), "{err}");
        let err = check_writable(&d).unwrap_err();
        assert!(err.to_string().contains("folder"), "{err}");
        std::fs::write(d.join("file"), b"x").unwrap();
        let err = check_writable(d.join("file/out.exr")).unwrap_err();
        assert!(err.to_string().contains("not a folder"), "{err}");
        std::fs::remove_dir_all(&d).ok();
    }
}
