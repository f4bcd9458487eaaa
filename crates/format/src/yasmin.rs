//! yasmin XML (the state machine files of yasmin_factory, the ROS 2
//! state-machine library of uleroboticsgroup/yasmin) read into the FSM/HFSM
//! model.
//!
//! - `<StateMachine name outcomes start_state>` is the machine; a nested
//!   `<StateMachine>` is a container (so a file with one is an HFSM), and a
//!   nested `<StateMachine file_path="other.xml">` takes its states and
//!   outcomes from that file (relative to the including file, kept inside the
//!   root like every named file: `format::source::resolve`), and one with
//!   `package="PKG" file_name="F"` from the first file named `F` below ROS
//!   package `PKG` (yasmin_factory's `create_sm`; where the package is:
//!   `format::ros_pkg`).
//! - A machine's outcomes are its `outcomes` attribute plus its
//!   `<FinalOutcome name>` children. Its start state is `start_state`, else
//!   its first state in document order (the first one added, as yasmin's
//!   `StateMachine.add_state` makes it).
//! - `<State name>` is a task state without a skill binding (its `class` /
//!   `module` is code the model does not run), and so is `<JoinState name
//!   sync_id outcome>` (the barrier of yasmin's `JoinState`, whose one
//!   outcome, `joined` by default, its `<Transition>` maps); `<Transition from="OUTCOME" to="TARGET">` is an outcome
//!   transition. `to` is resolved as yasmin's `StateMachine.execute` does:
//!   first an outcome of the enclosing machine, then a state of it; anything
//!   else is an error at the attribute, as yasmin's `validate` refuses it.
//! - A container's own `<Transition>` children map its outcomes in the
//!   enclosing machine.
//! - `<OrthogonalState name default_outcome>` is a parallel state
//!   (`Region::parallel`, as SCXML's `<parallel>`): its `<Region name
//!   outcomes start_state>` children are its regions, read as nested
//!   machines and all run at once; its outcomes are its `outcomes` attribute,
//!   the `outcome` of each `<OutcomeMap>`, its `default_outcome` and its
//!   `<FinalOutcome>`s (yasmin_factory's `_create_orthogonal_state`), and its
//!   own `<Transition>`s map them. `<Concurrence name default_outcome>`
//!   likewise, its children of any kind (states, machines) being what runs
//!   at once. Which region outcomes give which outcome
//!   (the `<Item>`s of an `<OutcomeMap>`) is not kept: the graph does not
//!   count it. `<Param>`, `<Key>`, `<ParamRemap>`, `<Remap>` and other
//!   elements (data flow, parameters, editor positions) are ignored.
//!
//! The document is walked region by region with a queue (no recursion on
//! nesting depth), and every element and included byte is charged to the
//! command's limits.

