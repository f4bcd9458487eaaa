//! Sequential FSM -> fault-tolerant (reactive) FSM, the paper's sec. IV-B
//! construction (Fig. 2 -> Fig. 4, Fig. 10 -> Fig. 11) as the authors' SMACH
//! code builds it (SPEC §4), and the detection of the two kinds of states
//! Eq. 4 counts: M_s sequential action states and M_fc fully connected ones.
//!
//! The construction:
//! - a decision state `SELECTOR` (reused when the machine has one) with
//!   `RUNNING` -> itself and one guarded arc to every connected state (first:
//!   they have priority), to the outcome the task ends in, and to every
//!   sequential state (latest step of the task first);
//! - every sequential state keeps its `SUCCESS` arc to the next state and
//!   gets `RUNNING` -> itself and `FAILURE` -> `SELECTOR`;
//! - every connected state (Recharge) keeps the arcs other states have to it,
//!   loses its own arcs to the sequential states and gets `RUNNING` -> itself
//!   and `SUCCESS` -> `SELECTOR`.
//!
//! Arcs already present are kept, so the transform of a fault-tolerant FSM is
//! the FSM itself. The `SELECTOR`'s resume guards come from an action
//! domain (`policies/domains/moma.toml` built in, or `convert --domain`):
//! each step's state is the domain action that runs its skill, and the
//! SELECTOR resumes at step k when k's *kernel* holds — the last step's
//! effect regressed through steps k..n, the facts the rest of the task
//! needs (the STRIPS triangle table, [`crate::plan::fsm::kernels`]) — tested
//! latest step first; it finishes when the last step's effect holds. So it
//! resumes correctly whatever a disturbance undid (a cube dropped at the
//! delivery station: not "Place", whose kernel also needs the cube in hand).
//! A connected state is entered on the guard the other states use to reach
//! it, else when its action's effect does not hold. Review the guards of a
//! generated machine: the structure is the paper's.

use crate::model::{
    Guard, GuardTerm, Policy, PolicyBody, State, StateBody, StateMachine, Target, Transition,
    Trigger,
};
use crate::plan::Domain;
use crate::plan::backchain::Step;
use crate::plan::fact::Fact;

const SUCCESS: &str = "SUCCESS";
const FAILURE: &str = "FAILURE";
const RUNNING: &str = "RUNNING";

/// The states Eq. 4 counts, by index, in file order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Detected {
    /// Action states that are not fully connected (M_s).
    pub sequential: Vec<usize>,
    /// Fully connected action states (M_fc), see
    /// [`crate::metrics::counts::fully_connected_states`].
    pub connected: Vec<usize>,
    /// The first top-level decision state (the paper's SELECTOR), if any.
    pub selector: Option<usize>,
}

/// Detects M_s, M_fc and the SELECTOR of a flat FSM.
pub fn detect(m: &StateMachine) -> Detected {
    let connected = crate::metrics::counts::fully_connected_states(m);
    let sequential = m
        .top
        .states
        .iter()
        .copied()
        .filter(|&i| is_action_state(m, i) && !connected.contains(&i))
        .collect();
    let selector = m
        .top
        .states
        .iter()
        .copied()
        .find(|&i| matches!(m.states[i].body, StateBody::Decision));
    Detected {
        sequential,
        connected,
        selector,
    }
}

fn is_action_state(m: &StateMachine, i: usize) -> bool {
    matches!(
        crate::graph::build::state_vertex_type(&m.states[i].body),
        crate::graph::VertexType::State
    )
}

/// Eq. 4: E(M_s, M_fc) = 3(M_s + 1) + M_fc[(M_s + M_fc - 1) + 3], the number
/// of edits that make a sequential FSM with M_s sequential and M_fc fully
/// connected states fault tolerant. Eq. 5 is the same number written with
/// M = M_s + M_fc: 3(M + 1) + M_fc(M - 1).
pub fn effort_formula(m_s: u64, m_fc: u64) -> u64 {
    if m_fc == 0 {
        return 3 * (m_s + 1);
    }
    3 * (m_s + 1) + m_fc * ((m_s + m_fc - 1) + 3)
}

