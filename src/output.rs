//! All-or-nothing output that holds under SIGKILL and concurrent writers.
//!
//! Each command publishes one *set* of files, `<dir>/<set>` (e.g.
//! `output/seed/run`), an ordinary folder: `cp -r` and `tar` copy it whole.
//! It is written completely in a hidden staging folder `<dir>/.<set>.<id>`
//! first and then swapped in with one `renameat2(RENAME_EXCHANGE)` (Linux), which
//! exchanges the two names atomically: a reader sees the old set or the new
//! one, never a mix, and the set never goes missing. The old set, now under
//! the hidden name, is removed. Commands have separate sets, so `optimize`
//! never overwrites the files `run` described in its summary.
//!
//! Where the exchange is not available (other systems, file systems without
//! it) the set is a symbolic link to its hidden folder, switched with
//! `rename(2)`, which replaces a link atomically.
//!
//! While a process stages, it holds an advisory lock on `<dir>/.<set>.<id>.lock`;
//! the lock dies with the process (also under SIGKILL), so the next command
//! knows a staging folder without a held lock is a leftover and removes it.
//! Hidden names are never taken for results; a published folder carries the
//! hidden marker file [`MARKER`], so that catflip never replaces a folder it
//! did not write.

use crate::error::{Error, Result};
use std::fs::{self, File, OpenOptions};
use std::path::{Path, PathBuf};

/// `s` as one CSV field (RFC 4180): quoted, its quotes doubled, when it
/// holds a comma, a quote or a line break, so that a reason keeps its own
/// punctuation and any CSV reader gets it back whole.
pub fn csv_field(s: &str) -> std::borrow::Cow<'_, str> {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\"")).into()
    } else {
        s.into()
    }
}

/// The paths (`a.b[2]`) of the nulls in a JSON value: the NaN and infinite
/// numbers serde_json writes as null. Empty when every number is finite.
pub fn null_numbers(v: &serde_json::Value) -> Vec<String> {
    fn walk(v: &serde_json::Value, at: String, out: &mut Vec<String>) {
        match v {
            serde_json::Value::Null => out.push(at),
            serde_json::Value::Array(xs) => {
                for (i, x) in xs.iter().enumerate() {
                    walk(x, format!("{at}[{i}]"), out)
                }
            }
            serde_json::Value::Object(m) => {
                for (k, x) in m {
                    let key = if at.is_empty() {
                        k.clone()
                    } else {
                        format!("{at}.{k}")
                    };
                    walk(x, key, out)
                }
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk(v, String::new(), &mut out);
    out
}

/// Refuses a JSON result with a null (NaN or infinite) number among `fields`
/// (all of them when `fields` is empty): catflip never reports success with one.
pub fn ensure_finite(v: &serde_json::Value, fields: &[&str]) -> Result<()> {
    let nulls: Vec<String> = null_numbers(v)
        .into_iter()
        .filter(|p| {
            fields.is_empty()
                || fields
                    .iter()
                    .any(|f| p == f || p.starts_with(&format!("{f}[")))
        })
        .collect();
    if nulls.is_empty() {
        Ok(())
    } else {
        Err(Error::NonFinite {
            fields: nulls.join(", "),
        })
    }
}

/// The set a command publishes with `--set` overrides: `<base>@<overrides>`
/// (e.g. `run@cat.joint=no-twist`), so that runs of one config with other
/// overrides keep their own reports side by side; `<base>` without any.
/// Spaces around each key and value are dropped, other characters than
/// letters, digits and `._=,+-` become `_`; a long
/// name keeps its first 80 characters and a hash of the whole.
pub fn set_name(base: &str, overrides: &[String]) -> String {
    if overrides.is_empty() {
        return base.to_string();
    }
    // (`--set "k = v"` and `--set k=v` are one config: one set)
    let all = overrides
        .iter()
        .map(|o| match o.split_once('=') {
            Some((k, v)) => format!("{}={}", k.trim(), v.trim()),
            None => o.trim().to_string(),
        })
        .collect::<Vec<_>>()
        .join(",");
    let slug: String = all
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "._=,+-".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    if slug.len() <= 100 {
        return format!("{base}@{slug}");
    }
    // FNV-1a: stable across runs and builds, unlike std's hasher
    let hash = all.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    });
    format!("{base}@{}~{hash:016x}", &slug[..80])
}

/// Files to write into one set, kept in memory until published.
#[derive(Debug, Default)]
pub struct Output {
    files: Vec<(String, Vec<u8>)>,
}

impl Output {
    pub fn add(&mut self, name: impl Into<String>, contents: impl Into<Vec<u8>>) {
        self.files.push((name.into(), contents.into()));
    }

    /// Replaces `from` by `to` in the text file `name`, if it was added
    /// (the CLI naming the user's own config where the library wrote a
    /// placeholder).
    pub fn replace_in(&mut self, name: &str, from: &str, to: &str) {
        for (n, contents) in &mut self.files {
            if n == name
                && let Ok(text) = std::str::from_utf8(contents)
                && text.contains(from)
            {
                *contents = text.replace(from, to).into_bytes();
            }
        }
    }

    /// Names of the files added so far.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.files.iter().map(|f| f.0.as_str())
    }

    /// The files added so far, name and contents (for a caller that keeps
    /// them in memory, such as the Python package's `run`).
    pub fn files(&self) -> impl Iterator<Item = (&str, &[u8])> {
        self.files.iter().map(|f| (f.0.as_str(), f.1.as_slice()))
    }

    /// Stages and publishes in one go as the set `set_path` (`<dir>/<set>`).
    /// Commands that compute for long should call [`Publisher::begin`] first,
    /// so that an unwritable folder is reported before the work.
    pub fn commit(self, set_path: &Path) -> Result<Vec<PathBuf>> {
        let (dir, set) = split_set(set_path)?;
        Publisher::begin(&dir, &set)?.publish(self)
    }
}

