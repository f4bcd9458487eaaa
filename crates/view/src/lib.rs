//! `btfsm view`: one self-contained HTML page that replays runs of policies
//! (issue 19, point 4): each policy's diagram (Graphviz SVG) with its nodes
//! coloured by their status at the current step — RUNNING yellow, SUCCESS
//! green, FAILURE red, the colours of `dot --trace` and of the paper's
//! supervision view (sec. IV-C) — a timeline of which actions ran when, and
//! a slider with step buttons shared by all the policies shown side by side.
//!
//! A replay is a list of [`Panel`]s, one per policy run: the statuses are
//! stored as per-step changes ([`Recorder`]), never as one snapshot per
//! step, so that a 10,000-step run stays small; the page's script applies
//! them incrementally, from a checkpoint it keeps every
//! [`CHECKPOINT_EVERY`] steps for jumps. Sources: a simulator scenario run
//! here (`sim.rs`), a `sim --trace` file (`sim.rs`), a BehaviorTree.CPP
//! `FileLogger2` log (`log.rs`). `timeline.rs` draws the timelines,
//! `html.rs` assembles the page.

pub mod html;
pub mod log;
pub mod sim;
pub mod timeline;

use btfsm_render::dot::Status;
use std::collections::HashMap;

/// Steps between two of the checkpoints the page's script keeps (a jump
/// applies at most this many steps of changes).
pub const CHECKPOINT_EVERY: usize = 128;

/// Most steps one panel may hold (a longer run is refused, not cut).
pub const MAX_STEPS: usize = 200_000;

/// Most status changes of all panels together.
pub const MAX_CHANGES: usize = 2_000_000;

/// Why a replay cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    #[error("{0}")]
    Input(String),
    #[error(
        "the run of `{policy}` has more than {limit} {what}; `btfsm view` shows at most that many"
    )]
    TooLarge {
        policy: String,
        what: &'static str,
        limit: usize,
    },
    /// A policy file that does not load (the diagnostics to print).
    #[error("{} problem(s) in a policy file", .0.len())]
    Diagnostics(Vec<btfsm_core::diagnostic::Diagnostic>),
    #[error(transparent)]
    Render(#[from] btfsm_render::dot::RenderError),
}

/// A status as the page codes it: 0 none (not ticked, IDLE, SKIPPED).
pub fn code(s: Option<Status>) -> u8 {
    match s {
        None => 0,
        Some(Status::Running) => 1,
        Some(Status::Success) => 2,
        Some(Status::Failure) => 3,
    }
}

/// One span of an action in a timeline row.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Span {
    /// When it started, s.
    pub start: f64,
    /// When it ended, s (`None`: still running at the end).
    pub end: Option<f64>,
    /// `success`, `failure`, `cancelled`, `aborted` or `running`.
    pub outcome: String,
    /// Its place in the run's executed-skill list (marked at a divergence).
    pub index: usize,
}

/// One row of a timeline: an action (skill with its arguments, or a log's
/// leaf node) and its spans.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Row {
    pub label: String,
    pub spans: Vec<Span>,
}

/// A marked moment of a panel's run: where it first diverges from another.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Mark {
    pub t: f64,
    /// The index of the executed skill where the runs differ.
    pub index: usize,
    pub text: String,
}

/// One policy's run, ready to draw.
#[derive(Debug, Clone)]
pub struct Panel {
    /// The policy's name.
    pub title: String,
    /// One line under the title: file, outcome, steps.
    pub subtitle: String,
    /// The policy as drawn.
    pub policy: btfsm_model::Policy,
    /// Statuses over the steps.
    pub rec: Recorder,
    /// The timeline's rows.
    pub rows: Vec<Row>,
    pub marks: Vec<Mark>,
}

/// A divergence between two panels' runs, shown in the page's header.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Divergence {
    pub a: usize,
    pub b: usize,
    pub t: f64,
    pub text: String,
}

