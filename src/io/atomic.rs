//! Atomic writes: an output is either the complete new file or untouched.
//!
//! Every writer in [`crate::io`] writes into a [`tempfile::NamedTempFile`]
//! created in the destination's directory (so the final rename never crosses
//! a file system), flushes and syncs it, and only then renames it over the
//! destination. An error, a panic inside a dependency's encoder (the `exr`
//! crate panics on some invalid inputs, after having written part of the
//! file) or an interrupt leaves the destination as it was: the temporary
//! file is deleted when it is dropped. Temporary files still being written
//! are registered, so a signal handler (the CLI's Ctrl-C handler) can
//! delete them with [`remove_temporary_files`] before exiting; after a
//! SIGKILL one may be left behind under a `.parvo-` name, never under the
//! destination's name.
//!
//! Several files that belong together (one PNG per mip level) are first all
//! [`stage`]d, then all committed, so a failure in level 5 does not leave
//! levels 0–4 of a new chain next to the old levels 5–12.

use std::any::Any;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use tempfile::NamedTempFile;

use crate::error::{Error, Result};

/// Temporary files that exist right now (created, not yet renamed or
/// deleted), and whether [`remove_temporary_files`] has run.
struct Live {
    paths: Vec<PathBuf>,
    closed: bool,
}

static LIVE: Mutex<Live> = Mutex::new(Live {
    paths: Vec::new(),
    closed: false,
});

fn live() -> std::sync::MutexGuard<'static, Live> {
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Delete every temporary file parvo is writing or has staged, for a
/// signal handler about to exit the process. Destinations are untouched.
/// No temporary file is created after it (a writer that tries gets an
/// error): a file is created and registered under the same lock, so none
/// made while the handler runs is missed.
pub fn remove_temporary_files() {
    let mut l = live();
    l.closed = true;
    for p in l.paths.drain(..) {
        let _ = std::fs::remove_file(p);
    }
}

/// A temporary file's registration in [`LIVE`]: registered while this
/// guard lives (from creation until renamed or deleted).
#[derive(Debug)]
struct Registered(PathBuf);

impl Registered {
    /// Create a temporary file with `make` and register it, unless
    /// [`remove_temporary_files`] has run.
    fn create(
        make: impl FnOnce() -> std::io::Result<NamedTempFile>,
    ) -> std::io::Result<(Self, NamedTempFile)> {
        let mut l = live();
        if l.closed {
            return Err(std::io::Error::new(
                std::io::ErrorKind::Interrupted,
                "interrupted: no new file is written",
            ));
        }
        let tmp = make()?;
        l.paths.push(tmp.path().to_path_buf());
        Ok((Registered(tmp.path().to_path_buf()), tmp))
    }
}

impl Drop for Registered {
    fn drop(&mut self) {
        live().paths.retain(|p| *p != self.0);
    }
}

/// A fully written temporary file waiting to be renamed over `dest`.
#[derive(Debug)]
pub struct Staged {
    // Declared before `tmp`, so dropping a `Staged` unregisters the
    // temporary file before deleting it.
    registered: Registered,
    tmp: NamedTempFile,
    dest: PathBuf,
}

impl Staged {
    /// Rename the temporary file over the destination.
    pub fn commit(self) -> Result<()> {
        let Staged {
            registered,
            tmp,
            dest,
        } = self;
        drop(registered);
        tmp.persist(&dest).map_err(|e| Error::Io {
            action: format!("cannot rename into {}", dest.display()),
            path: dest.clone(),
            error: e.error,
        })?;
        Ok(())
    }

    /// The destination this file will be renamed to.
    pub fn dest(&self) -> &Path {
        &self.dest
    }
}

/// Write `dest` atomically with `write` (see the module docs); returns
/// what `write` returned, once the file is in place.
pub fn write<F, T>(dest: &Path, write: F) -> Result<T>
where
    F: FnOnce(&mut BufWriter<&File>) -> Result<T>,
{
    let (staged, value) = stage_with(dest, write)?;
    staged.commit()?;
    Ok(value)
}

/// Write the contents of `dest` into a temporary file beside it, without
/// renaming it yet. Dropping the result deletes the temporary file.
pub fn stage<F>(dest: &Path, write: F) -> Result<Staged>
where
    F: FnOnce(&mut BufWriter<&File>) -> Result<()>,
{
    stage_with(dest, write).map(|(staged, ())| staged)
}