fn split_set(set_path: &Path) -> Result<(PathBuf, String)> {
    let set = set_path
        .file_name()
        .and_then(|s| s.to_str())
        .ok_or_else(|| Error::OutputDir {
            path: set_path.to_path_buf(),
            message: "not a folder name".into(),
        })?;
    let dir = set_path.parent().unwrap_or(Path::new("."));
    Ok((dir.to_path_buf(), set.to_string()))
}

/// A set being staged: created by [`Publisher::begin`] (which checks the folder
/// is writable), finished by [`Publisher::publish`]. Dropped unpublished, it
/// removes its staging folder and any folders it created.
#[derive(Debug)]
pub struct Publisher {
    dir: PathBuf,
    set: String,
    id: String,
    /// Held for the whole staging; released when dropped.
    _lock: File,
    /// Folders `begin` created, innermost last.
    created: Vec<PathBuf>,
    published: bool,
    /// Published by exchange: the set is a folder, the staging name is gone.
    exchanged: bool,
    /// Publish by the link scheme even where the exchange works (tests of the fallback).
    links_only: bool,
}

/// This process's sets not published yet, by staging id: their staging
/// folder, lock file and the folders `begin` created (what an interrupted
/// command removes, [`abandon_unpublished`]). A publish holds it while it
/// switches the set, so that an interrupt sees a set either whole or not begun.
static UNPUBLISHED: std::sync::Mutex<Vec<Unpublished>> = std::sync::Mutex::new(Vec::new());

/// A staging id, its staging folder and lock file, and the folders created for it.
type Unpublished = (String, [PathBuf; 2], Vec<PathBuf>);

fn unpublished() -> std::sync::MutexGuard<'static, Vec<Unpublished>> {
    UNPUBLISHED.lock().unwrap_or_else(|p| p.into_inner())
}

/// Removes the staging folders, lock files and created folders of this
/// process's unpublished sets, and ends the process with `status` while
/// still holding the registry, so that no publish starts after (what a
/// command that does not publish a partial set does on SIGINT or SIGTERM).
pub fn abandon_unpublished(status: i32, message: &str) -> ! {
    let sets = unpublished();
    for (_, [staging, lock], created) in sets.iter() {
        let _ = fs::remove_dir_all(staging);
        let _ = fs::remove_file(lock);
        remove_created(created);
    }
    eprintln!("{message}");
    std::process::exit(status)
}

/// The hidden file that marks a folder as a set catflip published.
pub const MARKER: &str = ".catflip-set";
const MARKER_TEXT: &str = "A set of files published by catflip; its next run of the same command replaces the folder whole.\n";

