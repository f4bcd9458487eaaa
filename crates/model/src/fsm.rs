//! Finite State Machines and Hierarchical FSMs (SPEC §1; the paper's sec. II-B and
//! III). One arena type serves both: an FSM is an HFSM whose states are all leaves.
//! States live in an arena so that machines of any nesting depth are walked
//! without recursion.

use super::{Guard, SkillCall, Span};

/// Index of a state in [`StateMachine::states`].
pub type StateIdx = usize;

#[derive(Debug, Clone, PartialEq)]
pub struct StateMachine {
    /// `true` for `kind = "hfsm"`.
    pub hierarchical: bool,
    /// The top-level region: its states, initial state and terminal outcomes.
    pub top: Region,
    pub states: Vec<State>,
}

/// The content of a machine or of a container state.
///
/// A region runs one of its states at a time, starting at `initial`; a
/// *parallel* region (SCXML `<parallel>`, UML orthogonal regions) runs all
/// of its states at once: each state directly inside it (but history
/// pseudo-states) is an orthogonal region of its own, all are entered
/// together, and the parallel state completes when every one of them has
/// reached a final state (W3C SCXML 3.4).
#[derive(Debug, Clone, PartialEq)]
pub struct Region {
    /// Where the region starts: a state directly inside it, or one of its
    /// own `outcomes` (a region whose initial is a final state: entering it
    /// completes it at once). In a parallel region, its first state (every
    /// state is entered, see [`Region::entered`]).
    pub initial: Target,
    /// Terminal outcomes of this region ("SUCCESS", "FAILURE", ...). A
    /// parallel region's are those its states' completion maps to: none for
    /// SCXML's `<parallel>` (its `done.state.ID` is an event), yasmin's
    /// `OutcomeMap` and `default_outcome` for an OrthogonalState.
    pub outcomes: Vec<String>,
    /// The states directly inside this region, in file order.
    pub states: Vec<StateIdx>,
    /// `true` for a parallel region (see above).
    pub parallel: bool,
}

#[derive(Debug, Clone, PartialEq)]
pub struct State {
    /// Name, unique within its region (the TOML key).
    pub name: String,
    /// Display name; defaults to the name.
    pub label: String,
    /// The container this state is in (`None` at the top level).
    pub parent: Option<StateIdx>,
    pub body: StateBody,
    /// Transitions in file order: guards first (checked before the skill runs),
    /// then outcome transitions.
    pub transitions: Vec<Transition>,
    /// The SCXML pseudo-state this state stands for (`None` for an ordinary
    /// state); such a state has no skill and is drawn and exported as what it is.
    pub pseudo: Option<Pseudo>,
    pub span: Option<Span>,
}

/// SCXML pseudo-states modelled as states of their region (W3C SCXML 3.10).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pseudo {
    /// `<history type="shallow">`: re-enters the region's last active child.
    ShallowHistory,
    /// `<history type="deep">`: re-enters the last active descendants.
    DeepHistory,
}

#[derive(Debug, Clone, PartialEq)]
pub enum StateBody {
    /// A state bound to a skill (an action or a condition); `None` when the file
    /// gives no binding (analysis only).
    Task(Option<SkillCall>),
    /// A decision state such as the paper's SELECTOR: runs no skill, only checks
    /// its guards in the order written.
    Decision,
    /// A container (HFSM only) holding its own states.
    Container(Region),
}

#[derive(Debug, Clone, PartialEq)]
pub struct Transition {
    pub trigger: Trigger,
    pub target: Target,
    pub span: Option<Span>,
}