use super::xml::{self, XDoc, XElem, shown};
use super::{Limits, Loaded};
use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use btfsm_model::{
    Policy, PolicyBody, Region, State, StateBody, StateMachine, Target, Transition, Trigger,
};
use std::collections::{HashMap, HashSet, VecDeque};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Does the text look like a yasmin file (its document element is
/// `<StateMachine`)?
pub fn looks_like_yasmin(head: &str) -> bool {
    let mut rest = head.trim_start_matches('\u{feff}');
    // Skip the XML declaration, comments and processing instructions.
    loop {
        rest = rest.trim_start();
        if let Some(r) = rest.strip_prefix("<?") {
            match r.find("?>") {
                Some(i) => rest = &r[i + 2..],
                None => return false,
            }
        } else if let Some(r) = rest.strip_prefix("<!--") {
            match r.find("-->") {
                Some(i) => rest = &r[i + 3..],
                None => return false,
            }
        } else {
            break;
        }
    }
    rest.strip_prefix("<StateMachine")
        .is_some_and(|r| r.starts_with(|c: char| c.is_whitespace() || c == '>' || c == '/'))
}

/// Reads yasmin XML already read from `path`.
pub fn load_read(
    file: Arc<SourceFile>,
    path: &Path,
    limits: &Limits,
) -> Result<Loaded, Vec<Diagnostic>> {
    let main = xml::parse(&file, limits.max_nodes, limits.max_nodes).map_err(|d| vec![d])?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut r = Reader {
        root: super::source::root_for(limits, &base),
        elems_left: limits.max_nodes - main.elems.len(),
        limits,
        diags: xml::Sink::default(),
        docs: vec![(main, base)],
        maps: Vec::new(),
    };
    let policy = r.read(path);
    let diags = r.diags.into_vec(&file);
    super::finish(&file, policy, diags, "state machine")
}

/// Reads yasmin XML from text (tests, fuzzing): includes are resolved
/// against the current directory.
pub fn parse_str(name: &str, text: &str, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    load_read(SourceFile::new(name, text), Path::new(name), limits)
}

/// A `<StateMachine>` element whose states are still to be read: in
/// document `doc`, for container `state` (`None`: the top level).
struct Pending {
    doc: usize,
    elem: usize,
    state: Option<usize>,
    depth: usize,
    /// Canonical paths of the files included on the way here (cycles).
    chain: Vec<PathBuf>,
}

/// The states of one machine element: by name, and as `(element, state)`
/// in document order.
struct MachineStates {
    names: HashMap<String, usize>,
    made: Vec<(usize, usize)>,
}

struct Reader<'l> {
    root: Option<PathBuf>,
    elems_left: usize,
    limits: &'l Limits,
    diags: xml::Sink,
    /// Documents read (the main file first) with their directories.
    docs: Vec<(XDoc, PathBuf)>,
    /// A container's transitions, checked against its outcomes once its
    /// content is read: (state, document, `<Transition>` span, outcome).
    maps: Vec<(usize, usize, std::ops::Range<usize>, String)>,
}

