//! All-or-nothing output that holds under SIGKILL and concurrent writers.
//!
//! Each command publishes one *set* of files, `<dir>/<set>` (e.g.
//! `output/seed/run`). The set is a symbolic link to a hidden folder
//! `<dir>/.<set>.<id>` that was written completely before the link was
//! switched to it with `rename(2)`, which replaces a link atomically: a reader
//! sees the old set or the new one, never a mix. Commands have separate sets,
//! so `optimize` never overwrites the files `run` described in its summary.
//!
//! While a process stages, it holds an advisory lock on `<dir>/.<set>.<id>.lock`;
//! the lock dies with the process (also under SIGKILL), so the next command
//! knows a staging folder without a held lock is a leftover and removes it.
//! Hidden names are never taken for results.

use crate::error::{Error, Result};
use std::fs::{self, File, OpenOptions};
use std::path::{Path, PathBuf};

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

/// Files to write into one set, kept in memory until published.
#[derive(Debug, Default)]
pub struct Output {
    files: Vec<(String, Vec<u8>)>,
}

impl Output {
    pub fn add(&mut self, name: impl Into<String>, contents: impl Into<Vec<u8>>) {
        self.files.push((name.into(), contents.into()));
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
}

impl Publisher {
    /// Prepares the set `<dir>/<set>`: creates `dir` if needed, checks it takes
    /// files, removes leftovers of killed commands and opens a private staging folder.
    pub fn begin(dir: &Path, set: &str) -> Result<Publisher> {
        let oerr = |path: &Path, e: std::io::Error| Error::OutputDir {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        let created = create_dirs(dir).map_err(|(p, e)| oerr(&p, e))?;
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
        };
        if let Ok(m) = fs::symlink_metadata(p.link())
            && !m.file_type().is_symlink()
        {
            return Err(Error::OutputDir {
                path: p.link(),
                message: "exists and is not a set published by catflip (a link to a hidden folder); move it away".into(),
            });
        }
        fs::create_dir(p.staging()).map_err(|e| oerr(&p.staging(), e))?;
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
        self.switch(&out)?;
        self.retire();
        Ok(out.files.iter().map(|(n, _)| self.link().join(n)).collect())
    }

    /// Writes the files and switches the link to the staging folder.
    fn switch(&mut self, out: &Output) -> Result<()> {
        let staging = self.staging();
        for (name, bytes) in &out.files {
            let path = staging.join(name);
            fs::write(&path, bytes).map_err(|e| Error::Write {
                path: self.link().join(name),
                message: e.to_string(),
            })?;
        }
        let own = self.folder_name(&self.id);
        let tmp_link = self.dir.join(format!("{own}.link"));
        let _ = fs::remove_file(&tmp_link);
        let werr = |e: std::io::Error| Error::Write {
            path: self.link(),
            message: e.to_string(),
        };
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
        if fs::read_link(self.link()).ok().as_deref() != Some(Path::new(&own)) {
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

    /// A switches the link, B switches it after and cleans up while A still
    /// holds its lock (so B skips A as live): A must then remove its own set.
    #[test]
    fn a_writer_superseded_while_it_held_its_lock_removes_its_own_set() {
        let dir = tempfile::tempdir().unwrap();
        let mut a = Publisher::begin(dir.path(), "s").unwrap();
        let b = Publisher::begin(dir.path(), "s").unwrap();
        a.switch(&one_file("A")).unwrap();
        b.publish(one_file("B")).unwrap();
        assert_eq!(hidden_sets(dir.path()).len(), 2, "B skipped A as live");
        a.retire();
        let left = hidden_sets(dir.path());
        assert_eq!(left.len(), 1, "{left:?}");
        assert_eq!(
            fs::read_to_string(dir.path().join("s/a.txt")).unwrap(),
            "B",
            "the last switch is published"
        );
        assert_eq!(
            Path::new(&left[0]),
            fs::read_link(dir.path().join("s")).unwrap()
        );
    }

    /// In the other order (A's lock gone before B cleans up) B removes A.
    #[test]
    fn a_superseded_set_without_a_lock_is_removed_by_the_next_writer() {
        let dir = tempfile::tempdir().unwrap();
        let a = Publisher::begin(dir.path(), "s").unwrap();
        let b = Publisher::begin(dir.path(), "s").unwrap();
        a.publish(one_file("A")).unwrap();
        b.publish(one_file("B")).unwrap();
        assert_eq!(hidden_sets(dir.path()).len(), 1);
        assert_eq!(fs::read_to_string(dir.path().join("s/a.txt")).unwrap(), "B");
    }
}
