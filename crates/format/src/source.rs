//! Reading input files under the threat model of a CI job on a stranger's
//! pull request (issue 12): every byte read is charged to one budget per
//! command, a file named by another file (subtree, `<include>`, scenario
//! policy) resolves inside a root and must be a regular file, and nothing
//! blocks on a FIFO or a pipe whose writer stalls.
//!
//! The root (docs/guide/limits.md): by default the top level of
//! the git work tree holding the file given on the command line (the
//! nearest ancestor with a `.git`), else that file's directory; `--root DIR`
//! sets it, `--allow-outside-root` lifts the rule for trusted local use.
//! Paths through a `.git` directory are refused whatever the root: a CI
//! checkout keeps its credentials in `.git/config`.

use super::Limits;
use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use std::io::Read;
use std::path::{Component, Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

/// Default of the total bytes one command reads across all its files.
pub const DEFAULT_MAX_TOTAL_BYTES: u64 = 256 * 1024 * 1024;

/// How long a pipe, FIFO or device may go without data before reading it
/// is an error (a writer that never writes nor closes).
pub const PIPE_IDLE: Duration = Duration::from_secs(10);

/// A count one command may still spend, shared by every clone of its
/// [`Limits`]: the bytes it reads (files on the command line, includes,
/// node models, baselines, traces), the nodes it creates by copying
/// subtrees.
#[derive(Debug)]
pub struct Budget {
    limit: u64,
    used: AtomicU64,
}

impl Budget {
    pub fn new(limit: u64) -> Arc<Budget> {
        Arc::new(Budget {
            limit,
            used: AtomicU64::new(0),
        })
    }

    /// The limit, in bytes.
    pub fn limit(&self) -> u64 {
        self.limit
    }

    /// Bytes still allowed.
    pub fn remaining(&self) -> u64 {
        self.limit.saturating_sub(self.used.load(Ordering::Relaxed))
    }

    /// Spends what remains.
    pub fn exhaust(&self) {
        self.used.store(self.limit, Ordering::Relaxed);
    }

    /// Charges `n` bytes; `false` (nothing charged) when they do not fit.
    pub fn charge(&self, n: u64) -> bool {
        self.used
            .fetch_update(Ordering::Relaxed, Ordering::Relaxed, |u| {
                u.checked_add(n).filter(|&t| t <= self.limit)
            })
            .is_ok()
    }
}

/// Where files named by other files may be.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub enum Confinement {
    /// The git work tree of the command-line file, else its directory.
    #[default]
    Auto,
    /// This directory (`--root`).
    Root(PathBuf),
    /// Anywhere (`--allow-outside-root`).
    Off,
}

/// The canonical root for the files named by a file in `dir` (a directory
/// holding a command-line file); `None` when confinement is off.
pub fn root_for(limits: &Limits, dir: &Path) -> Option<PathBuf> {
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    match &limits.confinement {
        Confinement::Off => None,
        Confinement::Root(r) => Some(canonical(r)),
        Confinement::Auto => {
            let dir = canonical(dir);
            let top = dir
                .ancestors()
                .find(|a| a.join(".git").symlink_metadata().is_ok())
                .map(Path::to_path_buf);
            Some(top.unwrap_or(dir))
        }
    }
}

/// The canonical path (symlinks resolved), or the path itself when it does
/// not exist.
pub fn canonical(p: &Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf())
}

/// Why a named file is not read: the message and a hint.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Refusal {
    pub message: String,
    pub hint: String,
}

const OUTSIDE_HINT: &str = "files named by a policy or scenario must be regular files inside the root (the git work tree of the file given on the command line, else its directory); set it with --root DIR, or pass --allow-outside-root for trusted local files";