impl Reader<'_> {
    fn err(&mut self, doc: usize, span: std::ops::Range<usize>, msg: String, hint: &str) {
        let f = self.docs[doc].0.file.clone();
        self.diags.push(Diagnostic::error(msg).at(&f, span)).hint = Some(hint.to_string());
    }

    fn read(&mut self, path: &Path) -> Option<Policy> {
        let top = &self.docs[0].0.elems[self.docs[0].0.root];
        if top.name != "StateMachine" {
            let span = top.span.clone();
            let msg = format!(
                "expected `<StateMachine>` as the document element, found `<{}>`",
                shown(&top.name)
            );
            self.err(
                0,
                span,
                msg,
                "a yasmin file is `<StateMachine outcomes=\"...\" start_state=\"...\">`",
            );
            return None;
        }
        let name = top.attr("name").map(str::to_string).unwrap_or_else(|| {
            path.file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("machine")
                .to_string()
        });
        let mut m = StateMachine::unset();
        let mut queue = VecDeque::from([Pending {
            doc: 0,
            elem: self.docs[0].0.root,
            state: None,
            depth: 0,
            chain: Vec::new(),
        }]);
        while let Some(p) = queue.pop_front() {
            self.region(&mut m, p, &mut queue);
            if !self.diags.room_for_errors() {
                break;
            }
        }
        // A container maps only the outcomes it has (its content is read).
        for (s, doc, span, from) in std::mem::take(&mut self.maps) {
            if let StateBody::Container(r) = &m.states[s].body
                && !r.outcomes.contains(&from)
            {
                let msg = format!(
                    "`{}` has no outcome `{}`",
                    shown(&m.states[s].name),
                    shown(&from)
                );
                self.err(
                    doc,
                    span,
                    msg,
                    "a nested machine's `<Transition from>` names one of its `outcomes`",
                );
            }
        }
        if self.diags.has_errors() {
            return None;
        }
        m.hierarchical = m
            .states
            .iter()
            .any(|s| matches!(s.body, StateBody::Container(_)));
        Some(Policy {
            name,
            description: top_description(&self.docs[0].0),
            body: PolicyBody::Machine(m),
        })
    }

    /// Reads the states of one machine element into region of `p.state`,
    /// queueing its nested machines.
    fn region(&mut self, m: &mut StateMachine, p: Pending, queue: &mut VecDeque<Pending>) {
        let (doc, elem) = (p.doc, p.elem);
        let outer_span = self.docs[doc].0.elems[elem].span.clone();
        // An `<OrthogonalState>`: its states are its `<Region>`s, all run at
        // once; its outcomes also those its `<OutcomeMap>`s and
        // `default_outcome` give (yasmin's OrthogonalState).
        let orth = self.docs[doc].0.elems[elem].name == "OrthogonalState";
        // A `<Concurrence>`: its states (of any kind) all run at once, its
        // outcomes as an orthogonal state's (yasmin's Concurrence).
        let conc = self.docs[doc].0.elems[elem].name == "Concurrence";
        let (outcome_set, outcomes) = machine_outcomes(&self.docs[doc].0, elem, orth || conc);
        let Some(MachineStates { names, made }) = self.machine_states(m, &p, orth, &outcomes)
        else {
            return;
        };
        let start = self.start_state(doc, elem, &names, &made);
        let start = if orth || conc {
            made.first().map(|&(_, s)| s)
        } else {
            start
        };
        if made.is_empty() {
            // An empty Concurrence runs nothing and ends at once in its
            // default outcome (yasmin_editor's own test file has one): a
            // state whose outcomes its transitions map.
            if let (true, Some(c)) = (conc, p.state) {
                m.states[c].body = StateBody::Task(None);
                return;
            }
            if !self.diags.has_errors() {
                let (msg, hint) = if orth {
                    (
                        "this orthogonal state has no regions",
                        "add `<Region name=\"...\" outcomes=\"...\">` children with their states",
                    )
                } else {
                    (
                        "this state machine has no states",
                        "add a `<State name=\"...\">` with its `<Transition from=\"...\" to=\"...\"/>`s",
                    )
                };
                self.err(doc, outer_span, msg.into(), hint);
            }
            return;
        }
        // Transitions of each state (a container's are its outcome map; a
        // region of an orthogonal state has none: yasmin reads only its
        // states).
        for &(c, s) in made.iter().filter(|_| !orth && !conc) {
            self.state_transitions(m, doc, (c, s), &outcome_set, &names);
        }
        // Install the region.
        let Some(start) = start else {
            return;
        };
        let states: Vec<usize> = made.iter().map(|&(_, s)| s).collect();
        let region = Region {
            parallel: orth || conc,
            ..Region::at(start, outcomes, states)
        };
        match p.state {
            None => m.top = region,
            Some(c) => m.states[c].body = StateBody::Container(region),
        }
        self.queue_nested(&p, &made, queue);
        // A container's outcome map may name outcomes its content lacks:
        // checked once its content is read (it is later in the queue).
    }

    /// The states of a machine element, in document order, added to `m`:
    /// by name, and as `(element, state)`. `None` when the node limit is
    /// hit.
    fn machine_states(
        &mut self,
        m: &mut StateMachine,
        p: &Pending,
        orth: bool,
        outcomes: &[String],
    ) -> Option<MachineStates> {
        let doc = p.doc;
        let kids: Vec<usize> = self.docs[doc].0.elems[p.elem].children.clone();
        let mut names: HashMap<String, usize> = HashMap::new();
        let mut made: Vec<(usize, usize)> = Vec::new(); // (element, state)
        for &c in &kids {
            let e = &self.docs[doc].0.elems[c];
            let container = match (orth, e.name.as_str()) {
                // A JoinState (a barrier between orthogonal regions) is a
                // task state with one outcome, `joined` by default.
                (false, "State" | "JoinState") => false,
                (false, "StateMachine" | "OrthogonalState" | "Concurrence") | (true, "Region") => {
                    true
                }
                _ => continue,
            };
            let Some(name) = self.state_name(doc, c, &names, outcomes) else {
                continue;
            };
            let e = &self.docs[doc].0.elems[c];
            if m.states.len() >= self.limits.max_nodes {
                let span = e.span.clone();
                self.err(
                    doc,
                    span,
                    format!("more than {} states", self.limits.max_nodes),
                    "raise the limit with --max-nodes",
                );
                return None;
            }
            let span = (doc == 0).then(|| e.span.clone());
            let body = if container {
                StateBody::Container(Region {
                    parallel: matches!(e.name.as_str(), "OrthogonalState" | "Concurrence"),
                    ..Region::unset(vec![])
                })
            } else {
                StateBody::Task(None)
            };
            let idx = m.states.len();
            m.states.push(State {
                name: name.clone(),
                label: name.clone(),
                parent: p.state,
                body,
                transitions: Vec::new(),
                pseudo: None,
                span,
            });
            names.insert(name, idx);
            made.push((c, idx));
        }
        Some(MachineStates { names, made })
    }

    /// The name of state element `c`: it must have one, within the length
    /// limit, unique in its machine and not an outcome's (else an error and
    /// `None`).
    fn state_name(
        &mut self,
        doc: usize,
        c: usize,
        names: &HashMap<String, usize>,
        outcomes: &[String],
    ) -> Option<String> {
        let e = &self.docs[doc].0.elems[c];
        let span = e.span.clone();
        let Some(name) = e.attr("name").map(str::to_string) else {
            let what = e.name.clone();
            self.err(
                doc,
                span,
                format!("`<{what}>` needs a `name`"),
                "write `<State name=\"Foo\" ...>`",
            );
            return None;
        };
        if name.len() > self.limits.max_name_bytes {
            self.err(
                doc,
                span,
                format!(
                    "state name `{}` is {} bytes long, more than the limit of {} bytes",
                    shown(&name),
                    name.len(),
                    self.limits.max_name_bytes
                ),
                "shorten it, or raise the limit with --max-name-bytes",
            );
            return None;
        }
        if names.contains_key(&name) {
            self.err(
                doc,
                span,
                format!("duplicate state `{}` in this machine", shown(&name)),
                "state names are unique within their machine (yasmin's add_state refuses a second one)",
            );
            return None;
        }
        if outcomes.contains(&name) {
            self.err(
                doc,
                span,
                format!(
                    "state `{}` has the name of an outcome of this machine",
                    shown(&name)
                ),
                "rename the state or the outcome (yasmin's add_state refuses a state named like an outcome)",
            );
            return None;
        }
        Some(name)
    }

    /// The start state of a machine element: its `start_state` (an error
    /// when it names none of its states), else its first state.
    fn start_state(
        &mut self,
        doc: usize,
        elem: usize,
        names: &HashMap<String, usize>,
        made: &[(usize, usize)],
    ) -> Option<usize> {
        match self.docs[doc].0.elems[elem].attr_full("start_state") {
            Some(a) => match names.get(a.value.as_str()) {
                Some(&s) => Some(s),
                None => {
                    let (v, span) = (a.value.clone(), a.span.clone());
                    self.err(
                        doc,
                        span,
                        format!("start state `{}` is not a state of this machine", shown(&v)),
                        "name one of the machine's own `<State>` or `<StateMachine>` children",
                    );
                    None
                }
            },
            None => made.first().map(|&(_, s)| s),
        }
    }

    /// Reads the `<Transition>`s of state element `c` (model state `s`)
    /// into `m`; a container's are checked against its outcomes later.
    fn state_transitions(
        &mut self,
        m: &mut StateMachine,
        doc: usize,
        (c, s): (usize, usize),
        outcome_set: &HashSet<String>,
        names: &HashMap<String, usize>,
    ) {
        let tkids: Vec<usize> = self.docs[doc].0.elems[c].children.clone();
        // An outcome maps to one target (yasmin keeps transitions in a
        // dict): a second one is an error, not a silent overwrite.
        let mut mapped: HashSet<String> = Default::default();
        for t in tkids {
            let te = &self.docs[doc].0.elems[t];
            if te.name != "Transition" {
                continue;
            }
            let tspan = te.span.clone();
            let (Some(from), Some(to)) = (te.attr("from"), te.attr_full("to")) else {
                self.err(
                    doc,
                    tspan,
                    "`<Transition>` needs `from` and `to`".into(),
                    "write `<Transition from=\"OUTCOME\" to=\"STATE_OR_OUTCOME\"/>`",
                );
                continue;
            };
            let (from, to_v, to_span) = (from.to_string(), to.value.clone(), to.span.clone());
            if !mapped.insert(from.clone()) {
                self.err(
                    doc,
                    tspan,
                    format!("a second transition from outcome `{}`", shown(&from)),
                    "each outcome of a state has one transition; remove one",
                );
                continue;
            }
            let target = if outcome_set.contains(&to_v) {
                Target::Outcome(to_v)
            } else if let Some(&n) = names.get(to_v.as_str()) {
                Target::State(n)
            } else {
                self.err(
                    doc,
                    to_span,
                    format!(
                        "`{}` is neither a state nor an outcome of this machine",
                        shown(&to_v)
                    ),
                    "`to` names a sibling state or one of the machine's `outcomes`",
                );
                continue;
            };
            if container_state(&self.docs[doc].0.elems[c]) {
                self.maps.push((s, doc, tspan.clone(), from.clone()));
            }
            m.states[s].transitions.push(Transition {
                trigger: Trigger::Outcome(from),
                target,
                span: (doc == 0).then_some(tspan),
            });
        }
    }

    /// Queues the nested machines of a machine element: their content,
    /// inline or from their file.
    fn queue_nested(
        &mut self,
        p: &Pending,
        made: &[(usize, usize)],
        queue: &mut VecDeque<Pending>,
    ) {
        let doc = p.doc;
        for &(c, s) in made {
            if !matches!(
                self.docs[doc].0.elems[c].name.as_str(),
                "StateMachine" | "OrthogonalState" | "Region" | "Concurrence"
            ) {
                continue;
            }
            if p.depth + 1 > self.limits.max_depth {
                let span = self.docs[doc].0.elems[c].span.clone();
                self.err(
                    doc,
                    span,
                    format!(
                        "state machines nested deeper than the limit of {} levels",
                        self.limits.max_depth
                    ),
                    "raise the limit with --max-depth",
                );
                continue;
            }
            let e = &self.docs[doc].0.elems[c];
            // yasmin_factory's `create_sm`: `file_path`, else `package` and
            // `file_name` (both), else the machine's own children.
            let target = match (
                e.attr_full("file_path"),
                e.attr_full("package"),
                e.attr("file_name"),
            ) {
                (Some(fp), _, _) => Some(Include::Path(fp.clone())),
                (None, Some(pkg), Some(f)) if !f.is_empty() && !pkg.value.is_empty() => {
                    Some(Include::Package(pkg.clone(), f.to_string()))
                }
                _ => None,
            };
            match target {
                None => queue.push_back(Pending {
                    doc,
                    elem: c,
                    state: Some(s),
                    depth: p.depth + 1,
                    chain: p.chain.clone(),
                }),
                Some(inc) => {
                    if let Some((nd, chain)) = self.include(doc, &inc, &p.chain) {
                        let root = self.docs[nd].0.root;
                        queue.push_back(Pending {
                            doc: nd,
                            elem: root,
                            state: Some(s),
                            depth: p.depth + 1,
                            chain,
                        });
                    }
                }
            }
        }
    }

    /// Reads the file an include names: its document index, and the
    /// include chain through it.
    fn include(
        &mut self,
        doc: usize,
        inc: &Include,
        chain: &[PathBuf],
    ) -> Option<(usize, Vec<PathBuf>)> {
        let fp = inc.attr();
        let (root, base) = (self.root.as_deref(), &self.docs[doc].1);
        let found = match inc {
            Include::Path(a) => super::source::resolve(root, base, &a.value),
            Include::Package(pkg, f) => {
                super::ros_pkg::find_in_package(&self.limits.ros, root, base, &pkg.value, f)
            }
        };
        let full = match found {
            Ok(p) => p,
            Err(r) => {
                self.err(
                    doc,
                    fp.span.clone(),
                    format!("cannot include this file: {}", r.message),
                    &r.hint,
                );
                return None;
            }
        };
        let canon = super::toml::canonical(&full);
        if chain.contains(&canon) {
            self.err(
                doc,
                fp.span.clone(),
                "cyclic include: a machine includes itself through `file_path`".into(),
                "a file must not include itself, directly or through others",
            );
            return None;
        }
        if chain.len() >= self.limits.max_include_depth {
            self.err(
                doc,
                fp.span.clone(),
                format!(
                    "includes nested deeper than {}",
                    self.limits.max_include_depth
                ),
                "raise the limit with --max-include-depth",
            );
            return None;
        }
        let shown_path = full.display().to_string();
        let file = match super::toml::read_included(&full, &shown_path, self.limits) {
            Ok(f) => f,
            Err(mut ds) => {
                let msg = ds.remove(0).message;
                self.err(
                    doc,
                    fp.span.clone(),
                    msg,
                    "`file_path` is relative to the including file",
                );
                return None;
            }
        };
        let parsed = match xml::parse(&file, self.elems_left, self.limits.max_nodes) {
            Ok(d) => d,
            Err(d) => {
                self.diags.push(d);
                return None;
            }
        };
        self.elems_left -= parsed.elems.len().min(self.elems_left);
        if parsed.elems[parsed.root].name != "StateMachine" {
            self.err(
                doc,
                fp.span.clone(),
                "the included file is not a yasmin state machine (its document element is not `<StateMachine>`)".into(),
                "`file_path` names another yasmin XML file",
            );
            return None;
        }
        let dir = full.parent().map(Path::to_path_buf).unwrap_or_default();
        self.docs.push((parsed, dir));
        let mut chain = chain.to_vec();
        chain.push(canon);
        Some((self.docs.len() - 1, chain))
    }
}

