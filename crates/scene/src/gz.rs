//! Files that may be gzip-compressed (pbrt-v4 reads `.pbrt.gz` includes and
//! `.ply.gz` meshes). Compression is recognised by the gzip magic number, not the
//! name, so a renamed file reads too.

use std::fs::File;
use std::io::{self, Cursor, Read};
use std::path::Path;

use flate2::read::MultiGzDecoder;

/// The first two bytes of every gzip member (RFC 1952, §2.3.1).
const MAGIC: [u8; 2] = [0x1f, 0x8b];

/// Opens `path` for reading, decompressing on the fly when it is gzip data.
pub fn open(path: &Path) -> io::Result<Box<dyn Read + Send>> {
    let file = File::open(path)?;
    open_file(file)
}

/// [`open`] for a file already opened (and checked) by the caller. The bytes looked
/// at are put back in front rather than sought over, so pipes work too.
pub fn open_file(mut file: File) -> io::Result<Box<dyn Read + Send>> {
    let mut head = [0u8; 2];
    let mut got = 0;
    while got < 2 {
        match file.read(&mut head[got..])? {
            0 => break,
            n => got += n,
        }
    }
    let whole = Cursor::new(head).take(got as u64).chain(file);
    Ok(if got == 2 && head == MAGIC {
        Box::new(MultiGzDecoder::new(whole))
    } else {
        Box::new(whole)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use flate2::{Compression, write::GzEncoder};
    use std::io::Write;

    #[test]
    fn plain_and_gzip_files_read_the_same() {
        let dir = std::env::temp_dir().join(format!("radiant-gz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let text = b"WorldBegin\nShape \"sphere\"\n".repeat(100);
        let plain = dir.join("a.pbrt");
        std::fs::write(&plain, &text).unwrap();
        let packed = dir.join("a.pbrt.gz");
        let mut enc = GzEncoder::new(Vec::new(), Compression::default());
        enc.write_all(&text).unwrap();
        std::fs::write(&packed, enc.finish().unwrap()).unwrap();
        for path in [&plain, &packed] {
            let mut out = Vec::new();
            open(path).unwrap().read_to_end(&mut out).unwrap();
            assert_eq!(out, text, "{}", path.display());
        }
        // One byte is not a gzip header.
        let one = dir.join("one");
        std::fs::write(&one, [0x1f]).unwrap();
        let mut out = Vec::new();
        open(&one).unwrap().read_to_end(&mut out).unwrap();
        assert_eq!(out, [0x1f]);
        // A damaged gzip stream is an error, not garbage.
        let mut bad = std::fs::read(&packed).unwrap();
        let n = bad.len();
        bad.truncate(n / 2);
        std::fs::write(&packed, bad).unwrap();
        assert!(open(&packed).unwrap().read_to_end(&mut Vec::new()).is_err());
    }
}
