//! Hostile input through the binary (issue 7): each answered with exit 2
//! and a message (or 0 where the input is legal but large), in bounded time
//! and memory; inputs are generated in milliseconds. Also: an interrupted run
//! leaves no partial output file.

use crate::common::btfsm;
use std::path::{Path, PathBuf};

/// A scratch directory removed on drop.
struct Scratch(PathBuf);

impl Scratch {
    fn new(tag: &str) -> Scratch {
        let d = std::env::temp_dir().join(format!("btfsm-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("tmp");
        Scratch(d)
    }

    fn write(&self, name: &str, text: impl AsRef<[u8]>) -> String {
        let p = self.0.join(name);
        std::fs::write(&p, text).expect("write");
        p.display().to_string()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn deep_bt(levels: usize) -> String {
    let mut s = String::from("kind = \"bt\"\nroot = \"n0\"\n[nodes]\n");
    for i in 0..levels {
        s.push_str(&format!("n{i} = {{ inverter = \"n{}\" }}\n", i + 1));
    }
    s.push_str(&format!(
        "n{levels} = {{ action = \"Dock!\", skill = \"Dock\" }}\n"
    ));
    s
}

#[test]
fn hostile_deep_bt_is_refused_by_the_depth_limit() {
    let dir = Scratch::new("deep-bt");
    let f = dir.write("deep.toml", deep_bt(100_000));
    let (code, _, stderr) = btfsm(&["analyze", &f]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("levels below the root, deeper than the limit of 1000 levels")
            && stderr.contains("--max-depth"),
        "{stderr}"
    );
    // Legal when the limit is raised: analyzed and drawn without recursion.
    let (code, stdout, stderr) =
        btfsm(&["analyze", &f, "--max-depth", "200000", "--format", "json"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("\"vertices\": 100001"), "{stdout}");
    let out = dir.0.join("deep.dot").display().to_string();
    let (code, _, stderr) = btfsm(&["dot", &f, "--max-depth", "200000", "-o", &out]);
    assert_eq!(code, 0, "{stderr}");
}

#[test]
fn hostile_deep_nesting_in_toml_is_a_positioned_error() {
    let dir = Scratch::new("deep-nest");
    let n = 100_000;
    // An HFSM nested 100k containers deep (inline tables), and arrays.
    let mut hfsm =
        String::from("kind = \"hfsm\"\ninitial = \"s\"\noutcomes = [\"SUCCESS\"]\nstates = ");
    for _ in 0..n {
        hfsm.push_str("{ s = { initial = \"s\", outcomes = [\"SUCCESS\"], states = ");
    }
    hfsm.push_str("{ s = { skill = \"Dock\" } }");
    for _ in 0..n {
        hfsm.push_str(" } }");
    }
    let arrays = format!("kind = \"bt\"\nx = {}{}\n", "[".repeat(n), "]".repeat(n));
    for (name, text) in [("hfsm.toml", hfsm), ("arrays.toml", arrays)] {
        let f = dir.write(name, text);
        let (code, _, stderr) = btfsm(&["validate", &f]);
        assert_eq!(code, 2, "{stderr}");
        assert!(stderr.contains("nested too deeply"), "{stderr}");
        assert!(stderr.contains(&format!("{name}:")), "{stderr}");
    }
    // HFSM headers: the TOML reader's nesting limit, said once.
    let mut headers = String::from("kind = \"hfsm\"\ninitial = \"s\"\noutcomes = [\"SUCCESS\"]\n");
    let mut key = String::from("states.s");
    for _ in 0..60 {
        headers.push_str(&format!(
            "[{key}]\ninitial = \"s\"\noutcomes = [\"SUCCESS\"]\non = {{ SUCCESS = \"SUCCESS\" }}\n"
        ));
        key.push_str(".states.s");
    }
    let f = dir.write("headers.toml", headers);
    let (code, _, stderr) = btfsm(&["validate", &f]);
    assert_eq!(code, 2, "{stderr}");
    assert_eq!(stderr.matches("nested too deeply").count(), 1, "{stderr}");
}

#[test]
fn hostile_ten_megabyte_names_are_refused() {
    let dir = Scratch::new("names");
    let long = "x".repeat(10 << 20);
    let cases = [
        format!("kind = \"bt\"\n[nodes]\nroot = {{ action = \"{long}\" }}\n"),
        format!("kind = \"bt\"\n[nodes]\n{long} = {{ action = \"Dock!\" }}\n"),
        format!(
            "kind = \"fsm\"\ninitial = \"{long}\"\noutcomes = [\"SUCCESS\"]\n[states.\"{long}\"]\non = {{ SUCCESS = \"SUCCESS\" }}\n"
        ),
    ];
    for (i, text) in cases.iter().enumerate() {
        let f = dir.write(&format!("long{i}.toml"), text);
        let (code, _, stderr) = btfsm(&["analyze", &f]);
        assert_eq!(code, 2, "{stderr}");
        assert!(
            stderr.contains("is 10485760 bytes long, more than the limit of 4096 bytes")
                && stderr.contains("--max-name-bytes"),
            "{}",
            &stderr[..stderr.len().min(2000)]
        );
        assert!(
            stderr.len() < 20_000,
            "the message quotes the name, not 10 MB"
        );
    }
}

fn xorshift(seed: u64) -> impl FnMut() -> u64 {
    let mut x = seed;
    move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    }
}

#[test]
fn hostile_binary_garbage_and_devices() {
    let dir = Scratch::new("garbage");
    let mut next = xorshift(7);
    let bytes: Vec<u8> = (0..1 << 20).map(|_| next() as u8).collect();
    let f = dir.write("garbage.toml", &bytes);
    let (code, _, stderr) = btfsm(&["analyze", &f]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("not valid UTF-8"), "{stderr}");
    // Valid UTF-8 noise: TOML errors, at most 20 of them.
    let text: String = (0..1 << 18)
        .map(|_| char::from_u32((next() % 0x3000) as u32).unwrap_or('?'))
        .collect();
    let f = dir.write("noise.toml", text);
    let (code, _, stderr) = btfsm(&["validate", &f]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("error:") && stderr.matches("error:").count() <= 22,
        "{stderr}"
    );
    // A device has no size: reading stops past the limit.
    if Path::new("/dev/zero").exists() {
        for cmd in ["analyze", "sim"] {
            let (code, _, stderr) = btfsm(&[cmd, "/dev/zero", "--max-file-bytes", "4096"]);
            assert_eq!(code, 2, "{stderr}");
            assert!(
                stderr.contains("larger than the limit of 4096 bytes"),
                "{stderr}"
            );
        }
        let f = dir.write(
            "dev.toml",
            "kind = \"bt\"\n[nodes]\nroot = { subtree = \"/dev/zero\" }\n",
        );
        let (code, _, stderr) = btfsm(&["analyze", &f]);
        assert_eq!(code, 2, "{stderr}");
        assert!(
            stderr.contains("an absolute path is not allowed"),
            "{stderr}"
        );
        // Trusted local use lifts the root, never the regular-file rule.
        let (code, _, stderr) = btfsm(&["analyze", &f, "--allow-outside-root"]);
        assert_eq!(code, 2, "{stderr}");
        assert!(stderr.contains("not a regular file"), "{stderr}");
    }
}

#[test]
fn hostile_include_loops_are_refused() {
    let dir = Scratch::new("loops");
    let node = |to: &str| {
        format!(
            "kind = \"bt\"\n[nodes]\nroot = {{ sequence = [\"s\"] }}\ns = {{ subtree = \"{to}\" }}\n"
        )
    };
    dir.write("self.toml", node("self.toml"));
    dir.write("a.toml", node("b.toml"));
    dir.write("b.toml", node("c.toml"));
    dir.write("c.toml", node("a.toml"));
    for (f, chain) in [
        ("self.toml", "self.toml -> self.toml"),
        ("a.toml", "a.toml -> b.toml -> c.toml -> a.toml"),
    ] {
        let (code, _, stderr) = btfsm(&["analyze", &dir.0.join(f).display().to_string()]);
        assert_eq!(code, 2, "{stderr}");
        assert!(
            stderr.contains(&format!("cyclic subtree include: {chain}")),
            "{stderr}"
        );
    }
}

/// `e0` includes `e1` twice, which includes `e2` twice, ...: 2^40 leaves
/// if expanded. Each file is read once and the node budget stops the
/// expansion as soon as it is spent.
#[test]
fn hostile_exponential_subtree_include_hits_the_node_budget() {
    let dir = Scratch::new("expo");
    let k = 40;
    for i in 0..k {
        dir.write(
            &format!("e{i}.toml"),
            format!(
                "kind = \"bt\"\n[nodes]\nroot = {{ sequence = [\"l\", \"r\"] }}\nl = {{ subtree = \"e{0}.toml\" }}\nr = {{ subtree = \"e{0}.toml\" }}\n",
                i + 1
            ),
        );
    }
    dir.write(
        &format!("e{k}.toml"),
        "kind = \"bt\"\n[nodes]\nleaf = { action = \"Dock!\", skill = \"Dock\" }\n",
    );
    let e0 = dir.0.join("e0.toml").display().to_string();
    for (limit, flag) in [
        ("100000", vec!["--max-nodes", "100000"]),
        ("150000", vec![]),
    ] {
        let mut args = vec!["analyze", e0.as_str()];
        args.extend(flag);
        let (code, _, stderr) = btfsm(&args);
        assert_eq!(code, 2, "{stderr}");
        assert!(
            stderr.contains(&format!("more than {limit} nodes")) && stderr.contains("--max-nodes"),
            "{stderr}"
        );
    }
    // Below the budget the expansion is legal: 2^12 leaves.
    let e = dir
        .0
        .join(format!("e{}.toml", k - 12))
        .display()
        .to_string();
    let (code, stdout, stderr) = btfsm(&["analyze", &e, "--format", "json"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains(&format!("\"vertices\": {}", (1 << 13) - 1)),
        "{stdout}"
    );
}

#[test]
fn hostile_million_problems_are_reported_in_bounded_time() {
    let dir = Scratch::new("many");
    let mut s = String::from("kind = \"bt\"\nroot = \"root\"\n[nodes]\nroot = { sequence = [");
    // Within the node limit (150,000): every node is read, each with errors.
    let n = 100_000;
    for i in 0..n {
        s.push_str(&format!("\"missing{i}\", "));
    }
    s.push_str("] }\n");
    for i in 0..n {
        s.push_str(&format!("n{i} = {{ action = \"A{i}\" }}\n"));
    }
    let f = dir.write("many.toml", s);
    let (code, _, stderr) = btfsm(&["validate", &f]);
    assert_eq!(code, 2);
    assert!(
        stderr.contains("more errors not shown"),
        "{}",
        &stderr[stderr.len().saturating_sub(2000)..]
    );
}

/// Ctrl-C at any moment leaves either no output file or the whole one,
/// never a prefix; a temporary left by the interrupted run is removed by
/// the next run writing the same file.
#[cfg(unix)]
#[test]
fn interrupted_runs_leave_no_partial_output() {
    use std::process::{Command, Stdio};
    use std::time::Duration;
    let dir = Scratch::new("sigint");
    let mut s = String::from("kind = \"bt\"\nroot = \"n0\"\n[nodes]\nn0 = { sequence = [");
    let n = 30_000;
    s.push_str(
        &(1..n)
            .map(|i| format!("\"n{i}\""))
            .collect::<Vec<_>>()
            .join(", "),
    );
    s.push_str("] }\n");
    for i in 1..n {
        s.push_str(&format!(
            "n{i} = {{ action = \"Act {i}!\", skill = \"Dock\" }}\n"
        ));
    }
    let input = dir.write("big.toml", s);
    let reference = dir.0.join("reference.toml").display().to_string();
    let (code, _, stderr) = btfsm(&["convert", &input, "--to", "toml", "-o", &reference]);
    assert_eq!(code, 0, "{stderr}");
    let whole = std::fs::read(&reference).expect("reference");
    let out = dir.0.join("out.toml");
    for delay_ms in [5u64, 20, 60, 150, 300, 600, 1200] {
        let _ = std::fs::remove_file(&out);
        let mut child = Command::new(env!("CARGO_BIN_EXE_btfsm"))
            .args(["convert", &input, "--to", "toml", "-o"])
            .arg(&out)
            .stderr(Stdio::null())
            .spawn()
            .expect("spawn");
        std::thread::sleep(Duration::from_millis(delay_ms));
        let _ = Command::new("kill")
            .args(["-INT", &child.id().to_string()])
            .status();
        let _ = child.wait();
        if let Ok(got) = std::fs::read(&out) {
            assert!(
                got == whole,
                "interrupted after {delay_ms} ms: partial output"
            );
        }
    }
    let (code, _, stderr) = btfsm(&[
        "convert",
        &input,
        "--to",
        "toml",
        "-o",
        &out.display().to_string(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let stray: Vec<_> = std::fs::read_dir(&dir.0)
        .expect("dir")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|f| f.ends_with(".tmp"))
        .collect();
    assert!(stray.is_empty(), "temporaries left: {stray:?}");
}

/// The importers: 100k levels of XML nesting and 10 MB names are refused by
/// the same limits, whatever the format.
#[test]
fn hostile_xml_and_scxml_nesting_and_names() {
    let dir = Scratch::new("xml");
    let n = 100_000;
    let deep_bt = format!(
        "<root BTCPP_format=\"4\"><BehaviorTree ID=\"Main\">{}<AlwaysSuccess/>{}</BehaviorTree></root>",
        "<Sequence>".repeat(n),
        "</Sequence>".repeat(n)
    );
    let mut deep_sc = String::from(
        "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" version=\"1.0\" initial=\"s0\">",
    );
    for i in 0..n {
        deep_sc.push_str(&format!("<state id=\"s{i}\">"));
    }
    deep_sc.push_str(&"</state>".repeat(n));
    deep_sc.push_str("</scxml>");
    let long = "x".repeat(10 << 20);
    let long_bt = format!(
        "<root BTCPP_format=\"4\"><BehaviorTree ID=\"Main\"><Sequence name=\"{long}\"><AlwaysSuccess/></Sequence></BehaviorTree></root>"
    );
    let long_sc = format!(
        "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" version=\"1.0\" initial=\"{long}\"><state id=\"{long}\"/></scxml>"
    );
    for (name, text, want) in [
        ("deep.xml", deep_bt, "deeper than the limit of 1000 levels"),
        (
            "deep.scxml",
            deep_sc,
            "deeper than the limit of 1000 levels",
        ),
        (
            "long.xml",
            long_bt,
            "is 10485760 bytes long, more than the limit of 4096 bytes",
        ),
        (
            "long.scxml",
            long_sc,
            "is 10485760 bytes long, more than the limit of 4096 bytes",
        ),
    ] {
        let f = dir.write(name, text);
        let (code, _, stderr) = btfsm(&["analyze", &f]);
        assert_eq!(code, 2, "{name}: {}", &stderr[..stderr.len().min(2000)]);
        assert!(
            stderr.contains(want),
            "{name}: {}",
            &stderr[..stderr.len().min(2000)]
        );
        assert!(
            stderr.len() < 20_000,
            "{name}: the message quotes names, not 10 MB"
        );
    }
}

// ---------------------------------------------------------------------------
// Output files (issue 12): symlinks, devices, FIFOs, `-`, permissions, long
// names, one path given twice; Graphviz under a deadline; a baseline whose
// numbers would wrap the gate's arithmetic.

/// What a run of the binary gave, and how long it took.
struct Run {
    code: i32,
    stdout: Vec<u8>,
    stderr: String,
    secs: f64,
}

/// Runs the built `btfsm` in `dir` with `path_prefix` put first on the
/// child's PATH (only the child's), killed after `limit_secs`.
#[cfg(unix)]
fn run_in(dir: &Path, args: &[&str], path_prefix: Option<&Path>, limit_secs: u64) -> Run {
    use std::io::Read;
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_btfsm"));
    cmd.args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    if let Some(pre) = path_prefix {
        let old = std::env::var_os("PATH").unwrap_or_default();
        let mut paths = vec![pre.to_path_buf()];
        paths.extend(std::env::split_paths(&old));
        cmd.env("PATH", std::env::join_paths(paths).expect("PATH"));
    }
    let t0 = Instant::now();
    let mut child = cmd.spawn().expect("spawn btfsm");
    let mut out = child.stdout.take().expect("stdout");
    let mut err = child.stderr.take().expect("stderr");
    let o = std::thread::spawn(move || {
        let mut v = Vec::new();
        let _ = out.read_to_end(&mut v);
        v
    });
    let e = std::thread::spawn(move || {
        let mut v = Vec::new();
        let _ = err.read_to_end(&mut v);
        v
    });
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break s;
        }
        if t0.elapsed() > Duration::from_secs(limit_secs) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("btfsm {args:?} still running after {limit_secs} s");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let secs = t0.elapsed().as_secs_f64();
    Run {
        code: status.code().unwrap_or(-1),
        stdout: o.join().expect("stdout thread"),
        stderr: String::from_utf8_lossy(&e.join().expect("stderr thread")).into_owned(),
        secs,
    }
}

/// The DOT drawing of `policies/paper/fig01-bt.toml`, as printed on stdout.
fn fig01_dot() -> Vec<u8> {
    let (code, stdout, stderr) = btfsm(&["dot", "policies/paper/fig01-bt.toml"]);
    assert_eq!(code, 0, "{stderr}");
    stdout.into_bytes()
}

fn fig01() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("policies/paper/fig01-bt.toml")
        .display()
        .to_string()
}

/// Names of the temporaries (`*.tmp`) left in `dir`.
fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .expect("dir")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|f| f.ends_with(".tmp"))
        .collect()
}

#[cfg(unix)]
#[test]
fn hostile_output_through_a_symlink_writes_its_target_and_keeps_the_link() {
    use std::os::unix::fs::symlink;
    let dir = Scratch::new("out-symlink");
    let other = dir.0.join("other");
    std::fs::create_dir_all(&other).expect("dir");
    let target = other.join("target.dot");
    std::fs::write(&target, "old").expect("write");
    // link.dot -> hop.dot -> other/target.dot (relative links, two hops).
    symlink("hop.dot", dir.0.join("link.dot")).expect("symlink");
    symlink("other/target.dot", dir.0.join("hop.dot")).expect("symlink");
    // dangling.dot -> other/new.dot, which does not exist yet.
    symlink("other/new.dot", dir.0.join("dangling.dot")).expect("symlink");
    let want = fig01_dot();
    for (link, written) in [
        ("link.dot", &target),
        ("dangling.dot", &other.join("new.dot")),
    ] {
        let r = run_in(&dir.0, &["dot", &fig01(), "-o", link], None, 60);
        assert_eq!(r.code, 0, "{}", r.stderr);
        let meta = std::fs::symlink_metadata(dir.0.join(link)).expect("link");
        assert!(meta.file_type().is_symlink(), "{link} was replaced");
        assert_eq!(std::fs::read(written).expect("target"), want);
    }
    assert_eq!(
        std::fs::read_link(dir.0.join("hop.dot")).expect("hop"),
        Path::new("other/target.dot")
    );
    assert!(temporaries(&dir.0).is_empty() && temporaries(&other).is_empty());
}

/// Opens the read end of a FIFO without waiting for a writer.
#[cfg(unix)]
fn open_fifo_reader(path: &Path) -> std::fs::File {
    use std::os::unix::fs::OpenOptionsExt;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
        .expect("open the FIFO for reading")
}

#[cfg(unix)]
fn mkfifo(path: &Path) {
    use std::os::unix::ffi::OsStrExt;
    let c = std::ffi::CString::new(path.as_os_str().as_bytes()).expect("path");
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0, "mkfifo");
}

/// `-o` onto a device writes into it: `/dev/null` (and a private copy of it,
/// checked first) stays a character device, `/dev/stdout` (and a private
/// link to `/proc/self/fd/1`) stays a link and the bytes reach stdout.
#[cfg(target_os = "linux")]
#[test]
fn hostile_output_onto_devices_writes_into_them() {
    use std::os::unix::ffi::OsStrExt;
    use std::os::unix::fs::{FileTypeExt, MetadataExt, symlink};
    let dir = Scratch::new("out-dev");
    let want = fig01_dot();
    // A private character device (1, 3), where allowed (root, no seccomp).
    let node = dir.0.join("null");
    let c = std::ffi::CString::new(node.as_os_str().as_bytes()).expect("path");
    // SAFETY: a valid NUL-terminated path.
    let made = unsafe { libc::mknod(c.as_ptr(), libc::S_IFCHR | 0o666, libc::makedev(1, 3)) } == 0;
    if made {
        let r = run_in(&dir.0, &["dot", &fig01(), "-o", "null"], None, 60);
        assert_eq!(r.code, 0, "{}", r.stderr);
        let meta = std::fs::symlink_metadata(&node).expect("node");
        assert!(
            meta.file_type().is_char_device(),
            "the device node was replaced"
        );
    }
    // A private link to this process's stdout: the bytes go to the pipe.
    symlink("/proc/self/fd/1", dir.0.join("stdout")).expect("symlink");
    let r = run_in(&dir.0, &["dot", &fig01(), "-o", "stdout"], None, 60);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        std::fs::symlink_metadata(dir.0.join("stdout"))
            .expect("link")
            .file_type()
            .is_symlink(),
        "the link to stdout was replaced"
    );
    assert_eq!(r.stdout, want);
    // The system's own entries.
    let before = std::fs::metadata("/dev/null").expect("/dev/null");
    let r = run_in(&dir.0, &["dot", &fig01(), "-o", "/dev/null"], None, 60);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let after = std::fs::symlink_metadata("/dev/null").expect("/dev/null");
    assert!(after.file_type().is_char_device(), "/dev/null was replaced");
    assert_eq!((after.ino(), after.rdev()), (before.ino(), before.rdev()));
    if std::fs::symlink_metadata("/dev/stdout").is_ok_and(|m| m.file_type().is_symlink()) {
        let r = run_in(&dir.0, &["dot", &fig01(), "-o", "/dev/stdout"], None, 60);
        assert_eq!(r.code, 0, "{}", r.stderr);
        assert_eq!(r.stdout, want);
        assert!(
            std::fs::symlink_metadata("/dev/stdout")
                .expect("/dev/stdout")
                .file_type()
                .is_symlink()
        );
    }
    assert!(temporaries(&dir.0).is_empty());
}

/// A FIFO is written into, not replaced; with no reader the run fails at
/// once (exit 2) instead of blocking.
#[cfg(unix)]
#[test]
fn hostile_output_onto_a_fifo_never_blocks() {
    use std::io::Read;
    use std::os::unix::fs::FileTypeExt;
    let dir = Scratch::new("out-fifo");
    let fifo = dir.0.join("pipe");
    mkfifo(&fifo);
    let r = run_in(&dir.0, &["dot", &fig01(), "-o", "pipe"], None, 20);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("no process is reading"), "{}", r.stderr);
    assert!(r.secs < 10.0, "took {} s", r.secs);
    let is_fifo = |p: &Path| std::fs::symlink_metadata(p).is_ok_and(|m| m.file_type().is_fifo());
    assert!(is_fifo(&fifo), "the FIFO was replaced");
    // With a reader (the DOT text fits in the pipe's buffer).
    let mut reader = open_fifo_reader(&fifo);
    let r = run_in(&dir.0, &["dot", &fig01(), "-o", "pipe"], None, 20);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let mut got = Vec::new();
    let mut buf = [0u8; 8192];
    loop {
        match reader.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => got.extend_from_slice(&buf[..n]),
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => break,
            Err(e) => panic!("{e}"),
        }
    }
    assert_eq!(got, fig01_dot());
    assert!(is_fifo(&fifo), "the FIFO was replaced");
    assert!(temporaries(&dir.0).is_empty());
}

