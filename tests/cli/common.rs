//! Helpers shared by the modules of the integration-test binary.

use std::path::PathBuf;
use std::process::Command;

/// Runs the built `btfsm` in the crate root: (exit code, stdout, stderr).
pub(crate) fn btfsm(args: &[&str]) -> (i32, String, String) {
    run(Command::new(env!("CARGO_BIN_EXE_btfsm")).args(args))
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

/// Runs the built `btfsm` in the crate root with its address space capped at
/// `mib` MiB (`ulimit -v` of sh): (exit code, stdout, stderr, wall time).
pub(crate) fn btfsm_capped(mib: u64, args: &[&str]) -> (i32, String, String, std::time::Duration) {
    let start = std::time::Instant::now();
    let (code, out, err) = run(Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {} && exec \"$0\" \"$@\"", mib * 1024))
        .arg(env!("CARGO_BIN_EXE_btfsm"))
        .args(args));
    (code, out, err, start.elapsed())
}
