//! Rendering DOT with Graphviz's `dot`: a child process under a deadline,
//! its output and error streams capped, never a half-written file.

use std::io::Write;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// An output format of [`render`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum RenderFormat {
    Svg,
    Png,
    Pdf,
}

impl RenderFormat {
    /// The file extension (and Graphviz `-T` name).
    pub fn extension(self) -> &'static str {
        match self {
            RenderFormat::Svg => "svg",
            RenderFormat::Png => "png",
            RenderFormat::Pdf => "pdf",
        }
    }

    /// The format an output file's extension asks for (`x.svg`, `x.PNG`,
    /// `x.pdf`); `None` for anything else (`x.dot`, `x.gv`, no extension),
    /// which gets DOT text.
    pub fn from_path(path: &std::path::Path) -> Option<RenderFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        [RenderFormat::Svg, RenderFormat::Png, RenderFormat::Pdf]
            .into_iter()
            .find(|f| f.extension() == ext)
    }
}

impl std::fmt::Display for RenderFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.extension())
    }
}

/// Why Graphviz could not render a diagram.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("graphviz `{program}` is not installed (apt-get install graphviz)")]
    NotInstalled { program: String },
    #[error("graphviz `{program}` failed ({status}): {stderr}")]
    Failed {
        program: String,
        status: String,
        stderr: String,
    },
    #[error(
        "graphviz `{program}` did not finish within {ms} ms and was stopped (give it more time with --timeout-ms)"
    )]
    Timeout { program: String, ms: u128 },
    #[error("graphviz `{program}` wrote more than {limit} bytes and was stopped")]
    TooLarge { program: String, limit: u64 },
    #[error("cannot run graphviz `{program}`: {source}")]
    Io {
        program: String,
        #[source]
        source: std::io::Error,
    },
}

/// Graphviz's time budget where the command has no `--timeout-ms` of its
/// own meaning (`dot --render`'s default).
pub const DEFAULT_RENDER_TIMEOUT_MS: u64 = 60_000;

/// Most bytes of a rendered diagram read from Graphviz: past them the child
/// is killed and the run fails.
pub const MAX_RENDER_BYTES: u64 = 256 << 20;

/// Most bytes of Graphviz's stderr kept for the message (the rest is read
/// and dropped, so that the child never blocks on it).
pub const MAX_RENDER_STDERR_BYTES: u64 = 64 << 10;

/// What a Graphviz run may take.
#[derive(Debug, Clone, Copy)]
pub(super) struct Budget {
    pub(super) timeout: Duration,
    pub(super) max_output: u64,
    pub(super) max_stderr: u64,
}

impl Budget {
    pub(super) fn new(timeout: Duration) -> Budget {
        Budget {
            timeout,
            max_output: MAX_RENDER_BYTES,
            max_stderr: MAX_RENDER_STDERR_BYTES,
        }
    }
}

