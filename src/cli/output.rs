//! Everything the CLI writes goes through here: files replace their target
//! atomically, and standard output reports a closed pipe as such.
//!
//! A file is written to a temporary file in the target's folder, flushed,
//! synced and renamed over the target, so a full disk or a killed process
//! leaves the old file (or none) in place, never a truncated one. Targets
//! that are not regular files (`/dev/stdout`, `/dev/full`, a FIFO) cannot be
//! replaced by a rename and are written in place.
//!
//! Standard output: a reader that went away (`robocal info *.png | head -1`)
//! ends the command quietly with exit code 141, what a shell reports for a
//! process killed by SIGPIPE, so pipelines behave as with other Unix tools;
//! any other write error (ENOSPC on `> /dev/full`) is a one-line error with
//! exit code 1.

use super::CliError;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Write `bytes` to `path`, replacing it atomically (see the module docs).
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    let mut file = AtomicFile::create(path)?;
    let written = file.write_all(bytes);
    file.finish(written)
}

/// Write `text` to stdout, with the module's handling of a closed pipe.
pub fn write_stdout(text: &str) -> Result<(), CliError> {
    let mut out = io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(stdout_error)
}

/// `text` and a newline to stdout, as `println!` but without its panic.
pub fn println_stdout(text: &str) -> Result<(), CliError> {
    let mut out = io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.write_all(b"\n"))
        .and_then(|()| out.flush())
        .map_err(stdout_error)
}

/// The CLI error for a failed write to stdout.
pub fn stdout_error(e: io::Error) -> CliError {
    if e.kind() == io::ErrorKind::BrokenPipe {
        CliError::BrokenPipe
    } else {
        CliError::Io(format!("cannot write to stdout: {e}"))
    }
}

/// Distinguishes the temporary files of one process's writes.
static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// A file being written: the temporary file beside the target, renamed over
/// it by [`AtomicFile::finish`]; dropped unfinished, the temporary file is
/// removed and the target is untouched.
pub struct AtomicFile {
    /// The file as the user named it, for messages.
    shown: PathBuf,
    /// The file renamed over (a symbolic link's target, so the link stays).
    target: PathBuf,
    /// The temporary file; `None` when writing in place (not a regular file).
    temp: Option<PathBuf>,
    out: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Start writing `path`.
    pub fn create(path: &Path) -> Result<Self, CliError> {
        let fail = |e: io::Error| CliError::Io(format!("cannot write '{}': {e}", path.display()));
        let existing = std::fs::metadata(path).ok();
        if existing.as_ref().is_some_and(|m| !m.is_file()) {
            if existing.as_ref().is_some_and(|m| m.is_dir()) {
                return Err(CliError::Io(format!(
                    "cannot write '{}': it is a folder",
                    path.display()
                )));
            }
            // A device or FIFO: written in place, there is nothing to keep.
            let file = std::fs::OpenOptions::new()
                .write(true)
                .open(path)
                .map_err(fail)?;
            return Ok(AtomicFile {
                shown: path.to_path_buf(),
                target: path.to_path_buf(),
                temp: None,
                out: Some(BufWriter::new(file)),
            });
        }
        let target = match existing {
            Some(_) => std::fs::canonicalize(path).map_err(fail)?,
            None => path.to_path_buf(),
        };
        let dir = match target.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let name = target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let temp = dir.join(format!(
            ".{name}.robocal-{}-{}.tmp",
            std::process::id(),
            TEMP_COUNTER.fetch_add(1, Ordering::Relaxed)
        ));
        let file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&temp)
            .map_err(fail)?;
        if let Some(m) = &existing {
            // Keep the old file's mode; failing that is not worth an error.
            let _ = file.set_permissions(m.permissions());
        }
        Ok(AtomicFile {
            shown: path.to_path_buf(),
            target,
            temp: Some(temp),
            out: Some(BufWriter::new(file)),
        })
    }

    /// Flush, sync and rename over the target when `written` is `Ok`;
    /// otherwise (or when any of that fails) remove the temporary file and
    /// report the first error, naming the file.
    pub fn finish(mut self, written: io::Result<()>) -> Result<(), CliError> {
        let result = written.and_then(|()| self.commit());
        result.map_err(|e| CliError::Io(format!("cannot write '{}': {e}", self.shown.display())))
    }

    fn commit(&mut self) -> io::Result<()> {
        let Some(out) = self.out.take() else {
            return Ok(());
        };
        let file = out.into_inner().map_err(|e| e.into_error())?;
        if self.temp.is_none() {
            return Ok(());
        }
        file.sync_all()?;
        drop(file);
        if let Some(temp) = &self.temp {
            std::fs::rename(temp, &self.target)?;
        }
        self.temp = None;
        Ok(())
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match self.out.as_mut() {
            Some(out) => out.write(buf),
            None => Err(io::Error::other("the file is already finished")),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        match self.out.as_mut() {
            Some(out) => out.flush(),
            None => Ok(()),
        }
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        // Unfinished or failed: the buffered bytes are dropped unwritten
        // (BufWriter's own drop would write them to the temporary file).
        if let Some(out) = self.out.take() {
            let (_, _) = out.into_parts();
        }
        if let Some(temp) = self.temp.take() {
            let _ = std::fs::remove_file(temp);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("robocal-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_write_replaces_the_file_and_leaves_no_temporary_file() {
        let dir = scratch("replace");
        let path = dir.join("out.json");
        std::fs::write(&path, b"old").unwrap();
        write_file(&path, b"new bytes").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new bytes");
        assert_eq!(names(&dir), vec!["out.json".to_string()]);
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn a_failed_write_keeps_the_old_file_and_removes_the_temporary_file() {
        let dir = scratch("fail");
        let path = dir.join("out.json");
        std::fs::write(&path, b"old").unwrap();
        let mut file = AtomicFile::create(&path).unwrap();
        file.write_all(b"half of the new").unwrap();
        let err = file
            .finish(Err(io::Error::other("No space left on device")))
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            format!("cannot write '{}': No space left on device", path.display())
        );
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(names(&dir), vec!["out.json".to_string()]);
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_keeps_pointing_at_the_new_bytes() {
        let dir = scratch("link");
        let real = dir.join("real.json");
        std::fs::write(&real, b"old").unwrap();
        let link = dir.join("link.json");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        write_file(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read(&real).unwrap(), b"new");
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn a_folder_is_not_a_file_to_write() {
        let dir = scratch("folder");
        let err = write_file(&dir, b"x").unwrap_err();
        assert_eq!(
            err.to_string(),
            format!("cannot write '{}': it is a folder", dir.display())
        );
        std::fs::remove_dir_all(dir).unwrap();
    }
}
