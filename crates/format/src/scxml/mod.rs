//! SCXML (W3C State Chart XML, 2015 Recommendation) read into the FSM/HFSM model.
//!
//! - `<scxml initial>` and nested `<state>`: a state holding states is a container,
//!   so a machine with any is an HFSM, else an FSM. A region's initial state is
//!   its `initial` attribute, its `<initial><transition target>`, or its first
//!   child (state, parallel state or final) in document order (SCXML 3.3); an
//!   `initial` naming a state deeper inside enters each container on the way
//!   at the next one (one `initial` may name one state in each region of a
//!   `<parallel>` inside it). An `initial` naming a final state of the region
//!   (or a region holding only finals, or a machine that is only a `<final>`)
//!   starts the region in that outcome: entering it completes it at once.
//!   A container whose own `initial` differs from the one an outer `initial`
//!   enters it at is refused (the model has one initial state per region).
//! - `<parallel>` is a parallel region (`Region::parallel`): a container whose
//!   states are its orthogonal regions, all entered together; it has no
//!   outcomes of its own (it completes when all its regions have, SCXML's
//!   `done.state.ID`, an event), and holds no `<final>`. An empty
//!   `<parallel>` is a plain state.
//! - `<final>` states are the outcomes of their region (top level: the machine's
//!   outcomes, vertices of the graph; inside a container: the container's). A
//!   transition to a final state of a region around the source's (every W3C
//!   test's `pass` and `fail`, targeted from deep inside) is a
//!   `Target::OuterOutcome` of that region; to a final of a region that does
//!   not enclose the source, an error.
//! - `<transition event cond target>`: an event that is an outcome the source
//!   state can return (`SUCCESS`, `FAILURE`, `RUNNING` of a task state, a
//!   container's final states) with no `cond` becomes an outcome transition;
//!   every other transition becomes a guard labelled `event`, `event [cond]` or
//!   `[cond]`. Targets may be in other regions (SCXML allows it). Transitions
//!   without a target change no state and are not counted (a warning says so).
//! - `<history>` is modelled as a decision pseudo-state of its region (its
//!   default transition, if any, is its guard). Transitions with several
//!   targets (into several regions of a `<parallel>` at once) are reported as
//!   unsupported with their position.
//! - Executable content (`<onentry>`, `<send>`, `<script>`, ...) and elements
//!   and attributes of other namespaces (Qt Creator's `qt:editorinfo`) are
//!   ignored; btfsm's own namespace carries what SCXML has no place for
//!   (`btfsm:name`, `btfsm:label`, `btfsm:skill`, `btfsm:arg.NAME`,
//!   `btfsm:decision` on states, `btfsm:outcomes` on a `<parallel>` (a yasmin
//!   OrthogonalState's outcomes); `btfsm:label`, `btfsm:terms`, `btfsm:guard`
//!   on transitions), written by `btfsm convert --to scxml`.
//!
//! The document is walked with explicit stacks (no recursion on nesting depth).

mod elements;
mod initial;
mod transitions;

pub use transitions::{guard_label, parse_terms};

use super::xml::{self, XDoc, XElem, shown};
use super::{Limits, Loaded};
use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use btfsm_model::{Policy, PolicyBody, Pseudo};
use std::borrow::Cow;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// The SCXML namespace.
pub const SCXML_NS: &str = "http://www.w3.org/2005/07/scxml";

/// Outcomes a task state returns (as in the TOML format).
const TASK_OUTCOMES: &[&str] = &["SUCCESS", "FAILURE", "RUNNING"];

/// Reads an SCXML file.
pub fn load_file(path: &Path, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    let shown = path.display().to_string();
    let file = super::toml::read_source(path, &shown, limits)?;
    load(file, limits)
}

/// Reads SCXML already read from a file.
pub fn load_read(file: Arc<SourceFile>, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    load(file, limits)
}

/// Reads SCXML from text.
pub fn parse_str(name: &str, text: &str, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    load(SourceFile::new(name, text), limits)
}

/// A state-like element found in the document.
enum Kind {
    State,
    /// `<parallel>`: a container whose states are its orthogonal regions.
    Parallel,
    History(Pseudo),
    Final,
}

fn load(file: Arc<SourceFile>, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    // Every element counts (states, transitions, executable content), as in
    // BehaviorTree.CPP files: memory is bounded before the states are read.
    let doc = xml::parse(&file, limits.max_nodes, limits.max_nodes).map_err(|d| vec![d])?;
    let mut diags = xml::Sink::default();
    let policy = read(&doc, limits, &mut diags);
    super::finish(&file, policy, diags.into_vec(&file), "state machine")
}

