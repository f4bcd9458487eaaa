//! Output files, written whole or not at all, without harming what the path
//! names (issue 12):
//!
//! - a regular file (new or existing) is replaced atomically: the bytes go to
//!   a temporary `.NAME.btfsm-PID.tmp` beside it (created exclusively, with
//!   the existing file's mode and owner), synced and renamed over it;
//! - a symlink is followed to its final target, which is replaced the same
//!   way beside itself: the link stays;
//! - a device, FIFO or socket (`/dev/null`, `/dev/stdout`, a named pipe) is
//!   written into directly, never renamed over; a FIFO is opened without
//!   blocking, so one that no process reads is an error, not a hang;
//! - `-`, or a path that is this process's stdout, is stdout;
//! - temporary names stay within NAME_MAX (255 bytes) whatever the name.
//!
//! [`check_distinct`] refuses one file named by two outputs of a command;
//! [`OutputRoot`] (`confine.rs`) keeps outputs inside the root and out of
//! `.git` (issue 33), and a replaced file never keeps an executable bit.

use std::ffi::{OsStr, OsString};
use std::fs::{File, Metadata, OpenOptions};
use std::io::{self, Write};
use std::os::unix::ffi::{OsStrExt, OsStringExt};
use std::os::unix::fs::{FileTypeExt, MetadataExt, OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};

mod confine;
pub use confine::{CONFINED_HINT, Confined, OutputRoot, is_confined};

/// Longest file name on the file systems btfsm writes to (Linux's NAME_MAX).
pub const NAME_MAX: usize = 255;

/// Symlinks followed before giving up (Linux's own limit).
const MAX_SYMLINKS: usize = 40;

/// Where the bytes of an output path go.
#[derive(Debug)]
pub enum Destination {
    /// `-`, or a path that is this process's standard output
    /// (`/dev/stdout`, `/proc/self/fd/1`).
    Stdout,
    /// A regular file, existing or not, replaced atomically: `dir` is its
    /// canonical directory (symlinks followed), `name` its file name.
    File {
        dir: PathBuf,
        name: OsString,
        existing: Option<Metadata>,
    },
    /// Written in place: a device, FIFO or socket, or a file reached through
    /// `/proc` (`/dev/stderr`).
    Direct { path: PathBuf },
}

/// What names one output: two outputs with the same identity write the
/// same file.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Identity {
    /// Device and inode of what exists.
    Node(u64, u64),
    /// Canonical directory and name of a file not created yet.
    Path(PathBuf),
    /// A closed or unreadable stdout.
    Stdout,
}

impl Destination {
    /// Follows `path` to what it names, without creating or opening it.
    pub fn resolve(path: &Path) -> io::Result<Destination> {
        if path.as_os_str() == "-" {
            return Ok(Destination::Stdout);
        }
        let mut p = path.to_path_buf();
        for _ in 0..MAX_SYMLINKS {
            let name = p
                .file_name()
                .ok_or_else(|| {
                    io::Error::new(io::ErrorKind::InvalidInput, "the path names no file")
                })?
                .to_os_string();
            let parent = match p.parent() {
                Some(d) if !d.as_os_str().is_empty() => d,
                _ => Path::new("."),
            };
            let dir = std::fs::canonicalize(parent)?;
            let full = dir.join(&name);
            // `/proc` links (`/dev/stdout` -> /proc/self/fd/1) name open
            // files, pipes and terminals that only opening them reaches.
            if dir.starts_with("/proc") {
                return Ok(match (std::fs::metadata(&full), stdout_identity()) {
                    (Ok(m), Identity::Node(dev, ino)) if (m.dev(), m.ino()) == (dev, ino) => {
                        Destination::Stdout
                    }
                    _ => Destination::Direct { path: full },
                });
            }
            match std::fs::symlink_metadata(&full) {
                Err(e) if e.kind() == io::ErrorKind::NotFound => {
                    return Ok(Destination::File {
                        dir,
                        name,
                        existing: None,
                    });
                }
                Err(e) => return Err(e),
                Ok(m) if m.file_type().is_symlink() => {
                    refuse_planted_link(&dir, &full, &m)?;
                    let to = std::fs::read_link(&full)?;
                    p = if to.is_absolute() { to } else { dir.join(to) };
                }
                Ok(m) if m.is_file() => {
                    return Ok(Destination::File {
                        dir,
                        name,
                        existing: Some(m),
                    });
                }
                Ok(m) if m.is_dir() => {
                    return Err(io::Error::new(
                        io::ErrorKind::IsADirectory,
                        "it is a directory",
                    ));
                }
                Ok(_) => return Ok(Destination::Direct { path: full }),
            }
        }
        Err(io::Error::other(format!(
            "more than {MAX_SYMLINKS} levels of symbolic links"
        )))
    }