/// Where a nested machine's states come from (yasmin_factory's
/// `create_sm`): a `file_path` relative to the including file, or the file
/// named `file_name` below ROS package `package` (`ros_pkg.rs`).
enum Include {
    Path(xml::XAttr),
    Package(xml::XAttr, String),
}

impl Include {
    /// The attribute errors point at.
    fn attr(&self) -> &xml::XAttr {
        match self {
            Include::Path(a) | Include::Package(a, _) => a,
        }
    }
}

/// The outcomes of a machine element: its `outcomes` attribute, then (an
/// `<OrthogonalState>`'s) its `default_outcome` and `<OutcomeMap>`
/// outcomes, then its `<FinalOutcome>`s, each once; as a set and a list
/// (nothing is quadratic in the outcome count).
fn machine_outcomes(x: &XDoc, elem: usize, orth: bool) -> (HashSet<String>, Vec<String>) {
    let e = &x.elems[elem];
    // Outcomes: the attribute, then `<FinalOutcome>`s not already named.
    let mut outcome_set: HashSet<String> = Default::default();
    let mut outcomes: Vec<String> = Vec::new();
    for o in e.attr("outcomes").unwrap_or_default().split_whitespace() {
        if outcome_set.insert(o.to_string()) {
            outcomes.push(o.to_string());
        }
    }
    let mut mapped_outcomes: Vec<&str> = Vec::new();
    if orth {
        mapped_outcomes.extend(e.attr("default_outcome").filter(|o| !o.is_empty()));
        for &c in &e.children {
            let k = &x.elems[c];
            if k.name == "OutcomeMap"
                && let Some(o) = k.attr("outcome")
            {
                mapped_outcomes.push(o);
            }
        }
    }
    for &c in &e.children {
        let k = &x.elems[c];
        if k.name == "FinalOutcome"
            && let Some(n) = k.attr("name")
        {
            mapped_outcomes.push(n);
        }
    }
    for n in mapped_outcomes {
        if outcome_set.insert(n.to_string()) {
            outcomes.push(n.to_string());
        }
    }
    (outcome_set, outcomes)
}

