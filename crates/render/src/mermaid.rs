//! Mermaid text of a policy (`btfsm convert --to mermaid`), which GitHub and
//! GitLab render inside markdown: a `flowchart TD` for a BT, a
//! `stateDiagram-v2` for an FSM or HFSM (syntax: mermaid.js.org, "Flowcharts"
//! and "State diagrams").
//!
//! - BT: control nodes are boxes labelled with the paper's symbols (`→`, `?`,
//!   `→*`, `?*`, `⇉ k/N`; other controls by their type), decorators hexagons,
//!   actions boxes with rounded corners, conditions stadiums; children in
//!   order, left to right.
//! - FSM/HFSM: `[*] -->` the initial state at every level, a container as a
//!   composite state, outcomes as states of their region with `--> [*]`,
//!   transitions labelled by outcome or guard.
//!
//! Identifiers are generated (`n0`, `s3`, ...), never taken from the file;
//! every label is written between quotes with `"`, `#`, `<`, `>`, `:`, `;`
//! and `%` as Mermaid entity codes and control characters removed, so no
//! name can end a statement, inject markup or open a `%%{init}%%`
//! directive.

use btfsm_model::Policy;
use btfsm_model::bt::{Arity, Bt};
use btfsm_model::{BtNodeKind, PolicyBody, Region, StateBody, StateMachine, Target};
use std::fmt::Write;

/// A label as Mermaid reads it between quotes (or after a transition's `:`).
pub fn label(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '"' => out.push_str("#quot;"),
            '#' => out.push_str("#35;"),
            '<' => out.push_str("#lt;"),
            '>' => out.push_str("#gt;"),
            ':' => out.push_str("#58;"),
            ';' => out.push_str("#59;"),
            // Mermaid reads a `%%{init: ...}%%` directive anywhere in the
            // text, inside a quoted label too.
            '%' => out.push_str("#37;"),
            '\n' | '\r' | '\t' => out.push(' '),
            c if c.is_control() || btfsm_core::sanitize::is_unsafe(c, false) => {}
            c => out.push(c),
        }
    }
    out
}

/// The front matter with the policy's name as the diagram's title: a YAML
/// single-quoted string (where only `'` is special, written `''`), on one
/// line, without control characters.
pub fn front_matter(name: &str) -> String {
    let title: String = name
        .chars()
        .filter_map(|c| match c {
            '\n' | '\r' | '\t' => Some(' '),
            c if c.is_control() || btfsm_core::sanitize::is_unsafe(c, false) => None,
            c => Some(c),
        })
        .collect();
    // `%%` would open a directive (`%%{init}%%`) or a comment.
    let title = title.replace("%%", "% %").replace("%%", "% %");
    format!("---\ntitle: '{}'\n---\n", title.replace('\'', "''"))
}

/// The Mermaid text of a policy.
pub fn policy_mermaid(p: &Policy) -> String {
    match &p.body {
        PolicyBody::Bt(bt) => bt_flowchart(&p.name, bt),
        PolicyBody::Machine(m) => state_diagram(&p.name, m),
    }
}

fn bt_flowchart(name: &str, bt: &Bt) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "{}flowchart TD", front_matter(name));
    for i in bt.preorder() {
        let n = &bt.nodes[i];
        let symbol = match n.kind {
            BtNodeKind::Sequence => Some("→".to_string()),
            BtNodeKind::Fallback => Some("?".to_string()),
            BtNodeKind::SequenceMemory => Some("→*".to_string()),
            BtNodeKind::FallbackMemory => Some("?*".to_string()),
            BtNodeKind::Parallel { success } => Some(format!("⇉ {success}/{}", n.children.len())),
            _ => None,
        };
        let text = match (&symbol, n.label == n.kind.default_label()) {
            (Some(s), true) => s.clone(),
            (Some(s), false) => format!("{s} {}", n.label),
            (None, _) => match &n.type_name {
                Some(t) if *t != n.label => format!("{} ({t})", n.label),
                _ => n.label.clone(),
            },
        };
        let (open, close) = match n.kind {
            BtNodeKind::Condition => ("([\"", "\"])"),
            BtNodeKind::Action => ("(\"", "\")"),
            k if k.arity() == Arity::One => ("{{\"", "\"}}"),
            k if k.arity() == Arity::Leaf => ("(\"", "\")"),
            _ => ("[\"", "\"]"),
        };
        let _ = writeln!(out, "    n{i}{open}{}{close}", label(&text));
    }
    for i in bt.preorder() {
        for &c in &bt.nodes[i].children {
            let _ = writeln!(out, "    n{i} --> n{c}");
        }
    }
    out
}