/// Resolves `rel`, named by a file in directory `base`, checking it against
/// `root` before anything is opened: no absolute path, nothing outside the
/// root (after resolving `..` and symlinks), nothing through `.git`, and
/// only a regular file. With no root (confinement off) only the last
/// check applies. The message never quotes the resolved path, which may
/// say what lies outside the root.
pub fn resolve(root: Option<&Path>, base: &Path, rel: &str) -> Result<PathBuf, Refusal> {
    let refuse = |what: &str| Refusal {
        message: what.to_string(),
        hint: OUTSIDE_HINT.to_string(),
    };
    let rel_path = Path::new(rel);
    if rel.is_empty() {
        return Err(Refusal {
            message: "the path is empty".into(),
            hint: "give a path relative to this file".into(),
        });
    }
    if root.is_some() && (rel_path.is_absolute() || rel.starts_with('~')) {
        return Err(refuse("an absolute path is not allowed here"));
    }
    let joined = base.join(rel_path);
    if let Some(root) = root {
        // Lexically first, so that a path outside is refused even when
        // it does not exist (and without saying whether it does).
        let lexical = normalise(&canonical_dir_of(base).join(rel_path));
        if !lexical.starts_with(root) {
            return Err(refuse("the path leads outside the root"));
        }
        let resolved = match std::fs::canonicalize(&joined) {
            Ok(p) => p,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(Refusal {
                    message: "no such file".into(),
                    hint: "the path is relative to the file that names it".into(),
                });
            }
            Err(_) => return Err(refuse("the path cannot be resolved")),
        };
        if !resolved.starts_with(root) {
            return Err(refuse(
                "the path leads outside the root (through a symbolic link)",
            ));
        }
        let below = resolved.strip_prefix(root).unwrap_or(&resolved);
        if below
            .components()
            .any(|c| matches!(c, Component::Normal(n) if n == ".git"))
        {
            return Err(refuse("paths into `.git` are not read"));
        }
    }
    match std::fs::metadata(&joined) {
        Ok(m) if m.is_file() => Ok(joined),
        Ok(m) if m.is_dir() => Err(Refusal {
            message: "it is a directory".into(),
            hint: "name a policy file".into(),
        }),
        Ok(_) => Err(refuse(
            "not a regular file (a device, FIFO or socket is not read here)",
        )),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(Refusal {
            message: "no such file".into(),
            hint: "the path is relative to the file that names it".into(),
        }),
        Err(e) => Err(Refusal {
            message: format!("cannot read it: {}", io_msg(&e)),
            hint: "check the file's permissions".into(),
        }),
    }
}

fn canonical_dir_of(base: &Path) -> PathBuf {
    if base.as_os_str().is_empty() {
        canonical(Path::new("."))
    } else {
        canonical(base)
    }
}

/// `.` and `..` removed lexically (`..` at the top stays at the top).
fn normalise(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in p.components() {
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

/// What a file named by another file must be (issue 33): its name and its
/// first bytes are checked before it is parsed, so that a file that is not
/// a policy (a `.env` a CI step wrote, a key) is refused without any of its
/// content being quoted in a message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Named {
    /// A TOML policy (`subtree`): a `.toml` file that sets `kind` before its
    /// first table.
    TomlPolicy,
    /// An XML file (`.xml`) whose document element is this
    /// (BehaviorTree.CPP `<include>`: `root`; yasmin `file_path`:
    /// `StateMachine`).
    Xml(&'static str),
    /// A policy of any format (a scenario's `file`, a trace's policy): a
    /// TOML policy, or a `.xml`, `.scxml` or `.btproj` file whose document
    /// element is `root`, `BehaviorTree`, `StateMachine` or `scxml`.
    AnyPolicy,
}

impl Named {
    fn what(self) -> &'static str {
        match self {
            Named::TomlPolicy => {
                "a TOML policy (a `.toml` file that sets `kind` before its first table)"
            }
            Named::Xml("root") => "a BehaviorTree.CPP XML file (`.xml`, document element `<root>`)",
            Named::Xml(_) => "a yasmin XML file (`.xml`, document element `<StateMachine>`)",
            Named::AnyPolicy => {
                "a policy file (a TOML policy that sets `kind`, BehaviorTree.CPP, yasmin or SCXML XML, a FlexBE behavior `.py` or a py_trees DOT render)"
            }
        }
    }
}

/// Refuses `text`, read from `path` (named by another file), unless it is
/// what `expect` says; the message quotes nothing of the file.
pub fn check_named(path: &Path, text: &str, expect: Named) -> Result<(), Refusal> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let toml = || ext == "toml" && crate::discover::has_top_level_kind(text);
    let element = || document_element(text);
    let ok = match expect {
        Named::TomlPolicy => toml(),
        Named::Xml(root) => ext == "xml" && element() == Some(root),
        Named::AnyPolicy => {
            toml()
                || (ext == "py" && crate::flexbe::looks_like_flexbe(path, text))
                || (["dot", "gv"].contains(&ext.as_str())
                    && crate::py_trees_dot::looks_like_py_trees_dot(text))
                || (["xml", "scxml", "btproj"].contains(&ext.as_str())
                    && element().is_some_and(|e| {
                        ["root", "BehaviorTree", "StateMachine", "scxml"].contains(&e)
                    }))
        }
    };
    if ok {
        return Ok(());
    }
    Err(Refusal {
        message: "not a policy file: it is not read, and nothing of it is shown".into(),
        hint: format!("a file named here must be {}", expect.what()),
    })
}