/// Is the element a nested machine (a container)?
fn container_state(e: &XElem) -> bool {
    e.name == "StateMachine" || e.name == "OrthogonalState" || e.name == "Concurrence"
}

/// The machine's `description` attribute, if any.
fn top_description(doc: &XDoc) -> Option<String> {
    let e: &XElem = &doc.elems[doc.root];
    e.attr("description").map(str::to_string)
}

#[cfg(test)]
mod tests {
    use super::*;
    use btfsm_model::StateBody;

    fn machine(text: &str) -> StateMachine {
        match parse_str("t.xml", text, &Limits::default())
            .unwrap()
            .policy
            .body
        {
            PolicyBody::Machine(m) => m,
            _ => unreachable!(),
        }
    }

    fn errors(text: &str) -> Vec<String> {
        parse_str("t.xml", text, &Limits::default())
            .unwrap_err()
            .into_iter()
            .filter(|d| d.is_error())
            .map(|d| d.to_string())
            .collect()
    }

    #[test]
    fn a_flat_machine_with_its_start_state_and_final_outcomes() {
        let m = machine(
            r#"<?xml version="1.0"?>
<StateMachine name="Demo" outcomes="outcome4" start_state="Foo">
  <Param name="p" default_type="int" default_value="2"/>
  <State name="Bar" type="py" class="BarState"><Transition from="outcome3" to="Foo"/></State>
  <State name="Foo" type="cpp" class="FooState">
    <Transition from="outcome1" to="Bar"/>
    <Transition from="outcome2" to="outcome4"/>
  </State>
  <FinalOutcome name="outcome4"/>
</StateMachine>"#,
        );
        assert!(!m.hierarchical);
        assert_eq!(m.states[m.top.initial_state().unwrap()].name, "Foo");
        assert_eq!(m.top.outcomes, vec!["outcome4"]);
        let foo = &m.states[m.top.initial_state().unwrap()];
        assert_eq!(foo.transitions.len(), 2);
        assert_eq!(foo.transitions[0].target, Target::State(0));
        assert_eq!(
            foo.transitions[1].target,
            Target::Outcome("outcome4".into())
        );
    }

