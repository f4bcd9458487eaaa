//! Where outputs may be written (issue 33): confined like reads
//! (`format::source`), so that a symlink a pull request commits cannot turn
//! `compare --dot diff.dot` into a write of `.git/hooks/pre-commit` or of a
//! file outside the work tree.
//!
//! The root is `--root DIR`, else the top of the git work tree holding the
//! current directory (the nearest ancestor with a `.git`), else the current
//! directory. An output whose path, as typed, lies inside the root must
//! resolve inside it: every symlink it passes (a parent directory or the
//! file itself) may point only within the root. An output typed outside the
//! root (`/tmp/out.svg`, `/dev/null`) is the user's own choice of place. In
//! both cases nothing is written into a `.git` directory (its hooks run, its
//! `config` holds the CI token). `--allow-outside-root` lifts both rules
//! for trusted local use.

use std::io;
use std::path::{Component, Path, PathBuf};

/// The rule outputs follow.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum OutputRoot {
    /// Anywhere (`--allow-outside-root`).
    Anywhere,
    /// Inside this canonical directory (and never into `.git`).
    Within(PathBuf),
}

/// Why an output is refused; carried inside the `io::Error` of a write so
/// that the command line can add its hint.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Confined(pub String);

impl std::fmt::Display for Confined {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Confined {}

/// What the command line says when an output is refused.
pub const CONFINED_HINT: &str = "outputs stay inside the root (--root DIR, else the git work tree of the current directory, else the current directory) and out of `.git`, whatever symbolic links they pass; name another path, or pass --allow-outside-root for trusted local use";

/// Whether `e` is a refusal of [`OutputRoot`].
pub fn is_confined(e: &io::Error) -> bool {
    e.get_ref().is_some_and(|x| x.is::<Confined>())
}

fn refuse(what: &str) -> io::Error {
    io::Error::new(io::ErrorKind::PermissionDenied, Confined(what.to_string()))
}

impl OutputRoot {
    /// The rule for the flags given: `off` is `--allow-outside-root`,
    /// `root` is `--root DIR`.
    pub fn new(off: bool, root: Option<&Path>) -> OutputRoot {
        if off {
            return OutputRoot::Anywhere;
        }
        let canonical = |p: &Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
        match root {
            Some(r) => OutputRoot::Within(canonical(r)),
            None => {
                let cwd = canonical(Path::new("."));
                let top = cwd
                    .ancestors()
                    .find(|a| a.join(".git").symlink_metadata().is_ok())
                    .map(Path::to_path_buf);
                OutputRoot::Within(top.unwrap_or(cwd))
            }
        }
    }

    /// Checks that `target`, what the output `typed` resolved to (symlinks
    /// followed, its directory canonical), may be written.
    pub fn check(&self, typed: &Path, target: &Path) -> io::Result<()> {
        let OutputRoot::Within(root) = self else {
            return Ok(());
        };
        if has_git_component(target) {
            return Err(refuse(
                "it leads into a `.git` directory, where nothing is written",
            ));
        }
        if lexically_inside(typed, root) && !target.starts_with(root) {
            return Err(refuse("it leads outside the root through a symbolic link"));
        }
        Ok(())
    }

    /// Checks a directory outputs will be written under (`plan -o DIR`),
    /// whether it exists or not: its deepest existing ancestor is resolved,
    /// the rest appended.
    pub fn check_dir(&self, typed: &Path) -> io::Result<()> {
        if let OutputRoot::Anywhere = self {
            return Ok(());
        }
        let abs = absolute(typed);
        let mut existing = abs.as_path();
        let mut rest: Vec<&std::ffi::OsStr> = Vec::new();
        let resolved = loop {
            match std::fs::canonicalize(existing) {
                Ok(c) => break c,
                Err(_) => match (existing.parent(), existing.file_name()) {
                    (Some(p), Some(n)) => {
                        rest.push(n);
                        existing = p;
                    }
                    _ => break existing.to_path_buf(),
                },
            }
        };
        let mut target = resolved;
        for n in rest.into_iter().rev() {
            target.push(n);
        }
        self.check(typed, &target)
    }
}

/// `p` made absolute against the current directory, `.` and `..` removed
/// lexically (`..` at the top stays at the top).
fn absolute(p: &Path) -> PathBuf {
    let joined = if p.is_absolute() {
        p.to_path_buf()
    } else {
        std::env::current_dir().unwrap_or_default().join(p)
    };
    let mut out = PathBuf::new();
    for c in joined.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// Whether the path as typed lies inside `root` (without following links).
fn lexically_inside(typed: &Path, root: &Path) -> bool {
    absolute(typed).starts_with(root)
}

fn has_git_component(p: &Path) -> bool {
    p.components()
        .any(|c| matches!(c, Component::Normal(n) if n == ".git"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn typed_paths_are_judged_lexically_and_targets_by_their_components() {
        let root = OutputRoot::Within(PathBuf::from("/w/repo"));
        let ok = |typed: &str, target: &str| root.check(Path::new(typed), Path::new(target));
        assert!(ok("/w/repo/out.dot", "/w/repo/out.dot").is_ok());
        assert!(ok("/w/repo/a/../out.dot", "/w/repo/sub/x.dot").is_ok());
        let e = ok("/w/repo/out.dot", "/home/u/.bashrc").unwrap_err();
        assert!(is_confined(&e), "{e}");
        assert!(e.to_string().contains("outside the root"), "{e}");
        let e = ok("/w/repo/out.dot", "/w/repo/.git/hooks/pre-commit").unwrap_err();
        assert!(e.to_string().contains("`.git`"), "{e}");
        // Typed outside the root: the user's place, but never `.git`.
        assert!(ok("/tmp/x.svg", "/tmp/x.svg").is_ok());
        assert!(ok("/dev/stderr", "/proc/self/fd/2").is_ok());
        assert!(ok("/tmp/.git/config", "/tmp/.git/config").is_err());
        assert!(
            OutputRoot::Anywhere
                .check(Path::new("x"), Path::new("/w/repo/.git/hooks/x"))
                .is_ok()
        );
    }
}