/// Whether Graphviz's `dot` runs on this machine (`dot -V` succeeds).
pub fn installed() -> bool {
    std::process::Command::new("dot")
        .arg("-V")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Renders DOT to svg/png/pdf by running Graphviz's `dot` as a child killed
/// after `timeout` or [`MAX_RENDER_BYTES`] of output; a clear error when
/// `dot` is not installed.
pub fn render(dot: &str, format: RenderFormat, timeout: Duration) -> Result<Vec<u8>, RenderError> {
    render_with("dot", dot, format, timeout)
}

/// [`render`] with another Graphviz program (a full path, or `neato`, ...).
pub fn render_with(
    program: &str,
    dot: &str,
    format: RenderFormat,
    timeout: Duration,
) -> Result<Vec<u8>, RenderError> {
    run_graphviz(program, dot, format, Budget::new(timeout)).map(|(out, _warnings)| out)
}

/// What the threads around a Graphviz child report.
enum Piped {
    /// Its input written (or not).
    Stdin(std::io::Result<()>),
    /// Its output, at most `max_output + 1` bytes.
    Stdout(std::io::Result<Vec<u8>>),
    /// Its first `max_stderr` bytes of stderr.
    Stderr(std::io::Result<Vec<u8>>),
}

/// Runs a Graphviz program on `dot`: its output and its warnings (stderr).
/// Input is fed and output read by threads, so that a child that does not
/// read, or writes a lot, cannot dead-lock us; the child is killed past the
/// budget's deadline or output size, without waiting for its pipes.
pub(super) fn run_graphviz(
    program: &str,
    dot: &str,
    format: RenderFormat,
    budget: Budget,
) -> Result<(Vec<u8>, String), RenderError> {
    use std::io::Read;
    use std::sync::mpsc;
    let io = |source: std::io::Error| RenderError::Io {
        program: program.to_string(),
        source,
    };
    let start = Instant::now();
    // No deadline when the budget passes the clock's range.
    let deadline = start.checked_add(budget.timeout);
    let mut child = Command::new(program)
        .arg(format!("-T{}", format.extension()))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => RenderError::NotInstalled {
                program: program.to_string(),
            },
            _ => io(e),
        })?;
    let (tx, rx) = mpsc::channel();
    let (mut stdin, stdout, stderr) = (
        child.stdin.take().expect("stdin is piped"),
        child.stdout.take().expect("stdout is piped"),
        child.stderr.take().expect("stderr is piped"),
    );
    let input = dot.as_bytes().to_vec();
    let t = tx.clone();
    std::thread::spawn(move || {
        let r = stdin.write_all(&input);
        drop(stdin);
        let _ = t.send(Piped::Stdin(r));
    });
    let t = tx.clone();
    std::thread::spawn(move || {
        let mut v = Vec::new();
        let r = stdout
            .take(budget.max_output.saturating_add(1))
            .read_to_end(&mut v);
        let _ = t.send(Piped::Stdout(r.map(|_| v)));
    });
    std::thread::spawn(move || {
        let mut v = Vec::new();
        let mut err = stderr;
        let r = (&mut err).take(budget.max_stderr).read_to_end(&mut v);
        // Drained, not kept.
        let _ = std::io::copy(&mut err, &mut std::io::sink());
        let _ = tx.send(Piped::Stderr(r.map(|_| v)));
    });
    let stop = |child: &mut std::process::Child| {
        let _ = child.kill();
        let _ = child.wait();
    };
    let (mut written, mut out, mut err, mut status) = (None, None, None, None);
    while written.is_none() || out.is_none() || err.is_none() || status.is_none() {
        let now = Instant::now();
        if deadline.is_some_and(|d| now >= d) {
            stop(&mut child);
            return Err(RenderError::Timeout {
                program: program.to_string(),
                ms: budget.timeout.as_millis(),
            });
        }
        let wait = deadline.map_or(Duration::from_millis(20), |d| {
            (d - now).min(Duration::from_millis(20))
        });
        match rx.recv_timeout(wait) {
            Ok(Piped::Stdin(r)) => written = Some(r),
            Ok(Piped::Stdout(r)) => {
                if r.as_ref().is_ok_and(|v| v.len() as u64 > budget.max_output) {
                    stop(&mut child);
                    return Err(RenderError::TooLarge {
                        program: program.to_string(),
                        limit: budget.max_output,
                    });
                }
                out = Some(r);
            }
            Ok(Piped::Stderr(r)) => err = Some(r),
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            // Every thread has reported: only the exit is awaited.
            Err(mpsc::RecvTimeoutError::Disconnected) => std::thread::sleep(wait),
        }
        if status.is_none() {
            status = child.try_wait().map_err(io)?;
        }
    }
    let (Some(status), Some(written), Some(out), Some(err)) = (status, written, out, err) else {
        unreachable!("the loop ends when all are known");
    };
    let stderr = String::from_utf8_lossy(&err.map_err(io)?)
        .trim()
        .to_string();
    if !status.success() {
        return Err(RenderError::Failed {
            program: program.to_string(),
            status: status.to_string(),
            stderr,
        });
    }
    written.map_err(io)?;
    Ok((out.map_err(io)?, stderr))
}

// ---------------------------------------------------------------------------
// DOT syntax helpers
