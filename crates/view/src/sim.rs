//! Replays of the simulator's runs: a scenario run here with its seed, as
//! `btfsm sim` runs it (its policies side by side, their first divergences
//! from the behavior-match verdicts of `sim::trace`), or a trace file that
//! `btfsm sim --trace` wrote (its policies read from the files it names,
//! inside the root, its verdicts as recorded).

use super::{
    Divergence, Map, Mark, Panel, Recorder, Replay, Row, Span, ViewError, code, drawn_keys,
};
use btfsm_format::Limits;
use btfsm_render::dot::Status;
use btfsm_sim::scenario::Scenario;
use btfsm_sim::trace::{Run, SkillRecord, Step};
use std::collections::HashMap;
use std::path::Path;

/// `Move-To(to=table)`: a timeline row's label.
fn skill_label(skill: &str, args: &[(String, String)]) -> String {
    let a: Vec<String> = args.iter().map(|(k, v)| format!("{k}={v}")).collect();
    format!("{skill}({})", a.join(", "))
}

/// Timeline rows of executed skills, in order of first start; a span's
/// index is its place in the list.
fn rows_of(skills: impl Iterator<Item = (String, Span)>) -> Vec<Row> {
    let mut rows: Vec<Row> = Vec::new();
    let mut at: HashMap<String, usize> = HashMap::new();
    for (label, span) in skills {
        let r = *at.entry(label.clone()).or_insert_with(|| {
            rows.push(Row {
                label,
                spans: Vec::new(),
            });
            rows.len() - 1
        });
        rows[r].spans.push(span);
    }
    rows
}

fn record_rows(skills: &[SkillRecord]) -> Vec<Row> {
    rows_of(skills.iter().enumerate().map(|(i, k)| {
        let args: Vec<(String, String)> =
            k.args.iter().map(|(a, b)| (a.clone(), b.clone())).collect();
        (
            skill_label(&k.skill, &args),
            Span {
                start: k.start,
                end: k.end,
                outcome: k.outcome.clone(),
                index: i,
            },
        )
    }))
}

fn status_code(s: &str) -> u8 {
    code(Status::from_outcome(s))
}

/// A policy's vertex keys, their other names, and the policy's name.
type Drawn = (Vec<String>, Vec<(String, usize)>, String);

/// Collects each run's statuses as the runs are made (`TraceOut`).
struct Collect<'s> {
    recorders: Vec<Recorder>,
    keys: Vec<Drawn>,
    err: Option<ViewError>,
    /// The scenario, for the map's pixels.
    scenario: &'s Scenario,
    /// Per run: the step and the robot's position in the map's pixels,
    /// where it moved by half a pixel or more.
    tracks: Vec<Vec<(usize, (f64, f64))>>,
}

impl btfsm_sim::run::TraceOut for Collect<'_> {
    fn begin(&mut self) {
        let (keys, alias, _) = &self.keys[self.recorders.len()];
        self.recorders.push(Recorder::new(keys.clone(), alias));
        self.tracks.push(Vec::new());
    }

    fn step(&mut self, st: &Step) {
        if self.err.is_some() {
            return;
        }
        let i = self.recorders.len() - 1;
        let name = &self.keys[i].2;
        let statuses = st
            .statuses
            .iter()
            .map(|(k, s)| (k.as_str(), status_code(s)));
        if let Err(e) = self.recorders[i].snapshot(name, st.t, statuses) {
            self.err = Some(e);
        }
        let k = self.recorders[i].times.len().saturating_sub(1);
        let q = btfsm_sim::plot::pixel(self.scenario, (st.x, st.y));
        let track = &mut self.tracks[i];
        if track
            .last()
            .is_none_or(|(_, p)| (p.0 - q.0).abs() >= 0.5 || (p.1 - q.1).abs() >= 0.5)
        {
            track.push((k, q));
        }
    }

    fn end(&mut self, _run: &Run) {}
}

fn subtitle(file: &str, outcome: &str, reason: &str, steps: u64) -> String {
    format!("{file} · {outcome} after {steps} steps ({reason})")
}

/// Marks the first divergence of every pair of runs in both panels.
fn mark(panels: &mut [Panel], divs: &[Divergence], index: &[(usize, usize)]) {
    for (d, &(ia, ib)) in divs.iter().zip(index) {
        let (na, nb) = (panels[d.a].title.clone(), panels[d.b].title.clone());
        panels[d.a].marks.push(Mark {
            t: d.t,
            index: ia,
            text: format!("first divergence from `{nb}`: {}", d.text),
        });
        panels[d.b].marks.push(Mark {
            t: d.t,
            index: ib,
            text: format!("first divergence from `{na}`: {}", d.text),
        });
    }
}

