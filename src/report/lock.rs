//! One writer per results directory: an advisory lock on
//! `<dir>/plyscape.lock`, held for the whole command.
//!
//! Two commands writing the same `runs.csv` would interleave rows and lose
//! some; the second one is refused instead, with who holds the directory.
//! The lock is the operating system's (`flock` on Unix): it is released
//! when the process ends, even when it is killed, so a stale lock file
//! never blocks anyone. The file itself stays (deleting it on release would
//! let two later commands lock two different files); its text names the
//! last holder and is read only while the lock is held by someone.

use crate::error::{Error, Result};
use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// Name of the lock file in a results directory.
pub const LOCK_FILE: &str = "plyscape.lock";

/// A held lock on a results directory; released on drop.
#[derive(Debug)]
pub struct DirLock {
    file: File,
    path: PathBuf,
}

impl DirLock {
    /// Lock `dir` (created if missing) for `command`, or refuse with the
    /// holder's process id, command and start time.
    pub fn acquire(dir: &Path, command: &str) -> Result<DirLock> {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        let path = dir.join(LOCK_FILE);
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(|e| Error::io(&path, e))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                let mut holder = String::new();
                let _ = file.read_to_string(&mut holder);
                let holder = holder.trim();
                let holder = if holder.is_empty() {
                    "another process"
                } else {
                    holder
                };
                return Err(Error::io(
                    &path,
                    std::io::Error::new(
                        std::io::ErrorKind::WouldBlock,
                        format!(
                            "results directory {} is in use by {holder}; wait for it to \
                             finish (or stop it), or write elsewhere with --out",
                            dir.display()
                        ),
                    ),
                ));
            }
            Err(TryLockError::Error(e)) => return Err(Error::io(&path, e)),
        }
        let who = format!(
            "plyscape {command} (process {}, started {})",
            std::process::id(),
            super::clock::iso_utc(std::time::SystemTime::now())
        );
        file.set_len(0)
            .and_then(|_| file.seek(SeekFrom::Start(0)))
            .and_then(|_| file.write_all(who.as_bytes()))
            .and_then(|_| file.flush())
            .map_err(|e| Error::io(&path, e))?;
        Ok(DirLock { file, path })
    }

    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        let _ = self.file.unlock();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn second_holder_is_refused_with_the_first_named() {
        let dir = std::env::temp_dir().join(format!("plyscape-lock-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let first = DirLock::acquire(&dir, "multistart").unwrap();
        let e = DirLock::acquire(&dir, "compare").unwrap_err().to_string();
        assert!(e.contains("in use by plyscape multistart"), "{e}");
        assert!(
            e.contains(&format!("process {}", std::process::id())),
            "{e}"
        );
        drop(first);
        // Released: the next command gets it and names itself.
        let again = DirLock::acquire(&dir, "map").unwrap();
        let text = std::fs::read_to_string(again.path()).unwrap();
        assert!(text.starts_with("plyscape map"), "{text}");
        drop(again);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
