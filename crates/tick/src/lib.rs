//! `btfsm tick`: ticks a BT against scripted leaf outcomes, without a world
//! (docs/bt-semantics.md). Each tick is BehaviorTree.CPP 4's
//! `tickExactlyOnce` on the shared executor ([`btfsm_sim::exec`]); the
//! report lists, per tick, every leaf ticked with the status it returned and
//! every running leaf halted, in the order they happened, and the root's
//! status. tests/differential/ checks these against BehaviorTree.CPP.

pub mod script;

use btfsm_model::bt::Bt;
use btfsm_sim::exec::{BtExec, CompiledBt, Leaves};
use btfsm_sim::skills::{Call, Status};
use script::Script;
use serde::Serialize;
use std::sync::Arc;

/// Most events (leaf ticks and halts) of one run: the tick budget, whatever
/// the tree does within a tick.
pub const MAX_EVENTS: usize = 4_000_000;

/// A leaf ticked or halted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Event {
    Tick(usize, Status),
    Halt(usize),
}

/// One tick of the tree.
#[derive(Debug, Clone)]
pub struct TickRecord {
    pub root: Status,
    pub events: Vec<Event>,
}

/// A run of a script on a tree.
#[derive(Debug, Clone)]
pub struct TickRun {
    pub ticks: Vec<TickRecord>,
    /// The leaves `halt = true` halted after the last tick.
    pub halt: Option<Vec<usize>>,
    /// Whether the run stopped at [`MAX_EVENTS`].
    pub cut: bool,
}

/// The scripted leaves: answers by (leaf, how many times it was ticked).
struct Scripted<'a> {
    script: &'a Script,
    action: Vec<bool>,
    count: Vec<u64>,
    events: Vec<Event>,
    total: usize,
}

impl Scripted<'_> {
    fn answer(&mut self, key: usize) -> Status {
        let k = self.count[key];
        self.count[key] += 1;
        let s = self.script.answer(key, k, self.action[key]);
        self.events.push(Event::Tick(key, s));
        s
    }
}

impl Leaves for Scripted<'_> {
    fn condition(&mut self, key: usize, _: &Call) -> bool {
        self.answer(key) == Status::Success
    }
    fn action(&mut self, key: usize, _: &Call) -> Status {
        self.answer(key)
    }
    fn halt(&mut self, key: usize) {
        self.events.push(Event::Halt(key));
    }
    fn now(&self) -> f64 {
        0.0
    }
}

/// Ticks `bt` as `script` says. The tree must have passed
/// [`btfsm_sim::exec::unsupported`].
pub fn run(bt: &Bt, script: &Script) -> TickRun {
    run_capped(bt, script, MAX_EVENTS)
}

/// [`run`] stopping after the tick that passes `cap` events.
fn run_capped(bt: &Bt, script: &Script, cap: usize) -> TickRun {
    let compiled = Arc::new(CompiledBt::scripted(bt));
    let mut ex = BtExec::new(compiled, false);
    let mut leaves = Scripted {
        script,
        action: (bt.nodes.iter())
            .map(|n| n.kind == btfsm_model::BtNodeKind::Action)
            .collect(),
        count: vec![0; bt.nodes.len()],
        events: Vec::new(),
        total: 0,
    };
    let mut ticks = Vec::new();
    let mut cut = false;
    for _ in 0..script.ticks {
        let root = ex.tick(&mut leaves);
        let events = std::mem::take(&mut leaves.events);
        leaves.total += events.len();
        ticks.push(TickRecord { root, events });
        if leaves.total > cap {
            cut = true;
            break;
        }
    }
    let halt = (script.halt && !cut).then(|| {
        ex.halt(&mut leaves);
        (leaves.events.iter())
            .filter_map(|e| match e {
                Event::Halt(n) => Some(*n),
                Event::Tick(..) => None,
            })
            .collect()
    });
    TickRun { ticks, halt, cut }
}

#[derive(Serialize)]
struct JsonEvent<'a> {
    #[serde(skip_serializing_if = "Option::is_none")]
    leaf: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    status: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    halt: Option<&'a str>,
}