/// The name of an XML text's document element, skipping a byte-order mark,
/// the XML declaration, processing instructions, comments and a DOCTYPE;
/// `None` when the text does not start as XML does.
pub fn document_element(text: &str) -> Option<&str> {
    let mut rest = text.strip_prefix('\u{feff}').unwrap_or(text);
    loop {
        rest = rest.trim_start();
        if let Some(r) = rest.strip_prefix("<?") {
            rest = &r[r.find("?>")? + 2..];
        } else if let Some(r) = rest.strip_prefix("<!--") {
            rest = &r[r.find("-->")? + 3..];
        } else if let Some(r) = rest.strip_prefix("<!") {
            rest = &r[r.find('>')? + 1..];
        } else {
            let r = rest.strip_prefix('<')?;
            let end = r
                .find(|c: char| c.is_whitespace() || c == '/' || c == '>')
                .unwrap_or(r.len());
            return (end > 0).then(|| &r[..end]);
        }
    }
}

pub(crate) fn io_msg(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".into(),
        std::io::ErrorKind::PermissionDenied => "permission denied".into(),
        _ => e.to_string().to_lowercase(),
    }
}

/// Reads a file as UTF-8 text into a [`SourceFile`] shown as `shown`: at
/// most `--max-file-bytes` and what remains of the command's budget, never
/// blocking on a FIFO with no writer (opened non-blocking; a pipe silent for
/// [`PIPE_IDLE`] is an error). `named`: a file named by another file, which
/// must be a regular file (see [`resolve`], which callers run first).
pub fn read(
    path: &Path,
    shown: &str,
    limits: &Limits,
    named: bool,
) -> Result<Arc<SourceFile>, Vec<Diagnostic>> {
    let bytes = read_bytes(path, shown, limits, named)?;
    match String::from_utf8(bytes) {
        Ok(text) => Ok(SourceFile::new(shown, text)),
        Err(e) => {
            let off = e.utf8_error().valid_up_to();
            let text = String::from_utf8_lossy(e.as_bytes()).into_owned();
            let f = SourceFile::new(shown, text);
            Err(vec![
                Diagnostic::error("file is not valid UTF-8")
                    .at(&f, off..off + 1)
                    .hint("policy files are UTF-8 text"),
            ])
        }
    }
}

/// The bytes of a file, bounded as [`read`] says.
pub fn read_bytes(
    path: &Path,
    shown: &str,
    limits: &Limits,
    named: bool,
) -> Result<Vec<u8>, Vec<Diagnostic>> {
    let cannot = |e: std::io::Error| {
        vec![Diagnostic::error(format!(
            "cannot read `{shown}`: {}",
            io_msg(&e)
        ))]
    };
    // `-` is standard input (read once, like any pipe).
    let path = if path == Path::new("-") && !named {
        Path::new("/dev/stdin")
    } else {
        path
    };
    let file = open_nonblocking(path).map_err(cannot)?;
    let meta = file.metadata().map_err(cannot)?;
    if meta.is_dir() {
        return Err(vec![Diagnostic::error(format!(
            "cannot read `{shown}`: it is a directory"
        ))]);
    }
    if named && !meta.is_file() {
        return Err(vec![
            Diagnostic::error(format!("cannot read `{shown}`: not a regular file"))
                .hint("a file named by another file must be a regular file"),
        ]);
    }
    let budget = &limits.read_budget;
    let cap = limits.max_file_bytes.min(budget.remaining());
    let too_big = |len: Option<u64>| {
        let size = len.map_or_else(|| "larger than".into(), |n| format!("{n} bytes, more than"));
        let d = if cap < limits.max_file_bytes {
            Diagnostic::error(format!(
                "`{shown}` is {size} what remains of the {} bytes this command may read in all",
                budget.limit()
            ))
            .hint("raise the limit with --max-total-bytes")
        } else {
            Diagnostic::error(format!(
                "`{shown}` is {size} the limit of {} bytes",
                limits.max_file_bytes
            ))
            .hint("raise the limit with --max-file-bytes")
        };
        vec![d]
    };
    if meta.is_file() && meta.len() > cap {
        return Err(too_big(Some(meta.len())));
    }
    let mut bytes = Vec::new();
    if meta.is_file() {
        set_blocking(&file);
        // Read at most one byte past the cap (a file may grow meanwhile).
        (&file)
            .take(cap.saturating_add(1))
            .read_to_end(&mut bytes)
            .map_err(cannot)?;
    } else {
        read_stream(&file, cap, &mut bytes).map_err(|e| {
            if e.kind() == std::io::ErrorKind::TimedOut {
                vec![
                    Diagnostic::error(format!(
                        "cannot read `{shown}`: no data for {} s",
                        PIPE_IDLE.as_secs()
                    ))
                    .hint("a pipe or FIFO must be written and closed by its writer"),
                ]
            } else {
                cannot(e)
            }
        })?;
    }
    if bytes.len() as u64 > cap {
        return Err(too_big(None));
    }
    if !budget.charge(bytes.len() as u64) {
        return Err(too_big(Some(bytes.len() as u64)));
    }
    Ok(bytes)
}