    #[test]
    fn nested_machines_are_containers_with_their_outcome_map() {
        let m = machine(
            r#"<StateMachine outcomes="final_outcome">
    <StateMachine name="NestedSM" outcomes="outcome1 outcome2">
        <State name="InnerState">
            <Transition from="outcome1" to="outcome1"/>
            <Transition from="outcome2" to="outcome2"/>
        </State>
        <Transition from="outcome1" to="NestedSM"/>
        <Transition from="outcome2" to="final_outcome"/>
    </StateMachine>
</StateMachine>"#,
        );
        assert!(m.hierarchical);
        let nested = &m.states[m.top.initial_state().unwrap()];
        assert_eq!(nested.name, "NestedSM");
        let StateBody::Container(r) = &nested.body else {
            panic!("not a container")
        };
        assert_eq!(r.outcomes, vec!["outcome1", "outcome2"]);
        assert_eq!(m.states[r.initial_state().unwrap()].name, "InnerState");
        assert_eq!(
            m.states[r.initial_state().unwrap()].parent,
            m.top.initial_state()
        );
        assert_eq!(nested.transitions.len(), 2);
        assert_eq!(nested.transitions[0].target, m.top.initial.clone());
    }

    #[test]
    fn bad_targets_and_start_states_are_errors_at_once() {
        let e = errors(
            r#"<StateMachine outcomes="end" start_state="nope">
  <State name="a"><Transition from="x" to="nowhere"/></State>
  <State name="a"/>
</StateMachine>"#,
        );
        assert_eq!(e.len(), 3, "{e:#?}");
        assert!(e[0].contains("start state `nope`"), "{e:#?}");
        assert!(
            e.iter()
                .any(|m| m.contains("`nowhere` is neither a state nor an outcome"))
        );
        assert!(e.iter().any(|m| m.contains("duplicate state `a`")));
        // An orthogonal state needs regions.
        let e = errors(
            r#"<StateMachine outcomes="end">
  <OrthogonalState name="o"/>
</StateMachine>"#,
        );
        assert!(
            e[0].contains("this orthogonal state has no regions"),
            "{e:#?}"
        );
    }

