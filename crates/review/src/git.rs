//! Git, through the `git` command (git-scm.com/docs: `rev-parse`,
//! `merge-base`, `diff --name-status -z`, `ls-tree -z`, `cat-file
//! --batch`): no shell, every argument a separate `argv` entry, every
//! revision checked with `rev-parse --verify --end-of-options REV^{commit}`
//! before use and every path given after `--`, so that nothing a pull
//! request names can be taken for an option.
//!
//! A repository's own configuration must run nothing: system config is not
//! read (`GIT_CONFIG_NOSYSTEM`), `core.fsmonitor` (a program git runs on
//! status and diff), `diff.external` and `core.hooksPath` are overridden on
//! the command line, and diffs run with `--no-ext-diff --no-textconv`.

use btfsm_core::diagnostic::Diagnostic;
use btfsm_core::sanitize::shown;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// Most bytes one git command may print (a listing of a very large tree).
const MAX_OUTPUT: u64 = 512 * 1024 * 1024;

/// A git repository: its work tree's top level.
#[derive(Debug, Clone)]
pub struct Repo {
    pub top: PathBuf,
}

/// A git command that failed: its stderr (first line), or why it did not run.
#[derive(Debug)]
pub(crate) struct GitError(pub(crate) String);

/// `git` with the options every call shares, run in `dir`.
fn command(dir: &Path) -> Command {
    let mut c = Command::new("git");
    c.current_dir(dir)
        .env("GIT_CONFIG_NOSYSTEM", "1")
        .env("GIT_TERMINAL_PROMPT", "0")
        .env("GIT_OPTIONAL_LOCKS", "0")
        .env("LC_ALL", "C")
        .env_remove("GIT_EXTERNAL_DIFF")
        .env_remove("GIT_PAGER")
        .args([
            "-c",
            "core.fsmonitor=false",
            "-c",
            "diff.external=",
            "-c",
            "core.hooksPath=/dev/null",
            "-c",
            "core.pager=cat",
            "-c",
            "core.quotePath=false",
        ])
        .stdin(Stdio::null());
    c
}

/// Runs `c`, giving its stdout, bounded by [`MAX_OUTPUT`].
fn output(mut c: Command) -> Result<Vec<u8>, GitError> {
    let mut child = c
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| GitError(format!("cannot run git: {e}")))?;
    let (mut stdout, mut stderr) = (child.stdout.take(), child.stderr.take());
    let err_thread = std::thread::spawn(move || {
        let mut s = Vec::new();
        if let Some(e) = stderr.as_mut() {
            let _ = e.take(64 * 1024).read_to_end(&mut s);
        }
        s
    });
    let mut bytes = Vec::new();
    if let Some(o) = stdout.as_mut() {
        let _ = o.take(MAX_OUTPUT + 1).read_to_end(&mut bytes);
    }
    drop(stdout);
    let status = child.wait().map_err(|e| GitError(e.to_string()))?;
    let err = err_thread.join().unwrap_or_default();
    if bytes.len() as u64 > MAX_OUTPUT {
        return Err(GitError(format!(
            "git printed more than {MAX_OUTPUT} bytes"
        )));
    }
    if !status.success() {
        let err = String::from_utf8_lossy(&err);
        let first = err.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
        return Err(GitError(first.trim().to_string()));
    }
    Ok(bytes)
}

/// How a file changed between two revisions.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    Added,
    Removed,
    Modified,
    Renamed,
    /// Not changed itself: a file it reads (an include, a node model) did.
    Dependency,
}

/// One changed path (`git diff --name-status`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Change {
    pub status: Status,
    /// The path in head (in base for a removed file).
    pub path: String,
    /// A renamed file's path in base.
    pub from: Option<String>,
}

/// A blob of a tree listing: mode, object id, size, path.
#[derive(Debug, Clone)]
pub(crate) struct Entry {
    pub(crate) mode: String,
    pub(crate) oid: String,
    pub(crate) size: u64,
    pub(crate) path: String,
}

impl Repo {
    /// The repository holding `dir`; not one: an error saying so.
    pub fn discover(dir: &Path) -> Result<Repo, Diagnostic> {
        let mut c = command(dir);
        c.args(["rev-parse", "--show-toplevel"]);
        match output(c) {
            Ok(out) => {
                let top = String::from_utf8_lossy(&out).trim_end().to_string();
                Ok(Repo {
                    top: PathBuf::from(top),
                })
            }
            Err(e) => Err(Diagnostic::error(format!(
                "not in a git repository: {}",
                shown(&e.0)
            ))
            .hint("run `btfsm review` inside a git work tree (a CI checkout), or use `btfsm compare OLD NEW` on two files")),
        }
    }

    fn git(&self) -> Command {
        command(&self.top)
    }