impl Transition {
    /// The transition taken when the source state's skill returns `o`.
    pub fn on_outcome(o: &str, target: Target) -> Self {
        Transition {
            trigger: Trigger::Outcome(o.to_string()),
            target,
            span: None,
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub enum Trigger {
    /// Fires when the state's skill (or container) returns this outcome.
    Outcome(String),
    /// Fires when the guard holds, checked before the state's skill runs.
    Guard(Guard),
}

impl Trigger {
    /// Short text for diagrams and edit scripts.
    pub fn label(&self) -> String {
        match self {
            Trigger::Outcome(o) => o.clone(),
            Trigger::Guard(g) => g.label.clone(),
        }
    }
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    /// A state: a sibling (same region) in TOML files; SCXML transitions may
    /// also target a state of another region.
    State(StateIdx),
    /// One of the enclosing region's outcomes (of a region's `initial`: one
    /// of that region's own).
    Outcome(String),
    /// An outcome of a region further out than the source's own: of the
    /// region of container `owner`, or of the machine's top region when
    /// `owner` is `None` (SCXML: a nested state's transition to a final
    /// state of an enclosing region, as every W3C test's `pass` and `fail`).
    /// Taking it leaves every container between the source and that region.
    OuterOutcome {
        owner: Option<StateIdx>,
        outcome: String,
    },
}

/// Longest key made of a path of names (see [`StateMachine::keys`]).
pub const MAX_PATH_KEY_BYTES: usize = 256;

/// The `initial` of a region a reader has still to set.
pub const UNSET: Target = Target::State(usize::MAX);

impl Region {
    /// A region with `outcomes` whose states and initial state a reader has
    /// still to set (`initial` is [`UNSET`] until then).
    pub fn unset(outcomes: Vec<String>) -> Region {
        Region {
            initial: UNSET,
            outcomes,
            states: vec![],
            parallel: false,
        }
    }

    /// A sequential region starting at state `initial`.
    pub fn at(initial: StateIdx, outcomes: Vec<String>, states: Vec<StateIdx>) -> Region {
        Region {
            initial: Target::State(initial),
            outcomes,
            states,
            parallel: false,
        }
    }

    /// Is `initial` still to be set?
    pub fn is_unset(&self) -> bool {
        self.initial == UNSET
    }

    /// The initial state, `None` when the region starts in an outcome.
    pub fn initial_state(&self) -> Option<StateIdx> {
        match self.initial {
            Target::State(s) if s != usize::MAX => Some(s),
            _ => None,
        }
    }

    /// The states entered when the region is entered at its default: every
    /// state of a parallel region but history pseudo-states, else the
    /// initial state (none when the region starts in an outcome).
    pub fn entered(&self, states: &[State]) -> Vec<StateIdx> {
        if self.parallel {
            self.states
                .iter()
                .copied()
                .filter(|&s| states.get(s).is_some_and(|st| st.pseudo.is_none()))
                .collect()
        } else {
            self.initial_state().into_iter().collect()
        }
    }
}

impl StateMachine {
    /// A flat machine with nothing in it yet, for a reader to fill.
    pub fn unset() -> StateMachine {
        StateMachine {
            hierarchical: false,
            top: Region::unset(vec![]),
            states: Vec::new(),
        }
    }

    /// The region a state is in.
    pub fn region_of(&self, s: StateIdx) -> &Region {
        match self.states[s].parent {
            None => &self.top,
            Some(p) => match &self.states[p].body {
                StateBody::Container(r) => r,
                _ => unreachable!("parent of a state is always a container"),
            },
        }
    }

    /// Each state's identity for `named` GED, edit scripts and diagrams
    /// (SPEC §3): its name where that name is unique in the whole machine,
    /// else its parent's key, `/`, and its name — the state's position under
    /// its nearest uniquely named ancestor (the full path when there is none).
    /// A BT converted to an HFSM keeps its node ids as keys, so wrapping a
    /// subtree in a new container changes only what was really edited.
    /// Keys are unique: should the rule ever give two states one key (a name
    /// containing `/`), those states fall back to their full paths, numbered
    /// by state index if even those clash. A key that would be longer than
    /// [`MAX_PATH_KEY_BYTES`] (a repeated name deep in the hierarchy) is the
    /// name and the state's index instead (`name#i`), so that keys take
    /// memory linear in the machine, whatever its depth.
    pub fn keys(&self) -> Vec<String> {
        use std::collections::HashMap;
        let n = self.states.len();
        let mut uses: HashMap<&str, usize> = HashMap::with_capacity(n);
        for s in &self.states {
            *uses.entry(s.name.as_str()).or_default() += 1;
        }
        for o in &self.top.outcomes {
            *uses.entry(o.as_str()).or_default() += 1;
        }
        let mut key: Vec<Option<String>> = vec![None; n];
        // Length of each state's path (without building it).
        let mut path_len: Vec<usize> = vec![0; n];
        for c in self.parents_first() {
            let name = &self.states[c].name;
            path_len[c] = self.states[c]
                .parent
                .map_or(name.len(), |p| path_len[p] + 1 + name.len());
            key[c] = Some(match self.states[c].parent {
                Some(p) if uses[name.as_str()] > 1 => {
                    let pk = key[p].as_deref().unwrap_or_default();
                    if pk.len() + 1 + name.len() > MAX_PATH_KEY_BYTES {
                        format!("{name}#{c}")
                    } else {
                        format!("{pk}/{name}")
                    }
                }
                _ => name.clone(),
            });
        }
        let mut key: Vec<String> = key.into_iter().map(Option::unwrap_or_default).collect();
        let mut seen: HashMap<&str, usize> = HashMap::with_capacity(n);
        for k in key.iter().chain(&self.top.outcomes) {
            *seen.entry(k.as_str()).or_default() += 1;
        }
        let clash: Vec<StateIdx> = (0..n).filter(|&i| seen[key[i].as_str()] > 1).collect();
        for &i in &clash {
            key[i] = if path_len[i] > MAX_PATH_KEY_BYTES {
                format!("{}#{i}", self.states[i].name)
            } else {
                self.path(i)
            };
        }
        // A path can still equal a literal name with `/` in it: number those.
        let mut seen: HashMap<String, usize> = HashMap::with_capacity(n);
        for k in key.iter().chain(&self.top.outcomes) {
            *seen.entry(k.clone()).or_default() += 1;
        }
        for i in clash {
            if seen[&key[i]] > 1 {
                key[i] = format!("{}#{i}", key[i]);
            }
        }
        key
    }

    /// Every state once, each container before the states it holds (breadth
    /// first from the top region; no recursion, whatever the nesting depth).
    pub fn parents_first(&self) -> Vec<StateIdx> {
        let mut order: Vec<StateIdx> = self.top.states.clone();
        let mut i = 0;
        while let Some(&s) = order.get(i) {
            if let StateBody::Container(r) = &self.states[s].body {
                order.extend_from_slice(&r.states);
            }
            i += 1;
        }
        order
    }

    /// Path of names from the top level, joined with `/` (unique in the machine).
    pub fn path(&self, s: StateIdx) -> String {
        let mut parts = vec![self.states[s].name.as_str()];
        let mut cur = self.states[s].parent;
        while let Some(p) = cur {
            parts.push(self.states[p].name.as_str());
            cur = self.states[p].parent;
        }
        parts.reverse();
        parts.join("/")
    }

    /// Which states the initial state reaches through transitions and
    /// containers' initial states (explicit stack). Entering a state enters
    /// every container around it (an SCXML transition may target a state
    /// inside another container, W3C SCXML 3.13), so those count as reached.
    pub fn reachable(&self) -> Vec<bool> {
        /// How a state is entered.
        #[derive(Clone, Copy, PartialEq)]
        enum Entry {
            /// A transition (or a history's default) targets it: entered at
            /// its default, and so are the containers around it (not at
            /// theirs) and, in a parallel state, its sibling regions.
            Target,
            /// A state inside it is targeted: entered, not at its default.
            Around,
            /// Its container is entered at its default (the region's initial
            /// state, or every region of a parallel state).
            Default,
        }
        let n = self.states.len();
        let mut seen = vec![false; n];
        // Each state's default entry and its way up are walked once.
        let mut defaulted = vec![false; n];
        let mut climbed = vec![false; n];
        // Per parallel state, the first region entered other than at its
        // default, and whether a second one has been (then every region
        // has been entered at its default): each parallel state's regions
        // are pushed at most twice, so the walk stays linear however many
        // regions are entered directly.
        let mut first_way_in: Vec<Option<StateIdx>> = vec![None; n];
        let mut all_defaulted = vec![false; n];
        let mut stack: Vec<(StateIdx, Entry)> = self
            .top
            .entered(&self.states)
            .into_iter()
            .map(|s| (s, Entry::Default))
            .collect();
        while let Some((s, how)) = stack.pop() {
            if s >= n {
                continue;
            }
            seen[s] = true;
            if how != Entry::Around && !defaulted[s] {
                defaulted[s] = true;
                if let StateBody::Container(r) = &self.states[s].body {
                    stack.extend(
                        r.entered(&self.states)
                            .into_iter()
                            .map(|c| (c, Entry::Default)),
                    );
                }
                for t in &self.states[s].transitions {
                    if let Target::State(j) = t.target {
                        stack.push((j, Entry::Target));
                    }
                }
            }
            if how == Entry::Around && !climbed[s] {
                // Its transitions too (entered, it may leave).
                for t in &self.states[s].transitions {
                    if let Target::State(j) = t.target {
                        stack.push((j, Entry::Target));
                    }
                }
            }
            if how != Entry::Default && !climbed[s] {
                climbed[s] = true;
                if let Some(p) = self.states[s].parent {
                    stack.push((p, Entry::Around));
                    // Entering one region of a parallel state enters the
                    // others at their defaults (W3C SCXML 3.13).
                    if let StateBody::Container(r) = &self.states[p].body
                        && r.parallel
                        && !all_defaulted[p]
                    {
                        match first_way_in[p] {
                            None => {
                                first_way_in[p] = Some(s);
                                stack.extend(
                                    r.entered(&self.states)
                                        .into_iter()
                                        .filter(|&c| c != s)
                                        .map(|c| (c, Entry::Default)),
                                );
                            }
                            Some(first) if first != s => {
                                all_defaulted[p] = true;
                                stack.push((first, Entry::Default));
                            }
                            Some(_) => {}
                        }
                    }
                }
            }
        }
        seen
    }

    /// Does the machine hold a parallel region?
    pub fn has_parallel(&self) -> bool {
        self.top.parallel
            || self
                .states
                .iter()
                .any(|s| matches!(&s.body, StateBody::Container(r) if r.parallel))
    }

    /// Number of states that run an action skill or have no binding
    /// (not decisions, not containers): the paper's M.
    pub fn task_state_count(&self) -> usize {
        self.states
            .iter()
            .filter(|s| matches!(s.body, StateBody::Task(_)))
            .count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(name: &str, parent: Option<StateIdx>, body: StateBody) -> State {
        State {
            name: name.into(),
            label: name.into(),
            parent,
            body,
            transitions: Vec::new(),
            pseudo: None,
            span: None,
        }
    }

    fn region(initial: StateIdx, states: Vec<StateIdx>) -> StateBody {
        StateBody::Container(Region::at(initial, vec!["SUCCESS".into()], states))
    }

    #[test]
    fn keys_are_names_unless_a_name_repeats() {
        // A{Move, Pick}, B{Move, C{Move}}: `Move` repeats, so it is keyed by
        // position under its nearest uniquely named ancestor.
        let states = vec![
            state("A", None, region(1, vec![1, 2])),
            state("Move", Some(0), StateBody::Task(None)),
            state("Pick", Some(0), StateBody::Task(None)),
            state("B", None, region(4, vec![4, 5])),
            state("Move", Some(3), StateBody::Task(None)),
            state("C", Some(3), region(6, vec![6])),
            state("Move", Some(5), StateBody::Task(None)),
        ];
        let m = StateMachine {
            hierarchical: true,
            top: Region::at(0, vec!["SUCCESS".into()], vec![0, 3]),
            states,
        };
        assert_eq!(
            m.keys(),
            ["A", "A/Move", "Pick", "B", "B/Move", "C", "C/Move"]
        );
        assert_eq!(m.path(6), "B/C/Move");
        assert_eq!(m.parents_first(), [0, 3, 1, 2, 4, 5, 6]);
    }

    /// A repeated name 5000 containers deep: keys stay short (linear
    /// memory), unique, and the shallow ones are the paths as before.
    #[test]
    fn deep_repeated_names_give_short_unique_keys() {
        let n = 5000;
        let states: Vec<State> = (0..n)
            .map(|i| {
                let body = if i + 1 < n {
                    region(i + 1, vec![i + 1])
                } else {
                    StateBody::Task(None)
                };
                state("s", i.checked_sub(1), body)
            })
            .collect();
        let m = StateMachine {
            hierarchical: true,
            top: Region::at(0, vec!["SUCCESS".into()], vec![0]),
            states,
        };
        let k = m.keys();
        assert_eq!(&k[..3], ["s", "s/s", "s/s/s"]);
        let total: usize = k.iter().map(String::len).sum();
        assert!(
            total < n * (MAX_PATH_KEY_BYTES + 8),
            "{total} bytes of keys"
        );
        assert!(k.iter().all(|x| x.len() <= MAX_PATH_KEY_BYTES));
        let distinct: std::collections::HashSet<&String> = k.iter().collect();
        assert_eq!(distinct.len(), n);
    }

    #[test]
    fn keys_fall_back_to_paths_on_a_clash() {
        // A state literally named `A/Move` would clash with A's `Move`.
        let states = vec![
            state("A", None, region(1, vec![1])),
            state("Move", Some(0), StateBody::Task(None)),
            state("A/Move", None, StateBody::Task(None)),
            state("Move", None, StateBody::Task(None)),
        ];
        let m = StateMachine {
            hierarchical: true,
            top: Region::at(0, vec![], vec![0, 2, 3]),
            states,
        };
        let k = m.keys();
        let unique: std::collections::BTreeSet<_> = k.iter().collect();
        assert_eq!(unique.len(), k.len(), "{k:?}");
    }

    /// A parallel state with 50,000 regions, each entered directly by a
    /// transition: every region is reached, and the walk stays linear (each
    /// parallel state's regions are pushed at most twice; pushing them once
    /// per region entered made 2.5 billion entries).
    #[test]
    fn many_regions_entered_directly_stay_linear() {
        let n = 50_000;
        let mut states = vec![
            state("go", None, StateBody::Task(None)),
            state(
                "p",
                None,
                StateBody::Container(Region {
                    parallel: true,
                    ..Region::at(2, vec![], (2..n + 2).collect())
                }),
            ),
        ];
        states.extend((0..n).map(|i| state(&format!("r{i}"), Some(1), StateBody::Task(None))));
        states[0].transitions = (2..n + 2)
            .map(|j| Transition {
                trigger: Trigger::Outcome("SUCCESS".into()),
                target: Target::State(j),
                span: None,
            })
            .collect();
        let m = StateMachine {
            hierarchical: true,
            top: Region::at(0, vec![], vec![0, 1]),
            states,
        };
        let t = std::time::Instant::now();
        assert!(m.reachable().iter().all(|&r| r));
        assert!(
            t.elapsed() < std::time::Duration::from_secs(20),
            "{:?}",
            t.elapsed()
        );
    }
}