fn open_nonblocking(path: &Path) -> std::io::Result<std::fs::File> {
    use std::os::unix::fs::OpenOptionsExt;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY)
        .open(path)
}

fn set_blocking(file: &std::fs::File) {
    use std::os::fd::AsRawFd;
    let fd = file.as_raw_fd();
    // SAFETY: fcntl on a descriptor this function's caller owns; no memory
    // is passed.
    unsafe {
        let flags = libc::fcntl(fd, libc::F_GETFL);
        if flags >= 0 {
            libc::fcntl(fd, libc::F_SETFL, flags & !libc::O_NONBLOCK);
        }
    }
}

/// Reads a pipe, FIFO or device opened non-blocking: waits at most
/// [`PIPE_IDLE`] for each chunk, stops one byte past `cap`. A FIFO with no
/// writer reads as empty at once.
fn read_stream(file: &std::fs::File, cap: u64, out: &mut Vec<u8>) -> std::io::Result<()> {
    use std::os::fd::AsRawFd;
    let mut chunk = vec![0u8; 64 * 1024];
    loop {
        let want = (cap.saturating_add(1) - out.len() as u64).min(chunk.len() as u64) as usize;
        if want == 0 {
            return Ok(());
        }
        match (&*file).read(&mut chunk[..want]) {
            Ok(0) => return Ok(()),
            Ok(n) => out.extend_from_slice(&chunk[..n]),
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                let mut pfd = libc::pollfd {
                    fd: file.as_raw_fd(),
                    events: libc::POLLIN,
                    revents: 0,
                };
                let ms = PIPE_IDLE.as_millis() as libc::c_int;
                // SAFETY: one pollfd on the stack, count 1.
                let r = unsafe { libc::poll(&mut pfd, 1, ms) };
                if r == 0 {
                    return Err(std::io::ErrorKind::TimedOut.into());
                }
                if r < 0 {
                    let e = std::io::Error::last_os_error();
                    if e.kind() != std::io::ErrorKind::Interrupted {
                        return Err(e);
                    }
                }
            }
            Err(e) => return Err(e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Dir(PathBuf);
    impl Drop for Dir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
    fn scratch(tag: &str) -> Dir {
        let d = std::env::temp_dir().join(format!("btfsm-src-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(d.join("sub")).unwrap();
        Dir(canonical(&d))
    }

    #[test]
    fn budget_charges_until_the_limit() {
        let b = Budget::new(10);
        assert!(b.charge(6));
        assert!(!b.charge(5));
        assert_eq!(b.remaining(), 4);
        assert!(b.charge(4));
        assert!(!b.charge(1));
        assert!(!b.charge(u64::MAX));
    }

    #[test]
    fn named_files_stay_inside_the_root() {
        let d = scratch("root");
        let root = d.0.clone();
        std::fs::write(root.join("sub/a.toml"), "x").unwrap();
        std::fs::write(root.join("b.toml"), "x").unwrap();
        let sub = root.join("sub");
        // Inside, through `..` that stays inside.
        assert!(resolve(Some(&root), &sub, "a.toml").is_ok());
        assert!(resolve(Some(&root), &sub, "../b.toml").is_ok());
        // Outside: `..`, absolute, home, a symlink out, a device.
        for rel in [
            "../../etc/passwd",
            "/etc/passwd",
            "~/x",
            "../../../../proc/self/environ",
        ] {
            let r = resolve(Some(&root), &sub, rel).unwrap_err();
            assert!(
                r.message.contains("absolute") || r.message.contains("outside"),
                "{rel}: {r:?}"
            );
            assert!(!r.message.contains("passwd") && !r.message.contains("environ"));
        }
        std::os::unix::fs::symlink("/etc/hostname", root.join("sub/link.toml")).unwrap();
        let r = resolve(Some(&root), &sub, "link.toml").unwrap_err();
        assert!(r.message.contains("symbolic link"), "{r:?}");
        std::fs::create_dir_all(root.join(".git")).unwrap();
        std::fs::write(root.join(".git/config"), "token").unwrap();
        let r = resolve(Some(&root), &sub, "../.git/config").unwrap_err();
        assert!(r.message.contains(".git"), "{r:?}");
        // No root: anything regular, but never a device.
        assert!(resolve(None, &sub, "/etc/hostname").is_ok());
        let r = resolve(None, &sub, "/dev/zero").unwrap_err();
        assert!(r.message.contains("not a regular file"), "{r:?}");
        assert!(
            resolve(Some(&root), &sub, "missing.toml")
                .unwrap_err()
                .message
                == "no such file"
        );
    }

    #[test]
    fn the_root_is_the_git_work_tree_else_the_directory() {
        let d = scratch("auto");
        let limits = Limits::default();
        assert_eq!(root_for(&limits, &d.0.join("sub")), Some(d.0.join("sub")));
        std::fs::create_dir_all(d.0.join(".git")).unwrap();
        assert_eq!(root_for(&limits, &d.0.join("sub")), Some(d.0.clone()));
        let off = Limits {
            confinement: Confinement::Off,
            ..Limits::default()
        };
        assert_eq!(root_for(&off, &d.0), None);
    }

    #[test]
    fn a_fifo_with_no_writer_reads_as_empty_at_once() {
        let d = scratch("fifo");
        let p = d.0.join("f.toml");
        let c = std::ffi::CString::new(p.to_str().unwrap()).unwrap();
        // SAFETY: a NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let t = std::time::Instant::now();
        let bytes = read_bytes(&p, "f.toml", &Limits::default(), false).unwrap();
        assert!(bytes.is_empty());
        assert!(t.elapsed() < Duration::from_secs(5));
        // Named by a file: refused without opening.
        let err = read_bytes(&p, "f.toml", &Limits::default(), true).unwrap_err();
        assert!(err[0].message.contains("not a regular file"));
    }

    #[test]
    fn a_pipe_whose_writer_stays_silent_is_an_error_after_the_idle_time() {
        let d = scratch("idle");
        let p = d.0.join("f.toml");
        let c = std::ffi::CString::new(p.to_str().unwrap()).unwrap();
        // SAFETY: a NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let (tx, rx) = std::sync::mpsc::channel::<()>();
        let w = p.clone();
        // A writer that opens the FIFO, writes a little, then says nothing.
        let writer = std::thread::spawn(move || {
            use std::io::Write;
            let mut f = std::fs::OpenOptions::new().write(true).open(w).unwrap();
            f.write_all(b"# ").unwrap();
            let _ = rx.recv_timeout(PIPE_IDLE * 2);
        });
        // Wait until the writer holds the FIFO open.
        std::thread::sleep(Duration::from_millis(200));
        let t = std::time::Instant::now();
        let err = read_bytes(&p, "f.toml", &Limits::default(), false).unwrap_err();
        assert!(err[0].message.contains("no data for 10 s"), "{}", err[0]);
        assert!(t.elapsed() >= PIPE_IDLE && t.elapsed() < PIPE_IDLE * 2);
        tx.send(()).unwrap();
        writer.join().unwrap();
    }

    #[test]
    fn every_read_is_charged_to_the_command() {
        let d = scratch("budget");
        let p = d.0.join("a.toml");
        std::fs::write(&p, vec![b'#'; 600]).unwrap();
        let limits = Limits {
            read_budget: Budget::new(1000),
            ..Limits::default()
        };
        assert!(read_bytes(&p, "a.toml", &limits, false).is_ok());
        let err = read_bytes(&p, "a.toml", &limits, false).unwrap_err();
        assert!(
            err[0].message.contains("remains of the 1000 bytes"),
            "{}",
            err[0]
        );
        assert!(
            err[0]
                .hint
                .as_deref()
                .unwrap()
                .contains("--max-total-bytes")
        );
        // /dev/zero stops at the cap.
        let err = read_bytes(Path::new("/dev/zero"), "z", &limits, false).unwrap_err();
        assert!(err[0].message.contains("larger than"), "{}", err[0]);
    }
}