    /// `<OrthogonalState>`: a parallel state whose `<Region>`s are its
    /// regions (nested machines, all run at once), whose outcomes are its
    /// outcome map's, `default_outcome` and its `<FinalOutcome>`s, mapped by
    /// its own `<Transition>`s.
    #[test]
    fn orthogonal_states_are_parallel_regions() {
        let m = machine(
            r#"<StateMachine outcomes="done fail" start_state="start">
  <State name="start"><Transition from="ok" to="par"/></State>
  <OrthogonalState name="par" default_outcome="timeout">
    <Transition from="success" to="done"/>
    <Transition from="timeout" to="fail"/>
    <OutcomeMap outcome="success"><Item state="A" outcome="a_done"/><Item state="B" outcome="b_done"/></OutcomeMap>
    <Region name="A" outcomes="a_done" start_state="w"><State name="w"><Transition from="ok" to="a_done"/></State></Region>
    <Region name="B" outcomes="b_done"><State name="v"><Transition from="ok" to="b_done"/></State></Region>
  </OrthogonalState>
</StateMachine>"#,
        );
        assert!(m.hierarchical && m.has_parallel());
        let par = m.states.iter().position(|s| s.name == "par").unwrap();
        let StateBody::Container(r) = &m.states[par].body else {
            panic!("a container")
        };
        assert!(r.parallel);
        assert_eq!(r.outcomes, ["timeout", "success"]);
        let regions: Vec<&str> = r
            .entered(&m.states)
            .into_iter()
            .map(|i| m.states[i].name.as_str())
            .collect();
        assert_eq!(regions, ["A", "B"]);
        assert_eq!(m.states[par].transitions.len(), 2);
        let g = btfsm_model::graph::policy_graph(&Policy {
            name: "t".into(),
            description: None,
            body: PolicyBody::Machine(m.clone()),
        });
        // start par A w B v + done fail; start->par, par's 2 outcomes, 2
        // regions, A->w, B->v, w's and v's transitions.
        assert_eq!((g.g.node_count(), g.g.edge_count()), (8, 9));
    }

