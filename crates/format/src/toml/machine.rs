//! Reading a TOML FSM or HFSM: states, containers, outcomes, guards and
//! transitions, and the unreachable-state warnings.

mod resolve;

use super::*;

/// A transition as written: its trigger, its target's name and the span of
/// the target (resolved once every region is read).
type RawTr = (Trigger, String, Range<usize>);

/// A state of the region being read: its name, index and key span.
type Local = (String, usize, Range<usize>);

/// A region still to be read: the table holding its `states`, that table's
/// span, and the container it is the region of (`None`: the machine).
struct Pending<'t, 'i> {
    table: &'t DeTable<'i>,
    span: Range<usize>,
    container: Option<usize>,
}

/// The region being read, with the words that name its owner in messages.
struct RegionAt<'t, 'i> {
    table: &'t DeTable<'i>,
    span: Range<usize>,
    container: Option<usize>,
    owner: String,
}

/// A state being read: its name and index, the spans of its key and of
/// its table, and its container.
struct StateAt<'a> {
    name: &'a str,
    idx: usize,
    key: Range<usize>,
    span: Range<usize>,
    container: Option<usize>,
}

/// A machine being read region by region, with what is resolved once every
/// region is known.
struct Reading<'t, 'i> {
    m: StateMachine,
    /// Regions to read, breadth-first (an explicit queue, no recursion).
    queue: Vec<Pending<'t, 'i>>,
    /// Per state, its transitions as written.
    raw_trs: Vec<Vec<RawTr>>,
    /// Per state (as `raw_trs`): whether it names a skill at all (a state
    /// whose skill is misspelled is not a state without one).
    names_skill: Vec<bool>,
    /// No error so far.
    ok: bool,
}

impl Loader {
    /// Reads an FSM (or, `hierarchical`, an HFSM) document, collecting every
    /// problem at once.
    pub(super) fn machine<'t, 'i>(
        &mut self,
        cx: &Ctx<'_>,
        doc: &'t DeTable<'i>,
        whole: Range<usize>,
        hierarchical: bool,
    ) -> Option<StateMachine> {
        let mut rd = Reading {
            m: StateMachine {
                hierarchical,
                top: Region::at(0, vec![], vec![]),
                states: Vec::new(),
            },
            queue: vec![Pending {
                table: doc,
                span: whole,
                container: None,
            }],
            raw_trs: Vec::new(),
            names_skill: Vec::new(),
            ok: true,
        };
        // Regions are read breadth-first with an explicit queue (no recursion).
        let mut qi = 0;
        while qi < rd.queue.len() {
            let pending = std::mem::replace(
                &mut rd.queue[qi],
                Pending {
                    table: doc,
                    span: 0..0,
                    container: None,
                },
            );
            qi += 1;
            self.region(cx, &mut rd, pending)?;
        }
        let Reading {
            mut m,
            raw_trs,
            names_skill,
            ok,
            ..
        } = rd;
        // Resolve transitions now that every region is known (even when other
        // problems were found, so that all of them are reported at once).
        let resolved = self.resolve_transitions(cx, &mut m, raw_trs, &names_skill);
        if !ok || !resolved {
            return None;
        }
        if !m.top.is_unset() {
            self.unreachable_states(cx, &m);
        }
        Some(m)
    }

