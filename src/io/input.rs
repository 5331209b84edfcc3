//! Reading a file a user names (a design, a centreline, a run folder's summary): regular files only, and no
//! more than a stated number of bytes.
//!
//! A path may name something that is not a file: `/dev/zero` and `/dev/urandom` never end (reading one
//! "until the end" fills memory), a FIFO blocks the reader for ever, a folder cannot be read. So the path is
//! checked before it is opened, opened without blocking (`O_NONBLOCK`: opening a FIFO with no writer would
//! itself block), checked again through the handle (the path may have been replaced in between), and read no
//! further than the limit plus one byte (a regular file may grow while it is read). A file over the limit is
//! refused without reading the rest.

use std::fs::FileType;
use std::io::Read as _;
use std::os::unix::fs::{FileTypeExt as _, OpenOptionsExt as _};
use std::path::Path;

/// Why [`read_regular_file`] returned no bytes.
#[derive(Debug)]
pub(crate) enum InputError {
    /// The operating system's error (missing file, no permission …).
    Io(std::io::Error),
    /// Not a regular file: what it is, in words ("a FIFO (named pipe)", "a character device", "a folder" …).
    NotRegular(&'static str),
    /// The file holds more than the limit: its size \[bytes\] where known, else the bytes read (limit + 1).
    TooLarge(u64),
}

/// The bytes of the regular file at `path`, at most `limit` of them (module docs).
///
/// # Errors
/// [`InputError::NotRegular`] for a device, FIFO, socket or folder, [`InputError::TooLarge`] for more than
/// `limit` bytes, [`InputError::Io`] when the operating system refuses.
pub(crate) fn read_regular_file(path: &Path, limit: u64) -> Result<Vec<u8>, InputError> {
    let metadata = std::fs::metadata(path).map_err(InputError::Io)?;
    if !metadata.is_file() {
        return Err(InputError::NotRegular(kind(metadata.file_type())));
    }
    if metadata.len() > limit {
        return Err(InputError::TooLarge(metadata.len()));
    }
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
        .map_err(InputError::Io)?;
    let metadata = file.metadata().map_err(InputError::Io)?;
    if !metadata.is_file() {
        return Err(InputError::NotRegular(kind(metadata.file_type())));
    }
    let mut bytes = Vec::new();
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(InputError::Io)?;
    if bytes.len() as u64 > limit {
        return Err(InputError::TooLarge(bytes.len() as u64));
    }
    Ok(bytes)
}

/// What a file that is not regular is, in words.
fn kind(file_type: FileType) -> &'static str {
    if file_type.is_dir() {
        "a folder"
    } else if file_type.is_char_device() {
        "a character device"
    } else if file_type.is_block_device() {
        "a block device"
    } else if file_type.is_fifo() {
        "a FIFO (named pipe)"
    } else if file_type.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    }
}

/// Largest `summary.json` stentkit reads back \[bytes\]: 16 MiB. A summary is a few kB (the straight stent's,
/// with its snapshots and timing, 5 kB; a failure report adds the residuals of one step); the limit only keeps
/// a file put in its place (a device, a FIFO, a huge file) from costing more than that.
pub(crate) const MAX_SUMMARY_BYTES: u64 = 16 * 1024 * 1024;

/// The JSON of the run summary at `path`, read as a regular file of at most [`MAX_SUMMARY_BYTES`]
/// ([`read_regular_file`]).
///
/// # Errors
/// A message (without the path) saying why it cannot be read: missing, not a regular file, too large, not
/// UTF-8 or not JSON.
pub(crate) fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T, String> {
    let bytes = read_regular_file(path, MAX_SUMMARY_BYTES).map_err(|e| match e {
        InputError::Io(e) => e.to_string(),
        InputError::NotRegular(what) => format!("{what}, not a regular file"),
        InputError::TooLarge(bytes) => format!(
            "{bytes} bytes, more than the {} MiB a summary may have",
            MAX_SUMMARY_BYTES >> 20
        ),
    })?;
    serde_json::from_slice(&bytes).map_err(|e| format!("not a stentkit summary: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn devices_fifos_and_folders_are_refused_and_files_are_bounded() {
        // /dev/zero never ends and a FIFO without a writer blocks a plain open or read for ever: both must be
        // refused at once, by kind, without reading. A 10-byte file is read whole under a limit of 10 and
        // refused under 9 (the limit is inclusive).
        assert!(matches!(
            read_regular_file(Path::new("/dev/zero"), 1024),
            Err(InputError::NotRegular("a character device"))
        ));
        let dir = std::env::temp_dir().join(format!("stentkit-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("scratch");
        assert!(matches!(
            read_regular_file(&dir, 1024),
            Err(InputError::NotRegular("a folder"))
        ));
        let fifo = dir.join("pipe");
        let name = std::ffi::CString::new(fifo.as_os_str().as_encoded_bytes()).expect("path");
        // SAFETY: `name` is a valid NUL-terminated path that outlives the call.
        assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o600) }, 0, "mkfifo");
        assert!(matches!(
            read_regular_file(&fifo, 1024),
            Err(InputError::NotRegular("a FIFO (named pipe)"))
        ));
        let file = dir.join("ten");
        std::fs::write(&file, b"0123456789").expect("write");
        assert_eq!(read_regular_file(&file, 10).expect("read"), b"0123456789");
        assert!(matches!(
            read_regular_file(&file, 9),
            Err(InputError::TooLarge(10))
        ));
        std::fs::remove_dir_all(&dir).expect("clean");
    }
}