    pub(crate) fn run(&self, args: &[&str]) -> Result<Vec<u8>, GitError> {
        let mut c = self.git();
        c.args(args);
        output(c)
    }

    /// The commit `rev` names (its full object id); missing: an error that
    /// says, in a shallow clone, how to fetch it.
    pub fn commit(&self, rev: &str, flag: &str) -> Result<String, Diagnostic> {
        let spec = format!("{rev}^{{commit}}");
        match self.run(&[
            "rev-parse",
            "--verify",
            "--quiet",
            "--end-of-options",
            &spec,
        ]) {
            Ok(out) => Ok(String::from_utf8_lossy(&out).trim().to_string()),
            Err(_) => Err(self.missing(rev, flag)),
        }
    }

    /// The error of a revision that is not here.
    fn missing(&self, rev: &str, flag: &str) -> Diagnostic {
        let shallow = self
            .run(&["rev-parse", "--is-shallow-repository"])
            .is_ok_and(|o| o.starts_with(b"true"));
        let d = Diagnostic::error(format!(
            "{flag} `{}`: no such commit in this repository",
            shown(rev)
        ));
        if shallow {
            d.hint("this clone is shallow: fetch the history it needs with `git fetch --deepen=100` (or all of it with `git fetch --unshallow`); in GitHub Actions set `fetch-depth: 0` on actions/checkout")
        } else {
            d.hint("name a branch, tag or commit that exists here (`git fetch origin BRANCH` brings a remote one)")
        }
    }

    /// The default base: the merge base of HEAD with the default branch
    /// (`origin/HEAD`, else `origin/main`, `origin/master`, `main`,
    /// `master`).
    pub fn default_base(&self) -> Result<String, Diagnostic> {
        let mut candidates = Vec::new();
        if let Ok(out) = self.run(&["symbolic-ref", "--quiet", "refs/remotes/origin/HEAD"]) {
            candidates.push(String::from_utf8_lossy(&out).trim().to_string());
        }
        for c in ["origin/main", "origin/master", "main", "master"] {
            candidates.push(c.to_string());
        }
        let head = self.commit("HEAD", "HEAD")?;
        for c in candidates {
            let spec = format!("{c}^{{commit}}");
            let Ok(out) = self.run(&[
                "rev-parse",
                "--verify",
                "--quiet",
                "--end-of-options",
                &spec,
            ]) else {
                continue;
            };
            let branch = String::from_utf8_lossy(&out).trim().to_string();
            return match self.run(&["merge-base", &head, &branch]) {
                Ok(out) => Ok(String::from_utf8_lossy(&out).trim().to_string()),
                Err(_) => Err(self.missing(&format!("merge base of HEAD and {c}"), "--base")),
            };
        }
        Err(Diagnostic::error("no default branch to review against: neither origin/HEAD nor main nor master exists here")
            .hint("name the base with --base REV (in a pull request: the base branch, e.g. `--base origin/main`)"))
    }

    /// The files that changed from `base` to `head` (`None`: the work tree,
    /// untracked files not ignored included), renames detected.
    pub fn changes(&self, base: &str, head: Option<&str>) -> Result<Vec<Change>, Diagnostic> {
        let mut args = vec![
            "diff",
            "--name-status",
            "-z",
            "-M",
            "--no-ext-diff",
            "--no-textconv",
            "--no-color",
            base,
        ];
        args.extend(head);
        args.push("--");
        let out = self.run(&args).map_err(|e| self.failed("git diff", &e))?;
        let mut changes = parse_name_status(&out);
        if head.is_none() {
            let out = self
                .run(&["ls-files", "-z", "--others", "--exclude-standard", "--"])
                .map_err(|e| self.failed("git ls-files", &e))?;
            for p in out.split(|&b| b == 0).filter(|p| !p.is_empty()) {
                changes.push(Change {
                    status: Status::Added,
                    path: String::from_utf8_lossy(p).into_owned(),
                    from: None,
                });
            }
        }
        changes.sort_by(|a, b| a.path.cmp(&b.path));
        Ok(changes)
    }

    pub(crate) fn failed(&self, what: &str, e: &GitError) -> Diagnostic {
        Diagnostic::error(format!("{what} failed: {}", shown(&e.0)))
            .hint("check that the repository is readable and the revisions are fetched")
    }

