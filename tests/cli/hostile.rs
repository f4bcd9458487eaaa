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
