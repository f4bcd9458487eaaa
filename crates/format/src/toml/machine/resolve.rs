//! Resolving a machine's transitions once every region is read: targets
//! by name in the region, by path, or outcomes of enclosing regions, and
//! the outcomes each state can return.

use super::*;

/// Where transition targets are looked up: by name among the states of a
/// region, and by path (targets in other regions, SCXML imports).
struct Targets<'m> {
    by_name: HashMap<(Option<usize>, &'m str), usize>,
    by_path: HashMap<String, usize>,
}

/// The state whose transitions are being resolved.
struct Source<'m> {
    si: usize,
    name: &'m str,
    /// The outcomes it can return.
    valid_outcomes: Vec<String>,
    /// It runs no skill (analysis only), so it may return any outcome.
    free: bool,
}

impl Loader {
    /// Resolves the transitions as written of every state to states and
    /// outcomes, checking the outcomes each state can return; `false` when
    /// one is wrong.
    pub(super) fn resolve_transitions(
        &mut self,
        cx: &Ctx<'_>,
        m: &mut StateMachine,
        raw_trs: Vec<Vec<RawTr>>,
        names_skill: &[bool],
    ) -> bool {
        let mut ok = true;
        let targets = Targets {
            by_name: m
                .states
                .iter()
                .enumerate()
                .map(|(i, st)| ((st.parent, st.name.as_str()), i))
                .collect(),
            // Targets in other regions (SCXML imports) are written as paths.
            by_path: (0..m.states.len()).map(|i| (m.path(i), i)).collect(),
        };
        let mut resolved_all: Vec<Vec<Transition>> = vec![Vec::new(); m.states.len()];
        for (si, trs) in raw_trs.into_iter().enumerate() {
            let src = Source {
                si,
                name: &m.states[si].name,
                valid_outcomes: match &m.states[si].body {
                    StateBody::Container(r) => r.outcomes.clone(),
                    StateBody::Decision => vec!["RUNNING".into()],
                    StateBody::Task(_) => TASK_OUTCOMES.iter().map(|s| s.to_string()).collect(),
                },
                // A state without a skill (analysis only) returns whatever its
                // code does, as yasmin and SMACH states do; a near miss of
                // SUCCESS / FAILURE / RUNNING is worth a warning (yasmin's own
                // `SUCCEED` is one).
                free: matches!(m.states[si].body, StateBody::Task(None))
                    && !names_skill.get(si).copied().unwrap_or(true),
            };
            for (trigger, target, span) in trs {
                if !self.returnable(cx, m, &src, &trigger, &span) {
                    ok = false;
                    continue;
                }
                let Some(resolved) = self.resolve_target(cx, m, &targets, &src, target, &span)
                else {
                    ok = false;
                    continue;
                };
                resolved_all[si].push(Transition {
                    trigger,
                    target: resolved,
                    span: Some(span),
                });
            }
        }
        drop(targets);
        for (st, trs) in m.states.iter_mut().zip(resolved_all) {
            st.transitions = trs;
        }
        ok
    }

    /// Whether the source state can return the outcome a transition is on:
    /// an error when it cannot (`false`), a warning for a near miss of a
    /// state without a skill.
    fn returnable(
        &mut self,
        cx: &Ctx<'_>,
        m: &StateMachine,
        src: &Source<'_>,
        trigger: &Trigger,
        span: &Range<usize>,
    ) -> bool {
        let Trigger::Outcome(o) = trigger else {
            return true;
        };
        if src.valid_outcomes.contains(o) {
            return true;
        }
        let sname = src.name;
        if src.free {
            let h = btfsm_core::diagnostic::suggest(o, TASK_OUTCOMES.iter().copied());
            if h.starts_with("did you mean") {
                self.warn(
                    cx,
                    span.clone(),
                    format!(
                        "state `{sname}` returns `{o}`: {h} (a state without a skill may return any outcome)"
                    ),
                );
            }
            return true;
        }
        let what = match &m.states[src.si].body {
            StateBody::Container(_) => "container",
            StateBody::Decision => "decision state",
            StateBody::Task(_) => "state",
        };
        let h = self.suggest(o, src.valid_outcomes.iter().map(String::as_str));
        // Point at the key: the span we have is the value's; say so by message.
        self.err(
            cx,
            span.clone(),
            format!("{what} `{sname}` cannot return `{o}`"),
        )
        .hint = Some(h);
        false
    }

    /// The state or outcome a transition of the source state goes to: in
    /// its region, by path, or an outcome of an enclosing region.
    fn resolve_target(
        &mut self,
        cx: &Ctx<'_>,
        m: &StateMachine,
        targets: &Targets<'_>,
        src: &Source<'_>,
        target: String,
        span: &Range<usize>,
    ) -> Option<Target> {
        let region = m.region_of(src.si);
        let parent = m.states[src.si].parent;
        if let Some(&t) = targets.by_name.get(&(parent, target.as_str())) {
            Some(Target::State(t))
        } else if region.outcomes.contains(&target) {
            Some(Target::Outcome(target))
        } else if let Some(&t) = targets.by_path.get(&target) {
            Some(Target::State(t))
        } else if let Some(o) = outer_outcome(m, &targets.by_path, src.si, &target) {
            Some(o)
        } else {
            let cands: Vec<&str> = region
                .states
                .iter()
                .map(|&t| m.states[t].name.as_str())
                .chain(region.outcomes.iter().map(String::as_str))
                .collect();
            let h = self.suggest(&target, cands);
            self.err(
                cx,
                span.clone(),
                format!("unknown state `{target}` in transition of `{}`", src.name),
            )
            .hint = Some(h);
            None
        }
    }
}

/// An outcome of a region enclosing state `si` (SCXML imports: a nested
/// state's transition to a final state further out), written `/OUTCOME` for
/// the machine's own outcomes and `PATH/OUTCOME` for those of the container
/// at `PATH`, an ancestor of `si`.
fn outer_outcome(
    m: &StateMachine,
    by_path: &HashMap<String, usize>,
    si: usize,
    target: &str,
) -> Option<Target> {
    m.states[si].parent?;
    let (path, o) = target.rsplit_once('/')?;
    let owner = if path.is_empty() {
        m.top.outcomes.iter().any(|x| x == o).then_some(None)?
    } else {
        let c = *by_path.get(path)?;
        let StateBody::Container(r) = &m.states[c].body else {
            return None;
        };
        r.outcomes.iter().any(|x| x == o).then_some(Some(c))?
    };
    // The owner must enclose the source (further out than its own region).
    let mut cur = m.states[si].parent;
    let own = cur;
    while let Some(p) = cur {
        if Some(p) == owner && Some(p) != own {
            break;
        }
        cur = m.states[p].parent;
    }
    (owner.is_none() || cur.is_some()).then(|| Target::OuterOutcome {
        owner,
        outcome: o.to_string(),
    })
}
