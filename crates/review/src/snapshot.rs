//! One revision's files on disk, so that a policy is read with its
//! include/SubTree closure and its node models from the same revision:
//! the work tree as it is, or a commit's files materialised into a private
//! temporary directory (mode 0700, removed when dropped) from `git ls-tree`
//! and `git cat-file --batch`.
//!
//! Only what a policy can read is written: regular files (no symbolic
//! link, no submodule) whose extension is one the readers take (`.toml`,
//! `.xml`, `.scxml`, `.btproj`, as `format::discover` walks), each path
//! checked to be relative and free of `..` and `.git` components; their
//! bytes in all are at most the command's read budget. An empty
//! `.git` directory marks the top, so that the readers' confinement root
//! (`format::source`) and the node model search (`lint::search`) stop
//! there, as they do in a checkout.

use super::git::Repo;
use btfsm_core::diagnostic::Diagnostic;
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// The files of one revision.
pub struct Snapshot {
    /// Its top level (canonical).
    pub root: PathBuf,
    /// The commit, or `None` for the work tree.
    pub commit: Option<String>,
    temp: Option<PathBuf>,
}

impl Drop for Snapshot {
    fn drop(&mut self) {
        if let Some(t) = self.temp.take() {
            let _ = std::fs::remove_dir_all(t);
        }
    }
}

/// Extensions of the files a policy may read.
pub(crate) fn is_candidate(path: &str) -> bool {
    Path::new(path)
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| {
            ["toml", "xml", "scxml", "btproj"].contains(&e.to_ascii_lowercase().as_str())
        })
}

/// Is `path` a plain relative path (no root, `..`, `.` or `.git` part)?
pub(crate) fn is_plain(path: &str) -> bool {
    let p = Path::new(path);
    !path.is_empty()
        && p.components().all(|c| match c {
            Component::Normal(s) => s != ".git",
            _ => false,
        })
}

impl Snapshot {
    /// The work tree of `repo`.
    pub fn work_tree(repo: &Repo) -> Snapshot {
        Snapshot {
            root: btfsm_format::source::canonical(&repo.top),
            commit: None,
            temp: None,
        }
    }

    /// The candidate files of `commit`, written into a new private
    /// directory; `max_bytes`: the most bytes written in all.
    pub fn materialise(repo: &Repo, commit: &str, max_bytes: u64) -> Result<Snapshot, Diagnostic> {
        let dir = private_dir()?;
        let snap = Snapshot {
            root: btfsm_format::source::canonical(&dir),
            commit: Some(commit.to_string()),
            temp: Some(dir),
        };
        let entries: Vec<_> = repo
            .tree(commit)?
            .into_iter()
            .filter(|e| matches!(e.mode.as_str(), "100644" | "100755"))
            .filter(|e| is_candidate(&e.path) && is_plain(&e.path))
            .collect();
        let total: u64 = entries.iter().map(|e| e.size).fold(0, u64::saturating_add);
        if total > max_bytes {
            return Err(Diagnostic::error(format!(
                "revision {}: its policy-like files (.toml, .xml, .scxml, .btproj) hold {total} bytes, more than the {max_bytes} this command may read",
                short(commit)
            ))
            .hint("raise the limit with --max-total-bytes, or review fewer paths"));
        }
        let oids: Vec<&str> = entries.iter().map(|e| e.oid.as_str()).collect();
        let blobs = repo.blobs(&oids)?;
        std::fs::create_dir(snap.root.join(".git")).map_err(io_error)?;
        for (e, bytes) in entries.iter().zip(blobs) {
            let path = snap.root.join(&e.path);
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent).map_err(io_error)?;
            }
            std::fs::write(&path, bytes).map_err(io_error)?;
        }
        Ok(snap)
    }

    /// A path of this revision, relative to its top.
    pub fn path(&self, rel: &str) -> PathBuf {
        self.root.join(rel)
    }

    /// The revision as shown: a short commit id, or `work tree`.
    pub fn label(&self) -> String {
        self.commit
            .as_deref()
            .map_or_else(|| "work tree".to_string(), |c| short(c).to_string())
    }
}

/// The first 12 characters of a commit id.
pub(crate) fn short(commit: &str) -> &str {
    commit.get(..12).unwrap_or(commit)
}

fn io_error(e: std::io::Error) -> Diagnostic {
    Diagnostic::error(format!(
        "cannot write a revision's files to a temporary directory: {e}"
    ))
    .hint("check that the temporary directory (TMPDIR) is writable and has room")
}

/// A new directory only this user can read, under the temporary directory.
fn private_dir() -> Result<PathBuf, Diagnostic> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let base = std::env::temp_dir();
    for _ in 0..16 {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let dir = base.join(format!("btfsm-review-{}-{n}-{nanos:x}", std::process::id()));
        let mut b = std::fs::DirBuilder::new();
        #[cfg(unix)]
        std::os::unix::fs::DirBuilderExt::mode(&mut b, 0o700);
        match b.create(&dir) {
            Ok(()) => return Ok(dir),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(io_error(e)),
        }
    }
    Err(io_error(std::io::Error::other("no fresh name")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_plain_relative_paths_are_written() {
        assert!(is_plain("a/b.xml"));
        for bad in [
            "",
            "/etc/x.xml",
            "../x.xml",
            "a/../b.xml",
            ".git/config.toml",
            "a/.git/x.xml",
            "./a.xml",
        ] {
            assert!(!is_plain(bad), "{bad}");
        }
        assert!(is_candidate("A.XML") && is_candidate("p.btproj") && !is_candidate("x.py"));
    }
}