#[cfg(unix)]
#[test]
fn hostile_output_keeps_an_existing_files_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let dir = Scratch::new("out-perm");
    let secret = dir.0.join("secret.toml");
    std::fs::write(&secret, "old").expect("write");
    std::fs::set_permissions(&secret, std::fs::Permissions::from_mode(0o600)).expect("chmod");
    let r = run_in(
        &dir.0,
        &["convert", &fig01(), "--to", "toml", "-o", "secret.toml"],
        None,
        60,
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    let mode = |p: &Path| std::fs::metadata(p).expect("meta").permissions().mode() & 0o7777;
    assert_eq!(mode(&secret), 0o600);
    assert!(
        std::fs::read_to_string(&secret)
            .expect("read")
            .contains("kind = \"bt\"")
    );
    // A new file gets the default mode (0666 less the umask).
    let reference = dir.0.join("reference");
    std::fs::write(&reference, "").expect("write");
    let r = run_in(&dir.0, &["dot", &fig01(), "-o", "new.dot"], None, 60);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert_eq!(mode(&dir.0.join("new.dot")), mode(&reference));
}

/// A legal 254-byte file name: the temporary beside it must stay within
/// NAME_MAX (255 bytes) too.
#[cfg(unix)]
#[test]
fn hostile_output_with_a_254_byte_name() {
    let dir = Scratch::new("out-long");
    let name = format!("{}.dot", "n".repeat(250));
    assert_eq!(name.len(), 254);
    for _ in 0..2 {
        let r = run_in(&dir.0, &["dot", &fig01(), "-o", &name], None, 60);
        assert_eq!(r.code, 0, "{}", r.stderr);
    }
    assert_eq!(std::fs::read(dir.0.join(&name)).expect("read"), fig01_dot());
    assert!(temporaries(&dir.0).is_empty());
}

