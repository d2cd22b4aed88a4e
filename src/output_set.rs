//! Output sets replaced as a whole: a command's outputs (a directory such as
//! `solve --out DIR`, or a few files such as `law --format all`) are written into a
//! fresh hidden staging directory beside the target and moved into place at the end,
//! under a lock, so that a reader finds the complete previous set or the complete new
//! one, never a mix.
//!
//! **Directory sets** ([`OutputSet::dir`]). Files go to `PARENT/.NAME.strata-new/`;
//! [`OutputSet::commit`] writes the manifest `.strata-set` (the list of the set's
//! files) into it, carries over what the previous directory holds that strata did not
//! write there (entries absent from its manifest, hard-linked, so a user's notes stay),
//! drops what the previous set had and the new one has not (an old `maps/`, old
//! plots), and swaps the two directories in one atomic `renameat2(RENAME_EXCHANGE)`
//! (Linux; elsewhere two renames, repaired by the next run if interrupted between
//! them). A directory holding the current working directory is refused.
//!
//! **File sets** ([`OutputSet::files`]: files of one directory, e.g. `law.csv`,
//! `law.json`, `law.inp`). Files go to `PARENT/.FIRST.strata-new/`; the commit writes
//! a journal (the list of files) and then renames the files into place one after the
//! other (microseconds apart). A run killed between those renames leaves the journal,
//! and the next run on the same output completes the renames before anything else
//! (roll forward), so the set that results is the complete new one.
//!
//! **Locks.** Every target has a lock file `PARENT/.NAME.strata-lock` (kept: removing
//! a lock file races with its next user); a second writer fails at once with a message
//! naming the output. Locks are released when the process ends, however it ends.
//!
//! **Failures.** An error before the commit removes the staging directory and leaves
//! the previous set untouched; a killed run leaves hidden staging debris beside the
//! target, which the next run on that target removes (or completes, see above). Debris
//! never blocks a run.
//!
//! **Test hook** (tests only): `STRATA_TEST_KILL_AT=write:K` kills the process
//! (SIGKILL) at the K-th output file, after writing half of it;
//! `STRATA_TEST_KILL_AT=commit:K` at the K-th step of the commit (directories: 1 after
//! the manifest, 2 after the carry-over, 3 after the swap; file sets: K−1 files
//! renamed).

use std::collections::BTreeSet;
use std::fs::{self, File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use thiserror::Error;

/// Name of the manifest of a directory set (one relative path per line after the
/// header line).
pub const MANIFEST: &str = ".strata-set";
/// Name of the commit journal of a file set (inside its staging directory).
const JOURNAL: &str = ".strata-commit";

/// Errors of output sets; each names the flag and the path concerned.
#[derive(Debug, Error)]
pub enum OutputSetError {
    #[error("{flag} {path}: exists and is not a directory")]
    NotADirectory { flag: &'static str, path: String },
    #[error("{flag} {path}: a directory is in the way of this output file")]
    IsADirectory { flag: &'static str, path: String },
    #[error(
        "{flag} {path}: directory is not empty (use --force to replace the outputs in it; files strata did not write there are kept)"
    )]
    NotEmpty { flag: &'static str, path: String },
    #[error("{flag} {path}: file exists (use --force to overwrite)")]
    Exists { flag: &'static str, path: String },
    #[error(
        "{flag} {path}: another strata process is writing this output (lock {lock} is held); wait for it to finish or choose another output"
    )]
    Busy {
        flag: &'static str,
        path: String,
        lock: String,
    },
    #[error(
        "{flag} {path}: is the current directory or one above it; strata replaces an output directory as a whole, so give a dedicated one (e.g. out/run1)"
    )]
    EnclosesCwd { flag: &'static str, path: String },
    #[error("{flag} {path} is also an input of this command ({what}); choose another path")]
    IsInput {
        flag: &'static str,
        path: String,
        what: String,
    },
    #[error("{flag} {path}: {reason}")]
    BadTarget {
        flag: &'static str,
        path: String,
        reason: &'static str,
    },
    #[error("{flag} {path}: {action}: {error}")]
    Io {
        flag: &'static str,
        path: String,
        action: String,
        error: std::io::Error,
    },
}

