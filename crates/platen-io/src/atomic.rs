//! Atomic output: every file platen writes goes to a temporary file in the destination's
//! folder, which is flushed, synced and renamed over the destination only when complete.
//! A failed or interrupted write removes the temporary file and leaves an existing
//! destination untouched. This is the one implementation every writer uses (CSV, streamed
//! CSV, Parquet, JSON, SVG, PNG, HTML). The file gets the mode of any new file (`0o666` less
//! the umask), not the temporary file's private `0600`.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use tempfile::NamedTempFile;

use crate::error::{IoAction, IoError, Result};

/// Capacity of the write buffer, bytes.
const BUFFER_BYTES: usize = 1 << 16;

/// An output being written: a buffered temporary file next to its destination.
///
/// Write through [`AtomicFile::writer`], then [`AtomicFile::commit`]. Dropping it without
/// committing (an error on the way) removes the temporary file.
#[derive(Debug)]
pub struct AtomicFile {
    path: PathBuf,
    out: BufWriter<NamedTempFile>,
    /// The sync started by [`AtomicFile::sync_ahead`], if one runs.
    ahead: Option<std::thread::JoinHandle<()>>,
}

impl AtomicFile {
    /// Creates the temporary file (`.NAME.XXXXXX.tmp`) in the folder of `path`, creating that
    /// folder (and its parents) first when it does not exist, as `--plot DIR` does.
    ///
    /// # Errors
    /// [`IoError::OutputFolderMissing`] if the folder of `path` exists but is not a folder;
    /// [`IoError::Io`] ([`IoAction::CreatingFolder`]) if it cannot be created;
    /// [`IoError::Io`] ([`IoAction::CreatingTemporary`]) if `path` names no file or the
    /// folder does not take a new file.
    pub fn create(path: &Path) -> Result<Self> {
        let Some(file_name) = path.file_name() else {
            return Err(write_error(
                path,
                io::Error::new(io::ErrorKind::InvalidInput, "the path names no file"),
            ));
        };
        let folder = directory_of(path);
        if !folder.exists() {
            std::fs::create_dir_all(folder).map_err(|source| IoError::Io {
                path: folder.to_path_buf(),
                action: IoAction::CreatingFolder,
                source,
            })?;
        }
        if !folder.is_dir() {
            return Err(IoError::OutputFolderMissing {
                path: path.to_path_buf(),
                folder: folder.to_path_buf(),
            });
        }
        let prefix = format!(".{}.", file_name.to_string_lossy());
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(".tmp");
        // The file platen writes is an ordinary output: created with the mode any program's
        // `File::create` gives (0o666 less the umask: 0644 under the usual 022) so that others
        // on the lab's machine can read it, not the temporary file's private 0600.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let temp = builder
            .tempfile_in(directory_of(path))
            .map_err(|source| IoError::Io {
                path: path.to_path_buf(),
                action: IoAction::CreatingTemporary,
                source,
            })?;
        Ok(Self {
            path: path.to_path_buf(),
            out: BufWriter::with_capacity(BUFFER_BYTES, temp),
            ahead: None,
        })
    }

    /// Starts syncing what was written so far to the disk on a thread of its own
    /// (`sync_data` on a second handle of the temporary file), so that the disk works while
    /// the writer goes on and [`AtomicFile::commit`]'s sync finds little left to do. Best
    /// effort: nothing happens while an earlier sync still runs, and a failure here is left
    /// to the commit's own sync to report.
    pub fn sync_ahead(&mut self) {
        if self.ahead.as_ref().is_some_and(|h| !h.is_finished()) {
            return;
        }
        if let Some(done) = self.ahead.take() {
            let _ = done.join();
        }
        if self.out.flush().is_err() {
            return;
        }
        if let Ok(handle) = self.out.get_ref().as_file().try_clone() {
            self.ahead = Some(std::thread::spawn(move || {
                let _ = handle.sync_data();
            }));
        }
    }

    /// The destination.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The buffered writer of the temporary file.
    pub fn writer(&mut self) -> &mut BufWriter<NamedTempFile> {
        &mut self.out
    }

    /// Flushes and syncs the temporary file and renames it over the destination.
    ///
    /// # Errors
    /// [`IoError::Io`] for a failed flush or sync ([`IoAction::Writing`]) or rename
    /// ([`IoAction::Renaming`]); the temporary file is removed.
    pub fn commit(self) -> Result<()> {
        if let Some(ahead) = self.ahead {
            let _ = ahead.join();
        }
        let path = self.path;
        let temp = self
            .out
            .into_inner()
            .map_err(|e| write_error(&path, e.into_error()))?;
        temp.as_file()
            .sync_all()
            .map_err(|source| write_error(&path, source))?;
        temp.persist(&path).map_err(|e| IoError::Io {
            path: path.clone(),
            action: IoAction::Renaming,
            source: e.error,
        })?;
        sync_directory(directory_of(&path));
        Ok(())
    }
}

/// Writes go to the buffered temporary file ([`AtomicFile::writer`]), so that a writer that
/// takes ownership of its sink (the Parquet writer) can hand the file back for
/// [`AtomicFile::commit`].
impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.out.write(buf)
    }

    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.out.write_all(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}

/// Writes `bytes` to `path` atomically (JSON, SVG, PNG and HTML outputs).
///
/// # Errors
/// As [`AtomicFile::create`] and [`AtomicFile::commit`].
pub fn write_bytes_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut file = AtomicFile::create(path)?;
    file.writer()
        .write_all(bytes)
        .map_err(|source| write_error(path, source))?;
    file.commit()
}

/// The error of a failed write to (the temporary file of) `path`.
pub(crate) fn write_error(path: &Path, source: io::Error) -> IoError {
    IoError::Io {
        path: path.to_path_buf(),
        action: IoAction::Writing,
        source,
    }
}

/// The folder that holds `path` (`.` for a bare file name).
fn directory_of(path: &Path) -> &Path {
    match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    }
}

/// Makes the rename durable where the platform allows it (best effort).
fn sync_directory(dir: &Path) {
    #[cfg(unix)]
    if let Ok(handle) = File::open(dir) {
        let _ = handle.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

/// The temporary files ([`AtomicFile`]'s `.NAME.XXXXXX.tmp`) left in `dir`: the writers' tests
/// check that none remains after a write, failed or not.
#[cfg(test)]
pub(crate) fn temp_files_in(dir: &std::path::Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.') && n.ends_with(".tmp"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Syncs started while writing (one running, the next skipped or started) change nothing
    /// of what is committed, and leave no temporary file; dropped uncommitted, the file goes.
    #[test]
    fn syncing_ahead_keeps_the_bytes_and_the_atomicity() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.csv");
        let mut expected = Vec::new();
        let mut file = AtomicFile::create(&path).unwrap();
        for k in 0..2000u32 {
            let line = format!("{k},{}\n", f64::from(k).sqrt());
            file.writer().write_all(line.as_bytes()).unwrap();
            expected.extend_from_slice(line.as_bytes());
            if k % 100 == 0 {
                file.sync_ahead();
            }
        }
        assert!(
            !path.exists(),
            "nothing at the destination before the commit"
        );
        file.commit().unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), expected);
        assert!(temp_files_in(dir.path()).is_empty());
        let other = dir.path().join("dropped.csv");
        let mut file = AtomicFile::create(&other).unwrap();
        file.writer().write_all(b"partial\n").unwrap();
        file.sync_ahead();
        drop(file);
        assert!(!other.exists() && temp_files_in(dir.path()).is_empty());
    }
}