/// [`stage`], keeping what `write` returned.
fn stage_with<F, T>(dest: &Path, write: F) -> Result<(Staged, T)>
where
    F: FnOnce(&mut BufWriter<&File>) -> Result<T>,
{
    if dest.is_dir() {
        return Err(Error::Io {
            path: dest.to_path_buf(),
            action: format!("cannot write {}", dest.display()),
            error: std::io::Error::other("it is a directory"),
        });
    }
    let dir = match dest.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".parvo-").suffix(".tmp");
    // Temporary files are created owner-only (0600); the finished file
    // should get what any new file gets (0666 less the umask).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let (registered, tmp) =
        Registered::create(|| builder.tempfile_in(dir)).map_err(|e| Error::Io {
            path: dir.to_path_buf(),
            action: format!("cannot create a file in {}", dir.display()),
            // tempfile appends the random temporary name; keep only the
            // operating system's reason.
            error: {
                let msg = e.to_string();
                let reason = msg.split(" at path ").next().unwrap_or(&msg).to_string();
                std::io::Error::new(e.kind(), reason)
            },
        })?;
    // Replacing a file keeps its permissions.
    if let Ok(meta) = std::fs::metadata(dest) {
        let _ = tmp.as_file().set_permissions(meta.permissions());
    }
    let io_err = |e: std::io::Error| Error::Io {
        path: dest.to_path_buf(),
        action: format!("cannot write {}", dest.display()),
        error: e,
    };
    let value = {
        let mut w = BufWriter::with_capacity(1 << 20, tmp.as_file());
        let value = match catch_unwind(AssertUnwindSafe(|| write(&mut w))) {
            Ok(r) => r?,
            Err(payload) => {
                return Err(Error::Encode {
                    format: "output",
                    reason: format!("encoder panicked: {}", panic_message(&*payload)),
                });
            }
        };
        w.flush().map_err(io_err)?;
        value
    };
    tmp.as_file().sync_all().map_err(io_err)?;
    let staged = Staged {
        registered,
        tmp,
        dest: dest.to_path_buf(),
    };
    Ok((staged, value))
}

/// Text of a panic payload (`&str` or `String`), or a placeholder.
pub fn panic_message(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic".into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_and_panicking_writers_leave_the_destination_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let dest = dir.path().join("out.bin");
        std::fs::write(&dest, b"old").unwrap();
        let e: Result<()> = write(&dest, |w| {
            w.write_all(b"partial").unwrap();
            Err(Error::InvalidOption("boom".into()))
        });
        assert!(e.is_err());
        let e: Result<()> = write(&dest, |w| {
            w.write_all(b"partial").unwrap();
            panic!("dependency bug")
        });
        assert!(e.unwrap_err().to_string().contains("dependency bug"));
        assert_eq!(std::fs::read(&dest).unwrap(), b"old");
        // Only the destination is left: no temporary files.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        write(&dest, |w| {
            w.write_all(b"new").unwrap();
            Ok(())
        })
        .unwrap();
        assert_eq!(std::fs::read(&dest).unwrap(), b"new");
    }

    /// A new file gets the permissions any newly created file gets here
    /// (not the temporary file's owner-only 0600); a replaced file keeps
    /// its own.
    #[test]
    #[cfg(unix)]
    fn written_files_get_ordinary_or_kept_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let plain = dir.path().join("plain.bin");
        std::fs::write(&plain, b"x").unwrap();
        let dest = dir.path().join("out.bin");
        write(&dest, |w| {
            w.write_all(b"new").unwrap();
            Ok(())
        })
        .unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&dest), mode(&plain));
        std::fs::set_permissions(&dest, std::fs::Permissions::from_mode(0o640)).unwrap();
        write(&dest, |w| {
            w.write_all(b"newer").unwrap();
            Ok(())
        })
        .unwrap();
        assert_eq!(mode(&dest), 0o640);
    }

    #[test]
    fn staged_files_are_registered_until_committed_or_removed() {
        let dir = tempfile::tempdir().unwrap();
        let a = stage(&dir.path().join("a"), |w| {
            w.write_all(b"a").unwrap();
            Ok(())
        })
        .unwrap();
        let tmp_path = a.tmp.path().to_path_buf();
        assert!(live().paths.contains(&tmp_path));
        a.commit().unwrap();
        assert!(!live().paths.contains(&tmp_path));
    }

    /// `remove_temporary_files` closes the process for new temporary
    /// files, so it runs in a child process of its own (the test binary
    /// re-run on the ignored test below), never beside the other tests.
    #[test]
    fn removing_temporary_files_deletes_staged_ones_and_refuses_new_ones() {
        let out = std::process::Command::new(std::env::current_exe().unwrap())
            .args([
                "--exact",
                "io::atomic::tests::remove_temporary_files_in_a_child_process",
                "--ignored",
                "--test-threads=1",
            ])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{text}");
        assert!(text.contains("1 passed"), "the child test ran: {text}");
    }

    #[test]
    #[ignore = "run in a child process by the test above"]
    fn remove_temporary_files_in_a_child_process() {
        let dir = tempfile::tempdir().unwrap();
        let b = stage(&dir.path().join("b"), |w| {
            w.write_all(b"b").unwrap();
            Ok(())
        })
        .unwrap();
        let b_tmp = b.tmp.path().to_path_buf();
        remove_temporary_files();
        assert!(!b_tmp.exists(), "removed by the signal-handler path");
        drop(b);
        assert!(!dir.path().join("b").exists());
        let e = write(&dir.path().join("c"), |w| {
            w.write_all(b"c").unwrap();
            Ok(())
        });
        assert!(e.unwrap_err().to_string().contains("interrupted"));
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
