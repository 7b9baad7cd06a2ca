//! All-or-nothing output: every file of a run is staged in memory, written
//! to a temporary sibling and renamed into place only when all were written.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// Files to write into one folder.
#[derive(Debug, Default)]
pub struct Output {
    files: Vec<(String, Vec<u8>)>,
}

impl Output {
    pub fn add(&mut self, name: impl Into<String>, contents: impl Into<Vec<u8>>) {
        self.files.push((name.into(), contents.into()));
    }

    /// Writes every file into `dir` (created if missing); returns their paths.
    pub fn commit(self, dir: &Path) -> Result<Vec<PathBuf>> {
        let werr = |path: &Path, source| Error::Write {
            path: path.to_path_buf(),
            source,
        };
        std::fs::create_dir_all(dir).map_err(|e| werr(dir, e))?;
        let mut staged = Vec::new();
        for (name, bytes) in &self.files {
            let fin = dir.join(name);
            let tmp = dir.join(format!(".{name}.tmp{}", std::process::id()));
            if let Err(e) = std::fs::write(&tmp, bytes) {
                for (t, _) in &staged {
                    let _ = std::fs::remove_file(t);
                }
                let _ = std::fs::remove_file(&tmp);
                return Err(werr(&fin, e));
            }
            staged.push((tmp, fin));
        }
        let mut done = Vec::new();
        for (tmp, fin) in staged {
            std::fs::rename(&tmp, &fin).map_err(|e| werr(&fin, e))?;
            done.push(fin);
        }
        Ok(done)
    }
}