/// Why a machine cannot be made fault tolerant.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FaultTolerantError {
    #[error("the fault-tolerant construction applies to flat FSMs, not to {0}s")]
    NotAnFsm(&'static str),
    #[error(
        "state `{state}` runs {skill}, which no action of domain `{domain}` runs, so the SELECTOR has no condition to resume the task there"
    )]
    NoPostcondition {
        state: String,
        skill: String,
        domain: String,
    },
}

fn has_outcome(s: &State, o: &str) -> bool {
    s.transitions
        .iter()
        .any(|t| matches!(&t.trigger, Trigger::Outcome(x) if x == o))
}

fn goes_to(s: &State, target: &Target) -> bool {
    s.transitions.iter().any(|t| &t.target == target)
}

/// Orders outcome transitions after guards (the model's invariant), stably.
fn guards_first(s: &mut State) {
    s.transitions
        .sort_by_key(|t| matches!(t.trigger, Trigger::Outcome(_)));
}

/// The fault-tolerant version of a policy (see the module documentation).
pub fn fault_tolerant_policy(p: &Policy) -> Result<Policy, Vec<FaultTolerantError>> {
    fault_tolerant_policy_with(p, crate::plan::domain::builtin())
}

/// [`fault_tolerant_policy`] with the skills' preconditions and effects
/// from `domain`.
pub fn fault_tolerant_policy_with(
    p: &Policy,
    domain: &Domain,
) -> Result<Policy, Vec<FaultTolerantError>> {
    let m = match &p.body {
        PolicyBody::Machine(m) if !m.hierarchical => m,
        _ => return Err(vec![FaultTolerantError::NotAnFsm(p.kind().as_str())]),
    };
    Ok(Policy {
        name: format!("{} (fault tolerant)", p.name),
        description: Some(format!(
            "generated by `btfsm convert --to fault-tolerant` from `{}` (the paper's sec. IV-B construction; review the SELECTOR's guards)",
            p.name
        )),
        body: PolicyBody::Machine(fault_tolerant(m, domain)?),
    })
}