    /// [`Destination::resolve`], then refused unless `root` allows what
    /// the path resolved to.
    pub fn resolve_within(path: &Path, root: &OutputRoot) -> io::Result<Destination> {
        let d = Destination::resolve(path)?;
        match &d {
            Destination::Stdout => {}
            Destination::File { dir, name, .. } => root.check(path, &dir.join(name))?,
            Destination::Direct { path: target } => root.check(path, target)?,
        }
        Ok(d)
    }

    /// Writes `bytes` whole: stdout, in place, or by atomic replacement.
    pub fn write(&self, bytes: &[u8]) -> io::Result<()> {
        match self {
            // The library never prints: the command line writes stdout.
            Destination::Stdout => Err(io::Error::other(
                "standard output is written by the command line, not here",
            )),
            Destination::Direct { path } => write_in_place(path, bytes),
            Destination::File {
                dir,
                name,
                existing,
            } => replace(dir, name, existing.as_ref(), bytes),
        }
    }

    /// What the output names, and whether several outputs may share it
    /// (a character device: `/dev/null`, a terminal).
    fn identity(&self) -> (Identity, bool) {
        let node = |m: &Metadata| {
            (
                Identity::Node(m.dev(), m.ino()),
                m.file_type().is_char_device(),
            )
        };
        match self {
            Destination::Stdout => match stdout_metadata() {
                Some(m) => node(&m),
                None => (Identity::Stdout, false),
            },
            Destination::File {
                existing: Some(m), ..
            } => node(m),
            Destination::File {
                dir,
                name,
                existing: None,
            } => (Identity::Path(dir.join(name)), false),
            Destination::Direct { path } => match std::fs::metadata(path) {
                Ok(m) => node(&m),
                Err(_) => (Identity::Path(path.clone()), false),
            },
        }
    }
}

/// Writes `bytes` to `path` whole or not at all (see the module's rules):
/// a regular file through a temporary renamed over it, a device or FIFO in
/// place, `-` to stdout.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    Destination::resolve(path)?.write(bytes)
}

/// Creates the directory `path` and its parents for outputs written under
/// it (`plan -o DIR`), once `root` allows where it resolves; each file
/// written under it is checked again as it is written.
pub fn create_dir_within(path: &Path, root: &OutputRoot) -> io::Result<()> {
    root.check_dir(path)?;
    std::fs::create_dir_all(path)?;
    root.check_dir(path)
}

/// One output of a command that names the same file as another: which
/// flags, and how they spelled it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum OutputClash {
    /// Two output flags name one file.
    Twice {
        first: (String, PathBuf),
        second: (String, PathBuf),
    },
    /// An output flag names the stdout where the report goes.
    Stdout { flag: String, path: PathBuf },
    /// An output cannot be written at all.
    Unwritable { path: PathBuf, error: String },
}

impl std::fmt::Display for OutputClash {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OutputClash::Twice { first, second } => write!(
                f,
                "{} `{}` and {} `{}` are the same file: one output path used twice in one command (one would overwrite the other)",
                first.0,
                first.1.display(),
                second.0,
                second.1.display()
            ),
            OutputClash::Stdout { flag, path } => write!(
                f,
                "{flag} `{}` is the standard output, where the report goes: one output used twice in one command",
                path.display()
            ),
            OutputClash::Unwritable { path, error } => {
                write!(f, "cannot write `{}`: {error}", path.display())
            }
        }
    }
}