/// Runs a scenario's policies (seed: `seed`, else the scenario's) and
/// makes their replay.
pub fn from_scenario(s: &Scenario, file: &str) -> Result<Replay, ViewError> {
    let mut collect = Collect {
        recorders: Vec::new(),
        keys: s
            .policies
            .iter()
            .map(|e| {
                let (k, a) = drawn_keys(&e.policy);
                (k, a, e.policy.name.clone())
            })
            .collect(),
        err: None,
        scenario: s,
        tracks: Vec::new(),
    };
    let (runs, _cut) = btfsm_sim::run::run_scenario_traced(s, None, &mut collect);
    if let Some(e) = collect.err {
        return Err(e);
    }
    let map = Map {
        svg: btfsm_sim::plot::svg(s, &runs),
        tracks: collect.tracks.into_iter().map(Map::thin).collect(),
    };
    // The page shows the first divergences, which the path distance does
    // not change: trajectories thinned to two points keep the 2,016 pairs
    // of 64 policies cheap.
    let verdicts = btfsm_sim::trace::verdicts(&runs, 2);
    let mut panels: Vec<Panel> = Vec::new();
    for ((e, run), rec) in s.policies.iter().zip(&runs).zip(collect.recorders) {
        panels.push(Panel {
            title: run.policy.clone(),
            subtitle: subtitle(&run.file, run.outcome.as_str(), &run.reason, run.steps),
            policy: e.policy.clone(),
            rec,
            rows: record_rows(&run.skills),
            marks: Vec::new(),
        });
    }
    // Without a deadline every pair has its verdict, in pair order: the
    // panels are found by place, not by name (two policies may share one).
    let mut divs = Vec::new();
    let mut index = Vec::new();
    for (v, (a, b)) in verdicts.iter().zip(btfsm_sim::episodes::pairs(runs.len())) {
        if let Some(d) = &v.first_divergence {
            divs.push(Divergence {
                a,
                b,
                t: d.t,
                text: d.summary(),
            });
            index.push((d.index, d.index));
        }
    }
    mark(&mut panels, &divs, &index);
    Ok(Replay {
        title: format!("{} (seed {})", s.name, s.seed),
        subtitle: s
            .description
            .clone()
            .unwrap_or_else(|| format!("scenario {file}")),
        step_name: format!("step of {} s", s.dt),
        panels,
        divergences: divs,
        compared_all: true,
        map: Some(map),
    })
}

fn str_of<'a>(v: &'a serde_json::Value, what: &str) -> Result<&'a str, ViewError> {
    v.as_str()
        .ok_or_else(|| ViewError::Input(format!("`{what}` is not a string")))
}

/// A trace of `btfsm sim --trace`: the policies it names read from their
/// files (paths as `sim` wrote them: relative to the current directory,
/// and inside `root` unless it is `None`).
pub fn from_trace(
    text: &str,
    shown: &str,
    root: Option<&Path>,
    limits: &Limits,
) -> Result<Replay, ViewError> {
    let bad = |m: String| not_a_trace(shown, m);
    let v: serde_json::Value = serde_json::from_str(text).map_err(|e| bad(e.to_string()))?;
    let runs = v["policies"]
        .as_array()
        .ok_or_else(|| bad("no `policies` array".into()))?;
    let mut panels = Vec::new();
    for (i, run) in runs.iter().enumerate() {
        panels.push(trace_panel(i, run, shown, root, limits)?);
    }
    let (divs, index) = trace_divergences(&v, &panels);
    mark(&mut panels, &divs, &index);
    let scenario = v["scenario"].as_str().unwrap_or("trace");
    Ok(Replay {
        title: format!("{scenario} (seed {})", v["seed"].as_u64().unwrap_or(0)),
        subtitle: format!("trace {shown}"),
        step_name: format!("step of {} s", v["dt"].as_f64().unwrap_or(0.0)),
        panels,
        divergences: divs,
        // A pair the run's budget skipped has no verdict in the trace.
        compared_all: v["skipped_verdicts"]
            .as_array()
            .is_none_or(|s| s.is_empty()),
        map: None,
    })
}

/// The error of a file `shown` that is not a trace, and why.
fn not_a_trace(shown: &str, m: String) -> ViewError {
    ViewError::Input(format!(
        "`{shown}` is not a trace written by `btfsm sim --trace`: {m}"
    ))
}

