//! Errors of this crate, split by cause so that the command line tool can tell a bad input file
//! (exit status 2) from an internal failure (exit status 1).
//!
//! The byte-level codecs (`hdr`, `exr`, `pfm`, `ldr`) know nothing about paths: they return a
//! [`DecodeError`] or an [`EncodeError`]. The file functions ([`crate::read_image`],
//! [`crate::write_image`]) wrap those into an [`IoError`] that names the file, so every message a
//! user sees starts with the path it is about.

use std::fmt;
use std::io;
use std::path::{Path, PathBuf};

/// Why a file could not be read or written. Every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    /// The operating system refused or failed the operation (missing file, no permission, disk
    /// full, ...).
    #[error("{}: {source}", path.display())]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The operating-system error.
        source: io::Error,
    },
    /// The content is corrupt or malformed.
    #[error("{}: invalid file: {reason}", path.display())]
    Invalid {
        /// The file concerned.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
    },
    /// The content is well formed but uses a feature this crate cannot handle (for example an
    /// OpenEXR compression method the `exr` crate cannot decode; the method is named in `what`).
    #[error("{}: unsupported: {what}", path.display())]
    Unsupported {
        /// The file concerned.
        path: PathBuf,
        /// The unsupported feature.
        what: String,
    },
    /// The header announces an image over the [`crate::Limits`], or larger than the rest of the
    /// file could possibly hold.
    #[error("{}: too large: {what}", path.display())]
    Limits {
        /// The file concerned.
        path: PathBuf,
        /// Which size is over which limit.
        what: String,
    },
    /// The output file is one of the input files (same path after canonicalisation, or the same
    /// inode).
    #[error("{}: refusing to overwrite an input file", path.display())]
    SameAsInput {
        /// The output path that names an input.
        path: PathBuf,
    },
}

impl IoError {
    /// Whether the error is the user's input's fault (bad, unsupported, oversized, unreadable or
    /// missing input file, or an output naming an input) rather than an internal failure.
    ///
    /// True for [`IoError::Invalid`], [`IoError::Unsupported`], [`IoError::Limits`],
    /// [`IoError::SameAsInput`], for [`IoError::Io`] errors of kind `NotFound`,
    /// `PermissionDenied` or `IsADirectory` raised while *reading*, and for errors raised while
    /// *writing* that the output's place causes (the user's path: a missing, read-only or full
    /// folder, see [`is_destination_fault`]); false for any other I/O error.
    pub fn is_bad_input(&self) -> bool {
        match self {
            IoError::Invalid { .. }
            | IoError::Unsupported { .. }
            | IoError::Limits { .. }
            | IoError::SameAsInput { .. } => true,
            IoError::Io { source, .. } => {
                let while_writing = source
                    .get_ref()
                    .is_some_and(|inner| inner.is::<WriteFailure>());
                if while_writing {
                    is_destination_fault(source.kind())
                } else {
                    matches!(
                        source.kind(),
                        io::ErrorKind::NotFound
                            | io::ErrorKind::PermissionDenied
                            | io::ErrorKind::IsADirectory
                    )
                }
            }
        }
    }

    /// An [`IoError::Io`] for a failed read of `path`.
    pub(crate) fn read(path: &Path, source: io::Error) -> IoError {
        IoError::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    /// An [`IoError::Io`] for a failed write of `path`; it keeps the error kind but is never
    /// counted as bad input.
    pub(crate) fn write(path: &Path, source: io::Error) -> IoError {
        let kind = source.kind();
        IoError::Io {
            path: path.to_path_buf(),
            source: io::Error::new(kind, WriteFailure(source)),
        }
    }
}

/// Whether a write failed because of where the user asked it to go (exit status 2): the folder
/// is missing or not a folder, refuses writes (permissions, a read-only file system), or is full
/// (no space, over quota, a file too large for it). Other write failures are internal (1).
pub fn is_destination_fault(kind: io::ErrorKind) -> bool {
    use io::ErrorKind as K;
    matches!(
        kind,
        K::NotFound
            | K::PermissionDenied
            | K::IsADirectory
            | K::NotADirectory
            | K::ReadOnlyFilesystem
            | K::StorageFull
            | K::QuotaExceeded
            | K::FileTooLarge
            | K::InvalidFilename
    )
}

/// Marks an `io::Error` raised while writing an output (see [`IoError::is_bad_input`]).
#[derive(Debug)]
struct WriteFailure(io::Error);

impl fmt::Display for WriteFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "cannot write: {}", self.0)
    }
}