/// Checks, before anything is written, that the outputs of one command
/// (flag, path) name distinct files, whatever their spelling (`x`, `./d/../x`,
/// a symlink to `x`, `/dev/stdout` and `-`), and none the stdout where the
/// command prints its report (`report_on_stdout`). Character devices
/// (`/dev/null`, a terminal) may take several outputs.
pub fn check_distinct(
    outputs: &[(&str, &Path)],
    report_on_stdout: bool,
) -> Result<(), OutputClash> {
    let mut seen: Vec<(Identity, &str, &Path)> = Vec::new();
    let stdout = report_on_stdout.then(|| Destination::Stdout.identity());
    for &(flag, path) in outputs {
        let dest = Destination::resolve(path).map_err(|e| OutputClash::Unwritable {
            path: path.to_path_buf(),
            error: e.to_string(),
        })?;
        let (id, shared) = dest.identity();
        if shared {
            continue;
        }
        if let Some((out, false)) = &stdout
            && *out == id
        {
            return Err(OutputClash::Stdout {
                flag: flag.to_string(),
                path: path.to_path_buf(),
            });
        }
        if let Some((_, f, p)) = seen.iter().find(|(i, _, _)| *i == id) {
            return Err(OutputClash::Twice {
                first: (f.to_string(), p.to_path_buf()),
                second: (flag.to_string(), path.to_path_buf()),
            });
        }
        seen.push((id, flag, path));
    }
    Ok(())
}

/// Linux's `protected_symlinks` rule, which following a link by hand would
/// bypass: a symlink in a sticky world-writable directory (`/tmp`) is
/// followed only when it belongs to the follower or to the directory's
/// owner; otherwise another user planted it (`/tmp/out.svg` ->
/// `/etc/shadow`, waiting for root to write `-o /tmp/out.svg`).
fn refuse_planted_link(dir: &Path, link: &Path, m: &Metadata) -> io::Result<()> {
    let Ok(d) = std::fs::metadata(dir) else {
        return Ok(());
    };
    // SAFETY: geteuid has no failure mode.
    let me = unsafe { libc::geteuid() };
    if d.mode() & 0o1002 == 0o1002 && m.uid() != d.uid() && m.uid() != me {
        return Err(io::Error::new(
            io::ErrorKind::PermissionDenied,
            format!(
                "`{}` is a symlink of another user in a shared sticky directory: not followed",
                link.display()
            ),
        ));
    }
    Ok(())
}

#[allow(
    clippy::disallowed_methods,
    reason = "asks which file stdout is (its device and inode), never writes to it"
)]
fn stdout_metadata() -> Option<Metadata> {
    use std::os::fd::AsFd;
    let fd = io::stdout().as_fd().try_clone_to_owned().ok()?;
    File::from(fd).metadata().ok()
}

fn stdout_identity() -> Identity {
    match stdout_metadata() {
        Some(m) => Identity::Node(m.dev(), m.ino()),
        None => Identity::Stdout,
    }
}

/// Writes into a device, FIFO or `/proc` file without renaming anything.
fn write_in_place(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut f = open_in_place(path)?;
    f.write_all(bytes)?;
    f.flush()
}

/// Opens a device, FIFO or `/proc` file for writing in place. The open does
/// not block: a FIFO no process reads is an error (ENXIO), and the flag is
/// cleared afterwards so that writes wait for the reader.
fn open_in_place(path: &Path) -> io::Result<File> {
    use std::os::fd::AsRawFd;
    let was_fifo = std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo());
    let f = OpenOptions::new()
        .write(true)
        .custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY)
        .open(path)
        .map_err(|e| match e.raw_os_error() {
            Some(libc::ENXIO) if was_fifo => io::Error::new(
                io::ErrorKind::BrokenPipe,
                "no process is reading this FIFO (open it for reading first)",
            ),
            _ => e,
        })?;
    let fd = f.as_raw_fd();
    // SAFETY: fcntl on a descriptor this function owns.
    let flags = unsafe { libc::fcntl(fd, libc::F_GETFL) };
    // SAFETY: as above.
    if flags < 0 || unsafe { libc::fcntl(fd, libc::F_SETFL, flags & !libc::O_NONBLOCK) } < 0 {
        return Err(io::Error::last_os_error());
    }
    if f.metadata()?.is_file() {
        // A regular file reached through `/proc`: written as `>` would.
        f.set_len(0)?;
    }
    Ok(f)
}