    /// Every blob of `rev`'s tree: mode, id, size and path.
    pub(crate) fn tree(&self, rev: &str) -> Result<Vec<Entry>, Diagnostic> {
        let out = self
            .run(&["ls-tree", "-r", "-z", "-l", "--full-tree", rev, "--"])
            .map_err(|e| self.failed("git ls-tree", &e))?;
        let mut entries = Vec::new();
        for rec in out.split(|&b| b == 0).filter(|r| !r.is_empty()) {
            // `<mode> SP <type> SP <object> SP+ <size> TAB <path>`
            let Some(tab) = rec.iter().position(|&b| b == b'\t') else {
                continue;
            };
            let head = String::from_utf8_lossy(&rec[..tab]);
            let mut f = head.split_whitespace();
            let (Some(mode), Some(kind), Some(oid), Some(size)) =
                (f.next(), f.next(), f.next(), f.next())
            else {
                continue;
            };
            if kind != "blob" {
                continue;
            }
            entries.push(Entry {
                mode: mode.to_string(),
                oid: oid.to_string(),
                size: size.parse().unwrap_or(u64::MAX),
                path: String::from_utf8_lossy(&rec[tab + 1..]).into_owned(),
            });
        }
        Ok(entries)
    }

    /// The contents of blobs `oids`, in order (`git cat-file --batch`).
    pub(crate) fn blobs(&self, oids: &[&str]) -> Result<Vec<Vec<u8>>, Diagnostic> {
        let mut c = self.git();
        c.args(["cat-file", "--batch"])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null());
        let mut child = c
            .spawn()
            .map_err(|e| self.failed("git cat-file", &GitError(e.to_string())))?;
        let mut stdin = child.stdin.take();
        let input: String = oids.iter().map(|o| format!("{o}\n")).collect();
        let writer = std::thread::spawn(move || {
            if let Some(s) = stdin.as_mut() {
                let _ = s.write_all(input.as_bytes());
            }
            drop(stdin);
        });
        let mut out = Vec::new();
        if let Some(o) = child.stdout.as_mut() {
            let _ = o.take(MAX_OUTPUT).read_to_end(&mut out);
        }
        let _ = writer.join();
        let _ = child.wait();
        parse_batch(&out, oids.len())
            .ok_or_else(|| self.failed("git cat-file", &GitError("unexpected output".into())))
    }
}

/// `git diff --name-status -z` records: `S\0path\0` or `Rnn\0from\0to\0`.
fn parse_name_status(out: &[u8]) -> Vec<Change> {
    let fields: Vec<String> = out
        .split(|&b| b == 0)
        .map(|f| String::from_utf8_lossy(f).into_owned())
        .collect();
    let mut changes = Vec::new();
    let mut i = 0;
    while i < fields.len() {
        let status = fields[i].clone();
        let Some(first) = status.chars().next() else {
            i += 1;
            continue;
        };
        let two = matches!(first, 'R' | 'C');
        let (Some(a), b) = (fields.get(i + 1).cloned(), fields.get(i + 2).cloned()) else {
            break;
        };
        i += if two { 3 } else { 2 };
        let change = match (first, b) {
            ('R', Some(to)) => Change {
                status: Status::Renamed,
                path: to,
                from: Some(a),
            },
            ('C', Some(to)) => Change {
                status: Status::Added,
                path: to,
                from: None,
            },
            ('A', _) => Change {
                status: Status::Added,
                path: a,
                from: None,
            },
            ('D', _) => Change {
                status: Status::Removed,
                path: a,
                from: None,
            },
            _ => Change {
                status: Status::Modified,
                path: a,
                from: None,
            },
        };
        changes.push(change);
    }
    changes
}

/// `git cat-file --batch` output: `<oid> blob <size>\n<bytes>\n` per object.
fn parse_batch(out: &[u8], n: usize) -> Option<Vec<Vec<u8>>> {
    let mut blobs = Vec::with_capacity(n);
    let mut at = 0;
    for _ in 0..n {
        let nl = at + out.get(at..)?.iter().position(|&b| b == b'\n')?;
        let header = String::from_utf8_lossy(&out[at..nl]);
        let size: usize = header.rsplit(' ').next()?.parse().ok()?;
        let start = nl + 1;
        blobs.push(out.get(start..start + size)?.to_vec());
        at = start + size + 1;
    }
    Some(blobs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn name_status_records_are_parsed_with_renames() {
        let out = b"M\0a.xml\0R087\0old.xml\0new.xml\0A\0-n.xml\0D\0gone.toml\0";
        let c = parse_name_status(out);
        assert_eq!(c.len(), 4);
        assert_eq!(c[1].status, Status::Renamed);
        assert_eq!(c[1].from.as_deref(), Some("old.xml"));
        assert_eq!(c[1].path, "new.xml");
        assert_eq!(c[2].path, "-n.xml");
        assert_eq!(c[3].status, Status::Removed);
    }

    #[test]
    fn batch_output_is_split_by_size() {
        let out = b"abc blob 3\nx\ny\ndef blob 0\n\n";
        let b = parse_batch(out, 2).unwrap();
        assert_eq!(b, vec![b"x\ny".to_vec(), Vec::new()]);
        assert!(parse_batch(b"abc blob 9\nxx\n", 1).is_none());
    }
}