/// `-o -` is stdout, for every command with `-o`; no file named `-`.
#[cfg(unix)]
#[test]
fn hostile_output_dash_means_stdout() {
    let dir = Scratch::new("out-dash");
    let f = fig01();
    let (_, toml, _) = btfsm(&["convert", &f, "--to", "toml"]);
    for (args, want) in [
        (vec!["dot", f.as_str(), "-o", "-"], fig01_dot()),
        (
            vec!["convert", f.as_str(), "--to", "toml", "-o", "-"],
            toml.into_bytes(),
        ),
    ] {
        let r = run_in(&dir.0, &args, None, 60);
        assert_eq!(r.code, 0, "{}", r.stderr);
        assert_eq!(r.stdout, want, "{args:?}");
        assert!(!dir.0.join("-").exists(), "{args:?} created a file `-`");
    }
}

/// One output path given twice (the same spelling, another spelling, a
/// symlink, or stdout where the report goes) is refused before anything is
/// written.
#[cfg(unix)]
#[test]
fn hostile_one_output_path_used_twice_is_refused() {
    let dir = Scratch::new("out-twice");
    std::fs::create_dir_all(dir.0.join("sub")).expect("dir");
    std::os::unix::fs::symlink("x.out", dir.0.join("link.out")).expect("symlink");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("policies/scenarios/exp1-nominal.toml")
        .display()
        .to_string();
    let s = scenario.as_str();
    let cases: Vec<Vec<&str>> = vec![
        vec!["sim", s, "--trace", "x.out", "--plot", "x.out"],
        vec!["sim", s, "--trace", "x.out", "--plot", "./sub/../x.out"],
        vec!["sim", s, "--trace", "link.out", "--plot", "x.out"],
        vec!["sim", s, "--trace", "-", "--plot", "y.out"],
    ];
    for args in &cases {
        let r = run_in(&dir.0, args, None, 60);
        assert_eq!(r.code, 2, "{args:?}: {}", r.stderr);
        assert!(r.stderr.contains("used twice"), "{args:?}: {}", r.stderr);
        assert!(r.stdout.is_empty(), "{args:?}");
        for f in ["x.out", "y.out", "-"] {
            assert!(!dir.0.join(f).exists(), "{args:?} wrote {f}");
        }
    }
    // compare: --dot on stdout, where the report goes.
    let a = fig01();
    let b = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("policies/paper/fig05-bt.toml")
        .display()
        .to_string();
    let r = run_in(
        &dir.0,
        &["compare", &a, &b, "--mode", "named", "--dot", "-"],
        None,
        60,
    );
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("used twice"), "{}", r.stderr);
    assert!(r.stdout.is_empty());
    // Distinct paths are fine.
    let r = run_in(
        &dir.0,
        &["sim", s, "--trace", "x.out", "--plot", "y.out"],
        None,
        60,
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
}