/// The first attribute of `e` (name or value) longer than
/// `--max-name-bytes`, as an error at the element: ids, names, labels, skill
/// arguments, events, conditions, targets.
fn long_attr(e: &XElem, f: &Arc<SourceFile>, limits: &Limits) -> Option<Diagnostic> {
    let max = limits.max_name_bytes;
    let (what, text) = std::iter::once(("element name".to_string(), e.name.as_str()))
        .chain(e.attrs.iter().flat_map(|a| {
            [
                ("attribute name".to_string(), a.name.as_str()),
                (format!("value of `{}`", shown(&a.name)), a.value.as_str()),
            ]
        }))
        .find(|(_, t)| t.len() > max)?;
    Some(
        Diagnostic::error(format!(
            "{what} `{}` of `<{}>` is {} bytes long, more than the limit of {max} bytes",
            shown(text),
            shown(&e.name),
            text.len()
        ))
        .at(f, e.span.clone())
        .hint("shorten it, or raise the limit with --max-name-bytes"),
    )
}

/// Is the element SCXML's (in its namespace, or in none)?
fn is_scxml(e: &XElem) -> bool {
    e.ns.is_none() || e.ns.as_deref() == Some(SCXML_NS)
}

/// An entry of pass 1: (element, kind, parent entry index).
type Entry = (usize, Kind, Option<usize>);

/// What the passes after the first share.
struct Ctx<'a> {
    doc: &'a XDoc,
    limits: &'a Limits,
    found: &'a [Entry],
    ids: &'a [Cow<'a, str>],
    by_id: &'a HashMap<&'a str, usize>,
    state_of: &'a [Option<usize>],
    entry_of: &'a [usize],
}

impl Ctx<'_> {
    /// The outcome name of the final state of entry `k`.
    fn final_name(&self, k: usize) -> String {
        self.doc.elems[self.found[k].0]
            .btfsm_attr("name")
            .unwrap_or(&self.ids[k])
            .to_string()
    }
}

fn read(doc: &XDoc, limits: &Limits, diags: &mut xml::Sink) -> Option<Policy> {
    let f = &doc.file;
    let err = |diags: &mut xml::Sink, e: &XElem, msg: String, hint: &str| {
        diags.push(Diagnostic::error(msg).at(f, e.span.clone()).hint(hint));
    };
    let root = &doc.elems[doc.root];
    if root.name != "scxml" || !is_scxml(root) {
        err(
            diags,
            root,
            format!(
                "expected `<scxml>` as the document element, found `<{}>`",
                shown(&root.name)
            ),
            "an SCXML file is `<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" version=\"1.0\" initial=\"...\">`",
        );
        return None;
    }
    let found = elements::collect(doc, limits, diags)?;
    let ids = elements::ids(doc, &found);
    let mut by_id: HashMap<&str, usize> = HashMap::with_capacity(ids.len());
    for (k, id) in ids.iter().enumerate() {
        if by_id.insert(id, k).is_some() {
            err(
                diags,
                &doc.elems[found[k].0],
                format!("duplicate id `{}`", shown(id)),
                "every state id in an SCXML document is unique",
            );
        }
    }
    let (mut m, state_of, entry_of) = elements::states(doc, &found, &ids, diags);
    let cx = Ctx {
        doc,
        limits,
        found: &found,
        ids: &ids,
        by_id: &by_id,
        state_of: &state_of,
        entry_of: &entry_of,
    };
    initial::initials(&cx, &mut m, diags)?;
    transitions::transitions(&cx, &mut m, diags)?;
    if diags.has_errors() {
        return None;
    }
    for (i, seen) in m.reachable().into_iter().enumerate() {
        if !seen {
            diags.push(
                Diagnostic::warning(format!(
                    "state `{}` is unreachable from the initial state",
                    shown(&ids[entry_of[i]])
                ))
                .at(f, m.states[i].span.clone().unwrap_or(0..0))
                .hint("add a transition to it, or remove it"),
            );
        }
    }
    let name = root
        .attr("name")
        .map(str::to_string)
        .unwrap_or_else(|| file_stem(&f.path));
    Some(Policy {
        name,
        description: None,
        body: PolicyBody::Machine(m),
    })
}

fn file_stem(path: &str) -> String {
    Path::new(path)
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("machine")
        .to_string()
}

impl XDoc {
    /// The first SCXML child element of `e` with a given name.
    pub fn children_of_name(&self, e: &XElem, name: &str) -> Option<&XElem> {
        e.children
            .iter()
            .map(|&c| &self.elems[c])
            .find(|c| is_scxml(c) && c.name == name)
    }
}

#[cfg(test)]
mod tests;