impl Publisher {
    /// Prepares the set `<dir>/<set>`: creates `dir` if needed, checks it takes
    /// files, removes leftovers of killed commands and opens a private staging folder.
    pub fn begin(dir: &Path, set: &str) -> Result<Publisher> {
        let oerr = |path: &Path, e: std::io::Error| Error::OutputDir {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        let created = create_dirs(dir).map_err(|(p, e)| {
            // a file where a folder must be: named, not the path below it
            match p.ancestors().find(|a| a.is_file()) {
                Some(file) => Error::OutputDir {
                    path: file.to_path_buf(),
                    message: "is a file, not a folder".into(),
                },
                None => oerr(&p, e),
            }
        })?;
        let (lock, id) = new_lock(dir, set).map_err(|e| {
            remove_created(&created);
            oerr(dir, e)
        })?;
        let p = Publisher {
            dir: dir.to_path_buf(),
            set: set.to_string(),
            id,
            _lock: lock,
            created,
            published: false,
            exchanged: false,
            links_only: false,
        };
        if let Ok(m) = fs::symlink_metadata(p.link())
            && !m.file_type().is_symlink()
            && !(m.is_dir() && p.link().join(MARKER).is_file())
        {
            return Err(Error::OutputDir {
                path: p.link(),
                message: format!(
                    "exists and is not a set published by catflip (a folder holding {MARKER}, or a link to a hidden folder); move it away"
                ),
            });
        }
        fs::create_dir(p.staging()).map_err(|e| oerr(&p.staging(), e))?;
        unpublished().push((
            p.id.clone(),
            [p.staging(), p.lock_path(&p.id)],
            p.created.clone(),
        ));
        p.remove_leftovers();
        Ok(p)
    }

    /// The published path `<dir>/<set>`.
    pub fn link(&self) -> PathBuf {
        self.dir.join(&self.set)
    }

    fn staging(&self) -> PathBuf {
        self.dir.join(self.folder_name(&self.id))
    }

    /// The hidden folder of the set staged by `id`: `.<set>.<id>` (the
    /// link's target, relative to `dir`).
    fn folder_name(&self, id: &str) -> String {
        format!(".{}.{id}", self.set)
    }

    /// Writes every file into the staging folder, then switches the link to it.
    /// Returns the files' published paths.
    pub fn publish(mut self, out: Output) -> Result<Vec<PathBuf>> {
        {
            // an interrupt waits for the switch (and finds the set gone from the list)
            let mut sets = unpublished();
            self.switch(&out)?;
            sets.retain(|(id, ..)| *id != self.id);
        }
        self.retire();
        Ok(out.files.iter().map(|(n, _)| self.link().join(n)).collect())
    }

    /// Writes the files and puts the staging folder in the set's place.
    fn switch(&mut self, out: &Output) -> Result<()> {
        let staging = self.staging();
        let marker = [(MARKER.to_string(), MARKER_TEXT.as_bytes().to_vec())];
        for (name, bytes) in out.files.iter().chain(&marker) {
            let path = staging.join(name);
            fs::write(&path, bytes).map_err(|e| Error::Write {
                path: self.link().join(name),
                message: e.to_string(),
            })?;
        }
        let werr = |e: std::io::Error| Error::Write {
            path: self.link(),
            message: e.to_string(),
        };
        let exchanged = if self.links_only {
            Ok(false)
        } else {
            exchange::publish(&staging, &self.link())
        };
        match exchanged {
            Ok(true) => {
                // the staging name now holds the set we replaced, if any
                // (a folder, or the link of the fallback scheme)
                match fs::symlink_metadata(&staging) {
                    Ok(m) if m.is_dir() => {
                        let _ = fs::remove_dir_all(&staging);
                    }
                    Ok(_) => {
                        let _ = fs::remove_file(&staging);
                    }
                    Err(_) => {}
                }
                self.published = true;
                self.exchanged = true;
                return Ok(());
            }
            Ok(false) => {}
            Err(e) => return Err(werr(e)),
        }
        let own = self.folder_name(&self.id);
        let tmp_link = self.dir.join(format!("{own}.link"));
        let _ = fs::remove_file(&tmp_link);
        symlink(Path::new(&own), &tmp_link).map_err(werr)?;
        fs::rename(&tmp_link, self.link()).map_err(|e| {
            let _ = fs::remove_file(&tmp_link);
            werr(e)
        })?;
        self.published = true;
        Ok(())
    }

    /// After [`Publisher::switch`]: removes the lock file and the superseded
    /// sets, this one included if another writer switched the link
    /// meanwhile. The lock itself stays held until the publisher drops, after
    /// this: a writer that finds our lock file still locked skips our set,
    /// and then this check, which comes after its switch, removes it.
    fn retire(&self) {
        // the link is switched before the lock goes: a set without a lock file
        // is either the link's target or superseded
        let _ = fs::remove_file(self.lock_path(&self.id));
        self.remove_leftovers();
        // A writer that switched the link after ours, while we still held the
        // lock, skipped our set as live; it is superseded, and only we see it.
        let own = self.folder_name(&self.id);
        if !self.exchanged && fs::read_link(self.link()).ok().as_deref() != Some(Path::new(&own)) {
            let _ = fs::remove_dir_all(self.staging());
        }
    }

    fn lock_path(&self, id: &str) -> PathBuf {
        self.dir.join(format!("{}.lock", self.folder_name(id)))
    }

    /// Removes staging folders of dead processes and superseded sets.
    fn remove_leftovers(&self) {
        let prefix = format!(".{}.", self.set);
        let Ok(entries) = fs::read_dir(&self.dir) else {
            return;
        };
        let mut ids: Vec<String> = entries
            .filter_map(|e| e.ok()?.file_name().into_string().ok())
            .filter_map(|n| {
                let rest = n.strip_prefix(&prefix)?;
                let id = rest
                    .strip_suffix(".lock")
                    .or_else(|| rest.strip_suffix(".link"))
                    .unwrap_or(rest);
                Some(id.to_string())
            })
            .filter(|id| *id != self.id && is_id(id))
            .collect();
        ids.sort();
        ids.dedup();
        for id in ids {
            let lock = self.lock_path(&id);
            let _held;
            if lock.exists() {
                let Ok(f) = OpenOptions::new().write(true).open(&lock) else {
                    continue;
                };
                if f.try_lock().is_err() {
                    continue; // a live command is staging
                }
                _held = f;
            }
            let name = self.folder_name(&id);
            let _ = fs::remove_file(self.dir.join(format!("{name}.link")));
            let target = fs::read_link(self.link()).ok();
            if target.as_deref() != Some(Path::new(&name)) {
                let _ = fs::remove_dir_all(self.dir.join(&name));
            }
            let _ = fs::remove_file(&lock);
        }
    }
}

impl Drop for Publisher {
    fn drop(&mut self) {
        if !self.published {
            unpublished().retain(|(id, ..)| *id != self.id);
            let _ = fs::remove_dir_all(self.staging());
            let _ = fs::remove_file(self.lock_path(&self.id));
            remove_created(&self.created);
        }
    }
}

/// Staging ids: `<pid>-<nanoseconds>-<counter>`.
fn is_id(s: &str) -> bool {
    !s.is_empty() && s.chars().all(|c| c.is_ascii_digit() || c == '-')
}

/// Creates and locks a fresh `<dir>/.<set>.<id>.lock`; returns it and the id.
fn new_lock(dir: &Path, set: &str) -> std::io::Result<(File, String)> {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    loop {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0);
        let id = format!(
            "{}-{nanos}-{}",
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed)
        );
        let path = dir.join(format!(".{set}.{id}.lock"));
        let f = match OpenOptions::new().write(true).create_new(true).open(&path) {
            Ok(f) => f,
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        };
        f.lock()?;
        // another command may have taken the file for a leftover between
        // create and lock, and removed it: then start again with a new id
        if same_file(&f, &path) {
            return Ok((f, id));
        }
    }
}