/// Everything a page shows.
#[derive(Debug, Clone)]
pub struct Replay {
    pub title: String,
    pub subtitle: String,
    /// What a step is (`step of 0.1 s`, `status change`).
    pub step_name: String,
    pub panels: Vec<Panel>,
    pub divergences: Vec<Divergence>,
    /// Whether every pair of panels was compared (`divergences` then
    /// lists every pair that differs; panels of inputs that cannot be
    /// compared leave it `false`, and the page says so instead of calling
    /// the runs the same).
    pub compared_all: bool,
    /// The room with the runs' paths and a robot per panel that moves with
    /// the slider (a scenario run here; a trace file has no room).
    pub map: Option<Map>,
}

/// Most robot positions a map keeps per panel: past this, every k-th
/// (the robot then jumps k steps at a time on the map).
pub const MAP_POINTS: usize = 20_000;

/// The room of a simulator replay: `sim --plot`'s picture, and each
/// panel's robot positions as `[step, x, y, ...]` in the picture's pixels,
/// one entry where the robot moved (and the first step).
#[derive(Debug, Clone, PartialEq)]
pub struct Map {
    pub svg: String,
    pub tracks: Vec<Vec<f32>>,
}

impl Map {
    /// A track of positions by step, thinned to at most [`MAP_POINTS`]
    /// (every k-th, and the last).
    pub fn thin(track: Vec<(usize, (f64, f64))>) -> Vec<f32> {
        let stride = track.len().div_ceil(MAP_POINTS).max(1);
        let last = track.last().copied();
        let mut kept: Vec<(usize, (f64, f64))> = track.into_iter().step_by(stride).collect();
        if let Some(l) = last
            && kept.last() != Some(&l)
        {
            kept.push(l);
        }
        let r1 = |v: f64| ((v * 10.0).round() / 10.0) as f32;
        kept.into_iter()
            .flat_map(|(k, (x, y))| [k as f32, r1(x), r1(y)])
            .collect()
    }
}

/// A run's statuses as per-step changes. Node numbers index `keys`, the
/// vertex keys of the drawn policy first (in the order given), then any key
/// the run names that the drawing has not (shown in no diagram).
#[derive(Debug, Clone, Default)]
pub struct Recorder {
    pub keys: Vec<String>,
    index: HashMap<String, u32>,
    /// Each key's status after the last step.
    cur: Vec<u8>,
    /// Nodes with a status other than 0 after the last step.
    live: Vec<u32>,
    /// Time of each step, s.
    pub times: Vec<f64>,
    /// Per step: `(node, new status)` of the nodes whose status changed.
    pub deltas: Vec<Vec<(u32, u8)>>,
    pub changes: usize,
}

impl Recorder {
    /// A recorder for a drawing whose vertices have these keys; `alias`
    /// names a vertex by another key (an HFSM state's path in a trace).
    pub fn new(keys: Vec<String>, alias: &[(String, usize)]) -> Recorder {
        let mut index: HashMap<String, u32> = HashMap::with_capacity(keys.len() + alias.len());
        for (i, k) in keys.iter().enumerate() {
            index.entry(k.clone()).or_insert(i as u32);
        }
        for (a, i) in alias {
            index.entry(a.clone()).or_insert(*i as u32);
        }
        Recorder {
            cur: vec![0; keys.len()],
            keys,
            index,
            ..Default::default()
        }
    }

    /// The node number of a key, added when new.
    fn node(&mut self, key: &str) -> u32 {
        if let Some(&i) = self.index.get(key) {
            return i;
        }
        let i = self.keys.len() as u32;
        self.keys.push(key.to_string());
        self.index.insert(key.to_string(), i);
        self.cur.push(0);
        i
    }

    fn check(&self, policy: &str) -> Result<(), ViewError> {
        if self.times.len() > MAX_STEPS {
            return Err(ViewError::TooLarge {
                policy: policy.to_string(),
                what: "steps",
                limit: MAX_STEPS,
            });
        }
        if self.changes > MAX_CHANGES {
            return Err(ViewError::TooLarge {
                policy: policy.to_string(),
                what: "status changes",
                limit: MAX_CHANGES,
            });
        }
        Ok(())
    }