/// Graphviz is a child under a deadline: a `dot` that never answers (a
/// script whose `sleep` child holds the pipes, first on the child's PATH)
/// is killed at `--timeout-ms` and the run exits 2, writing nothing.
#[cfg(unix)]
#[test]
fn hostile_graphviz_past_its_deadline_is_killed() {
    use std::os::unix::fs::PermissionsExt;
    let dir = Scratch::new("out-graphviz");
    let bin = dir.0.join("bin");
    std::fs::create_dir_all(&bin).expect("dir");
    let fake = bin.join("dot");
    std::fs::write(&fake, "#!/bin/sh\nsleep 30\n").expect("write");
    std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    let f = fig01();
    let b = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("policies/paper/fig05-bt.toml")
        .display()
        .to_string();
    let cases: Vec<(Vec<&str>, u64)> = vec![
        (
            vec![
                "dot",
                &f,
                "--render",
                "svg",
                "--timeout-ms",
                "1000",
                "-o",
                "out.svg",
            ],
            1000,
        ),
        (
            vec![
                "compare",
                &f,
                &b,
                "--mode",
                "named",
                "--timeout-ms",
                "1000",
                "--dot",
                "out.svg",
                "--render",
                "svg",
            ],
            1000,
        ),
    ];
    for (args, ms) in cases {
        let r = run_in(&dir.0, &args, Some(&bin), 25);
        assert_eq!(r.code, 2, "{args:?}: {}", r.stderr);
        assert!(
            r.stderr.contains(&format!("did not finish within {ms} ms")),
            "{args:?}: {}",
            r.stderr
        );
        assert!(
            r.secs < ms as f64 / 1000.0 + 5.0,
            "{args:?}: took {} s",
            r.secs
        );
        assert!(!dir.0.join("out.svg").exists(), "{args:?} wrote a file");
    }
}