#[derive(Debug)]
enum Layout {
    /// A whole directory (absolute path).
    Dir { target: PathBuf },
    /// Named files of one directory (absolute), sorted.
    Files { dir: PathBuf, names: Vec<String> },
}

/// An output set being written (see the module docs). Dropping it without
/// [`commit`](Self::commit) discards the new files and keeps the previous set.
#[derive(Debug)]
pub struct OutputSet {
    flag: &'static str,
    shown: String,
    layout: Layout,
    staging: PathBuf,
    _locks: Vec<File>,
    committed: bool,
}

static WRITES: AtomicUsize = AtomicUsize::new(0);
static COMMITS: AtomicUsize = AtomicUsize::new(0);

/// The test hook (module docs): true when `STRATA_TEST_KILL_AT` names this point.
fn hook(kind: &str, counter: &AtomicUsize) -> bool {
    let k = counter.fetch_add(1, Ordering::SeqCst) + 1;
    std::env::var("STRATA_TEST_KILL_AT")
        .ok()
        .and_then(|v| {
            let (a, b) = v.split_once(':')?;
            Some(a == kind && b.trim().parse::<usize>().ok()? == k)
        })
        .unwrap_or(false)
}

/// Ends the process as `kill -9` would (the test hook).
fn die() -> ! {
    // SAFETY: kill(2) on our own pid with a valid signal number has no memory effects.
    unsafe {
        libc::kill(libc::getpid(), libc::SIGKILL);
    }
    std::process::abort()
}

fn hidden(dir: &Path, name: &str, suffix: &str) -> PathBuf {
    dir.join(format!(".{name}.strata-{suffix}"))
}