/// The panel of run `i` of a trace: its policy read from the file it
/// names, its steps' statuses, its executed skills.
fn trace_panel(
    i: usize,
    run: &serde_json::Value,
    shown: &str,
    root: Option<&Path>,
    limits: &Limits,
) -> Result<Panel, ViewError> {
    let bad = |e: ViewError| not_a_trace(shown, e.to_string());
    let name = str_of(&run["policy"], "policy").map_err(bad)?;
    let file = str_of(&run["file"], "file").map_err(bad)?;
    let path = btfsm_format::source::resolve(root, Path::new("."), file).map_err(|r| {
        ViewError::Diagnostics(vec![
            btfsm_core::diagnostic::Diagnostic::error(format!(
                "{shown}: policy {} names the file `{}`: {}",
                i + 1,
                btfsm_core::sanitize::shown(file),
                r.message,
            ))
            .hint(r.hint),
        ])
    })?;
    let loaded = btfsm_format::load_named(&path, limits).map_err(ViewError::Diagnostics)?;
    let mut policy = if run["convert"] == "hfsm" {
        btfsm_transform::bt_to_hfsm::bt_policy_to_hfsm(&loaded.policy)
            .map_err(|e| ViewError::Input(format!("{file}: {}", e[0])))?
    } else {
        loaded.policy
    };
    // Named as it ran (a scenario may rename it).
    policy.name = name.to_string();
    let (keys, alias) = drawn_keys(&policy);
    let mut rec = Recorder::new(keys, &alias);
    let empty = Vec::new();
    for st in run["trace"].as_array().unwrap_or(&empty) {
        let t = st["t"].as_f64().unwrap_or(f64::NAN);
        let pairs = st["statuses"].as_array().unwrap_or(&empty);
        let statuses = pairs
            .iter()
            .filter_map(|p| Some((p[0].as_str()?, status_code(p[1].as_str().unwrap_or("")))));
        rec.snapshot(name, t, statuses)?;
    }
    let rows = trace_rows(run["skills"].as_array().unwrap_or(&empty));
    Ok(Panel {
        title: name.to_string(),
        subtitle: subtitle(
            file,
            run["outcome"].as_str().unwrap_or("?"),
            run["reason"].as_str().unwrap_or(""),
            run["steps"].as_u64().unwrap_or(rec.times.len() as u64),
        ),
        policy,
        rec,
        rows,
        marks: Vec::new(),
    })
}

/// Timeline rows of a trace's executed skills (missing fields read as
/// empty).
fn trace_rows(skills: &[serde_json::Value]) -> Vec<Row> {
    rows_of(skills.iter().enumerate().map(|(i, k)| {
        let args: Vec<(String, String)> = k["args"]
            .as_object()
            .map(|o| {
                o.iter()
                    .map(|(a, b)| (a.clone(), b.as_str().unwrap_or("").to_string()))
                    .collect()
            })
            .unwrap_or_default();
        (
            skill_label(k["skill"].as_str().unwrap_or("?"), &args),
            Span {
                start: k["start"].as_f64().unwrap_or(0.0),
                end: k["end"].as_f64(),
                outcome: k["outcome"].as_str().unwrap_or("").to_string(),
                index: i,
            },
        )
    }))
}