impl std::error::Error for WriteFailure {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.0)
    }
}

/// Why a byte buffer could not be decoded (no path; see [`IoError`] for the file-level error).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DecodeError {
    /// Corrupt or malformed content.
    #[error("invalid file: {0}")]
    Invalid(String),
    /// A valid feature this crate cannot decode (named in the message).
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// Header sizes over the [`crate::Limits`] or larger than the data could hold.
    #[error("too large: {0}")]
    Limits(String),
}

impl DecodeError {
    /// Always true: every cause is the bytes' content.
    pub fn is_bad_input(&self) -> bool {
        true
    }

    /// Shorthand for [`DecodeError::Invalid`].
    pub(crate) fn invalid(reason: impl Into<String>) -> DecodeError {
        DecodeError::Invalid(reason.into())
    }

    /// Attaches the file name.
    pub fn with_path(self, path: &Path) -> IoError {
        let path = path.to_path_buf();
        match self {
            DecodeError::Invalid(reason) => IoError::Invalid { path, reason },
            DecodeError::Unsupported(what) => IoError::Unsupported { path, what },
            DecodeError::Limits(what) => IoError::Limits { path, what },
        }
    }
}

/// Why an image could not be encoded into bytes (an internal failure, never the user's input).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("cannot encode image: {reason}")]
pub struct EncodeError {
    /// What went wrong.
    pub reason: String,
}

impl EncodeError {
    /// Always false: encoding our own images fails only internally.
    pub fn is_bad_input(&self) -> bool {
        false
    }

    /// Builds an error from any message.
    pub(crate) fn new(reason: impl Into<String>) -> EncodeError {
        EncodeError {
            reason: reason.into(),
        }
    }

    /// Attaches the file name; encoding failures are internal (`is_bad_input` is false).
    pub fn with_path(self, path: &Path) -> IoError {
        IoError::write(path, io::Error::other(self.reason))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_input_classification() {
        let p = Path::new("in.hdr");
        assert!(IoError::read(p, io::Error::from(io::ErrorKind::NotFound)).is_bad_input());
        assert!(IoError::read(p, io::Error::from(io::ErrorKind::PermissionDenied)).is_bad_input());
        assert!(!IoError::read(p, io::Error::from(io::ErrorKind::OutOfMemory)).is_bad_input());
        // Issue 13: a missing, read-only or full output folder is the user's path (exit 2);
        // before, every write error was internal.
        for kind in [
            io::ErrorKind::NotFound,
            io::ErrorKind::PermissionDenied,
            io::ErrorKind::ReadOnlyFilesystem,
            io::ErrorKind::StorageFull,
            io::ErrorKind::QuotaExceeded,
        ] {
            assert!(
                IoError::write(p, io::Error::from(kind)).is_bad_input(),
                "{kind:?}"
            );
        }
        assert!(!IoError::write(p, io::Error::from(io::ErrorKind::OutOfMemory)).is_bad_input());
        assert!(!IoError::write(p, io::Error::other("disk on fire")).is_bad_input());
        assert!(!EncodeError::new("x").with_path(p).is_bad_input());
        assert!(DecodeError::invalid("x").with_path(p).is_bad_input());
        assert!(IoError::SameAsInput { path: p.into() }.is_bad_input());
    }

    #[test]
    fn messages_name_the_file() {
        let p = Path::new("dir/probe.exr");
        for e in [
            DecodeError::invalid("bad magic").with_path(p),
            DecodeError::Unsupported("HTJ2K".into()).with_path(p),
            DecodeError::Limits("huge".into()).with_path(p),
            IoError::read(p, io::Error::from(io::ErrorKind::NotFound)),
            IoError::write(p, io::Error::from(io::ErrorKind::StorageFull)),
            IoError::SameAsInput { path: p.into() },
        ] {
            assert!(e.to_string().starts_with("dir/probe.exr: "), "{e}");
        }
        let w = IoError::write(p, io::Error::other("disk on fire"));
        assert!(w.to_string().contains("cannot write: disk on fire"), "{w}");
    }
}
