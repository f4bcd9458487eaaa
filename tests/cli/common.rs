//! Helpers shared by the modules of the integration-test binary.

use std::path::PathBuf;
use std::process::Command;

/// Runs the built `btfsm` in the crate root: (exit code, stdout, stderr).
pub(crate) fn btfsm(args: &[&str]) -> (i32, String, String) {
    run(Command::new(env!("CARGO_BIN_EXE_btfsm")).args(args))
}

/// [`btfsm`] with environment variables set and removed.
pub(crate) fn btfsm_env(
    args: &[&str],
    set: &[(&str, &str)],
    remove: &[&str],
) -> (i32, String, String) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_btfsm"));
    cmd.args(args);
    for k in remove {
        cmd.env_remove(k);
    }
    for (k, v) in set {
        cmd.env(k, v);
    }
    run(&mut cmd)
}

/// Runs `cmd` in the crate root: (exit code, stdout, stderr).
fn run(cmd: &mut Command) -> (i32, String, String) {
    let out = cmd
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run btfsm");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A scratch directory of this test process.
pub(crate) fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("btfsm-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).expect("tmp");
    d
}

/// CPU seconds a capped run may take (`ulimit -t`): what stops a hang or a
/// quadratic blow-up. CPU time, not wall time, so that a loaded machine
/// cannot fail a test; the slowest capped run takes about 23 s of CPU in a
/// debug build, under half of this.
pub(crate) const CAPPED_CPU_SECS: u64 = 60;

/// Runs the built `btfsm` in the crate root with its address space capped at
/// `mib` MiB (`ulimit -v`) and its CPU time at [`CAPPED_CPU_SECS`] (`ulimit
/// -t`; past it the kernel kills it and the exit code is -1): (exit code,
/// stdout, stderr, wall time, for messages only).
pub(crate) fn btfsm_capped(mib: u64, args: &[&str]) -> (i32, String, String, std::time::Duration) {
    let start = std::time::Instant::now();
    let (code, out, err) = run(Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {} && ulimit -t {CAPPED_CPU_SECS} && exec \"$0\" \"$@\"",
            mib * 1024
        ))
        .arg(env!("CARGO_BIN_EXE_btfsm"))
        .args(args));
    (code, out, err, start.elapsed())
}

/// Whether Graphviz's `dot` runs on this machine; when it does not, says on
/// stderr that `test` is skipped. Tests that draw through Graphviz call it
/// first; `make test` (hence CI) checks that `dot` is installed before any
/// test runs, so there nothing is skipped.
pub(crate) fn graphviz(test: &str) -> bool {
    static HAVE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let have = *HAVE.get_or_init(|| {
        Command::new("dot")
            .arg("-V")
            .output()
            .is_ok_and(|o| o.status.success())
    });
    if !have {
        eprintln!("skipped {test}: Graphviz `dot` is not installed");
    }
    have
}

/// Runs the built `btfsm` with a `PATH` where no program is found, as on a
/// machine without Graphviz: (exit code, stdout, stderr).
pub(crate) fn btfsm_without_graphviz(args: &[&str]) -> (i32, String, String) {
    let empty = scratch("no-path");
    run(Command::new(env!("CARGO_BIN_EXE_btfsm"))
        .args(args)
        .env("PATH", &empty))
}

/// Runs the built `btfsm` with `dir` as its current directory: (exit code,
/// stdout, stderr).
pub(crate) fn btfsm_in(dir: &std::path::Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_btfsm"))
        .args(args)
        .current_dir(dir)
        .stdin(std::process::Stdio::null())
        .output()
        .expect("run btfsm");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}
