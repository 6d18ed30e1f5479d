//! Reading whole input files with a bound that holds whatever the file is.
//!
//! A length from `metadata` bounds a regular file only: `/dev/zero` and a FIFO report 0 bytes and
//! then never end, and a regular file can grow between the check and the read. So every input
//! read goes through [`read_bounded`]:
//!
//! 1. the path's type is checked before it is opened (a FIFO blocks `open` until a writer comes,
//!    so it must be refused by type, not by trying): directories, FIFOs, sockets and character
//!    or block devices are refused, naming the type;
//! 2. the opened handle's type and length are checked again (the path may have been replaced);
//! 3. at most `max_bytes + 1` bytes are read, so a file that grew past the bound is refused
//!    instead of filling memory.
//!
//! Every refusal is bad input ([`IoError::is_bad_input`]): the message names the file and why.

use std::fs::{File, FileType, Metadata};
use std::io::Read;
use std::path::Path;

use crate::IoError;

/// Reads the whole of `path` if it is a regular file (symbolic links followed) of at most
/// `max_bytes`; otherwise an [`IoError::Invalid`] naming its type, or an [`IoError::Limits`]
/// naming its size and the bound. Nothing over `max_bytes + 1` bytes is ever read or allocated.
pub fn read_bounded(path: &Path, max_bytes: u64) -> Result<Vec<u8>, IoError> {
    let io = |e| IoError::read(path, e);
    let (file, meta) = open_regular(path)?;
    if meta.len() > max_bytes {
        return Err(over_limit(path, meta.len(), max_bytes));
    }
    // The length is a hint only: read at most one byte past the bound to see it exceeded.
    let capacity = usize::try_from(meta.len()).unwrap_or(0);
    let mut bytes = Vec::with_capacity(capacity);
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > max_bytes {
        return Err(IoError::Limits {
            path: path.to_path_buf(),
            what: format!("the file grew past the limit of {max_bytes} bytes while it was read"),
        });
    }
    Ok(bytes)
}

/// Reads the first `max_bytes` of `path` (all of it when shorter), a regular file only (the same
/// type checks as [`read_bounded`]); for headers.
pub fn read_prefix(path: &Path, max_bytes: u64) -> Result<Vec<u8>, IoError> {
    let (file, _) = open_regular(path)?;
    let mut bytes = Vec::new();
    file.take(max_bytes)
        .read_to_end(&mut bytes)
        .map_err(|e| IoError::read(path, e))?;
    Ok(bytes)
}

/// Opens `path` for reading if it is a regular file, checked twice: by its path before opening
/// (a FIFO would block `open`) and by the opened handle (the path may have been replaced between).
fn open_regular(path: &Path) -> Result<(File, Metadata), IoError> {
    let io = |e| IoError::read(path, e);
    check_regular(path, &std::fs::metadata(path).map_err(io)?)?;
    let file = File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    check_regular(path, &meta)?;
    Ok((file, meta))
}

/// Reads a UTF-8 text file of at most `max_bytes` (through [`read_bounded`]); text that is not
/// UTF-8 is an [`IoError::Invalid`].
pub fn read_text(path: &Path, max_bytes: u64) -> Result<String, IoError> {
    let bytes = read_bounded(path, max_bytes)?;
    String::from_utf8(bytes).map_err(|e| IoError::Invalid {
        path: path.to_path_buf(),
        reason: format!("not UTF-8 text: {e}"),
    })
}

/// Refuses anything but a regular file, naming what it is.
pub fn check_regular(path: &Path, meta: &Metadata) -> Result<(), IoError> {
    if meta.is_file() {
        return Ok(());
    }
    Err(IoError::Invalid {
        path: path.to_path_buf(),
        reason: format!(
            "{}, not a regular file (inputs are read whole, so only regular files are accepted)",
            type_name(meta.file_type())
        ),
    })
}

fn over_limit(path: &Path, len: u64, max_bytes: u64) -> IoError {
    IoError::Limits {
        path: path.to_path_buf(),
        what: format!("{len} bytes, over the limit of {max_bytes} for this kind of file"),
    }
}

/// What a file that is not regular is, in words.
fn type_name(t: FileType) -> &'static str {
    if t.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
    }
    "a special file"
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    #[test]
    fn regular_files_within_the_bound_are_read_whole() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.txt");
        std::fs::write(&p, b"hello").unwrap();
        assert_eq!(read_bounded(&p, 5).unwrap(), b"hello");
        assert_eq!(read_text(&p, 100).unwrap(), "hello");
        let e = read_bounded(&p, 4).unwrap_err();
        assert!(matches!(e, IoError::Limits { .. }), "{e}");
        assert!(e.is_bad_input());
    }

    #[cfg(unix)]
    #[test]
    fn devices_directories_and_fifos_are_refused_by_type_without_reading() {
        let dir = tempfile::tempdir().unwrap();
        for (path, kind) in [
            (Path::new("/dev/zero"), "character device"),
            (dir.path(), "directory"),
        ] {
            let e = read_bounded(path, 1 << 20).unwrap_err();
            assert!(e.is_bad_input() && e.to_string().contains(kind), "{e}");
        }
        // A FIFO would block `open` until a writer came: refused before opening.
        let fifo = dir.path().join("pipe.hdr");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let e = read_bounded(&fifo, 1 << 20).unwrap_err();
            assert!(e.to_string().contains("FIFO"), "{e}");
        }
    }

    #[test]
    fn text_that_is_not_utf8_is_invalid_input() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("bad.json");
        std::fs::write(&p, b"\xff\xfe{}").unwrap();
        let e = read_text(&p, 100).unwrap_err();
        assert!(
            matches!(e, IoError::Invalid { .. }) && e.is_bad_input(),
            "{e}"
        );
    }
}
