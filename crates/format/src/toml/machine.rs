//! Reading a TOML FSM or HFSM: states, containers, outcomes, guards and
//! transitions, and the unreachable-state warnings.

use super::*;

impl Loader {
    #[expect(clippy::too_many_lines, reason = "to be split: issue 28")]
    pub(super) fn machine(
        &mut self,
        cx: &Ctx<'_>,
        doc: &DeTable<'_>,
        whole: Range<usize>,
        hierarchical: bool,
    ) -> Option<StateMachine> {
        let mut m = StateMachine {
            hierarchical,
            top: Region::at(0, vec![], vec![]),
            states: Vec::new(),
        };
        // Regions are read breadth-first with an explicit queue (no recursion).
        struct Pending<'t, 'i> {
            table: &'t DeTable<'i>,
            span: Range<usize>,
            container: Option<usize>,
        }
        let mut queue = vec![Pending {
            table: doc,
            span: whole,
            container: None,
        }];
        let mut ok = true;
        // (state, transitions to resolve)
        type RawTr = (Trigger, String, Range<usize>);
        let mut raw_trs: Vec<Vec<RawTr>> = Vec::new();
        // Per state (as `raw_trs`): whether it names a skill at all (a state
        // whose skill is misspelled is not a state without one).
        let mut names_skill: Vec<bool> = Vec::new();
        let mut qi = 0;
        while qi < queue.len() {
            let Pending {
                table,
                span,
                container,
            } = std::mem::replace(
                &mut queue[qi],
                Pending {
                    table: doc,
                    span: 0..0,
                    container: None,
                },
            );
            qi += 1;
            let owner =
                container.map_or_else(|| "the machine".to_string(), |c| format!("`{}`", m.path(c)));
            // A parallel state completes when its regions have: SCXML's
            // has no outcomes (`outcomes` may be left out), yasmin's
            // OrthogonalState those its outcome map gives.
            let is_parallel = container.is_some()
                && table.get("parallel").and_then(|v| v.get_ref().as_bool()) == Some(true);
            let outcomes = match table.get("outcomes") {
                None if is_parallel => vec![],
                _ => self.outcomes(cx, table, &span, &owner),
            };
            let Some(states_v) = table.get("states") else {
                self.err(
                    cx,
                    span.start..span.start,
                    format!("{owner} has no `states`"),
                )
                .hint = Some("add `[states]` (or `[states.NAME]` tables)".into());
                ok = false;
                continue;
            };
            let DeValue::Table(states) = states_v.get_ref() else {
                self.err(
                    cx,
                    states_v.span(),
                    format!(
                        "`states` must be a table, found {}",
                        type_name(states_v.get_ref())
                    ),
                );
                ok = false;
                continue;
            };
            let mut region = Region::unset(outcomes.clone());
            let mut local: Vec<(String, usize, Range<usize>)> = Vec::new();
            for (k, v) in states.iter() {
                let name = k.get_ref().to_string();
                if outcomes.contains(&name) {
                    self.err(
                        cx,
                        k.span(),
                        format!("state `{name}` has the name of an outcome of {owner}"),
                    )
                    .hint = Some("rename the state or the outcome".into());
                    ok = false;
                }
                if self.node_budget == 0 {
                    self.err(
                        cx,
                        k.span(),
                        format!("more than {} states", self.limits.max_nodes),
                    );
                    return None;
                }
                self.node_budget -= 1;
                let idx = m.states.len();
                let DeValue::Table(st) = v.get_ref() else {
                    self.err(
                        cx,
                        v.span(),
                        format!(
                            "state `{name}` must be a table, found {}",
                            type_name(v.get_ref())
                        ),
                    )
                    .hint = Some(format!(
                        "write `[states.\"{name}\"]` with `skill = ...` and `on = {{ SUCCESS = \"...\" }}`"
                    ));
                    ok = false;
                    continue;
                };
                let is_container = st.contains_key("states");
                let allowed: &[&str] = if is_container {
                    &[
                        "label", "initial", "outcomes", "states", "on", "guards", "parallel",
                    ]
                } else {
                    &[
                        "label", "skill", "args", "decision", "history", "on", "guards",
                    ]
                };
                let before = self.problems();
                self.check_keys(cx, st, allowed, &format!("field of state `{name}`"));
                if self.problems() > before {
                    ok = false;
                }
                let label = self
                    .opt_str(cx, st, "label")
                    .unwrap_or_else(|| name.clone());
                let decision = match st.get("decision") {
                    None => false,
                    Some(d) => match d.get_ref().as_bool() {
                        Some(b) => b,
                        None => {
                            self.err(cx, d.span(), "`decision` must be `true` or `false`");
                            false
                        }
                    },
                };
                let pseudo = match st.get("history") {
                    None => None,
                    Some(h) => match h.get_ref().as_str() {
                        Some("shallow") => Some(btfsm_model::Pseudo::ShallowHistory),
                        Some("deep") => Some(btfsm_model::Pseudo::DeepHistory),
                        _ => {
                            self.err(cx, h.span(), "`history` must be \"shallow\" or \"deep\"")
                                .hint = Some(
                                "an SCXML history pseudo-state; it also needs `decision = true`"
                                    .into(),
                            );
                            ok = false;
                            None
                        }
                    },
                };
                if pseudo.is_some() && !decision {
                    self.err(
                        cx,
                        k.span(),
                        format!("history state `{name}` must be a decision state"),
                    )
                    .hint = Some("add `decision = true`: a history state runs no skill".into());
                    ok = false;
                }
                let body = if is_container {
                    if !hierarchical {
                        self.err(
                            cx,
                            k.span(),
                            format!(
                                "state `{name}` holds `states`, but only an `hfsm` has containers"
                            ),
                        )
                        .hint = Some("write `kind = \"hfsm\"` at the top of the file".into());
                        ok = false;
                    }
                    queue.push(Pending {
                        table: st,
                        span: v.span(),
                        container: Some(idx),
                    });
                    StateBody::Container(Region::unset(vec![]))
                } else if decision {
                    if st.contains_key("skill") {
                        self.err(
                            cx,
                            k.span(),
                            format!("decision state `{name}` cannot run a skill"),
                        )
                        .hint = Some("remove `skill`, or `decision = true`".into());
                        ok = false;
                    }
                    StateBody::Decision
                } else {
                    let call = self.skill_call(cx, st, &format!("state `{name}`"), None);
                    if st.contains_key("skill") && call.is_none() {
                        ok = false;
                    }
                    StateBody::Task(call)
                };
                // Transitions: guards (in order), then outcome transitions.
                let mut trs: Vec<RawTr> = Vec::new();
                if let Some(gv) = st.get("guards") {
                    match gv.get_ref() {
                        DeValue::Array(a) => {
                            for g in a.iter() {
                                match self.guard(cx, g, &name) {
                                    Some(t) => trs.push(t),
                                    None => ok = false,
                                }
                            }
                        }
                        other => {
                            self.err(
                                cx,
                                gv.span(),
                                format!(
                                    "`guards` of state `{name}` must be an array, found {}",
                                    type_name(other)
                                ),
                            )
                            .hint = Some(
                                "write `guards = [{ unless = \"Battery-Level\", args = { min = 20 }, to = \"Recharge\" }]`"
                                    .into(),
                            );
                            ok = false;
                        }
                    }
                }
                if let Some(ov) = st.get("on") {
                    match ov.get_ref() {
                        DeValue::Table(ot) => {
                            for (ok_key, tv) in ot.iter() {
                                match tv.get_ref().as_str() {
                                    Some(target) => trs.push((
                                        Trigger::Outcome(ok_key.get_ref().to_string()),
                                        target.to_string(),
                                        tv.span(),
                                    )),
                                    None => {
                                        self.err(
                                            cx,
                                            tv.span(),
                                            format!(
                                                "target of `{}` in state `{name}` must be a state or outcome name, found {}",
                                                ok_key.get_ref(),
                                                type_name(tv.get_ref())
                                            ),
                                        );
                                        ok = false;
                                    }
                                }
                            }
                        }
                        other => {
                            self.err(
                                cx,
                                ov.span(),
                                format!(
                                    "`on` of state `{name}` must be a table, found {}",
                                    type_name(other)
                                ),
                            )
                            .hint = Some(
                                "write `on = { SUCCESS = \"Next\", FAILURE = \"SELECTOR\" }`"
                                    .into(),
                            );
                            ok = false;
                        }
                    }
                }
                // Outcome keys valid for this kind of state (container outcomes
                // are checked after the container's region is read).
                m.states.push(State {
                    name: name.clone(),
                    label,
                    parent: container,
                    body,
                    transitions: Vec::new(),
                    pseudo,
                    span: Some(k.span()),
                });
                raw_trs.push(trs);
                names_skill.push(st.contains_key("skill"));
                region.states.push(idx);
                local.push((name, idx, k.span()));
            }
            // A parallel region (SCXML `<parallel>`): every state runs at
            // once; no `initial`.
            match container.and(table.get("parallel")) {
                None => {}
                Some(pv) => match pv.get_ref().as_bool() {
                    Some(b) => region.parallel = b,
                    None => {
                        self.err(cx, pv.span(), "`parallel` must be `true` or `false`");
                        ok = false;
                    }
                },
            }
            let starts_in_outcome = table
                .get("initial")
                .and_then(|iv| iv.get_ref().as_str())
                .is_some_and(|s| outcomes.iter().any(|o| o == s));
            if local.is_empty() && !starts_in_outcome {
                self.err(cx, states_v.span(), format!("{owner} has no states"));
                ok = false;
            }
            // Initial state.
            match table.get("initial") {
                None if region.parallel => {
                    if let Some((_, idx, _)) = local.first() {
                        region.initial = Target::State(*idx);
                    }
                }
                Some(iv) if region.parallel => {
                    self.err(
                        cx,
                        iv.span(),
                        format!("{owner} is parallel: all its states start, it has no `initial`"),
                    )
                    .hint = Some("remove `initial`, or `parallel = true`".into());
                    ok = false;
                }
                None => {
                    let h = local
                        .first()
                        .map(|(n, _, _)| format!("add `initial = \"{n}\"`"))
                        .unwrap_or_else(|| "add `initial = \"STATE\"`".into());
                    let at = match container {
                        Some(c) => m.states[c].span.clone().unwrap_or(span.clone()),
                        None => span.start..span.start,
                    };
                    self.err(cx, at, format!("missing initial state of {owner}"))
                        .hint = Some(h);
                    ok = false;
                }
                Some(iv) => match iv.get_ref().as_str() {
                    Some(s) => match local.iter().find(|(n, _, _)| n == s) {
                        Some((_, idx, _)) => region.initial = Target::State(*idx),
                        None if starts_in_outcome => region.initial = Target::Outcome(s.into()),
                        None => {
                            let h = self.suggest(s, local.iter().map(|(n, _, _)| n.as_str()));
                            self.err(
                                cx,
                                iv.span(),
                                format!("unknown initial state `{s}` of {owner}"),
                            )
                            .hint = Some(h);
                            ok = false;
                        }
                    },
                    None => {
                        self.err(cx, iv.span(), "`initial` must be a state name (a string)");
                        ok = false;
                    }
                },
            }
            match container {
                None => m.top = region,
                Some(c) => m.states[c].body = StateBody::Container(region),
            }
        }
        // Resolve transitions now that every region is known (even when other
        // problems were found, so that all of them are reported at once).
        let by_name: HashMap<(Option<usize>, &str), usize> = m
            .states
            .iter()
            .enumerate()
            .map(|(i, st)| ((st.parent, st.name.as_str()), i))
            .collect();
        // Targets in other regions (SCXML imports) are written as paths.
        let by_path: HashMap<String, usize> = (0..m.states.len()).map(|i| (m.path(i), i)).collect();
        let mut resolved_all: Vec<Vec<Transition>> = vec![Vec::new(); m.states.len()];
        for (si, trs) in raw_trs.into_iter().enumerate() {
            let region = m.region_of(si);
            let parent = m.states[si].parent;
            let sname = m.states[si].name.clone();
            let valid_outcomes: Vec<String> = match &m.states[si].body {
                StateBody::Container(r) => r.outcomes.clone(),
                StateBody::Decision => vec!["RUNNING".into()],
                StateBody::Task(_) => TASK_OUTCOMES.iter().map(|s| s.to_string()).collect(),
            };
            // A state without a skill (analysis only) returns whatever its
            // code does, as yasmin and SMACH states do; a near miss of
            // SUCCESS / FAILURE / RUNNING is worth a warning (yasmin's own
            // `SUCCEED` is one).
            let free = matches!(m.states[si].body, StateBody::Task(None))
                && !names_skill.get(si).copied().unwrap_or(true);
            for (trigger, target, span) in trs {
                if free
                    && let Trigger::Outcome(o) = &trigger
                    && !valid_outcomes.contains(o)
                {
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
                } else if let Trigger::Outcome(o) = &trigger
                    && !valid_outcomes.contains(o)
                {
                    let what = match &m.states[si].body {
                        StateBody::Container(_) => "container",
                        StateBody::Decision => "decision state",
                        StateBody::Task(_) => "state",
                    };
                    let h = self.suggest(o, valid_outcomes.iter().map(String::as_str));
                    // Point at the key: the span we have is the value's; say so by message.
                    self.err(
                        cx,
                        span.clone(),
                        format!("{what} `{sname}` cannot return `{o}`"),
                    )
                    .hint = Some(h);
                    ok = false;
                    continue;
                }
                let resolved = if let Some(&t) = by_name.get(&(parent, target.as_str())) {
                    Target::State(t)
                } else if region.outcomes.contains(&target) {
                    Target::Outcome(target)
                } else if let Some(&t) = by_path.get(&target) {
                    Target::State(t)
                } else if let Some(o) = outer_outcome(&m, &by_path, si, &target) {
                    o
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
                        span,
                        format!("unknown state `{target}` in transition of `{sname}`"),
                    )
                    .hint = Some(h);
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
        drop(by_name);
        drop(by_path);
        for (st, trs) in m.states.iter_mut().zip(resolved_all) {
            st.transitions = trs;
        }
        if !ok {
            return None;
        }
        if !m.top.is_unset() {
            self.unreachable_states(cx, &m);
        }
        Some(m)
    }

    pub(super) fn outcomes(
        &mut self,
        cx: &Ctx<'_>,
        table: &DeTable<'_>,
        span: &Range<usize>,
        owner: &str,
    ) -> Vec<String> {
        let Some(ov) = table.get("outcomes") else {
            self.err(
                cx,
                span.start..span.start,
                format!("{owner} has no `outcomes`"),
            )
            .hint = Some("add `outcomes = [\"SUCCESS\", \"FAILURE\"]`".into());
            return vec![];
        };
        let DeValue::Array(a) = ov.get_ref() else {
            self.err(
                cx,
                ov.span(),
                format!(
                    "`outcomes` must be an array of names, found {}",
                    type_name(ov.get_ref())
                ),
            );
            return vec![];
        };
        let mut out: Vec<String> = Vec::new();
        for o in a.iter() {
            match o.get_ref().as_str() {
                Some(s) if out.iter().any(|x| x == s) => {
                    self.err(cx, o.span(), format!("duplicate outcome `{s}`"));
                }
                Some(s) => out.push(s.to_string()),
                None => {
                    self.err(cx, o.span(), "outcome names must be strings");
                }
            }
        }
        // `outcomes = []` is a machine that never terminates (as SCXML machines
        // without `<final>` states are).
        out
    }

    pub(super) fn guard(
        &mut self,
        cx: &Ctx<'_>,
        g: &Val<'_>,
        state: &str,
    ) -> Option<(Trigger, String, Range<usize>)> {
        let DeValue::Table(t) = g.get_ref() else {
            self.err(
                cx,
                g.span(),
                format!(
                    "a guard of state `{state}` must be a table, found {}",
                    type_name(g.get_ref())
                ),
            );
            return None;
        };
        let before = self.problems();
        self.check_keys(
            cx,
            t,
            &["if", "unless", "args", "all", "to", "label"],
            &format!("field of a guard of `{state}`"),
        );
        if self.problems() > before {
            return None;
        }
        let owner = format!("guard of `{state}`");
        let all = match t.get("all") {
            Some(av) => {
                if t.contains_key("if") || t.contains_key("unless") {
                    self.err(
                        cx,
                        av.span(),
                        format!("a {owner} has both `all` and `if`/`unless`"),
                    )
                    .hint = Some("put every condition inside `all`".into());
                    return None;
                }
                let DeValue::Array(items) = av.get_ref() else {
                    self.err(
                        cx,
                        av.span(),
                        format!("`all` of a {owner} must be an array of conditions"),
                    );
                    return None;
                };
                let mut terms = Vec::new();
                for item in items.iter() {
                    let DeValue::Table(it) = item.get_ref() else {
                        self.err(cx, item.span(), "a condition in `all` must be a table")
                            .hint = Some(
                            "write `{ if = \"In-Hand\", args = { object = \"cube2\" } }`".into(),
                        );
                        return None;
                    };
                    let before = self.problems();
                    self.check_keys(
                        cx,
                        it,
                        &["if", "unless", "args"],
                        &format!("field of a condition of a {owner}"),
                    );
                    if self.problems() > before {
                        return None;
                    }
                    terms.push(self.guard_term(cx, it, item.span(), &owner)?);
                }
                if terms.is_empty() {
                    self.err(cx, av.span(), format!("`all` of a {owner} is empty"));
                    return None;
                }
                terms
            }
            // A guard that names no condition of the skill library, only its
            // `label` (an SCXML event or condition, kept as text).
            None if !t.contains_key("if")
                && !t.contains_key("unless")
                && t.contains_key("label") =>
            {
                vec![]
            }
            None => vec![self.guard_term(cx, t, g.span(), &owner)?],
        };
        let Some(to_v) = t.get("to") else {
            self.err(
                cx,
                g.span(),
                format!("a guard of state `{state}` needs `to`"),
            )
            .hint = Some("write `to = \"TARGET STATE\"`".into());
            return None;
        };
        let Some(to) = to_v.get_ref().as_str() else {
            self.err(cx, to_v.span(), "`to` must be a state or outcome name");
            return None;
        };
        let label = self.opt_str(cx, t, "label").unwrap_or_else(|| {
            all.iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(" and ")
        });
        Some((
            Trigger::Guard(Guard { all, label }),
            to.to_string(),
            to_v.span(),
        ))
    }

    /// Reads one `if`/`unless` condition with its `args`.
    pub(super) fn guard_term(
        &mut self,
        cx: &Ctx<'_>,
        t: &DeTable<'_>,
        span: Range<usize>,
        owner: &str,
    ) -> Option<GuardTerm> {
        let (negate, cond_v) = match (t.get("if"), t.get("unless")) {
            (Some(c), None) => (false, c),
            (None, Some(c)) => (true, c),
            _ => {
                self.err(cx, span, format!("a {owner} needs exactly one of `if` or `unless`"))
                    .hint = Some(
                    "write `{ unless = \"Battery-Level\", args = { min = 20 }, to = \"Recharge\" }`".into(),
                );
                return None;
            }
        };
        let Some(cond_name) = cond_v.get_ref().as_str() else {
            self.err(
                cx,
                cond_v.span(),
                "the guard's condition must be a skill name",
            );
            return None;
        };
        // Reuse the skill reader on a view where `skill` is the condition.
        let mut view = DeTable::new();
        view.insert(
            Spanned::new(0..0, std::borrow::Cow::Borrowed("skill")),
            Spanned::new(
                cond_v.span(),
                DeValue::String(std::borrow::Cow::Owned(cond_name.to_string())),
            ),
        );
        if let Some((k, a)) = t.get_key_value("args") {
            view.insert(k.clone(), a.clone());
        }
        let condition = self.skill_call(cx, &view, owner, Some(SkillKind::Condition))?;
        Some(GuardTerm { condition, negate })
    }

    /// Warns about states that no transition can reach.
    pub(super) fn unreachable_states(&mut self, cx: &Ctx<'_>, m: &StateMachine) {
        let seen = m.reachable();
        for (i, s) in m.states.iter().enumerate() {
            if !seen[i] {
                self.warn(
                    cx,
                    s.span.clone().unwrap_or(0..0),
                    format!(
                        "state `{}` is unreachable from the initial state",
                        m.path(i)
                    ),
                );
                self.hint_last("add a transition to it, or remove it");
            }
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