    /// A step that ticked exactly these nodes (a simulator step: a node not
    /// listed has no status in it), at time `t`.
    pub fn snapshot<'a>(
        &mut self,
        policy: &str,
        t: f64,
        statuses: impl IntoIterator<Item = (&'a str, u8)>,
    ) -> Result<(), ViewError> {
        // A node listed twice has its last status.
        let mut listed: std::collections::BTreeMap<u32, u8> = std::collections::BTreeMap::new();
        for (k, s) in statuses {
            let n = self.node(k);
            listed.insert(n, s);
        }
        let next: Vec<(u32, u8)> = listed.into_iter().filter(|d| d.1 != 0).collect();
        let mut delta = Vec::new();
        // Nodes ticked in this step whose status changed.
        for &(n, s) in &next {
            if self.cur[n as usize] != s {
                delta.push((n, s));
            }
        }
        // Nodes no longer ticked: back to none.
        let old = std::mem::take(&mut self.live);
        for &n in &old {
            self.cur[n as usize] = 0;
        }
        for &(n, s) in &next {
            self.cur[n as usize] = s;
        }
        for n in old {
            if self.cur[n as usize] == 0 {
                delta.push((n, 0));
            }
        }
        delta.sort_unstable();
        self.live = next.iter().map(|d| d.0).collect();
        self.changes += delta.len();
        self.deltas.push(delta);
        self.times.push(t);
        self.check(policy)
    }

    /// A step that changed one node (a log record), at time `t`.
    pub fn change(&mut self, policy: &str, t: f64, key: &str, s: u8) -> Result<(), ViewError> {
        let n = self.node(key);
        let delta = if self.cur[n as usize] == s {
            Vec::new()
        } else {
            self.cur[n as usize] = s;
            self.changes += 1;
            vec![(n, s)]
        };
        self.deltas.push(delta);
        self.times.push(t);
        self.check(policy)
    }

    /// A step that changed nothing shown, at time `t`.
    pub fn nothing(&mut self, policy: &str, t: f64) -> Result<(), ViewError> {
        self.deltas.push(Vec::new());
        self.times.push(t);
        self.check(policy)
    }

    /// Each node's status after step `k`, by replaying the changes (what
    /// the page's script computes; for tests).
    pub fn state_at(&self, k: usize) -> Vec<u8> {
        let mut s = vec![0u8; self.keys.len()];
        for d in self.deltas.iter().take(k + 1) {
            for &(n, v) in d {
                s[n as usize] = v;
            }
        }
        s
    }
}

