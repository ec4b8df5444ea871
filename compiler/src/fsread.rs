//! The one reader of every file the CLI and the server read (missions,
//! catalogs, strategies, task graphs and their sub-graphs, generation's
//! manifests): bounded, and only regular files.

use std::path::Path;

/// The largest file read (missions, catalogs, strategies, task graphs and the
/// sub-graphs they reference): larger ones are refused with a message rather
/// than held in memory.
pub const MAX_FILE_BYTES: u64 = 16 * 1024 * 1024;

/// A file's text: the one reader of every input file of the CLI and the
/// server. Only regular files are read (a FIFO, a device such as `/dev/zero`
/// or a socket is refused without blocking on it), and only up to
/// [`MAX_FILE_BYTES`]. Invalid UTF-8 is replaced rather than refused, so the
/// rest is still checked.
pub fn read_text(path: &Path) -> std::io::Result<String> {
    read_text_limited(path, MAX_FILE_BYTES)
}

/// [`read_text`] with another size limit.
pub fn read_text_limited(path: &Path, limit: u64) -> std::io::Result<String> {
    use std::io::{Error, ErrorKind, Read};
    use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
    // Non-blocking, so that opening a FIFO returns at once instead of waiting
    // for a writer; the type is checked on the opened file itself.
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(rustix::fs::OFlags::NONBLOCK.bits() as i32)
        .open(path)?;
    let meta = file.metadata()?;
    let kind = meta.file_type();
    let not_regular = if kind.is_dir() {
        Some("a folder")
    } else if kind.is_fifo() {
        Some("a FIFO")
    } else if kind.is_char_device() || kind.is_block_device() {
        Some("a device")
    } else if kind.is_socket() {
        Some("a socket")
    } else if !kind.is_file() {
        Some("not a regular file")
    } else {
        None
    };
    if let Some(what) = not_regular {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!("is {what}, not a regular file: not read"),
        ));
    }
    let too_large = |size: u64| {
        Error::new(
            ErrorKind::FileTooLarge,
            format!("is {size} bytes, more than the {limit} bytes a file may have: not read"),
        )
    };
    if meta.len() > limit {
        return Err(too_large(meta.len()));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(limit + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        // It grew while being read.
        return Err(too_large(bytes.len() as u64));
    }
    Ok(String::from_utf8(bytes)
        .unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into_owned()))
}