/// The `stateDiagram-v2` text of an FSM or HFSM.
fn state_diagram(name: &str, m: &StateMachine) -> String {
    let mut d = Diagram {
        m,
        out: String::new(),
        decisions: Vec::new(),
        stack: vec![Item::Region(None, 1)],
    };
    let _ = writeln!(d.out, "{}stateDiagram-v2", front_matter(name));
    while let Some(item) = d.stack.pop() {
        match item {
            Item::Close(depth) => {
                let _ = writeln!(d.out, "{}}}", "    ".repeat(depth - 1));
            }
            Item::Separator(depth) => {
                let _ = writeln!(d.out, "{}--", "    ".repeat(depth));
            }
            Item::Orthogonal(s, depth) => d.orthogonal(s, depth),
            Item::Region(owner, depth) => d.region(owner, depth),
        }
    }
    for s in d.decisions {
        let _ = writeln!(d.out, "    class s{s} decision");
    }
    let _ = writeln!(d.out, "    classDef decision fill:#fff3c4");
    d.out
}

/// What is left to write of a state diagram. Regions go on an explicit
/// stack: a container's block is opened, its region written (states,
/// outcomes, transitions of its states), its nested containers written
/// inside, then closed.
enum Item {
    Region(Option<usize>, usize),
    Close(usize),
    /// `--` between two regions of a parallel state (Mermaid's
    /// concurrency separator).
    Separator(usize),
    /// A region of a parallel state at a depth: its start, and the
    /// state itself (a block when it holds states).
    Orthogonal(usize, usize),
}

/// The id of the outcome state `k` of a region: `o{k}` at the top,
/// `o{c}_{k}` in container c.
fn outcome_id(owner: Option<usize>, k: usize) -> String {
    match owner {
        None => format!("o{k}"),
        Some(c) => format!("o{c}_{k}"),
    }
}

/// A state diagram being written: the text so far, the decision states met
/// (styled at the end) and what is left to write.
struct Diagram<'m> {
    m: &'m StateMachine,
    out: String,
    decisions: Vec<usize>,
    stack: Vec<Item>,
}

impl<'m> Diagram<'m> {
    /// The transitions of state `s`, whose region's outcomes are `outcomes`
    /// (an outcome of an enclosing region: that region's outcome state).
    fn transitions(&mut self, pad: &str, s: usize, outcomes: &[String]) {
        let m = self.m;
        for t in &m.states[s].transitions {
            let to = match &t.target {
                Target::State(j) => format!("s{j}"),
                Target::Outcome(o) => match outcomes.iter().position(|x| x == o) {
                    Some(k) => outcome_id(m.states[s].parent, k),
                    None => continue,
                },
                Target::OuterOutcome { owner, outcome } => {
                    let outer = match owner {
                        None => &m.top.outcomes,
                        Some(c) => match &m.states[*c].body {
                            StateBody::Container(r) => &r.outcomes,
                            _ => continue,
                        },
                    };
                    match outer.iter().position(|x| x == outcome) {
                        Some(k) => outcome_id(*owner, k),
                        None => continue,
                    }
                }
            };
            match label(&t.trigger.label()) {
                l if l.trim().is_empty() => {
                    let _ = writeln!(self.out, "{pad}s{s} --> {to}");
                }
                l => {
                    let _ = writeln!(self.out, "{pad}s{s} --> {to} : {l}");
                }
            }
        }
    }