/// The vertex keys of a policy's drawing, and the other names a run gives
/// them (an HFSM state's full path, which the simulator's trace uses).
pub fn drawn_keys(policy: &btfsm_model::Policy) -> (Vec<String>, Vec<(String, usize)>) {
    match &policy.body {
        btfsm_model::PolicyBody::Bt(bt) => {
            (bt.nodes.iter().map(|n| n.id.clone()).collect(), vec![])
        }
        btfsm_model::PolicyBody::Machine(m) => {
            let keys = m.keys();
            let alias = (0..m.states.len()).map(|i| (m.path(i), i)).collect();
            let mut all = keys;
            all.extend(m.top.outcomes.iter().cloned());
            (all, alias)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn snapshots_are_stored_as_changes_and_replay_to_the_same_states() {
        let mut r = Recorder::new(vec!["a".into(), "b".into(), "c".into()], &[]);
        let steps: [&[(&str, u8)]; 5] = [
            &[("a", 1), ("b", 1)],
            &[("a", 1), ("b", 1)],
            &[("a", 1), ("c", 3)],
            &[],
            &[("zz", 2)],
        ];
        for (i, st) in steps.iter().enumerate() {
            r.snapshot("p", i as f64, st.iter().copied()).unwrap();
        }
        assert_eq!(r.deltas[1], vec![], "nothing changed");
        assert_eq!(r.deltas[2], vec![(1, 0), (2, 3)]);
        assert_eq!(r.deltas[3], vec![(0, 0), (2, 0)]);
        assert_eq!(r.keys[3], "zz", "a key the drawing has not is added");
        for (k, st) in steps.iter().enumerate() {
            let mut want = vec![0u8; r.keys.len()];
            for (key, s) in *st {
                want[r.keys.iter().position(|x| x == key).unwrap()] = *s;
            }
            assert_eq!(r.state_at(k), want, "step {k}");
        }
    }

    #[test]
    fn log_records_change_one_node_each() {
        let mut r = Recorder::new(vec!["a".into()], &[("alias".into(), 0)]);
        r.change("p", 0.0, "alias", 1).unwrap();
        r.change("p", 0.5, "a", 1).unwrap();
        r.change("p", 1.0, "a", 2).unwrap();
        assert_eq!(r.deltas, vec![vec![(0, 1)], vec![], vec![(0, 2)]]);
        assert_eq!(r.changes, 2);
    }

    /// `DotOptions::svg_ids` gives every vertex (and every HFSM container's
    /// cluster) the id the page looks it up by, one-to-one.
    #[test]
    fn svg_ids_name_every_vertex_of_the_rendered_svg() {
        use btfsm_render::dot::{DotOptions, RenderFormat, render, svg_cluster_id, svg_id};
        let keys = ["a-b", "a_b", "a b", "\"a\"", "<x>", "é", "a-2db"];
        let ids: std::collections::HashSet<String> = keys.iter().map(|k| svg_id(k)).collect();
        assert_eq!(ids.len(), keys.len(), "{ids:?}");
        for id in &ids {
            assert!(
                id.chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
            );
        }
        let l = btfsm_format::load(
            std::path::Path::new(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../policies/paper/fig06-hfsm.toml"
            )),
            &Default::default(),
        )
        .unwrap();
        let opts = DotOptions {
            svg_ids: true,
            ..Default::default()
        };
        let dot = btfsm_render::dot::policy_dot(&l.policy, &opts);
        if !btfsm_render::dot::installed() {
            return; // this checks Graphviz's SVG (`make test` requires it)
        }
        let svg = render(&dot, RenderFormat::Svg, std::time::Duration::from_secs(60)).unwrap();
        let svg = String::from_utf8(svg).unwrap().replace("&#45;", "-");
        let (keys, _) = drawn_keys(&l.policy);
        for k in &keys {
            assert!(svg.contains(&format!("id=\"{}\"", svg_id(k))), "{k}");
        }
        let btfsm_model::PolicyBody::Machine(m) = &l.policy.body else {
            panic!("an HFSM")
        };
        let containers = (0..m.states.len())
            .filter(|&i| matches!(m.states[i].body, btfsm_model::StateBody::Container(_)))
            .count();
        assert!(containers > 0);
        let mkeys = m.keys();
        for (i, k) in mkeys.iter().enumerate() {
            if matches!(m.states[i].body, btfsm_model::StateBody::Container(_)) {
                assert!(
                    svg.contains(&format!("id=\"{}\"", svg_cluster_id(k))),
                    "{k}"
                );
            }
        }
        // Without the option a node's id is its key as Graphviz writes it
        // (`dot`'s own drawing); with it, the encoded id above, once.
        let plain = btfsm_render::dot::policy_dot(&l.policy, &DotOptions::default());
        let k = &keys[0];
        assert!(!plain.contains(&svg_id(k)) && dot.contains(&svg_id(k)));
        assert!(svg.matches(&format!("id=\"{}\"", svg_id(k))).count() == 1);
    }

    #[test]
    fn a_run_past_the_step_cap_is_refused() {
        let mut r = Recorder::new(vec![], &[]);
        let mut last = Ok(());
        for i in 0..=MAX_STEPS {
            last = r.change("p", i as f64, "a", (i % 2) as u8);
            if last.is_err() {
                break;
            }
        }
        assert!(matches!(last, Err(ViewError::TooLarge { .. })));
    }
}