    #[test]
    fn a_state_named_like_an_outcome_is_an_error() {
        // yasmin's StateMachine.add_state: "State name '...' is already
        // registered as an outcome". Found by `mangled_files_never_panic`:
        // an `outcomes` attribute cut into a sentence holding `Bar`.
        let e = errors(
            r#"<StateMachine outcomes="Bar done" start_state="Bar">
  <State name="Bar" type="py" module="m" class="C"><Transition from="ok" to="done"/></State>
</StateMachine>"#,
        );
        assert!(
            e.iter()
                .any(|m| m.contains("state `Bar` has the name of an outcome")),
            "{e:?}"
        );
    }

    #[test]
    fn a_container_maps_only_its_outcomes_and_each_outcome_once() {
        let e = errors(
            r#"<StateMachine outcomes="end">
  <StateMachine name="In" outcomes="done">
    <State name="s"><Transition from="ok" to="done"/><Transition from="ok" to="s"/></State>
    <Transition from="done" to="end"/>
    <Transition from="nope" to="end"/>
  </StateMachine>
</StateMachine>"#,
        );
        assert!(
            e.iter()
                .any(|m| m.contains("a second transition from outcome `ok`")),
            "{e:#?}"
        );
        assert!(
            e.iter().any(|m| m.contains("`In` has no outcome `nope`")),
            "{e:#?}"
        );
    }

    #[test]
    fn sniffing_sees_the_document_element() {
        assert!(looks_like_yasmin(
            "<?xml version='1.0'?>\n<!-- c --><StateMachine outcomes=\"a\">"
        ));
        assert!(!looks_like_yasmin("<root BTCPP_format=\"4\">"));
        assert!(!looks_like_yasmin("<StateMachineX/>"));
    }

    /// yasmin's `<JoinState>` (a barrier in an orthogonal region, one
    /// outcome) is a state; a `<Concurrence>` is a parallel state whose
    /// children all run at once, and an empty one (yasmin_editor's test
    /// file) a state ending in its default outcome.
    #[test]
    fn join_states_and_concurrences_are_read() {
        let m = machine(
            r#"<StateMachine name="M" outcomes="ok" start_state="par">
  <OrthogonalState name="par" outcomes="done" default_outcome="done">
    <Region name="A" outcomes="end" start_state="w">
      <State name="w"><Transition from="ready" to="j"/></State>
      <JoinState name="j" sync_id="s" outcome="joined"><Transition from="joined" to="end"/></JoinState>
    </Region>
    <Transition from="done" to="cc"/>
  </OrthogonalState>
  <Concurrence name="cc" outcomes="both" default_outcome="both">
    <State name="x"/>
    <State name="y"/>
    <Transition from="both" to="empty"/>
  </Concurrence>
  <Concurrence name="empty" outcomes="fin" default_outcome="fin">
    <Transition from="fin" to="ok"/>
  </Concurrence>
</StateMachine>"#,
        );
        let by = |n: &str| {
            m.states
                .iter()
                .find(|s| s.name == n)
                .unwrap_or_else(|| panic!("{n}"))
        };
        assert!(matches!(by("j").body, StateBody::Task(None)));
        match &by("cc").body {
            StateBody::Container(r) => assert!(r.parallel && r.states.len() == 2),
            other => panic!("{other:?}"),
        }
        assert!(matches!(by("empty").body, StateBody::Task(None)));
    }
}