/// A baseline whose numbers would wrap the gate's subtraction (cc =
/// i64::MIN passed the gate) or are no count at all: exit 2, positioned.
#[test]
fn hostile_baseline_numbers_out_of_range_are_refused() {
    let dir = Scratch::new("out-baseline");
    let f = "policies/paper/fig04-fsm.toml";
    let (code, json, _) = btfsm(&["analyze", f, "--format", "json"]);
    assert_eq!(code, 0);
    for bad in [
        "-9223372036854775808",
        "9223372036854775807",
        "18446744073709551615",
        "1e300",
        "-1",
    ] {
        let text = json.replacen("\"cc\": 14", &format!("\"cc\": {bad}"), 1);
        assert_ne!(text, json);
        let base = dir.write("base.json", &text);
        let (code, _, stderr) = btfsm(&["analyze", f, "--baseline", &base]);
        assert_eq!(code, 2, "cc = {bad}: {stderr}");
        assert!(stderr.contains("out of range"), "cc = {bad}: {stderr}");
        let line = text.lines().position(|l| l.contains(bad)).expect("line") + 1;
        assert!(
            stderr.contains(&format!("base.json:{line}:")),
            "cc = {bad}: {stderr}"
        );
    }
    // Extreme growth limits do not wrap either.
    let base = dir.write("base.json", &json);
    for (limit, want) in [
        ("cc=-9223372036854775808", 1),
        ("cc=9223372036854775807", 0),
    ] {
        let (code, _, stderr) =
            btfsm(&["analyze", f, "--baseline", &base, "--max-increase", limit]);
        assert_eq!(code, want, "{limit}: {stderr}");
    }
}