    /// One region of a parallel state: its start `s`, written as a state
    /// unless it is a container (whose region is then written inside).
    fn orthogonal(&mut self, s: usize, depth: usize) {
        let pad = "    ".repeat(depth);
        let st = &self.m.states[s];
        let _ = writeln!(self.out, "{pad}[*] --> s{s}");
        if !matches!(st.body, StateBody::Container(_)) {
            if matches!(st.body, StateBody::Decision) {
                self.decisions.push(s);
            }
            let _ = writeln!(self.out, "{pad}state \"{}\" as s{s}", label(&st.label));
        }
        self.transitions(&pad, s, &[]);
        if matches!(st.body, StateBody::Container(_)) {
            self.stack.push(Item::Region(Some(s), depth + 1));
        }
    }

    /// The region of container `owner` (the top region for `None`) at
    /// `depth`, its container's block opened.
    fn region(&mut self, owner: Option<usize>, depth: usize) {
        let m = self.m;
        let pad = "    ".repeat(depth);
        let region = match owner {
            None => &m.top,
            Some(c) => {
                let outer = "    ".repeat(depth - 1);
                let _ = writeln!(
                    self.out,
                    "{outer}state \"{}\" as s{c}",
                    label(&m.states[c].label)
                );
                let _ = writeln!(self.out, "{outer}state s{c} {{");
                match &m.states[c].body {
                    StateBody::Container(r) => r,
                    _ => unreachable!("only containers are pushed"),
                }
            }
        };
        if region.parallel {
            self.parallel_region(owner, region, depth, &pad);
        } else {
            self.sequential_region(owner, region, depth, &pad);
        }
    }

    /// A parallel region: each state is a region of its own, separated by
    /// `--`; history pseudo-states (no region) go in the first.
    fn parallel_region(&mut self, owner: Option<usize>, region: &Region, depth: usize, pad: &str) {
        let m = self.m;
        for &s in &region.states {
            if m.states[s].pseudo.is_some() {
                self.decisions.push(s);
                let _ = writeln!(
                    self.out,
                    "{pad}state \"{}\" as s{s}",
                    label(&m.states[s].label)
                );
                self.transitions(pad, s, &[]);
            }
        }
        if owner.is_some() {
            self.stack.push(Item::Close(depth));
        }
        let regions = region.entered(&m.states);
        for (k, &c) in regions.iter().enumerate().rev() {
            self.stack.push(Item::Orthogonal(c, depth));
            if k > 0 {
                self.stack.push(Item::Separator(depth));
            }
        }
    }