/// Replaces `dir/name` atomically (see [`Replacement`]).
fn replace(dir: &Path, name: &OsStr, existing: Option<&Metadata>, bytes: &[u8]) -> io::Result<()> {
    let mut r = Replacement::create(dir, name, existing)?;
    r.file.write_all(bytes)?;
    r.commit()
}

/// The temporary that replaces `dir/name`: beside it, created exclusively
/// (a planted file or symlink of that name is never followed), given the
/// existing file's owner and mode (a new file gets the default mode, 0666
/// less the umask); [`Replacement::commit`] syncs it and renames it over
/// the target. Dropped uncommitted, it is removed. The existing file's
/// mode loses its executable, set-id and sticky bits: an output is data, so
/// replacing a hook or a script leaves a file that does not run.
struct Replacement {
    file: File,
    tmp: PathBuf,
    dir: PathBuf,
    target: PathBuf,
    done: bool,
}

impl Replacement {
    fn create(dir: &Path, name: &OsStr, existing: Option<&Metadata>) -> io::Result<Replacement> {
        remove_stale_temporaries(dir, name);
        let tmp = dir.join(temp_name(name, std::process::id()));
        let open = || {
            OpenOptions::new()
                .write(true)
                .create_new(true)
                // Private until the existing file's mode is set.
                .mode(if existing.is_some() { 0o600 } else { 0o666 })
                .open(&tmp)
        };
        let file = match open() {
            // Left by an earlier process with this pid.
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {
                std::fs::remove_file(&tmp)?;
                open()?
            }
            r => r?,
        };
        let r = Replacement {
            file,
            tmp,
            dir: dir.to_path_buf(),
            target: dir.join(name),
            done: false,
        };
        if let Some(m) = existing {
            // Best effort: only root may give a file to another owner.
            let mine = r.file.metadata()?;
            if mine.uid() != m.uid() || mine.gid() != m.gid() {
                let _ = std::os::unix::fs::fchown(&r.file, Some(m.uid()), Some(m.gid()));
            }
            r.file
                .set_permissions(std::fs::Permissions::from_mode(m.mode() & 0o666))?;
        }
        Ok(r)
    }

    fn commit(mut self) -> io::Result<()> {
        self.file.sync_all()?;
        std::fs::rename(&self.tmp, &self.target)?;
        self.done = true;
        if let Ok(d) = File::open(&self.dir) {
            // The rename itself, on disk (best effort).
            let _ = d.sync_all();
        }
        Ok(())
    }
}