#[derive(Serialize)]
struct JsonTick<'a> {
    tick: usize,
    root: &'static str,
    events: Vec<JsonEvent<'a>>,
}

#[derive(Serialize)]
struct JsonRun<'a> {
    tree: &'a str,
    script: &'a str,
    ticks: Vec<JsonTick<'a>>,
    halt: Option<Vec<&'a str>>,
    cut: bool,
}

impl TickRun {
    /// The JSON contract (docs/bt-semantics.md): one object, on one line.
    pub fn json(&self, bt: &Bt, tree: &str, script: &str) -> String {
        let id = |n: usize| bt.nodes[n].id.as_str();
        let run = JsonRun {
            tree,
            script,
            ticks: (self.ticks.iter().enumerate())
                .map(|(i, t)| JsonTick {
                    tick: i + 1,
                    root: t.root.as_str(),
                    events: (t.events.iter())
                        .map(|e| match *e {
                            Event::Tick(n, s) => JsonEvent {
                                leaf: Some(id(n)),
                                status: Some(s.as_str()),
                                halt: None,
                            },
                            Event::Halt(n) => JsonEvent {
                                leaf: None,
                                status: None,
                                halt: Some(id(n)),
                            },
                        })
                        .collect(),
                })
                .collect(),
            halt: self
                .halt
                .as_ref()
                .map(|h| h.iter().map(|&n| id(n)).collect()),
            cut: self.cut,
        };
        let mut s = btfsm_core::sanitize::json(serde_json::to_string(&run).expect("serializable"));
        s.push('\n');
        s
    }

    /// The table: a line per tick, its events in order.
    pub fn table(&self, bt: &Bt, tree: &str, script: &str) -> String {
        use btfsm_core::sanitize::shown;
        let id = |n: usize| shown(&bt.nodes[n].id);
        let mut out = format!(
            "tree `{}`, script `{}`: {} tick{}\n\ntick  root     leaves ticked (status) and halted, in order\n",
            shown(tree),
            shown(script),
            self.ticks.len(),
            if self.ticks.len() == 1 { "" } else { "s" }
        );
        for (i, t) in self.ticks.iter().enumerate() {
            let ev: Vec<String> = (t.events.iter())
                .map(|e| match *e {
                    Event::Tick(n, s) => format!("{} {}", id(n), s.as_str()),
                    Event::Halt(n) => format!("halt {}", id(n)),
                })
                .collect();
            let ev = if ev.is_empty() {
                "-".to_string()
            } else {
                ev.join(", ")
            };
            out.push_str(&format!("{:<5} {:<8} {ev}\n", i + 1, t.root.as_str()));
        }
        if let Some(h) = &self.halt {
            let ev: Vec<String> = h.iter().map(|&n| format!("halt {}", id(n))).collect();
            let ev = if ev.is_empty() {
                "-".to_string()
            } else {
                ev.join(", ")
            };
            out.push_str(&format!("{:<5} {:<8} {ev}\n", "halt", ""));
        }
        if self.cut {
            out.push_str(&format!(
                "\nstopped after {MAX_EVENTS} events (a fixed limit)\n"
            ));
        }
        out
    }
}

/// What `btfsm tick` prints: a run of a tree against a script, in the
/// table or the JSON contract of docs/bt-semantics.md.
pub struct TickReport<'a> {
    pub run: &'a TickRun,
    pub bt: &'a Bt,
    /// The tree's and the script's file names, as given.
    pub tree: &'a str,
    pub script: &'a str,
}