    /// Reads one region: its outcomes, its states (queueing the regions of
    /// containers), whether it is parallel, and its initial state. `None`
    /// when the node limit is hit.
    fn region<'t, 'i>(
        &mut self,
        cx: &Ctx<'_>,
        rd: &mut Reading<'t, 'i>,
        pending: Pending<'t, 'i>,
    ) -> Option<()> {
        let Pending {
            table,
            span,
            container,
        } = pending;
        let owner = container.map_or_else(
            || "the machine".to_string(),
            |c| format!("`{}`", rd.m.path(c)),
        );
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
            rd.ok = false;
            return Some(());
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
            rd.ok = false;
            return Some(());
        };
        let at = RegionAt {
            table,
            span,
            container,
            owner,
        };
        let mut region = Region::unset(outcomes.clone());
        let local = self.region_states(cx, rd, &at, states, &mut region)?;
        // A parallel region (SCXML `<parallel>`): every state runs at
        // once; no `initial`.
        match container.and(table.get("parallel")) {
            None => {}
            Some(pv) => match pv.get_ref().as_bool() {
                Some(b) => region.parallel = b,
                None => {
                    self.err(cx, pv.span(), "`parallel` must be `true` or `false`");
                    rd.ok = false;
                }
            },
        }
        let starts_in_outcome = table
            .get("initial")
            .and_then(|iv| iv.get_ref().as_str())
            .is_some_and(|s| outcomes.iter().any(|o| o == s));
        if local.is_empty() && !starts_in_outcome {
            self.err(cx, states_v.span(), format!("{} has no states", at.owner));
            rd.ok = false;
        }
        self.region_initial(cx, rd, &at, &local, starts_in_outcome, &mut region);
        match container {
            None => rd.m.top = region,
            Some(c) => rd.m.states[c].body = StateBody::Container(region),
        }
        Some(())
    }

    /// Reads the states of a region, in order, into the machine and the
    /// region; returns them by name. `None` when the node limit is hit.
    fn region_states<'t, 'i>(
        &mut self,
        cx: &Ctx<'_>,
        rd: &mut Reading<'t, 'i>,
        at: &RegionAt<'t, 'i>,
        states: &'t DeTable<'i>,
        region: &mut Region,
    ) -> Option<Vec<Local>> {
        let mut local: Vec<Local> = Vec::new();
        for (k, v) in states.iter() {
            let name = k.get_ref().to_string();
            if region.outcomes.contains(&name) {
                self.err(
                    cx,
                    k.span(),
                    format!("state `{name}` has the name of an outcome of {}", at.owner),
                )
                .hint = Some("rename the state or the outcome".into());
                rd.ok = false;
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
            let idx = rd.m.states.len();
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
                rd.ok = false;
                continue;
            };
            let state_at = StateAt {
                name: &name,
                idx,
                key: k.span(),
                span: v.span(),
                container: at.container,
            };
            self.state(cx, rd, &state_at, st);
            region.states.push(idx);
            local.push((name, idx, k.span()));
        }
        Some(local)
    }

    /// Sets a region's initial state from its `initial` (a parallel
    /// region's is its first state).
    fn region_initial(
        &mut self,
        cx: &Ctx<'_>,
        rd: &mut Reading<'_, '_>,
        at: &RegionAt<'_, '_>,
        local: &[Local],
        starts_in_outcome: bool,
        region: &mut Region,
    ) {
        let owner = &at.owner;
        match at.table.get("initial") {
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
                rd.ok = false;
            }
            None => {
                let h = local
                    .first()
                    .map(|(n, _, _)| format!("add `initial = \"{n}\"`"))
                    .unwrap_or_else(|| "add `initial = \"STATE\"`".into());
                let pos = match at.container {
                    Some(c) => rd.m.states[c].span.clone().unwrap_or(at.span.clone()),
                    None => at.span.start..at.span.start,
                };
                self.err(cx, pos, format!("missing initial state of {owner}"))
                    .hint = Some(h);
                rd.ok = false;
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
                        rd.ok = false;
                    }
                },
                None => {
                    self.err(cx, iv.span(), "`initial` must be a state name (a string)");
                    rd.ok = false;
                }
            },
        }
    }

    /// Reads one state (its fields, body and transitions as written) into
    /// the machine; a container's region is queued.
    fn state<'t, 'i>(
        &mut self,
        cx: &Ctx<'_>,
        rd: &mut Reading<'t, 'i>,
        at: &StateAt<'_>,
        st: &'t DeTable<'i>,
    ) {
        let name = at.name;
        let allowed: &[&str] = if st.contains_key("states") {
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
            rd.ok = false;
        }
        let label = self
            .opt_str(cx, st, "label")
            .unwrap_or_else(|| name.to_string());
        let decision = self.decision(cx, st);
        let pseudo = self.history(cx, st, &mut rd.ok);
        if pseudo.is_some() && !decision {
            self.err(
                cx,
                at.key.clone(),
                format!("history state `{name}` must be a decision state"),
            )
            .hint = Some("add `decision = true`: a history state runs no skill".into());
            rd.ok = false;
        }
        let body = self.state_body(cx, rd, at, st, decision);
        // Transitions: guards (in order), then outcome transitions.
        let mut trs: Vec<RawTr> = Vec::new();
        self.guard_transitions(cx, st, name, &mut trs, &mut rd.ok);
        self.outcome_transitions(cx, st, name, &mut trs, &mut rd.ok);
        // Outcome keys valid for this kind of state (container outcomes
        // are checked after the container's region is read).
        rd.m.states.push(State {
            name: name.to_string(),
            label,
            parent: at.container,
            body,
            transitions: Vec::new(),
            pseudo,
            span: Some(at.key.clone()),
        });
        rd.raw_trs.push(trs);
        rd.names_skill.push(st.contains_key("skill"));
    }

    /// A state's `decision` flag (`false` when absent).
    fn decision(&mut self, cx: &Ctx<'_>, st: &DeTable<'_>) -> bool {
        match st.get("decision") {
            None => false,
            Some(d) => match d.get_ref().as_bool() {
                Some(b) => b,
                None => {
                    self.err(cx, d.span(), "`decision` must be `true` or `false`");
                    false
                }
            },
        }
    }

    /// A state's `history` kind (an SCXML history pseudo-state), if any.
    fn history(
        &mut self,
        cx: &Ctx<'_>,
        st: &DeTable<'_>,
        ok: &mut bool,
    ) -> Option<btfsm_model::Pseudo> {
        match st.get("history") {
            None => None,
            Some(h) => match h.get_ref().as_str() {
                Some("shallow") => Some(btfsm_model::Pseudo::ShallowHistory),
                Some("deep") => Some(btfsm_model::Pseudo::DeepHistory),
                _ => {
                    self.err(cx, h.span(), "`history` must be \"shallow\" or \"deep\"")
                        .hint = Some(
                        "an SCXML history pseudo-state; it also needs `decision = true`".into(),
                    );
                    *ok = false;
                    None
                }
            },
        }
    }

    /// What a state is: a container (its region queued, the body set once
    /// read), a decision state, or a task with its skill call.
    fn state_body<'t, 'i>(
        &mut self,
        cx: &Ctx<'_>,
        rd: &mut Reading<'t, 'i>,
        at: &StateAt<'_>,
        st: &'t DeTable<'i>,
        decision: bool,
    ) -> StateBody {
        let name = at.name;
        if st.contains_key("states") {
            if !rd.m.hierarchical {
                self.err(
                    cx,
                    at.key.clone(),
                    format!("state `{name}` holds `states`, but only an `hfsm` has containers"),
                )
                .hint = Some("write `kind = \"hfsm\"` at the top of the file".into());
                rd.ok = false;
            }
            rd.queue.push(Pending {
                table: st,
                span: at.span.clone(),
                container: Some(at.idx),
            });
            StateBody::Container(Region::unset(vec![]))
        } else if decision {
            if st.contains_key("skill") {
                self.err(
                    cx,
                    at.key.clone(),
                    format!("decision state `{name}` cannot run a skill"),
                )
                .hint = Some("remove `skill`, or `decision = true`".into());
                rd.ok = false;
            }
            StateBody::Decision
        } else {
            let call = self.skill_call(cx, st, &format!("state `{name}`"), None);
            if st.contains_key("skill") && call.is_none() {
                rd.ok = false;
            }
            StateBody::Task(call)
        }
    }

    /// Adds a state's `guards` transitions, in order.
    fn guard_transitions(
        &mut self,
        cx: &Ctx<'_>,
        st: &DeTable<'_>,
        name: &str,
        trs: &mut Vec<RawTr>,
        ok: &mut bool,
    ) {
        let Some(gv) = st.get("guards") else {
            return;
        };
        match gv.get_ref() {
            DeValue::Array(a) => {
                for g in a.iter() {
                    match self.guard(cx, g, name) {
                        Some(t) => trs.push(t),
                        None => *ok = false,
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
                *ok = false;
            }
        }
    }

    /// Adds a state's outcome transitions (its `on` table), in order.
    fn outcome_transitions(
        &mut self,
        cx: &Ctx<'_>,
        st: &DeTable<'_>,
        name: &str,
        trs: &mut Vec<RawTr>,
        ok: &mut bool,
    ) {
        let Some(ov) = st.get("on") else {
            return;
        };
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
                            *ok = false;
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
                .hint = Some("write `on = { SUCCESS = \"Next\", FAILURE = \"SELECTOR\" }`".into());
                *ok = false;
            }
        }
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