    /// A region that is not parallel: its start, its outcomes, its states,
    /// their transitions, then its nested containers.
    fn sequential_region(
        &mut self,
        owner: Option<usize>,
        region: &Region,
        depth: usize,
        pad: &str,
    ) {
        let m = self.m;
        if let Some(i) = region.initial_state() {
            let _ = writeln!(self.out, "{pad}[*] --> s{i}");
        } else if let Target::Outcome(o) = &region.initial
            && let Some(k) = region.outcomes.iter().position(|x| x == o)
        {
            let _ = writeln!(self.out, "{pad}[*] --> {}", outcome_id(owner, k));
        }
        for (k, o) in region.outcomes.iter().enumerate() {
            let id = outcome_id(owner, k);
            let _ = writeln!(self.out, "{pad}state \"{}\" as {id}", label(o));
            let _ = writeln!(self.out, "{pad}{id} --> [*]");
        }
        let mut nested = Vec::new();
        for &s in &region.states {
            let st = &m.states[s];
            match st.body {
                StateBody::Container(_) => nested.push(s),
                StateBody::Decision => {
                    self.decisions.push(s);
                    let _ = writeln!(self.out, "{pad}state \"{}\" as s{s}", label(&st.label));
                }
                StateBody::Task(_) => {
                    let _ = writeln!(self.out, "{pad}state \"{}\" as s{s}", label(&st.label));
                }
            }
        }
        for &s in &region.states {
            self.transitions(pad, s, &region.outcomes);
        }
        if owner.is_some() {
            self.stack.push(Item::Close(depth));
        }
        for &c in nested.iter().rev() {
            self.stack.push(Item::Region(Some(c), depth + 1));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use btfsm_format::{Limits, toml::parse_str};
    use std::path::Path;

    fn load(name: &str) -> Policy {
        let text = std::fs::read_to_string(format!(
            "{}/../../policies/paper/{name}",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap();
        parse_str(
            name,
            &text,
            Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../policies/paper")),
            &Limits::default(),
        )
        .unwrap()
        .policy
    }

    #[test]
    fn the_title_is_one_single_quoted_yaml_line() {
        assert_eq!(
            front_matter("it's a\\b\n\"c\""),
            "---\ntitle: 'it''s a\\b \"c\"'\n---\n"
        );
    }

    #[test]
    fn labels_cannot_break_out_of_their_quotes() {
        assert_eq!(
            label("a\"b; c: <d> #e\nf\u{1b}"),
            "a#quot;b#59; c#58; #lt;d#gt; #35;e f"
        );
        assert_eq!(label("%%{init: {}}%%"), "#37;#37;{init#58; {}}#37;#37;");
        assert!(!front_matter("a %%%{init}%%").contains("%%"));
    }

    #[test]
    fn fig01_is_a_flowchart_with_every_node_and_edge() {
        let p = load("fig01-bt.toml");
        let PolicyBody::Bt(bt) = &p.body else {
            panic!()
        };
        let text = policy_mermaid(&p);
        assert!(text.contains("flowchart TD"));
        let nodes = text
            .lines()
            .filter(|l| l.trim_start().starts_with('n') && !l.contains("-->"))
            .count();
        let edges = text.matches(" --> ").count();
        assert_eq!(nodes, bt.nodes.len());
        assert_eq!(edges, bt.nodes.len() - 1);
    }

    /// A parallel state's regions are separated by `--`, each starting with
    /// its own `[*] -->`; a transition out to the machine's outcome.
    #[test]
    fn parallel_regions_are_separated_by_dashes() {
        let l = btfsm_format::toml::parse_str(
            "p.toml",
            include_str!("../../../tests/fixtures/valid/parallel-regions.toml"),
            Path::new("."),
            &Default::default(),
        )
        .unwrap();
        let text = policy_mermaid(&l.policy);
        insta::assert_snapshot!("parallel", text);
        assert_eq!(text.matches("\n        --\n").count(), 1, "{text}");
        assert!(text.contains("s4 --> o0 : FAILURE"), "{text}");
    }

    #[test]
    fn an_hfsm_nests_its_containers_with_their_initial_states() {
        let p = load("fig06-hfsm.toml");
        let PolicyBody::Machine(m) = &p.body else {
            panic!()
        };
        let text = policy_mermaid(&p);
        assert!(text.contains("stateDiagram-v2"));
        let containers = m
            .states
            .iter()
            .filter(|s| matches!(s.body, StateBody::Container(_)))
            .count();
        assert_eq!(text.matches(" {\n").count(), containers, "{text}");
        assert_eq!(text.lines().filter(|l| l.trim() == "}").count(), containers);
        // One `[*] -->` per region, one `--> [*]` per outcome of every region.
        assert_eq!(text.matches("[*] --> s").count(), containers + 1);
        let transitions: usize = m.states.iter().map(|s| s.transitions.len()).sum();
        assert_eq!(text.matches(" : ").count(), transitions, "{text}");
    }
}