impl btfsm_core::output::Report for TickReport<'_> {
    const FORMATS: &'static [btfsm_core::output::Format] = &[
        btfsm_core::output::Format::Table,
        btfsm_core::output::Format::Json,
    ];

    fn write(&self, format: btfsm_core::output::Format) -> String {
        match Self::supported(format) {
            btfsm_core::output::Format::Json => self.run.json(self.bt, self.tree, self.script),
            _ => self.run.table(self.bt, self.tree, self.script),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use btfsm_core::diagnostic::SourceFile;
    use btfsm_format::Limits;
    use btfsm_model::PolicyBody;
    use std::path::Path;

    fn bt_of(p: &btfsm_model::Policy) -> &Bt {
        let PolicyBody::Bt(bt) = &p.body else {
            panic!("a BT")
        };
        bt
    }

    /// Per tick: the root status and each leaf event (node, status or halt).
    type Ticks = Vec<(Status, Vec<(String, Option<Status>)>)>;

    fn events(bt: &Bt, script: &str) -> Ticks {
        let s = script::parse(&SourceFile::new("s.toml", script), bt).expect("script");
        run(bt, &s)
            .ticks
            .iter()
            .map(|t| {
                let ev = (t.events.iter())
                    .map(|e| match *e {
                        Event::Tick(n, s) => (bt.nodes[n].id.clone(), Some(s)),
                        Event::Halt(n) => (bt.nodes[n].id.clone(), None),
                    })
                    .collect();
                (t.root, ev)
            })
            .collect()
    }

    /// docs/robustness.md: a run stops at its event cap, and says so.
    #[test]
    fn a_run_stops_at_its_event_cap() {
        let text = "kind = \"bt\"\nroot = \"a\"\n[nodes]\na = { action = \"A!\" }\n";
        let t = btfsm_format::toml::parse_str("t.toml", text, Path::new("."), &Limits::default())
            .unwrap()
            .policy;
        let s = script::parse(
            &SourceFile::new("s.toml", "ticks = 100000\nhalt = true\n"),
            bt_of(&t),
        )
        .unwrap();
        let r = run_capped(bt_of(&t), &s, 10);
        assert!(r.cut && r.ticks.len() == 11 && r.halt.is_none());
        assert!(r.table(bt_of(&t), "t", "s").contains("stopped after"));
    }

    /// docs/bt-semantics.md: a TOML `parallel` fails when it can no longer
    /// succeed, and means the same once exported to BehaviorTree.CPP XML
    /// (`failure_count = n - success + 1`); an XML `Parallel` without
    /// `failure_count` fails at its first failure (BehaviorTree.CPP's default).
    #[test]
    fn parallel_failure_thresholds_survive_export_and_default_on_import() {
        let text = "kind = \"bt\"\nroot = \"p\"\n[nodes]\np = { parallel = [\"a\", \"b\", \"c\"], success = 1 }\na = { action = \"A!\" }\nb = { action = \"B!\" }\nc = { action = \"C!\" }\n";
        let lim = Limits::default();
        let t = btfsm_format::toml::parse_str("t.toml", text, Path::new("."), &lim)
            .unwrap()
            .policy;
        let xml = btfsm_format::btcpp_xml_write::write_policy(&t).unwrap();
        assert!(xml.contains("failure_count=\"3\""), "{xml}");
        let x = btfsm_format::btcpp_xml::parse_str("t.xml", &xml, Path::new("."), &lim)
            .unwrap()
            .policy;
        let script =
            "ticks = 2\ndefault = \"running\"\n[leaves]\na = [\"failure\"]\nb = [\"failure\"]\n";
        let want = events(bt_of(&t), script);
        assert_eq!(
            want[0].0,
            Status::Running,
            "two failures of three: still running"
        );
        assert_eq!(events(bt_of(&x), script), want);
        let imported = "<root BTCPP_format=\"4\"><BehaviorTree ID=\"T\"><Parallel success_count=\"1\"><AlwaysSuccess name=\"a\"/><AlwaysSuccess name=\"b\"/></Parallel></BehaviorTree></root>";
        let x = btfsm_format::btcpp_xml::parse_str("i.xml", imported, Path::new("."), &lim)
            .unwrap()
            .policy;
        let p = &bt_of(&x).nodes[bt_of(&x).root];
        assert_eq!(p.ports.get("failure_count").map(String::as_str), Some("1"));
        let e = events(bt_of(&x), "ticks = 1\n[leaves]\na = [\"failure\"]\n");
        assert_eq!(e[0].0, Status::Failure, "{e:?}");
    }
}
