//! `btfsm view`: the replay page is one self-contained HTML file (its data
//! block, no URL but the SVG namespaces, no script but its own), hostile
//! names stay text, a 10,000-step run stays small, a `sim --trace` file
//! replays as its scenario does, a .btlog replays record by record, and bad
//! inputs exit 2. tests/browser/view.mjs drives the pages in Chromium.

use crate::common::{btfsm, scratch};

/// The page `view` writes for these inputs (exit 0 asserted).
fn page(tag: &str, inputs: &[&str]) -> String {
    let out = scratch("view").join(format!("{tag}.html"));
    let out_s = out.to_str().unwrap();
    let mut args = vec!["view"];
    args.extend_from_slice(inputs);
    args.extend_from_slice(&["-o", out_s]);
    let (code, _, stderr) = btfsm(&args);
    assert_eq!(code, 0, "{stderr}");
    std::fs::read_to_string(&out).unwrap()
}

/// The JSON of the page's data block.
fn data(html: &str) -> serde_json::Value {
    let open = r#"<script type="application/json" id="btfsm-data">"#;
    let at = html.find(open).expect("the data block") + open.len();
    let end = at + html[at..].find("</script>").unwrap();
    serde_json::from_str(&html[at..end]).expect("the data block is JSON")
}

#[test]
fn view_writes_one_self_contained_page() {
    if !crate::common::graphviz("view_writes_one_self_contained_page") {
        return;
    }
    let html = page("nominal", &["policies/scenarios/exp1-nominal.toml"]);
    let d = data(&html);
    let panels = d["panels"].as_array().unwrap();
    assert_eq!(panels.len(), 4, "the scenario's four policies");
    assert_eq!(html.matches(r#"<section class="panel""#).count(), 4);
    for p in panels {
        let steps = p["times"].as_array().unwrap().len();
        assert_eq!(p["deltas"].as_array().unwrap().len(), steps);
        assert!(steps > 100, "{steps}");
    }
    // Nothing loaded from anywhere: the only URLs are the SVG and XLink
    // namespaces, no element names an external resource, and the policy
    // forbids any fetch.
    let mut rest = html.as_str();
    while let Some(i) = rest.find("http") {
        let tail = &rest[i..];
        assert!(
            tail.starts_with("http://www.w3.org/2000/svg")
                || tail.starts_with("http://www.w3.org/1999/xlink")
                || tail.starts_with("http-equiv="),
            "{}",
            &tail[..tail.len().min(60)]
        );
        rest = &tail[4..];
    }
    for bad in ["<link", " src=", "<img", "<iframe", "@import", "url("] {
        assert!(!html.contains(bad), "{bad}");
    }
    assert!(html.contains("Content-Security-Policy\" content=\"default-src 'none'"));
    assert_eq!(
        html.matches("<script").count(),
        2,
        "the data block and the script"
    );
    // The diagrams are inline SVG without prolog, doctype or comments, and
    // every node of the drawing can be found by the id the data gives it.
    assert!(!html.contains("<?xml") && !html.contains("<!DOCTYPE svg") && !html.contains("<!--"));
    for id in panels[0]["ids"].as_array().unwrap() {
        let id = id.as_str().unwrap().replace('-', "&#45;");
        assert!(html.contains(&format!("id=\"p0-{id}\"")), "{id}");
    }
    // All four runs do the same thing: no divergence to mark.
    assert_eq!(d["divergences"], serde_json::json!([]));
    assert!(html.contains("The executed skills of all the runs are the same"));
}

#[test]
fn view_marks_the_first_divergence() {
    if !crate::common::graphviz("view_marks_the_first_divergence") {
        return;
    }
    let html = page("pick-fails", &["policies/scenarios/exp1-pick-fails.toml"]);
    let d = data(&html);
    let divs = d["divergences"].as_array().unwrap();
    // The sequential FSM of Fig. 2 stops at the failed grasp; the three
    // others retry it (the verdicts of `sim`).
    assert_eq!(divs.len(), 3, "{divs:?}");
    for v in divs {
        assert_eq!(v["b"], 3, "each against the sequential FSM");
        assert!(v["text"].as_str().unwrap().contains("Pick(object=cube2)"));
        // The step of the divergence is its time, 9.4 s, at 0.1 s a step.
        assert_eq!(v["step"], 93);
    }
    // Marked in the timelines of both runs of each pair.
    assert_eq!(html.matches(r#"<g class="divergence">"#).count(), 6);
}

#[test]
fn view_escapes_hostile_names() {
    if !crate::common::graphviz("view_escapes_hostile_names") {
        return;
    }
    let html = page("hostile", &["tests/fixtures/view/hostile.toml"]);
    // Only the page's own two scripts; no tag any name tried to open.
    assert_eq!(html.matches("<script").count(), 2);
    for bad in [
        "<script>alert",
        "<img src=x",
        "<svg onload",
        "\" onmouseover=\"",
        "<move-to-cube>",
        "\u{202e}",
    ] {
        assert!(!html.contains(bad), "{bad}");
    }
    assert!(html.contains("&lt;/script&gt;&lt;script&gt;alert(&#39;scenario&#39;)"));
    // The data block holds the hostile keys, escaped, as the same strings.
    let d = data(&html);
    let keys = d["panels"][0]["keys"].as_array().unwrap();
    assert!(keys.contains(&serde_json::json!("</script><script>alert(3)</script>")));
    assert!(keys.contains(&serde_json::json!("held\" id=\"x")));
    let json_at = html.find(r#"id="btfsm-data">"#).unwrap();
    let block = &html[json_at..json_at + html[json_at..].find("</script>").unwrap()];
    assert!(!block[16..].contains('<'), "no `<` inside the data block");
}

/// The page of a 10,000-step run holds changes, not snapshots: measured
/// 355 KB for the two runs of 10,860 steps (docs/view.md).
#[test]
fn view_of_a_10000_step_run_stays_small() {
    if !crate::common::graphviz("view_of_a_10000_step_run_stays_small") {
        return;
    }
    let html = page("long", &["tests/fixtures/view/five-cubes-10k.toml"]);
    let d = data(&html);
    let steps = d["panels"][0]["times"].as_array().unwrap().len();
    assert!(steps >= 10_000, "{steps}");
    assert!(html.len() < 1_000_000, "{} bytes", html.len());
}

#[test]
fn a_sim_trace_replays_as_its_scenario() {
    if !crate::common::graphviz("a_sim_trace_replays_as_its_scenario") {
        return;
    }
    let dir = scratch("view-trace");
    let trace = dir.join("t.json");
    let (code, _, stderr) = btfsm(&[
        "sim",
        "policies/scenarios/exp1-pick-fails.toml",
        "--trace",
        trace.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let from_scenario = data(&page("s", &["policies/scenarios/exp1-pick-fails.toml"]));
    // The trace is outside the repository: the policies it names are
    // inside the root given.
    let from_trace = data(&page("t", &[trace.to_str().unwrap(), "--root", "."]));
    assert_eq!(from_trace["panels"], from_scenario["panels"]);
    let steps = |d: &serde_json::Value| -> Vec<serde_json::Value> {
        (d["divergences"].as_array().unwrap().iter())
            .map(|v| v["step"].clone())
            .collect()
    };
    assert_eq!(steps(&from_trace), steps(&from_scenario));
}

/// `--seed S` replays the episode `sim --seed S` runs.
#[test]
fn view_seed_runs_the_episode_of_sim_seed() {
    if !crate::common::graphviz("view_seed_runs_the_episode_of_sim_seed") {
        return;
    }
    let scenario = "policies/scenarios/exp1-pick-fails.toml";
    let html = page("seed", &[scenario, "--seed", "17"]);
    assert!(html.contains("<h1>exp1-pick-fails (seed 17)</h1>"));
    let (code, json, stderr) = btfsm(&["sim", scenario, "--seed", "17", "--format", "json"]);
    assert!(code == 0 || code == 1, "{stderr}");
    let sim: serde_json::Value = serde_json::from_str(&json).unwrap();
    let d = data(&html);
    for (p, run) in d["panels"]
        .as_array()
        .unwrap()
        .iter()
        .zip(sim["policies"].as_array().unwrap())
    {
        assert_eq!(
            p["times"].as_array().unwrap().len() as u64,
            run["steps"].as_u64().unwrap()
        );
    }
}

#[test]
fn a_btlog_replays_record_by_record() {
    if !crate::common::graphviz("a_btlog_replays_record_by_record") {
        return;
    }
    let html = page("log", &["tests/fixtures/logs/fig01.btlog"]);
    let d = data(&html);
    let p = &d["panels"][0];
    // 349 records (tests/fixtures/logs/README.md), one step each.
    assert_eq!(p["times"].as_array().unwrap().len(), 349);
    let changes: usize = (p["deltas"].as_array().unwrap().iter())
        .map(|x| x.as_array().unwrap().len() / 2)
        .sum();
    assert!(changes > 300 && changes <= 349, "{changes}");
    // Two logs side by side share the slider.
    let two = data(&page(
        "logs",
        &[
            "tests/fixtures/logs/fig01.btlog",
            "tests/fixtures/logs/subtree.btlog",
        ],
    ));
    assert_eq!(two["panels"].as_array().unwrap().len(), 2);
}

#[cfg(feature = "sqlite")]
#[test]
fn a_db3_replays_its_last_session_record_by_record() {
    if !crate::common::graphviz("a_db3_replays_its_last_session_record_by_record") {
        return;
    }
    // tests/fixtures/logs/sessions.db3: session 2 holds 182 records
    // (`log report` counts them; tests/fixtures/logs/README.md).
    let (code, report, err) = btfsm(&[
        "log",
        "report",
        "tests/fixtures/logs/sessions.db3",
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{err}");
    let r: serde_json::Value = serde_json::from_str(&report).unwrap();
    let records = r["records"].as_u64().unwrap() as usize;
    let d = data(&page("db3", &["tests/fixtures/logs/sessions.db3"]));
    assert_eq!(d["panels"][0]["times"].as_array().unwrap().len(), records);
}

#[test]
fn view_pages_every_bundled_scenario() {
    if !crate::common::graphviz("view_pages_every_bundled_scenario") {
        return;
    }
    let mut n = 0;
    for e in std::fs::read_dir("policies/scenarios").unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            let d = data(&page(
                p.file_stem().unwrap().to_str().unwrap(),
                &[p.to_str().unwrap()],
            ));
            assert!(!d["panels"].as_array().unwrap().is_empty(), "{p:?}");
            n += 1;
        }
    }
    assert!(n >= 9, "{n}");
}

#[test]
fn view_refuses_bad_inputs_with_exit_2() {
    let dir = scratch("view-bad");
    let w = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let not_trace = w("x.json", "[1, 2");
    let (code, _, stderr) = btfsm(&["view", &not_trace]);
    assert_eq!(code, 2);
    assert!(
        stderr.contains("not a trace written by `btfsm sim --trace`"),
        "{stderr}"
    );
    // A trace naming a file outside the root: refused, the file not read.
    let outside = w(
        "out.json",
        r#"{"policies":[{"policy":"p","file":"/etc/passwd","trace":[]}]}"#,
    );
    let (code, _, stderr) = btfsm(&["view", &outside]);
    assert_eq!(code, 2);
    assert!(
        stderr.contains("names the file") && stderr.contains("hint"),
        "{stderr}"
    );
    assert!(!stderr.contains("root:x"), "{stderr}");
    let bad_log = w("x.btlog", "BTCPP4-FileLogger2\u{1}");
    let (code, _, stderr) = btfsm(&["view", &bad_log]);
    assert_eq!(code, 2);
    assert!(stderr.contains("byte"), "{stderr}");
    let (code, _, stderr) = btfsm(&["view", "policies/domains/moma-sim.toml"]);
    assert_eq!(code, 2);
    assert!(stderr.contains("symbolic scenario"), "{stderr}");
    let (code, _, stderr) = btfsm(&["view", "tests/fixtures/sim-invalid/does-not-exist.toml"]);
    assert_eq!(code, 2, "{stderr}");
    // A FIFO with no writer, as a log or a scenario: an answer at once.
    for name in ["f.btlog", "f.toml"] {
        let fifo = dir.join(name);
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: a NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let t0 = std::time::Instant::now();
        let (code, _, stderr) = btfsm(&["view", fifo.to_str().unwrap()]);
        assert_eq!(code, 2, "{stderr}");
        assert!(t0.elapsed() < std::time::Duration::from_secs(20));
    }
}

/// A trace names an HFSM's states by their path (`moma/deliver/.../pick`);
/// `dot --trace` colours the state drawn under its key (`pick`).
#[test]
fn dot_trace_colours_hfsm_states_named_by_their_path() {
    let dir = scratch("view-hfsm-trace");
    let trace = dir.join("t.json");
    let (code, _, stderr) = btfsm(&[
        "sim",
        "policies/scenarios/exp1-pick-fails.toml",
        "--trace",
        trace.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&trace).unwrap()).unwrap();
    let run = &v["policies"][1];
    assert_eq!(run["convert"], "hfsm");
    // Step 96 (9.7 s): Pick is running, named by its path in the trace.
    let st = &run["trace"][96]["statuses"];
    assert!(
        st.as_array()
            .unwrap()
            .iter()
            .any(|p| p[0].as_str().unwrap().ends_with("/pick") && p[1] == "RUNNING"),
        "{st}"
    );
    let (code, dot, stderr) = btfsm(&[
        "dot",
        "policies/paper/fig01-bt.toml",
        "--trace",
        trace.to_str().unwrap(),
        "--step",
        "96",
        "--policy",
        "Fig. 1 BT baseline (HFSM)",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let pick = dot
        .lines()
        .find(|l| l.trim_start().starts_with("pick["))
        .unwrap_or("");
    assert!(pick.contains("fillcolor=gold"), "{dot}");
}

/// Without the `sqlite` feature a `.db3` is refused with a message that
/// names the feature (exit 2), never read as something else.
#[cfg(not(feature = "sqlite"))]
#[test]
fn a_db3_without_the_sqlite_feature_says_so() {
    let (code, _, err) = btfsm(&["log", "report", "tests/fixtures/logs/sessions.db3"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("`sqlite` feature"), "{err}");
}

/// Two logs on one page are compared as `btfsm log compare` compares them:
/// the page names the same first divergence (it said "the executed skills
/// of all the runs are the same" where `log compare` found them diverging,
/// issue 31); a log beside a scenario is not compared, and the page says so
/// rather than calling the runs the same.
#[test]
fn view_of_two_logs_names_the_divergence_log_compare_finds() {
    if !crate::common::graphviz("view_of_two_logs_names_the_divergence_log_compare_finds") {
        return;
    }
    let (a, b) = (
        "tests/fixtures/logs/compare-nominal.btlog",
        "tests/fixtures/logs/compare-pick-fails.btlog",
    );
    let (_, out, _) = btfsm(&["log", "compare", a, b, "--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let d = &v["first_divergence"];
    let html = page("two-logs", &[a, b]);
    let want = format!(
        "at {} s, skill {}: ",
        d["t"].as_f64().unwrap(),
        d["index"].as_u64().unwrap() + 1
    );
    assert!(html.contains(&want), "{want}");
    assert!(!html.contains("are the same, in the same order"));
    let html = page(
        "log-and-scenario",
        &[a, "policies/scenarios/exp1-nominal.toml"],
    );
    assert!(html.contains("Not every pair of runs was compared"));
    assert!(!html.contains("are the same, in the same order"));
}