#[cfg(unix)]
fn same_file(f: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (f.metadata(), fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_f: &File, path: &Path) -> bool {
    path.exists()
}

/// The atomic exchange of the staging folder with the published set.
mod exchange {
    use std::path::Path;

    /// Puts `staging` at `set`: exchanged with the set there, or renamed to
    /// it when there is none. `Ok(false)` when this system or file system
    /// cannot (the caller falls back to the link scheme).
    #[cfg(target_os = "linux")]
    pub fn publish(staging: &Path, set: &Path) -> std::io::Result<bool> {
        use std::os::unix::ffi::OsStrExt;
        let c = |p: &Path| {
            std::ffi::CString::new(p.as_os_str().as_bytes())
                .map_err(|_| std::io::Error::other("a path with a NUL byte"))
        };
        let (from, to) = (c(staging)?, c(set)?);
        let rename2 = |flags: libc::c_uint| {
            // SAFETY: two valid NUL-terminated paths, relative to the working folder
            let r = unsafe {
                libc::syscall(
                    libc::SYS_renameat2,
                    libc::AT_FDCWD,
                    from.as_ptr(),
                    libc::AT_FDCWD,
                    to.as_ptr(),
                    flags,
                )
            };
            if r == 0 {
                Ok(())
            } else {
                Err(std::io::Error::last_os_error())
            }
        };
        let unsupported = |e: &std::io::Error| {
            matches!(
                e.raw_os_error(),
                Some(libc::EINVAL | libc::ENOSYS | libc::EOPNOTSUPP)
            )
        };
        // a set appearing or going between the two attempts tries again
        for _ in 0..100 {
            let flags = if std::fs::symlink_metadata(set).is_ok() {
                libc::RENAME_EXCHANGE
            } else {
                libc::RENAME_NOREPLACE
            };
            match rename2(flags) {
                Ok(()) => return Ok(true),
                Err(e) if unsupported(&e) => return Ok(false),
                Err(e) if matches!(e.raw_os_error(), Some(libc::EEXIST | libc::ENOENT)) => {}
                Err(e) => return Err(e),
            }
        }
        Err(std::io::Error::other(
            "other commands kept replacing the set; try again",
        ))
    }

    #[cfg(not(target_os = "linux"))]
    pub fn publish(_staging: &Path, _set: &Path) -> std::io::Result<bool> {
        Ok(false)
    }
}

#[cfg(unix)]
fn symlink(target: &Path, link: &Path) -> std::io::Result<()> {
    std::os::unix::fs::symlink(target, link)
}

#[cfg(windows)]
fn symlink(target: &Path, link: &Path) -> std::io::Result<()> {
    std::os::windows::fs::symlink_dir(target, link)
}

/// `create_dir_all` that returns the folders it created, outermost first.
fn create_dirs(dir: &Path) -> std::result::Result<Vec<PathBuf>, (PathBuf, std::io::Error)> {
    let mut missing = Vec::new();
    let mut cur = Some(dir);
    while let Some(d) = cur {
        if d.as_os_str().is_empty() || d.exists() {
            break;
        }
        missing.push(d.to_path_buf());
        cur = d.parent();
    }
    missing.reverse();
    let mut created = Vec::new();
    for d in missing {
        match fs::create_dir(&d) {
            Ok(()) => created.push(d),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && d.is_dir() => {}
            Err(e) => {
                remove_created(&created);
                return Err((d, e));
            }
        }
    }
    if !dir.is_dir() {
        return Err((
            dir.to_path_buf(),
            std::io::Error::other("exists and is not a folder"),
        ));
    }
    Ok(created)
}

/// Removes folders this command created, innermost first, if they are empty.
fn remove_created(created: &[PathBuf]) {
    for d in created.iter().rev() {
        let _ = fs::remove_dir(d);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A field reads back whole with a CSV reader's rule: plain text as is;
    /// with a comma, quote or line break quoted, its quotes doubled.
    #[test]
    fn a_csv_field_keeps_its_punctuation() {
        assert_eq!(csv_field("converged"), "converged");
        assert_eq!(csv_field(""), "");
        assert_eq!(
            csv_field("needs 1,000 trials; see \"x\""),
            "\"needs 1,000 trials; see \"\"x\"\"\""
        );
        assert_eq!(csv_field("a\nb"), "\"a\nb\"");
        // read back: strip the quotes, undouble
        let f = csv_field("a, \"b\", c");
        let back = f[1..f.len() - 1].replace("\"\"", "\"");
        assert_eq!(back, "a, \"b\", c");
    }

    /// One config, one set: the spaces a shell keeps around `=` do not
    /// name another folder; other characters still become `_`.
    #[test]
    fn spaces_around_a_key_and_value_name_the_same_set() {
        let set =
            |o: &[&str]| set_name("run", &o.iter().map(|s| s.to_string()).collect::<Vec<_>>());
        assert_eq!(
            set(&["cat.mass = 2", " fall.height=3 "]),
            "run@cat.mass=2,fall.height=3"
        );
        assert_eq!(set(&["cat.mass=2"]), set(&[" cat.mass =2"]));
        assert_eq!(set(&["name=\"a b\""]), "run@name=_a_b_");
        assert_eq!(set(&[]), "run");
    }

    fn hidden_sets(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .filter_map(|e| e.ok()?.file_name().into_string().ok())
            .filter(|n| n.starts_with(".s.") && !n.ends_with(".lock"))
            .collect();
        v.sort();
        v
    }

    fn one_file(text: &str) -> Output {
        let mut o = Output::default();
        o.add("a.txt", text);
        o
    }

    fn begin(dir: &Path, links_only: bool) -> Publisher {
        let mut p = Publisher::begin(dir, "s").unwrap();
        p.links_only = links_only;
        p
    }

    /// The hidden folders a published set keeps: the link's target in the
    /// link scheme, none for a folder published by exchange.
    fn live(dir: &Path) -> Vec<String> {
        match fs::read_link(dir.join("s")) {
            Ok(t) => vec![t.to_string_lossy().into_owned()],
            Err(_) => vec![],
        }
    }

    /// A switches the set, B switches it after and cleans up while A still
    /// holds its lock (so B skips A as live): A must then remove its own set.
    #[test]
    fn a_writer_superseded_while_it_held_its_lock_removes_its_own_set() {
        for links_only in [false, true] {
            let dir = tempfile::tempdir().unwrap();
            let mut a = begin(dir.path(), links_only);
            let b = begin(dir.path(), links_only);
            a.switch(&one_file("A")).unwrap();
            b.publish(one_file("B")).unwrap();
            if links_only {
                assert_eq!(hidden_sets(dir.path()).len(), 2, "B skipped A as live");
            }
            a.retire();
            assert_eq!(
                fs::read_to_string(dir.path().join("s/a.txt")).unwrap(),
                "B",
                "the last switch is published"
            );
            assert_eq!(
                hidden_sets(dir.path()),
                live(dir.path()),
                "links {links_only}"
            );
            // an ordinary folder where the exchange works, a link otherwise
            assert_eq!(dir.path().join("s").is_symlink(), links_only);
        }
    }

    /// In the other order (A's lock gone before B cleans up) B removes A.
    #[test]
    fn a_superseded_set_without_a_lock_is_removed_by_the_next_writer() {
        for links_only in [false, true] {
            let dir = tempfile::tempdir().unwrap();
            let a = begin(dir.path(), links_only);
            let b = begin(dir.path(), links_only);
            a.publish(one_file("A")).unwrap();
            b.publish(one_file("B")).unwrap();
            assert_eq!(hidden_sets(dir.path()), live(dir.path()));
            assert_eq!(hidden_sets(dir.path()).len(), usize::from(links_only));
            assert_eq!(fs::read_to_string(dir.path().join("s/a.txt")).unwrap(), "B");
        }
    }

    /// A set of the link scheme (older catflip, or a file system without
    /// the exchange) is replaced by a folder, its hidden target removed; a
    /// folder catflip did not write is refused.
    #[test]
    fn a_linked_set_becomes_a_folder_and_a_foreign_folder_is_kept() {
        let dir = tempfile::tempdir().unwrap();
        begin(dir.path(), true).publish(one_file("A")).unwrap();
        assert!(dir.path().join("s").is_symlink());
        begin(dir.path(), false).publish(one_file("B")).unwrap();
        let s = dir.path().join("s");
        assert!(s.is_dir() && !s.is_symlink());
        assert!(s.join(MARKER).is_file());
        assert_eq!(fs::read_to_string(s.join("a.txt")).unwrap(), "B");
        assert!(
            hidden_sets(dir.path()).is_empty(),
            "{:?}",
            hidden_sets(dir.path())
        );
        fs::create_dir(dir.path().join("mine")).unwrap();
        fs::write(dir.path().join("mine/x"), "x").unwrap();
        let e = Publisher::begin(dir.path(), "mine")
            .unwrap_err()
            .to_string();
        assert!(e.contains("not a set published by catflip"), "{e}");
        assert_eq!(fs::read_to_string(dir.path().join("mine/x")).unwrap(), "x");
    }
}
