//! Opening an image file before reading it: the checks that keep a wrong
//! path from costing time or memory.
//!
//! 1. Only regular files are read: a FIFO with no writer would block for
//!    ever, `/dev/zero` would fill memory, a directory is a mistake.
//! 2. The first [`HEAD_BYTES`] bytes are read and the format recognised
//!    from them: a 3 GB file of anything but an image is refused after
//!    reading its first bytes, whatever its name.
//! 3. A file longer than the decoder's memory limit
//!    ([`DecodeOptions::max_alloc_bytes`], 1 GiB by default, raised with
//!    `--max-pixels`) is refused before it is read: no image the decoder
//!    accepts is larger (an uncompressed image is its pixel buffer).
//! 4. Only then is the rest read, into a buffer of the file's length.

use super::CliError;
use robocal::image::DecodeOptions;
use std::fs::File;
use std::io::Read;

/// Bytes read before the rest of the file: enough for every format's
/// magic bytes, and for the header of most files (an EXIF block is at most
/// 64 KiB), from which `detect` budgets its memory.
pub const HEAD_BYTES: u64 = 256 << 10;

/// An image file checked and its first bytes read.
pub struct ImageFile {
    path: String,
    file: File,
    len: u64,
    /// The first `min(len, HEAD_BYTES)` bytes.
    pub head: Vec<u8>,
}

/// Open `path` as an image: a regular file whose first bytes are an image
/// format, no longer than the decoder's memory limit.
pub fn open_image(path: &str, options: &DecodeOptions) -> Result<ImageFile, CliError> {
    let cannot = |e: std::io::Error| CliError::Io(format!("cannot read '{path}': {e}"));
    let meta = std::fs::metadata(path).map_err(cannot)?;
    if !meta.is_file() {
        return Err(CliError::Io(format!(
            "'{path}' is not a regular file ({}): give an image file",
            kind_of(&meta.file_type())
        )));
    }
    let mut file = File::open(path).map_err(cannot)?;
    let mut head = Vec::new();
    (&mut file)
        .take(HEAD_BYTES)
        .read_to_end(&mut head)
        .map_err(cannot)?;
    robocal::image::sniff_format(&head)?;
    let len = meta.len();
    if len > options.max_alloc_bytes {
        return Err(CliError::Io(format!(
            "'{path}' is {len} bytes, more than any image the decoder accepts \
             (at most {} bytes, its memory limit): downscale or compress the image, \
             or raise the limit with --max-pixels (10 bytes a pixel)",
            options.max_alloc_bytes
        )));
    }
    Ok(ImageFile {
        path: path.to_string(),
        file,
        len,
        head,
    })
}

impl ImageFile {
    /// The file's length in bytes when it was opened.
    pub fn len(&self) -> u64 {
        self.len
    }

    /// The whole file: the first bytes and the rest (never more than its
    /// length when opened plus one byte, should it grow meanwhile).
    pub fn read_all(self) -> Result<Vec<u8>, CliError> {
        let ImageFile {
            path,
            mut file,
            len,
            mut head,
        } = self;
        let rest = len.saturating_sub(head.len() as u64);
        head.try_reserve_exact(rest as usize).map_err(|_| {
            CliError::Io(format!(
                "cannot read '{path}': out of memory for {len} bytes"
            ))
        })?;
        (&mut file)
            .take(rest + 1)
            .read_to_end(&mut head)
            .map_err(|e| CliError::Io(format!("cannot read '{path}': {e}")))?;
        Ok(head)
    }
}

/// Read a whole image file through [`open_image`].
pub fn read_image(path: &str, options: &DecodeOptions) -> Result<Vec<u8>, CliError> {
    open_image(path, options)?.read_all()
}

/// What a path that is not a regular file is, in words.
fn kind_of(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a directory"
    } else {
        "not a file"
    }
}