/// [`crate::common::btfsm_capped`] with the wall time in seconds.
fn btfsm_capped(mib: u64, args: &[&str]) -> (i32, String, String, f64) {
    let (code, out, err, took) = crate::common::btfsm_capped(mib, args);
    (code, out, err, took.as_secs_f64())
}

/// The first `n` bytes of `s` (for assertion messages).
fn head(s: &str, n: usize) -> &str {
    let mut end = s.len().min(n);
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    &s[..end]
}

/// Every element of every BehaviorTree.CPP file read counts against
/// `--max-nodes`, in trees that are never run too, with the position of the
/// first element beyond the limit (in the included file that holds it).
#[test]
fn hostile_unused_xml_trees_count_against_max_nodes() {
    let dir = Scratch::new("xml-unused");
    let unused = |id: &str, n: usize| {
        format!(
            "<BehaviorTree ID=\"{id}\">\n<Sequence>\n{}</Sequence>\n</BehaviorTree>\n",
            "<AlwaysSuccess/>\n".repeat(n)
        )
    };
    let lib = dir.write(
        "lib.xml",
        format!(
            "<root BTCPP_format=\"4\">\n{}</root>\n",
            unused("LibUnused", 600)
        ),
    );
    let main = dir.write(
        "main.xml",
        format!(
            "<root BTCPP_format=\"4\" main_tree_to_execute=\"Main\">\n<include path=\"lib.xml\"/>\n<BehaviorTree ID=\"Main\"><AlwaysSuccess/></BehaviorTree>\n{}</root>\n",
            unused("Unused", 600)
        ),
    );
    let (code, _, stderr) = btfsm(&["analyze", &main, "--max-nodes", "2000"]);
    assert_eq!(code, 0, "{stderr}");
    // main.xml: 6 + 600 elements; lib.xml's 1000 - 606 + 1 = 395th is the
    // first beyond: root, BehaviorTree, Sequence, then a leaf per line.
    let (code, _, stderr) = btfsm(&["analyze", &main, "--max-nodes", "1000"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("more than 1000 elements") && stderr.contains("--max-nodes"),
        "{stderr}"
    );
    assert!(stderr.contains(&format!("--> {lib}:395:1")), "{stderr}");
    // With the default limit (150,000): 2.1 million elements of a tree never run.
    let big = dir.write(
        "big.xml",
        format!(
            "<root BTCPP_format=\"4\" main_tree_to_execute=\"Main\">\n<BehaviorTree ID=\"Main\"><AlwaysSuccess/></BehaviorTree>\n{}</root>\n",
            unused("Unused", 2_100_000)
        ),
    );
    let (code, _, stderr, _) = btfsm_capped(1024, &["analyze", &big]);
    assert_eq!(code, 2, "{}", head(&stderr, 2000));
    assert!(
        stderr.contains("more than 150000 elements")
            && stderr.contains(&format!("--> {big}:150000:1")),
        "{}",
        head(&stderr, 2000)
    );
    assert!(stderr.len() < 2000, "{} bytes of stderr", stderr.len());
}

/// SCXML nested 999 states deep with 4000-byte ids or repeated 4000-byte
/// names: keys, paths and warnings used to carry every ancestor's name
/// (about 4 GB); now memory is linear in the 4 MB input, under a 1 GiB cap.
#[test]
fn hostile_deep_scxml_with_long_names_stays_linear() {
    let dir = Scratch::new("scxml-deep-names");
    let n = 999;
    let long = |i: usize| format!("{i:x>4000}");
    let head_sc = "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" xmlns:btfsm=\"urn:btfsm\" version=\"1.0\"";
    // Unreachable chain of unique long ids: a warning per state.
    let unreachable = format!(
        "{head_sc} initial=\"z\"><state id=\"z\"/>{}{}</scxml>",
        (0..n)
            .map(|i| format!("<state id=\"{}\">\n", long(i)))
            .collect::<String>(),
        "</state>".repeat(n)
    );
    // The same long name at every level: keys by path.
    let same = format!(
        "{head_sc} initial=\"s0\">{}{}</scxml>",
        (0..n)
            .map(|i| format!("<state id=\"s{i}\" btfsm:name=\"{}\">\n", "n".repeat(4000)))
            .collect::<String>(),
        "</state>".repeat(n)
    );
    for (name, text, vertices) in [
        ("unreachable.scxml", unreachable, 1000),
        ("same.scxml", same, 999),
    ] {
        let f = dir.write(name, text);
        let (code, stdout, stderr, _) = btfsm_capped(1024, &["analyze", &f, "--format", "json"]);
        assert_eq!(code, 0, "{name}: {}", head(&stderr, 2000));
        assert!(
            stdout.contains(&format!("\"vertices\": {vertices}")),
            "{name}: {}",
            head(&stdout, 2000)
        );
        assert!(
            stderr.len() < 300_000,
            "{name}: {} bytes of stderr",
            stderr.len()
        );
    }
}

/// The text of `convert` is linear in the input: a policy N levels deep
/// gives less than 8 bytes per input byte for N = 250 and 999, and reads
/// back with the same counts; an HFSM the TOML format cannot nest is
/// refused (it did not read back, and was quadratic: 55 MB from 21 KB).
#[test]
fn hostile_convert_output_is_linear_in_depth() {
    let dir = Scratch::new("convert-deep");
    let counts = |f: &str| {
        let (code, stdout, stderr) = btfsm(&["analyze", f, "--format", "csv"]);
        assert_eq!(code, 0, "{f}: {}", head(&stderr, 2000));
        let row = stdout.lines().nth(1).expect("a row").to_string();
        row.split_once(',').expect("file,").1.to_string()
    };
    for n in [250usize, 999] {
        let toml_bt = format!(
            "kind = \"bt\"\nroot = \"n0\"\n[nodes]\n{}n{n} = {{ action = \"Dock!\", skill = \"Dock\" }}\n",
            (0..n)
                .map(|i| format!("n{i} = {{ sequence = [\"n{}\"] }}\n", i + 1))
                .collect::<String>()
        );
        let xml_bt = format!(
            "<root BTCPP_format=\"4\"><BehaviorTree ID=\"Main\">{}<AlwaysSuccess/>{}</BehaviorTree></root>",
            "<Inverter>".repeat(n),
            "</Inverter>".repeat(n)
        );
        let scxml = format!(
            "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" xmlns:btfsm=\"urn:btfsm\" version=\"1.0\" initial=\"s0\">{}<state id=\"leaf\" btfsm:name=\"s\"/>{}</scxml>",
            (0..n)
                .map(|i| format!("<state id=\"s{i}\" btfsm:name=\"s\">"))
                .collect::<String>(),
            "</state>".repeat(n)
        );
        for (name, text, to, ext) in [
            ("bt.toml", &toml_bt, "btcpp-xml", "xml"),
            ("bt.xml", &xml_bt, "btcpp-xml", "xml"),
            ("m.scxml", &scxml, "scxml", "scxml"),
        ] {
            let f = dir.write(&format!("{n}-{name}"), text);
            let out = dir
                .0
                .join(format!("{n}-{name}.out.{ext}"))
                .display()
                .to_string();
            let (code, _, stderr, _) = btfsm_capped(1024, &["convert", &f, "--to", to, "-o", &out]);
            assert_eq!(code, 0, "{name} {n}: {}", head(&stderr, 2000));
            let size = std::fs::metadata(&out).expect("written").len() as usize;
            assert!(
                size < 8 * text.len(),
                "{name} {n} --to {to}: {size} bytes from {}",
                text.len()
            );
            assert_eq!(counts(&out), counts(&f), "{name} {n}: read back");
        }
        // Machines deeper than the TOML format nests: refused, briefly.
        for (name, to) in [("bt.toml", "hfsm"), ("m.scxml", "toml")] {
            let f = dir.0.join(format!("{n}-{name}")).display().to_string();
            let out = dir.0.join(format!("{n}-{name}.toml")).display().to_string();
            let (code, _, stderr) = btfsm(&["convert", &f, "--to", to, "-o", &out]);
            assert_eq!(code, 2, "{name} {n} --to {to}: {stderr}");
            assert!(
                stderr.contains("the TOML format reads back at most 39") && stderr.len() < 1000,
                "{stderr}"
            );
            assert!(!Path::new(&out).exists());
        }
    }
    // As deep as TOML nests: written, and reads back.
    let n = 39;
    let f = dir.write(
        "39.toml",
        format!(
            "kind = \"bt\"\nroot = \"n0\"\n[nodes]\n{}n{n} = {{ action = \"Dock!\", skill = \"Dock\" }}\n",
            (0..n)
                .map(|i| format!("n{i} = {{ sequence = [\"n{}\"] }}\n", i + 1))
                .collect::<String>()
        ),
    );
    let out = dir.0.join("39-hfsm.toml").display().to_string();
    let (code, _, stderr) = btfsm(&["convert", &f, "--to", "hfsm", "-o", &out]);
    assert_eq!(code, 0, "{stderr}");
    let (code, stdout, stderr) = btfsm(&["analyze", &out, "--format", "json"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("\"kind\": \"hfsm\""), "{stdout}");
}

/// 10 MB names where the XML readers quoted them whole (an unknown node
/// type three times: 31 MB of stderr), and ports and events that escaped
/// `--max-name-bytes`: each refused at its element, with a short message.
#[test]
fn hostile_long_xml_names_are_limited_and_quoted_short() {
    let dir = Scratch::new("xml-long-names");
    let long = "x".repeat(10 << 20);
    let bt = |body: &str| {
        format!(
            "<root BTCPP_format=\"4\">\n<BehaviorTree ID=\"Main\">\n<Sequence>\n{body}\n</Sequence>\n</BehaviorTree>\n</root>\n"
        )
    };
    let sc = |body: &str| {
        format!(
            "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" version=\"1.0\">\n<state id=\"a\">\n{body}\n</state>\n</scxml>\n"
        )
    };
    let cases = [
        ("type.xml", bt(&format!("<{long}/>")), "element name", 4),
        (
            "port-value.xml",
            bt(&format!("<Script code=\"{long}\"/>")),
            "value of `code`",
            4,
        ),
        (
            "port-name.xml",
            bt(&format!("<Script {long}=\"1\"/>")),
            "attribute name",
            4,
        ),
        (
            "event.scxml",
            sc(&format!("<transition event=\"{long}\" target=\"a\"/>")),
            "value of `event`",
            3,
        ),
        (
            "target.scxml",
            sc(&format!("<transition event=\"go\" target=\"{long}\"/>")),
            "value of `target`",
            3,
        ),
    ];
    for (name, text, what, line) in cases {
        let f = dir.write(name, text);
        let (code, _, stderr, _) = btfsm_capped(1024, &["analyze", &f]);
        assert_eq!(code, 2, "{name}: {}", head(&stderr, 2000));
        assert!(
            stderr.contains(what)
                && stderr.contains("is 10485760 bytes long, more than the limit of 4096 bytes")
                && stderr.contains("--max-name-bytes")
                && stderr.contains(&format!("--> {f}:{line}:1")),
            "{name}: {}",
            head(&stderr, 2000)
        );
        assert!(
            stderr.len() < 5000,
            "{name}: {} bytes of stderr",
            stderr.len()
        );
    }
    // Long values that are no names are quoted short too.
    let f = dir.write(
        "main-tree.xml",
        format!(
            "<root BTCPP_format=\"{long}\" main_tree_to_execute=\"{long}\">\n<BehaviorTree ID=\"Main\"><AlwaysSuccess/></BehaviorTree>\n</root>\n"
        ),
    );
    let (code, _, stderr) = btfsm(&["analyze", &f]);
    assert_eq!(code, 2, "{}", head(&stderr, 2000));
    assert!(
        stderr.contains("names unknown tree `xxxx") && stderr.contains("…(10485760 bytes)"),
        "{}",
        head(&stderr, 2000)
    );
    assert!(stderr.len() < 5000, "{} bytes of stderr", stderr.len());
}

/// Limit errors of the XML readers say where: `--> file:line:col` of the
/// element (they used to come from the shape check after reading, with no
/// position).
#[test]
fn hostile_xml_limit_errors_are_positioned() {
    let dir = Scratch::new("xml-positions");
    let n = 1005;
    let deep_bt = format!(
        "<root BTCPP_format=\"4\">\n<BehaviorTree ID=\"Main\">\n{}<AlwaysSuccess/>\n{}</BehaviorTree>\n</root>\n",
        "  <Inverter>\n".repeat(n),
        "</Inverter>".repeat(n)
    );
    let deep_sc = format!(
        "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" version=\"1.0\">\n{}{}</scxml>\n",
        (0..n)
            .map(|i| format!("  <state id=\"s{i}\">\n"))
            .collect::<String>(),
        "</state>".repeat(n)
    );
    let long = "y".repeat(5000);
    let long_bt = format!(
        "<root BTCPP_format=\"4\">\n<BehaviorTree ID=\"Main\">\n  <Sequence name=\"{long}\"><AlwaysSuccess/></Sequence>\n</BehaviorTree>\n</root>\n"
    );
    let long_sc = format!(
        "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" version=\"1.0\">\n  <state id=\"{long}\"/>\n</scxml>\n"
    );
    for (name, text, want, at) in [
        (
            "deep.xml",
            deep_bt,
            "deeper than the limit of 1000 levels",
            "1004:3",
        ),
        (
            "deep.scxml",
            deep_sc,
            "deeper than the limit of 1000 levels",
            "1003:3",
        ),
        (
            "long.xml",
            long_bt,
            "more than the limit of 4096 bytes",
            "3:3",
        ),
        (
            "long.scxml",
            long_sc,
            "more than the limit of 4096 bytes",
            "2:3",
        ),
    ] {
        let f = dir.write(name, text);
        let (code, _, stderr) = btfsm(&["analyze", &f]);
        assert_eq!(code, 2, "{name}: {stderr}");
        assert!(
            stderr.contains(want) && stderr.contains(&format!("--> {f}:{at}\n")),
            "{name}: {}",
            head(&stderr, 2000)
        );
    }
}

/// Nodes of a TOML subtree include are `moma1/x`, as
/// policies/paper/README.md says (they printed as `moma1//x`).
#[test]
fn included_node_ids_join_with_one_slash() {
    let (code, stdout, stderr) = btfsm(&["convert", "policies/paper/scal-bt.toml", "--to", "toml"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("\"moma1/cube-delivered\" = {"), "{stdout}");
    assert!(!stdout.contains("//"), "{stdout}");
}

/// BT -> HFSM of a Sequence with 200,000 children: linear (it scanned the
/// siblings of every child: about a minute in a debug build).
#[test]
fn hostile_wide_bt_converts_to_hfsm_in_linear_time() {
    let dir = Scratch::new("wide-hfsm");
    let f = dir.write(
        "wide.xml",
        format!(
            "<root BTCPP_format=\"4\"><BehaviorTree ID=\"M\"><ReactiveSequence>{}</ReactiveSequence></BehaviorTree></root>",
            "<AlwaysSuccess/>".repeat(200_000)
        ),
    );
    let out = dir.0.join("wide.toml").display().to_string();
    let (code, _, stderr, _) = btfsm_capped(
        2048,
        &[
            "convert",
            &f,
            "--to",
            "hfsm",
            "-o",
            &out,
            "--max-nodes",
            "300000",
        ],
    );
    assert_eq!(code, 0, "{}", head(&stderr, 2000));
}

/// 20,000 SubTrees each inside the last, sharing their blackboard by name
/// (`_autoremap`), around 100,000 ports: each port's entry is looked up in
/// O(1) (it walked up the whole chain: over 100 s in a debug build).
#[test]
fn hostile_long_autoremap_subtree_chain_resolves_ports_in_linear_time() {
    let dir = Scratch::new("autoremap-chain");
    let k = 20_000;
    let mut text = String::from("<root BTCPP_format=\"4\" main_tree_to_execute=\"T0\">");
    for i in 0..k {
        text.push_str(&format!(
            "<BehaviorTree ID=\"T{i}\"><SubTree ID=\"T{}\" _autoremap=\"true\" d{i}=\"x\"/></BehaviorTree>",
            i + 1
        ));
    }
    text.push_str(&format!(
        "<BehaviorTree ID=\"T{k}\"><Sequence>{}</Sequence></BehaviorTree></root>",
        "<Script code=\"{c}\"/>".repeat(100_000)
    ));
    let f = dir.write("chain.xml", text);
    let (code, stdout, stderr, _) = btfsm_capped(1024, &["analyze", &f, "--format", "json"]);
    assert_eq!(code, 0, "{}", head(&stderr, 2000));
    assert!(
        stdout.contains("\"vertices\": 100001"),
        "{}",
        head(&stdout, 2000)
    );
}

/// Two million distinct unknown BehaviorTree.CPP types: the reader keeps
/// 200 messages of each kind while reading, under a 1 GiB cap (it kept every
/// one, about 2 GB, and trimmed when reporting). (A type used many times is
/// one error.)
#[test]
fn hostile_million_bad_xml_elements_keep_bounded_messages() {
    let dir = Scratch::new("xml-many-errors");
    let n = 1_990_000;
    let leaves: String = (0..n).map(|i| format!("<X{i}/>")).collect();
    let bt = dir.write(
        "unknown.xml",
        format!(
            "<root BTCPP_format=\"4\"><BehaviorTree ID=\"M\"><Sequence>{leaves}</Sequence></BehaviorTree></root>"
        ),
    );
    let (code, _, stderr, _) = btfsm_capped(1024, &["analyze", &bt, "--max-nodes", "2100000"]);
    assert_eq!(code, 2, "{}", head(&stderr, 2000));
    assert!(
        stderr.contains(&format!(
            "{} more errors not shown (the first 200 messages are)",
            n - 200
        )),
        "{}",
        head(&stderr, 2000)
    );
    assert!(stderr.len() < 300_000, "{} bytes of stderr", stderr.len());
}