/// The first divergences a trace's verdicts record between two of its
/// panels, and the index of the skill each is at in both.
fn trace_divergences(
    v: &serde_json::Value,
    panels: &[Panel],
) -> (Vec<Divergence>, Vec<(usize, usize)>) {
    let pos = |n: &serde_json::Value| panels.iter().position(|p| n == p.title.as_str());
    let mut divs = Vec::new();
    let mut index = Vec::new();
    let empty = Vec::new();
    for verdict in v["verdicts"].as_array().unwrap_or(&empty) {
        let d = &verdict["first_divergence"];
        if let (Some(a), Some(b), Some(t), Some(k)) = (
            pos(&verdict["a"]),
            pos(&verdict["b"]),
            d["t"].as_f64(),
            d["index"].as_u64(),
        ) {
            let side = |x: &str| d[x].as_str().unwrap_or("(none)").to_string();
            divs.push(Divergence {
                a,
                b,
                t,
                text: format!(
                    "at {t} s, skill {}: {} | {}",
                    k.saturating_add(1),
                    side("a"),
                    side("b")
                ),
            });
            index.push((k as usize, k as usize));
        }
    }
    (divs, index)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A trace from a stranger: wrong types, missing fields, hostile
    /// values give an error or a replay, never a panic.
    #[test]
    fn malformed_traces_never_panic() {
        let fig = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../policies/paper/fig01-bt.toml"
        );
        let cases = [
            "{}".to_string(),
            "[]".into(),
            r#"{"policies": 3}"#.into(),
            r#"{"policies": [{}]}"#.into(),
            format!(r#"{{"policies": [{{"policy": 1, "file": "{fig}"}}]}}"#),
            format!(
                r#"{{"policies": [{{"policy": "p", "file": "{fig}", "trace": [{{"t": "x", "statuses": [[1, 2], ["moma"], ["moma", "RUNNING", 3], "s"]}}, 7, {{"t": 1e308}}], "skills": [{{"skill": 3, "args": [1], "start": null, "end": "x"}}, 5]}}], "verdicts": [{{"a": "p", "b": "p", "first_divergence": {{"t": -1e308, "index": 18446744073709551615}}}}, 3]}}"#
            ),
            format!(
                r#"{{"policies": [{{"policy": "p", "file": "{fig}", "convert": "hfsm", "trace": [{{"t": 0, "statuses": [["moma/deliver", "SUCCESS"]]}}]}}]}}"#
            ),
        ];
        for c in &cases {
            let _ = from_trace(c, "t.json", None, &Limits::default());
        }
        let ok = from_trace(&cases[5], "t.json", None, &Limits::default()).unwrap();
        assert_eq!(ok.panels[0].rec.times.len(), 3);
        assert_eq!(ok.divergences.len(), 1);
        if !btfsm_render::dot::installed() {
            return; // the page draws through Graphviz (`make test` requires it)
        }
        let html = super::super::html::page(&ok, std::time::Duration::from_secs(60)).unwrap();
        assert!(html.contains("btfsm-data"));
    }

    /// Two policies of one name: each divergence is marked on the panels
    /// of its own pair, found by place.
    #[test]
    fn divergences_go_to_their_own_panels_when_names_repeat() {
        let text = r#"name = "dup"
goal = [{ if = "Object-At", args = { object = "cube2", at = "delivery" } }]
[world]
robot = "start"
objects = { cube2 = { at = "east-table" } }
[[policies]]
file = "../paper/fig02-fsm.toml"
[[policies]]
file = "../paper/fig01-bt.toml"
[[policies]]
file = "../paper/fig02-fsm.toml"
[[disturbances]]
at = 0.0
fail = "Pick"
times = 1
"#;
        let base = std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../policies/scenarios"
        ));
        let file = std::sync::Arc::new(btfsm_core::diagnostic::SourceFile::new("dup.toml", text));
        let s = btfsm_sim::scenario::parse(&file, base, &Limits::default()).expect("scenario");
        let r = from_scenario(&s, "dup.toml").expect("replay");
        let pairs: Vec<(usize, usize)> = r.divergences.iter().map(|d| (d.a, d.b)).collect();
        // The two sequential FSMs match; each differs from the BT.
        assert_eq!(pairs, [(0, 1), (1, 2)]);
        assert!(
            r.panels.iter().all(|p| !p.marks.is_empty()),
            "every panel marked"
        );
    }

    /// A scenario's replay has the room map: one track per panel, steps
    /// ascending from 0, positions in the plot's pixels (100 px a metre),
    /// and the page a robot per panel on it.
    #[test]
    fn a_scenario_replay_has_a_map_with_a_robot_per_run() {
        let base = std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../policies/scenarios"
        ));
        let text = std::fs::read_to_string(base.join("exp1-pick-fails.toml")).unwrap();
        let file = std::sync::Arc::new(btfsm_core::diagnostic::SourceFile::new("e.toml", text));
        let s = btfsm_sim::scenario::parse(&file, base, &Limits::default()).expect("scenario");
        let r = from_scenario(&s, "e.toml").expect("replay");
        let m = r.map.as_ref().expect("a map");
        assert_eq!(m.tracks.len(), r.panels.len());
        for (t, p) in m.tracks.iter().zip(&r.panels) {
            assert!(t.len() >= 6 && t.len() % 3 == 0);
            assert_eq!(t[0], 0.0, "from the first step");
            let steps: Vec<f32> = t.iter().step_by(3).copied().collect();
            assert!(steps.windows(2).all(|w| w[0] < w[1]));
            assert!(*steps.last().unwrap() as usize <= p.rec.times.len());
        }
        // The robot starts at `start` (-2.0, -2.2): its pixel is the plot's.
        let (x, y) = btfsm_sim::plot::pixel(&s, (-2.0, -2.2));
        let t = &m.tracks[0];
        assert!((t[1] as f64 - x).abs() < 60.0 && (t[2] as f64 - y).abs() < 60.0);
        assert!(m.svg.contains("<svg") && m.svg.contains("class=\"arrows\""));
        if !btfsm_render::dot::installed() {
            return;
        }
        let html = super::super::html::page(&r, std::time::Duration::from_secs(60)).unwrap();
        for i in 0..r.panels.len() {
            assert!(html.contains(&format!("id=\"map-robot-{i}\"")));
        }
    }

    #[test]
    fn a_long_track_is_thinned_to_the_map_bound() {
        let track: Vec<(usize, (f64, f64))> = (0..100_000).map(|k| (k, (k as f64, 0.0))).collect();
        let t = Map::thin(track);
        assert!(t.len() / 3 <= crate::MAP_POINTS + 1, "{}", t.len());
        assert_eq!(t[t.len() - 3], 99_999.0, "the last kept");
    }
}