/// Swaps two directory entries atomically where the kernel and file system allow it.
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    use std::ffi::CString;
    use std::os::unix::ffi::OsStrExt;
    let ca = CString::new(a.as_os_str().as_bytes()).map_err(std::io::Error::other)?;
    let cb = CString::new(b.as_os_str().as_bytes()).map_err(std::io::Error::other)?;
    // SAFETY: both strings are valid NUL-terminated paths that outlive the call.
    let r = unsafe {
        libc::syscall(
            libc::SYS_renameat2,
            libc::AT_FDCWD,
            ca.as_ptr(),
            libc::AT_FDCWD,
            cb.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    if r == 0 {
        Ok(())
    } else {
        Err(std::io::Error::last_os_error())
    }
}

#[cfg(not(target_os = "linux"))]
fn exchange(_: &Path, _: &Path) -> std::io::Result<()> {
    Err(std::io::Error::from(std::io::ErrorKind::Unsupported))
}

fn sync_dir(dir: &Path) {
    // Durability only: a file system that cannot sync a directory still renamed it.
    if let Ok(f) = File::open(dir) {
        let _ = f.sync_all();
    }
}

/// Relative paths ('/'-separated) of the files below `root`, sorted.
fn walk(root: &Path) -> std::io::Result<Vec<String>> {
    fn go(root: &Path, rel: &str, out: &mut Vec<String>) -> std::io::Result<()> {
        for e in fs::read_dir(root.join(rel))? {
            let e = e?;
            let name = e.file_name().to_string_lossy().into_owned();
            let r = if rel.is_empty() {
                name
            } else {
                format!("{rel}/{name}")
            };
            if e.file_type()?.is_dir() {
                go(root, &r, out)?;
            } else {
                out.push(r);
            }
        }
        Ok(())
    }
    let mut out = Vec::new();
    go(root, "", &mut out)?;
    out.sort();
    Ok(out)
}

/// Recreates `src` at `dst` with hard links (copies where linking fails).
fn link_tree(src: &Path, dst: &Path) -> std::io::Result<()> {
    let meta = fs::symlink_metadata(src)?;
    if meta.file_type().is_symlink() {
        #[cfg(unix)]
        return std::os::unix::fs::symlink(fs::read_link(src)?, dst);
        #[cfg(not(unix))]
        return fs::copy(src, dst).map(|_| ());
    }
    if meta.is_dir() {
        fs::create_dir(dst)?;
        for e in fs::read_dir(src)? {
            let e = e?;
            link_tree(&e.path(), &dst.join(e.file_name()))?;
        }
        return Ok(());
    }
    if fs::hard_link(src, dst).is_err() {
        fs::copy(src, dst)?;
    }
    Ok(())
}

/// Top-level names the manifest of `dir` says strata wrote (empty without one).
fn owned_names(dir: &Path) -> BTreeSet<String> {
    let mut owned = BTreeSet::new();
    if let Ok(text) = fs::read_to_string(dir.join(MANIFEST)) {
        owned.insert(MANIFEST.to_string());
        for line in text.lines().filter(|l| !l.starts_with('#')) {
            if let Some(first) = line.split('/').next().filter(|s| !s.is_empty()) {
                owned.insert(first.to_string());
            }
        }
    }
    owned
}

/// An I/O error of output `shown` while doing `action`, for `map_err`.
fn io_error(
    flag: &'static str,
    shown: &str,
    action: &str,
) -> impl FnOnce(std::io::Error) -> OutputSetError + use<> {
    let (path, action) = (shown.to_string(), action.to_string());
    move |error| OutputSetError::Io {
        flag,
        path,
        action,
        error,
    }
}

fn bad_target(flag: &'static str, shown: &str, reason: &'static str) -> OutputSetError {
    OutputSetError::BadTarget {
        flag,
        path: shown.to_string(),
        reason,
    }
}

/// Where an output at `abs` is written: through a symbolic link to its target (a link
/// is never replaced: `--out /dev/stdout` or a link into another directory writes where
/// it points), refusing a dangling link and anything but a regular file or directory (a
/// device, FIFO or socket, e.g. `/dev/full` or `/proc/self/fd/1`: strata replaces
/// outputs by renaming, which would replace the node itself).
fn resolve_output(
    flag: &'static str,
    shown: &str,
    abs: PathBuf,
) -> Result<PathBuf, OutputSetError> {
    let Ok(meta) = fs::symlink_metadata(&abs) else {
        return Ok(abs);
    };
    let target = if meta.file_type().is_symlink() {
        abs.canonicalize().map_err(|_| {
            bad_target(
                flag,
                shown,
                "is a symbolic link whose target does not exist (strata writes through links and never replaces them)",
            )
        })?
    } else {
        abs
    };
    match fs::metadata(&target) {
        Ok(m) if !(m.file_type().is_file() || m.file_type().is_dir()) => Err(bad_target(
            flag,
            shown,
            "is a device, FIFO or socket: strata writes regular files and directories only",
        )),
        _ => Ok(target),
    }
}

/// Refuses an output `out` (as given on the command line) that is also an input of the
/// same command, before any work: `inputs` are (what it is, e.g. "the scene"; path).
/// Paths are compared after canonicalisation, so a file reached through a symbolic link
/// or `./` is the same file (an output is written through links, see `resolve_output`);
/// a hard link is a different name that the rename of the commit leaves alone. For an
/// output directory, an input inside it is refused too when the previous set's manifest
/// says strata wrote it there (e.g. a surface read from `OUT/maps/`): `--force` would
/// replace or remove it; files the user put there are kept, so they may be inputs.
pub fn refuse_inputs(
    flag: &'static str,
    out: &Path,
    inputs: &[(String, PathBuf)],
) -> Result<(), OutputSetError> {
    let Ok(target) = out.canonicalize() else {
        return Ok(()); // nothing there yet: no input can be it
    };
    let owned = if target.is_dir() {
        owned_names(&target)
    } else {
        BTreeSet::new()
    };
    for (what, p) in inputs {
        let Ok(input) = p.canonicalize() else {
            continue;
        };
        let replaced = input == target
            || input
                .strip_prefix(&target)
                .ok()
                .and_then(|rel| rel.components().next())
                .is_some_and(|c| owned.contains(&*c.as_os_str().to_string_lossy()));
        if replaced {
            return Err(OutputSetError::IsInput {
                flag,
                path: out.display().to_string(),
                what: what.clone(),
            });
        }
    }
    Ok(())
}

impl OutputSet {
    fn io(&self, action: impl Into<String>) -> impl FnOnce(std::io::Error) -> OutputSetError {
        io_error(self.flag, &self.shown, &action.into())
    }

    /// Starts a directory set at `target` (`flag` names the option in messages). An
    /// existing non-empty directory needs `force`.
    pub fn dir(flag: &'static str, target: &Path, force: bool) -> Result<Self, OutputSetError> {
        let shown = target.display().to_string();
        let io = |action: &str| io_error(flag, &shown, action);
        let bad = |reason| bad_target(flag, &shown, reason);
        let abs = std::path::absolute(target).map_err(io("resolving the path"))?;
        let abs = resolve_output(flag, &shown, abs)?;
        if let (Ok(cwd), Ok(t)) = (
            std::env::current_dir().and_then(|c| c.canonicalize()),
            abs.canonicalize(),
        ) && cwd.starts_with(&t)
        {
            return Err(OutputSetError::EnclosesCwd { flag, path: shown });
        }
        let name = abs
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .filter(|n| n != "..")
            .ok_or_else(|| bad("not a directory name"))?;
        let parent = abs
            .parent()
            .ok_or_else(|| bad("has no parent directory"))?
            .to_path_buf();
        fs::create_dir_all(&parent).map_err(io("creating its parent directory"))?;
        let lock = lock(flag, &shown, &parent, &name)?;
        let new = hidden(&parent, &name, "new");
        let old = hidden(&parent, &name, "old");
        // Repair a run killed inside its commit (two-rename fallback), then clear debris.
        if old.exists() {
            if !abs.exists() {
                let from = if new.join(MANIFEST).is_file() {
                    &new
                } else {
                    &old
                };
                fs::rename(from, &abs).map_err(io("restoring after an interrupted run"))?;
            }
            if old.exists() {
                fs::remove_dir_all(&old).map_err(io("removing an interrupted run's files"))?;
            }
        }
        if new.exists() {
            fs::remove_dir_all(&new).map_err(io("removing an interrupted run's files"))?;
        }
        if abs.exists() {
            if !abs.is_dir() {
                return Err(OutputSetError::NotADirectory { flag, path: shown });
            }
            let non_empty = fs::read_dir(&abs)
                .map_err(io("reading the directory"))?
                .next()
                .is_some();
            if non_empty && !force {
                return Err(OutputSetError::NotEmpty { flag, path: shown });
            }
        }
        fs::create_dir(&new).map_err(io("creating the staging directory"))?;
        Ok(OutputSet {
            flag,
            shown,
            layout: Layout::Dir { target: abs },
            staging: new,
            _locks: vec![lock],
            committed: false,
        })
    }

    /// Starts a set of files in one directory (`paths` must share it). Existing files
    /// need `force`.
    pub fn files(
        flag: &'static str,
        paths: &[PathBuf],
        force: bool,
    ) -> Result<Self, OutputSetError> {
        let shown = paths
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ");
        let io = |action: &str| io_error(flag, &shown, action);
        let bad = |reason| bad_target(flag, &shown, reason);
        let mut dir: Option<PathBuf> = None;
        let mut names = Vec::new();
        for p in paths {
            let abs = std::path::absolute(p).map_err(io("resolving the path"))?;
            let abs = resolve_output(flag, &shown, abs)?;
            let name = abs
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .filter(|n| n != "..")
                .ok_or_else(|| bad("not a file name"))?;
            let parent = abs
                .parent()
                .ok_or_else(|| bad("has no parent directory"))?
                .to_path_buf();
            match &dir {
                None => dir = Some(parent),
                Some(d) if *d != parent => return Err(bad("the files must share one directory")),
                _ => {}
            }
            names.push(name);
        }
        names.sort();
        names.dedup();
        let dir = dir.ok_or_else(|| bad("no file given"))?;
        fs::create_dir_all(&dir).map_err(io("creating the directory"))?;
        let mut locks = Vec::new();
        for n in &names {
            locks.push(lock(flag, &shown, &dir, n)?);
        }
        // Complete a commit a killed run left half done, then clear debris.
        for n in &names {
            let st = hidden(&dir, n, "new");
            if !st.exists() {
                continue;
            }
            if let Ok(journal) = fs::read_to_string(st.join(JOURNAL)) {
                let listed: Vec<&str> = journal.lines().filter(|l| !l.is_empty()).collect();
                if listed.iter().all(|l| names.iter().any(|n| n == l)) {
                    for l in listed {
                        let from = st.join(l);
                        if from.exists() {
                            fs::rename(&from, dir.join(l))
                                .map_err(io("completing an interrupted run"))?;
                        }
                    }
                }
            }
            fs::remove_dir_all(&st).map_err(io("removing an interrupted run's files"))?;
        }
        for n in &names {
            let p = dir.join(n);
            if p.is_dir() {
                return Err(OutputSetError::IsADirectory {
                    flag,
                    path: p.display().to_string(),
                });
            }
            if p.exists() && !force {
                return Err(OutputSetError::Exists {
                    flag,
                    path: p.display().to_string(),
                });
            }
        }
        let staging = hidden(&dir, &names[0], "new");
        fs::create_dir(&staging).map_err(io("creating the staging directory"))?;
        Ok(OutputSet {
            flag,
            shown,
            layout: Layout::Files { dir, names },
            staging,
            _locks: locks,
            committed: false,
        })
    }

    /// A single output file: [`files`](Self::files) with one path.
    pub fn file(flag: &'static str, path: &Path, force: bool) -> Result<Self, OutputSetError> {
        Self::files(flag, &[path.to_path_buf()], force)
    }

    /// The staging directory (writers that fill a directory themselves).
    pub fn root(&self) -> &Path {
        &self.staging
    }

    /// Where to write the set's file `rel` (a path relative to the set's directory,
    /// '/'-separated; for a file set, one of its file names). Creates parent
    /// directories; counts one output file for the test hook (killed before writing).
    pub fn path(&self, rel: &str) -> Result<PathBuf, OutputSetError> {
        if hook("write", &WRITES) {
            die();
        }
        self.staged(rel)
    }

    fn staged(&self, rel: &str) -> Result<PathBuf, OutputSetError> {
        if let Layout::Files { names, .. } = &self.layout
            && !names.iter().any(|n| n == rel)
        {
            return Err(OutputSetError::BadTarget {
                flag: self.flag,
                path: rel.to_string(),
                reason: "internal error: not a file of this output set",
            });
        }
        let p = self.staging.join(rel);
        if let Some(d) = p.parent() {
            fs::create_dir_all(d).map_err(self.io(format!("creating {}", d.display())))?;
        }
        Ok(p)
    }

    /// Writes the set's file `rel` (see [`path`](Self::path)).
    pub fn write(&self, rel: &str, bytes: &[u8]) -> Result<(), OutputSetError> {
        let kill = hook("write", &WRITES);
        let p = self.staged(rel)?;
        let mut f = File::create(&p).map_err(self.io(format!("writing {rel}")))?;
        if kill {
            let _ = f.write_all(&bytes[..bytes.len() / 2]);
            let _ = f.flush();
            die();
        }
        f.write_all(bytes)
            .and_then(|()| f.flush())
            .map_err(self.io(format!("writing {rel}")))
    }

    fn commit_hook() {
        if hook("commit", &COMMITS) {
            die();
        }
    }

    /// Moves the new set into place (see the module docs) and releases the lock.
    pub fn commit(mut self) -> Result<(), OutputSetError> {
        let files = walk(&self.staging).map_err(self.io("listing the new files"))?;
        for f in &files {
            File::open(self.staging.join(f))
                .and_then(|h| h.sync_all())
                .map_err(self.io(format!("syncing {f}")))?;
        }
        match &self.layout {
            Layout::Dir { target } => self.commit_dir(target.clone(), &files)?,
            Layout::Files { dir, .. } => self.commit_files(dir.clone(), &files)?,
        }
        self.committed = true;
        Ok(())
    }

    fn commit_dir(&self, target: PathBuf, files: &[String]) -> Result<(), OutputSetError> {
        let mut manifest = format!(
            "# strata {} output set: the files below were written by one run; anything else here is yours and is kept\n",
            env!("CARGO_PKG_VERSION")
        );
        for f in files {
            manifest.push_str(f);
            manifest.push('\n');
        }
        let mp = self.staging.join(MANIFEST);
        fs::write(&mp, manifest)
            .and_then(|()| File::open(&mp)?.sync_all())
            .map_err(self.io("writing the manifest"))?;
        Self::commit_hook();
        let parent = target.parent().map(Path::to_path_buf).unwrap_or_default();
        if target.exists() {
            let owned = owned_names(&target);
            for e in fs::read_dir(&target).map_err(self.io("reading the previous outputs"))? {
                let e = e.map_err(self.io("reading the previous outputs"))?;
                let name = e.file_name().to_string_lossy().into_owned();
                let dst = self.staging.join(&name);
                if owned.contains(&name) || fs::symlink_metadata(&dst).is_ok() {
                    continue; // the previous set's, or replaced by the new set
                }
                link_tree(&e.path(), &dst).map_err(self.io(format!("keeping {name}")))?;
            }
            Self::commit_hook();
            sync_dir(&self.staging);
            match exchange(&self.staging, &target) {
                Ok(()) => {
                    Self::commit_hook();
                    sync_dir(&parent);
                    // The staging path now holds the previous set.
                    fs::remove_dir_all(&self.staging)
                        .map_err(self.io("removing the previous outputs"))?;
                }
                Err(_) => {
                    let name = target
                        .file_name()
                        .map(|n| n.to_string_lossy().into_owned())
                        .unwrap_or_default();
                    let old = hidden(&parent, &name, "old");
                    fs::rename(&target, &old).map_err(self.io("moving the previous outputs"))?;
                    Self::commit_hook();
                    fs::rename(&self.staging, &target)
                        .map_err(self.io("moving the new outputs into place"))?;
                    sync_dir(&parent);
                    fs::remove_dir_all(&old).map_err(self.io("removing the previous outputs"))?;
                }
            }
        } else {
            Self::commit_hook();
            sync_dir(&self.staging);
            fs::rename(&self.staging, &target)
                .map_err(self.io("moving the new outputs into place"))?;
            sync_dir(&parent);
        }
        Ok(())
    }

    fn commit_files(&self, dir: PathBuf, files: &[String]) -> Result<(), OutputSetError> {
        let jp = self.staging.join(JOURNAL);
        fs::write(&jp, files.join("\n"))
            .and_then(|()| File::open(&jp)?.sync_all())
            .map_err(self.io("writing the commit journal"))?;
        sync_dir(&self.staging);
        for f in files {
            Self::commit_hook();
            fs::rename(self.staging.join(f), dir.join(f))
                .map_err(self.io(format!("moving {f} into place")))?;
        }
        sync_dir(&dir);
        fs::remove_dir_all(&self.staging).map_err(self.io("removing the staging directory"))?;
        Ok(())
    }
}

impl Drop for OutputSet {
    fn drop(&mut self) {
        if !self.committed {
            // Best effort: debris left here is removed by the next run on this target.
            let _ = fs::remove_dir_all(&self.staging);
        }
    }
}

fn lock(flag: &'static str, shown: &str, dir: &Path, name: &str) -> Result<File, OutputSetError> {
    let path = hidden(dir, name, "lock");
    let f = OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&path)
        .map_err(io_error(
            flag,
            shown,
            &format!("creating the lock file {}", path.display()),
        ))?;
    // A lock released a moment ago can still look held: a thread of this process that
    // forks (a test harness, a host embedding strata) shares the descriptor with the
    // child until the child's exec closes it. A writer that really holds the output
    // holds it for its whole run, so a short retry (≤ 0.1 s) tells the two apart.
    let mut tries = 0;
    let held = loop {
        match f.try_lock() {
            Err(fs::TryLockError::WouldBlock) if tries < 20 => {
                tries += 1;
                std::thread::sleep(std::time::Duration::from_millis(5));
            }
            other => break other,
        }
    };
    match held {
        Ok(()) => Ok(f),
        Err(fs::TryLockError::WouldBlock) => Err(OutputSetError::Busy {
            flag,
            path: shown.to_string(),
            lock: path.display().to_string(),
        }),
        Err(fs::TryLockError::Error(error)) => Err(io_error(
            flag,
            shown,
            &format!("locking {}", path.display()),
        )(error)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("strata-set-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        d
    }

    fn listing(dir: &Path) -> Vec<String> {
        walk(dir).unwrap()
    }

    /// A directory set replaces the previous set as a whole: stale files go, the
    /// user's own files stay, nothing is left beside the target.
    /// Devices and FIFOs are refused and left as they are (`law --out /dev/full
    /// --force` as root replaced the device node by a regular file); a symlinked output
    /// file or directory is written through, the link kept; a dangling link is refused.
    #[test]
    fn links_are_written_through_and_devices_refused() {
        let root = tmp("links");
        fs::create_dir_all(&root).unwrap();
        // a character device
        for force in [false, true] {
            let e = OutputSet::file("--out", Path::new("/dev/null"), force).expect_err("refused");
            assert!(e.to_string().contains("device, FIFO or socket"), "{e}");
        }
        assert!(!fs::metadata("/dev/null").unwrap().file_type().is_file());
        // a FIFO
        let fifo = root.join("fifo");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let e = OutputSet::file("--out", &fifo, true).expect_err("refused");
            assert!(e.to_string().contains("device, FIFO or socket"), "{e}");
            use std::os::unix::fs::FileTypeExt;
            assert!(fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
        }
        // a link to a file in another directory
        let other = root.join("other");
        fs::create_dir_all(&other).unwrap();
        fs::write(other.join("law.csv"), b"old").unwrap();
        let link = root.join("law.csv");
        std::os::unix::fs::symlink(other.join("law.csv"), &link).unwrap();
        let set = OutputSet::file("--out", &link, true).unwrap();
        set.write("law.csv", b"new").unwrap();
        set.commit().unwrap();
        assert!(
            fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(fs::read(other.join("law.csv")).unwrap(), b"new");
        // a link to a directory
        let target = root.join("target-dir");
        fs::create_dir_all(&target).unwrap();
        let dlink = root.join("out-link");
        std::os::unix::fs::symlink(&target, &dlink).unwrap();
        let set = OutputSet::dir("--out", &dlink, true).unwrap();
        set.write("curve.csv", b"x").unwrap();
        set.commit().unwrap();
        assert!(
            fs::symlink_metadata(&dlink)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(fs::read(target.join("curve.csv")).unwrap(), b"x");
        // a dangling link
        let dangling = root.join("dangling");
        std::os::unix::fs::symlink(root.join("missing/nowhere"), &dangling).unwrap();
        let e = OutputSet::dir("--out", &dangling, true).expect_err("refused");
        assert!(e.to_string().contains("does not exist"), "{e}");
        assert!(
            fs::symlink_metadata(&dangling)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        fs::remove_dir_all(&root).ok();
    }

    #[test]
    fn directory_set_replaces_the_previous_one() {
        let d = tmp("dir");
        let out = d.join("out");
        let s = OutputSet::dir("--out", &out, false).unwrap();
        s.write("curve.csv", b"one\n").unwrap();
        s.write("maps/m0.npy", b"map").unwrap();
        s.commit().unwrap();
        fs::write(out.join("notes.txt"), "mine").unwrap();
        let e = OutputSet::dir("--out", &out, false)
            .unwrap_err()
            .to_string();
        assert!(e.contains("--force"), "{e}");
        let s = OutputSet::dir("--out", &out, true).unwrap();
        // A second writer fails at once, naming the output.
        let busy = OutputSet::dir("--out", &out, true).unwrap_err().to_string();
        assert!(
            busy.contains("another strata process") && busy.contains("out"),
            "{busy}"
        );
        s.write("curve.csv", b"two\n").unwrap();
        s.commit().unwrap();
        assert_eq!(listing(&out), [MANIFEST, "curve.csv", "notes.txt"]);
        assert_eq!(fs::read(out.join("curve.csv")).unwrap(), b"two\n");
        let beside: Vec<String> = fs::read_dir(&d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert!(
            beside
                .iter()
                .all(|n| n == "out" || n.ends_with(".strata-lock")),
            "{beside:?}"
        );
        // A run that fails (dropped without commit) changes nothing.
        let s = OutputSet::dir("--out", &out, true).unwrap();
        s.write("curve.csv", b"three\n").unwrap();
        drop(s);
        assert_eq!(fs::read(out.join("curve.csv")).unwrap(), b"two\n");
        assert!(!hidden(&d, "out", "new").exists());
        fs::remove_dir_all(&d).unwrap();
    }

    /// Debris of a killed run (staging with and without manifest, the fallback's
    /// `.old` directory with the target missing) is repaired by the next run.
    #[test]
    fn interrupted_commits_are_repaired() {
        let d = tmp("repair");
        let out = d.join("out");
        // Killed between the two renames of the fallback, staging complete: roll forward.
        fs::create_dir_all(hidden(&d, "out", "old")).unwrap();
        fs::write(hidden(&d, "out", "old").join("curve.csv"), "old").unwrap();
        fs::create_dir_all(hidden(&d, "out", "new")).unwrap();
        fs::write(hidden(&d, "out", "new").join("curve.csv"), "new").unwrap();
        fs::write(hidden(&d, "out", "new").join(MANIFEST), "#\ncurve.csv\n").unwrap();
        let s = OutputSet::dir("--out", &out, true).unwrap();
        assert_eq!(fs::read(out.join("curve.csv")).unwrap(), b"new");
        drop(s);
        // Staging incomplete: roll back.
        fs::rename(&out, hidden(&d, "out", "old")).unwrap();
        fs::create_dir_all(hidden(&d, "out", "new")).unwrap();
        fs::write(hidden(&d, "out", "new").join("curve.csv"), "partial").unwrap();
        let s = OutputSet::dir("--out", &out, true).unwrap();
        assert_eq!(fs::read(out.join("curve.csv")).unwrap(), b"new");
        drop(s);
        assert!(!hidden(&d, "out", "old").exists() && !hidden(&d, "out", "new").exists());
        fs::remove_dir_all(&d).unwrap();
    }

    /// A file set commits every file; a journal left by a killed commit is completed
    /// by the next run; existing files need force; a directory in the way is refused.
    #[test]
    fn file_sets_commit_and_roll_forward() {
        let d = tmp("files");
        let paths: Vec<PathBuf> = ["law.csv", "law.json"].iter().map(|n| d.join(n)).collect();
        let s = OutputSet::files("--out", &paths, false).unwrap();
        s.write("law.csv", b"c1").unwrap();
        s.write("law.json", b"j1").unwrap();
        assert!(s.write("other.txt", b"x").is_err());
        s.commit().unwrap();
        let e = OutputSet::files("--out", &paths, false)
            .unwrap_err()
            .to_string();
        assert!(e.contains("law.csv") && e.contains("--force"), "{e}");
        // A killed commit: csv moved, json still staged, journal present.
        let st = hidden(&d, "law.csv", "new");
        fs::create_dir_all(&st).unwrap();
        fs::write(st.join("law.json"), "j2").unwrap();
        fs::write(st.join(JOURNAL), "law.csv\nlaw.json").unwrap();
        fs::write(d.join("law.csv"), "c2").unwrap();
        let s = OutputSet::files("--out", &paths, true).unwrap();
        assert_eq!(fs::read(d.join("law.json")).unwrap(), b"j2");
        drop(s);
        assert!(!st.exists());
        fs::create_dir_all(d.join("t.strata")).unwrap();
        let e = OutputSet::file("--out", &d.join("t.strata"), true)
            .unwrap_err()
            .to_string();
        assert!(e.contains("directory is in the way"), "{e}");
        fs::remove_dir_all(&d).unwrap();
    }
}