/// The fault-tolerant version of a flat FSM (see the module documentation).
pub fn fault_tolerant(
    m: &StateMachine,
    domain: &Domain,
) -> Result<StateMachine, Vec<FaultTolerantError>> {
    if m.hierarchical {
        return Err(vec![FaultTolerantError::NotAnFsm("hfsm")]);
    }
    let det = detect(m);
    let mut out = m.clone();
    let mut errors = Vec::new();
    let step = |i: usize| -> Option<Step<'_>> {
        match &m.states[i].body {
            StateBody::Task(Some(call)) => domain.step_of(call),
            _ => None,
        }
    };
    let no_action = |i: usize| FaultTolerantError::NoPostcondition {
        state: m.states[i].name.clone(),
        skill: match &m.states[i].body {
            StateBody::Task(Some(call)) => call.skill.clone(),
            _ => "no skill".to_string(),
        },
        domain: domain.name.clone(),
    };

    // The task's steps in execution order: the SUCCESS chain from the initial
    // state, then sequential states off the chain in file order.
    let mut chain: Vec<usize> = Vec::new();
    let mut end: Option<String> = None;
    let mut cur = m.top.initial_state();
    while let Some(s) = cur.take() {
        if !det.sequential.contains(&s) || chain.contains(&s) {
            break;
        }
        chain.push(s);
        for t in &m.states[s].transitions {
            if matches!(&t.trigger, Trigger::Outcome(o) if o == SUCCESS) {
                match &t.target {
                    Target::State(j) => cur = Some(*j),
                    Target::Outcome(o) | Target::OuterOutcome { outcome: o, .. } => {
                        end = Some(o.clone())
                    }
                }
                break;
            }
        }
    }
    for &s in &det.sequential {
        if !chain.contains(&s) {
            chain.push(s);
        }
    }
    let end = end.or_else(|| m.top.outcomes.first().cloned());

    // The SELECTOR: reused or added.
    let sel = match det.selector {
        Some(s) => s,
        None => {
            let mut name = "SELECTOR".to_string();
            let mut k = 2;
            while m.top.states.iter().any(|&i| m.states[i].name == name) {
                name = format!("SELECTOR {k}");
                k += 1;
            }
            out.states.push(State {
                name: name.clone(),
                label: name,
                parent: None,
                body: StateBody::Decision,
                transitions: Vec::new(),
                pseudo: None,
                span: None,
            });
            let idx = out.states.len() - 1;
            out.top.states.push(idx);
            idx
        }
    };

    // Connected states: drop their arcs to sequential states, add RUNNING and
    // SUCCESS -> SELECTOR.
    for &c in &det.connected {
        let st = &mut out.states[c];
        st.transitions
            .retain(|t| !matches!(t.target, Target::State(j) if det.sequential.contains(&j)));
        if !has_outcome(st, SUCCESS) {
            st.transitions
                .push(Transition::on_outcome(SUCCESS, Target::State(sel)));
        }
        if !has_outcome(st, RUNNING) {
            st.transitions
                .push(Transition::on_outcome(RUNNING, Target::State(c)));
        }
    }
    // Sequential states: RUNNING -> itself, FAILURE -> SELECTOR.
    for &s in &det.sequential {
        let st = &mut out.states[s];
        if !has_outcome(st, FAILURE) {
            st.transitions
                .push(Transition::on_outcome(FAILURE, Target::State(sel)));
        }
        if !has_outcome(st, RUNNING) {
            st.transitions
                .push(Transition::on_outcome(RUNNING, Target::State(s)));
        }
    }

    // The SELECTOR's arcs.
    let mut front: Vec<Transition> = Vec::new();
    let mut back: Vec<Transition> = Vec::new();
    let selector_has = |t: &Target| goes_to(&out.states[sel], t);
    for &c in &det.connected {
        let target = Target::State(c);
        if selector_has(&target) {
            continue;
        }
        // The guard the other states use to enter c, else "c's work is not done".
        let used = m.states.iter().flat_map(|s| &s.transitions).find_map(|t| {
            match (&t.trigger, &t.target) {
                (Trigger::Guard(g), Target::State(j)) if *j == c => Some(g.clone()),
                _ => None,
            }
        });
        let guard = match used {
            Some(g) => g,
            None => match step(c).and_then(|st| st.adds().into_iter().next()) {
                Some(f) => {
                    let term = domain.fact_term(&f, true);
                    Guard {
                        label: format!("{term}"),
                        all: vec![term],
                    }
                }
                None => {
                    errors.push(no_action(c));
                    continue;
                }
            },
        };
        front.push(Transition {
            trigger: Trigger::Guard(guard),
            target,
            span: None,
        });
    }
    let resume = |label: String, all: Vec<GuardTerm>, target: Target| Transition {
        trigger: Trigger::Guard(Guard { label, all }),
        target,
        span: None,
    };
    // The chain's steps in the domain, and their kernels.
    let steps: Vec<Option<Step<'_>>> = chain.iter().map(|&s| step(s)).collect();
    for (k, st) in steps.iter().enumerate() {
        if st.is_none() {
            errors.push(no_action(chain[k]));
        }
    }
    let steps: Vec<Step<'_>> = steps.into_iter().flatten().collect();
    if !chain.is_empty() && steps.len() == chain.len() {
        let goal = steps.last().map(Step::adds).unwrap_or_default();
        let kernels = crate::plan::fsm::kernels(&steps, &goal);
        let terms = |fs: &[Fact], negate: bool| -> Vec<GuardTerm> {
            fs.iter().map(|f| domain.fact_term(f, negate)).collect()
        };
        let text = |ts: &[GuardTerm]| {
            ts.iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(" and ")
        };
        if let Some(o) = &end {
            let target = Target::Outcome(o.clone());
            if !selector_has(&target) {
                let ts = terms(&goal, false);
                back.push(resume(format!("done: {}", text(&ts)), ts, target));
            }
        }
        for k in (0..chain.len()).rev() {
            let s = chain[k];
            let target = Target::State(s);
            if selector_has(&target) {
                continue;
            }
            // An empty kernel (the first step's, usually): "not the next
            // kernel's first fact", which the SELECTOR knows here.
            let made = if kernels[k].is_empty() {
                kernels
                    .get(k + 1)
                    .and_then(|next| next.first())
                    .map(|f| (true, terms(std::slice::from_ref(f), true)))
            } else {
                Some((false, terms(&kernels[k], false)))
            };
            if let Some((restart, ts)) = made {
                let label = if restart {
                    format!("restart: {}", text(&ts))
                } else {
                    format!("resume at {}: {}", m.states[s].label, text(&ts))
                };
                back.push(resume(label, ts, target));
            }
        }
    }
    if !errors.is_empty() {
        errors.dedup();
        return Err(errors);
    }
    let st = &mut out.states[sel];
    let mut trs = front;
    trs.append(&mut st.transitions);
    trs.extend(back);
    st.transitions = trs;
    if !has_outcome(st, RUNNING) {
        st.transitions
            .push(Transition::on_outcome(RUNNING, Target::State(sel)));
    }
    for &i in det.sequential.iter().chain(&det.connected).chain([&sel]) {
        guards_first(&mut out.states[i]);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::Limits;
    use std::path::Path;

    use crate::transform::paper_policy as paper;

    fn machine(p: &Policy) -> &StateMachine {
        match &p.body {
            PolicyBody::Machine(m) => m,
            PolicyBody::Bt(_) => panic!("not a machine"),
        }
    }

    use crate::transform::named_ged as named;

    #[test]
    fn eq4_and_eq5_agree() {
        for m_s in 0..20u64 {
            for m_fc in 0..5u64 {
                let m = m_s + m_fc;
                let eq5 = 3 * (m + 1) + m_fc * m.saturating_sub(1);
                assert_eq!(effort_formula(m_s, m_fc), eq5, "M_s {m_s} M_fc {m_fc}");
            }
        }
    }

    #[test]
    fn detects_sequential_and_connected_states() {
        let fig10 = paper("fig10-fsm");
        let d = detect(machine(&fig10));
        assert_eq!((d.sequential.len(), d.connected.len()), (4, 1));
        assert_eq!(machine(&fig10).states[d.connected[0]].name, "Recharge");
        assert_eq!(d.selector, None);
        let fig02 = paper("fig02-fsm");
        let d = detect(machine(&fig02));
        assert_eq!((d.sequential.len(), d.connected.len()), (4, 0));
    }

    #[test]
    fn fig02_becomes_fig04_and_fig10_becomes_fig11() {
        for (from, to) in [("fig02-fsm", "fig04-fsm"), ("fig10-fsm", "fig08d-fsm")] {
            let a = paper(from);
            let ft = fault_tolerant_policy(&a).expect("transform");
            let b = paper(to);
            assert_eq!(named(&ft, &b), 0, "{from} -> generated vs {to}");
            assert_eq!(named(&a, &ft), named(&a, &b));
        }
    }

    #[test]
    fn transform_is_idempotent_on_fault_tolerant_machines() {
        for f in ["fig04-fsm", "fig08d-fsm", "fig15-fsm", "fig16b-fsm"] {
            let a = paper(f);
            let ft = fault_tolerant_policy(&a).expect("transform");
            assert_eq!(named(&a, &ft), 0, "{f}");
        }
    }

    #[test]
    fn generated_machine_round_trips_through_toml() {
        let ft = fault_tolerant_policy(&paper("fig10-fsm")).expect("transform");
        let text = crate::format::toml_write::write_policy(&ft);
        let back =
            crate::format::toml::parse_str("gen.toml", &text, Path::new("."), &Limits::default())
                .unwrap_or_else(|d| panic!("{text}\n{d:?}"));
        assert_eq!(named(&ft, &back.policy), 0);
    }

    #[test]
    fn hfsm_and_bt_are_rejected() {
        let bt = paper("fig01-bt");
        assert_eq!(
            fault_tolerant_policy(&bt).unwrap_err(),
            vec![FaultTolerantError::NotAnFsm("bt")]
        );
    }
}