impl Drop for Replacement {
    fn drop(&mut self) {
        if !self.done {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// An output file written as it is made (`sim --trace`), with the rules of
/// [`Destination`]: a regular file (or a symlink's target) is replaced
/// whole or not at all when [`OutputFile::commit`] is called (dropped
/// without it, the temporary is removed and the target left as it was); a
/// device or FIFO is written into as the bytes come. Standard output is the
/// command line's to write: `-` is refused here.
pub struct OutputFile {
    out: io::BufWriter<File>,
    replacement: Option<Replacement>,
}

impl OutputFile {
    pub fn create(path: &Path, root: &OutputRoot) -> io::Result<OutputFile> {
        match Destination::resolve_within(path, root)? {
            Destination::Stdout => Err(io::Error::other(
                "this output cannot go to standard output; name a file",
            )),
            Destination::Direct { path } => Ok(OutputFile {
                out: io::BufWriter::with_capacity(1 << 16, open_in_place(&path)?),
                replacement: None,
            }),
            Destination::File {
                dir,
                name,
                existing,
            } => {
                let r = Replacement::create(&dir, &name, existing.as_ref())?;
                let f = r.file.try_clone()?;
                Ok(OutputFile {
                    out: io::BufWriter::with_capacity(1 << 16, f),
                    replacement: Some(r),
                })
            }
        }
    }

    /// Flushes, then (a file) syncs and renames the temporary over the target.
    pub fn commit(mut self) -> io::Result<()> {
        self.out.flush()?;
        match self.replacement.take() {
            Some(r) => r.commit(),
            None => Ok(()),
        }
    }
}

impl Write for OutputFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.out.write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}

const TMP_INFIX: &[u8] = b".btfsm-";
const TMP_SUFFIX: &[u8] = b".tmp";

/// The `NAME` part of `.NAME.btfsm-PID.tmp`: the name itself, or, when the
/// temporary would pass NAME_MAX, its head and a hash of the whole name.
fn temp_stem(name: &OsStr) -> Vec<u8> {
    let name = name.as_bytes();
    // The dot, the infix, a pid of up to 10 digits (u32) and the suffix.
    let budget = NAME_MAX - 1 - TMP_INFIX.len() - 10 - TMP_SUFFIX.len();
    if name.len() <= budget {
        return name.to_vec();
    }
    let hash = format!("~{:016x}", fnv1a(name));
    let mut stem = name[..budget - hash.len()].to_vec();
    stem.extend_from_slice(hash.as_bytes());
    stem
}

/// FNV-1a, 64 bits: stable across builds, so that a later run finds the
/// temporaries of an earlier one.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// `.NAME.btfsm-PID.tmp`, at most NAME_MAX bytes.
fn temp_name(name: &OsStr, pid: u32) -> OsString {
    let mut t = vec![b'.'];
    t.extend(temp_stem(name));
    t.extend_from_slice(TMP_INFIX);
    t.extend_from_slice(pid.to_string().as_bytes());
    t.extend_from_slice(TMP_SUFFIX);
    OsString::from_vec(t)
}

/// Removes `.NAME.btfsm-PID.tmp` files beside the target left by runs that
/// were killed between writing and renaming (the target itself is never
/// half-written: the rename is atomic). Only temporaries of processes that
/// no longer run are removed; where that cannot be told (no `/proc`), none.
fn remove_stale_temporaries(dir: &Path, name: &OsStr) {
    if !Path::new("/proc/self").exists() {
        return;
    }
    let mut prefix = vec![b'.'];
    prefix.extend(temp_stem(name));
    prefix.extend_from_slice(TMP_INFIX);
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let file = e.file_name();
        let Some(pid) = file
            .as_bytes()
            .strip_prefix(prefix.as_slice())
            .and_then(|r| r.strip_suffix(TMP_SUFFIX))
            .filter(|p| !p.is_empty() && p.iter().all(u8::is_ascii_digit))
        else {
            continue;
        };
        if !Path::new("/proc").join(OsStr::from_bytes(pid)).exists() {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::symlink;

    /// A scratch directory removed on drop.
    struct Dir(PathBuf);

    impl Dir {
        fn new(tag: &str) -> Dir {
            let d = std::env::temp_dir().join(format!("btfsm-out-{tag}-{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&d);
            std::fs::create_dir_all(&d).unwrap();
            Dir(d)
        }

        fn temporaries(&self) -> usize {
            std::fs::read_dir(&self.0)
                .unwrap()
                .flatten()
                .filter(|e| e.file_name().as_bytes().ends_with(TMP_SUFFIX))
                .count()
        }
    }

    impl Drop for Dir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    fn mode(p: &Path) -> u32 {
        std::fs::metadata(p).unwrap().permissions().mode() & 0o7777
    }

    #[test]
    fn a_symlink_is_written_through_and_kept() {
        let d = Dir::new("link");
        std::fs::create_dir_all(d.0.join("real")).unwrap();
        std::fs::write(d.0.join("real/t.txt"), "old").unwrap();
        symlink("real/t.txt", d.0.join("hop")).unwrap();
        symlink(d.0.join("hop"), d.0.join("link")).unwrap();
        write_atomically(&d.0.join("link"), b"new").unwrap();
        assert!(
            std::fs::symlink_metadata(d.0.join("link"))
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read(d.0.join("real/t.txt")).unwrap(), b"new");
        // A dangling link creates its target.
        symlink("real/n.txt", d.0.join("dangling")).unwrap();
        write_atomically(&d.0.join("dangling"), b"n").unwrap();
        assert_eq!(std::fs::read(d.0.join("real/n.txt")).unwrap(), b"n");
        // A loop is an error, not a hang.
        symlink("loop", d.0.join("loop")).unwrap();
        let e = write_atomically(&d.0.join("loop"), b"x").unwrap_err();
        assert!(e.to_string().contains("symbolic links"), "{e}");
        assert_eq!(d.temporaries(), 0);
    }

    #[test]
    fn a_symlink_planted_by_another_user_in_a_sticky_directory_is_refused() {
        let d = Dir::new("sticky");
        std::fs::set_permissions(&d.0, std::fs::Permissions::from_mode(0o1777)).unwrap();
        let victim = d.0.join("victim");
        std::fs::write(&victim, "keep").unwrap();
        let link = d.0.join("out");
        symlink(&victim, &link).unwrap();
        // Only root can give the link to another user.
        if std::os::unix::fs::lchown(&link, Some(54321), None).is_err() {
            return;
        }
        let e = write_atomically(&link, b"data").unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::PermissionDenied, "{e}");
        assert!(e.to_string().contains("not followed"), "{e}");
        assert_eq!(std::fs::read(&victim).unwrap(), b"keep");
        // The directory's owner's (or one's own) links are followed.
        std::os::unix::fs::lchown(&link, Some(std::fs::metadata(&d.0).unwrap().uid()), None)
            .unwrap();
        write_atomically(&link, b"data").unwrap();
        assert_eq!(std::fs::read(&victim).unwrap(), b"data");
    }

    #[test]
    fn an_existing_files_mode_is_kept_but_never_executable_and_new_files_get_the_default() {
        let d = Dir::new("mode");
        let p = d.0.join("secret");
        for m in [0o600, 0o640, 0o755, 0o4775] {
            std::fs::write(&p, "old").unwrap();
            std::fs::set_permissions(&p, std::fs::Permissions::from_mode(m)).unwrap();
            write_atomically(&p, b"new").unwrap();
            // Read and write bits kept; never executable (a hook replaced
            // by an output no longer runs), never set-id.
            assert_eq!(mode(&p), m & 0o666);
            assert_eq!(std::fs::read(&p).unwrap(), b"new");
        }
        std::fs::write(d.0.join("reference"), "").unwrap();
        write_atomically(&d.0.join("fresh"), b"x").unwrap();
        assert_eq!(mode(&d.0.join("fresh")), mode(&d.0.join("reference")));
    }

    #[test]
    fn temporaries_of_long_names_fit_and_are_cleaned() {
        let d = Dir::new("long");
        for len in [1, 200, 233, 234, 254, 255] {
            let name = OsString::from("x".repeat(len));
            let t = temp_name(&name, u32::MAX);
            assert!(t.len() <= NAME_MAX, "{len}: {} bytes", t.len());
            // A run killed before its rename left this (pid above pid_max).
            std::fs::write(d.0.join(&t), "partial").unwrap();
            write_atomically(&d.0.join(&name), b"whole").unwrap();
            assert_eq!(std::fs::read(d.0.join(&name)).unwrap(), b"whole");
            assert!(!d.0.join(&t).exists(), "{len}: stale temporary kept");
        }
        // Two long names sharing their head get distinct temporaries.
        let a = OsString::from(format!("{}a", "y".repeat(250)));
        let b = OsString::from(format!("{}b", "y".repeat(250)));
        assert_ne!(temp_name(&a, 1), temp_name(&b, 1));
        assert_eq!(d.temporaries(), 0);
    }

    #[test]
    fn a_planted_temporary_is_not_followed() {
        let d = Dir::new("planted");
        let victim = d.0.join("victim");
        std::fs::write(&victim, "keep").unwrap();
        // A symlink where this process's temporary will be.
        let t = temp_name(OsStr::new("out"), std::process::id());
        symlink(&victim, d.0.join(&t)).unwrap();
        write_atomically(&d.0.join("out"), b"data").unwrap();
        assert_eq!(std::fs::read(&victim).unwrap(), b"keep");
        assert_eq!(std::fs::read(d.0.join("out")).unwrap(), b"data");
    }

    fn mkfifo(p: &Path) {
        let c = std::ffi::CString::new(p.as_os_str().as_bytes()).unwrap();
        // SAFETY: a valid NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    }

    #[test]
    fn a_fifo_is_written_into_and_one_without_reader_is_an_error() {
        use std::io::Read;
        let d = Dir::new("fifo");
        let p = d.0.join("pipe");
        mkfifo(&p);
        let t0 = std::time::Instant::now();
        let e = write_atomically(&p, b"x").unwrap_err();
        assert!(e.to_string().contains("no process is reading"), "{e}");
        assert!(t0.elapsed().as_secs() < 5);
        // A reader thread drains the FIFO while 1 MiB (more than a pipe
        // buffer) is written.
        let reader = {
            let p = p.clone();
            std::thread::spawn(move || {
                let mut v = Vec::new();
                File::open(&p).unwrap().read_to_end(&mut v).unwrap();
                v
            })
        };
        let data = vec![7u8; 1 << 20];
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(20);
        // The reader opens the FIFO at some point: retry until it has.
        loop {
            match write_atomically(&p, &data) {
                Ok(()) => break,
                Err(e) if e.kind() == io::ErrorKind::BrokenPipe => {
                    assert!(std::time::Instant::now() < deadline, "no reader");
                    std::thread::sleep(std::time::Duration::from_millis(5));
                }
                Err(e) => panic!("{e}"),
            }
        }
        assert_eq!(reader.join().unwrap(), data);
        assert!(std::fs::symlink_metadata(&p).unwrap().file_type().is_fifo());
    }

    #[test]
    fn a_device_is_written_into_not_replaced() {
        let d = Dir::new("dev");
        let node = d.0.join("null");
        let c = std::ffi::CString::new(node.as_os_str().as_bytes()).unwrap();
        // SAFETY: a valid NUL-terminated path.
        let made =
            unsafe { libc::mknod(c.as_ptr(), libc::S_IFCHR | 0o666, libc::makedev(1, 3)) } == 0;
        let target = if made {
            node
        } else {
            PathBuf::from("/dev/null")
        };
        symlink(&target, d.0.join("link")).unwrap();
        for p in [target.clone(), d.0.join("link")] {
            write_atomically(&p, b"gone").unwrap();
            let m = std::fs::symlink_metadata(&target).unwrap();
            assert!(m.file_type().is_char_device(), "{}", p.display());
        }
        assert_eq!(d.temporaries(), 0);
        // A directory is refused.
        let e = write_atomically(&d.0, b"x").unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::IsADirectory, "{e}");
    }

    #[test]
    fn one_file_named_twice_is_found_whatever_the_spelling() {
        let d = Dir::new("twice");
        std::fs::create_dir_all(d.0.join("sub")).unwrap();
        symlink("x", d.0.join("link")).unwrap();
        let x = d.0.join("x");
        let spelled = d.0.join("sub/../x");
        let link = d.0.join("link");
        let y = d.0.join("y");
        for existing in [false, true] {
            if existing {
                std::fs::write(&x, "").unwrap();
            }
            for other in [&x, &spelled, &link] {
                let e = check_distinct(&[("--a", &x), ("--b", other)], false).unwrap_err();
                assert!(matches!(e, OutputClash::Twice { .. }), "{e}");
                assert!(e.to_string().contains("used twice"), "{e}");
            }
            assert_eq!(check_distinct(&[("--a", &x), ("--b", &y)], false), Ok(()));
        }
        // `-` is stdout: where the report goes, or given twice.
        let dash = Path::new("-");
        assert!(matches!(
            check_distinct(&[("--a", dash)], true),
            Err(OutputClash::Stdout { .. }) | Ok(())
        ));
        let twice = check_distinct(&[("--a", dash), ("--b", dash)], false);
        // Both are stdout; only a terminal or /dev/null may take both.
        let shared = stdout_metadata().is_some_and(|m| m.file_type().is_char_device());
        assert_eq!(twice.is_ok(), shared, "{twice:?}");
        // Character devices may take several outputs.
        let null = Path::new("/dev/null");
        assert_eq!(
            check_distinct(&[("--a", null), ("--b", null)], true),
            Ok(())
        );
        // A missing directory is said before anything is written.
        let e = check_distinct(&[("--a", &d.0.join("no/such"))], false).unwrap_err();
        assert!(matches!(e, OutputClash::Unwritable { .. }), "{e}");
    }
}
