//! Conflicts among the preconditions of a Sequence, and their order.
//!
//! Sibling j *undoes* sibling i when an action below j deletes the fact i
//! ensures (explicitly, or by adding a fact that excludes it: `Move-To
//! cube2` adds `Robot-At(cube2)` and so deletes `Robot-At(delivery)`). If j
//! runs after i, the Sequence re-ticks i, whose subtree undoes j's fact in
//! turn, and so on: the robot chatters (the paper's Fig. 3). So j must run
//! first. The siblings are put in the stable topological order of "must
//! run first" (HandlePriority of Colledanchise, Almeida & Ögren 2019,
//! "Towards Blended Reactive Planning and Acting using Behavior Trees",
//! generalised to any number of siblings); siblings that undo each other
//! (a cycle) keep the domain's order and are reported, never silently
//! ordered.

use super::backchain::Step;
use super::domain::Domain;
use super::fact::Fact;
use std::collections::BTreeSet;

/// One conflict between two siblings of a Sequence.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Conflict {
    /// The sibling whose condition is undone (node id).
    pub ensures: String,
    /// The fact it ensures.
    pub fact: String,
    /// The sibling that undoes it.
    pub undone_by: String,
    /// What became of it.
    pub outcome: Outcome,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Outcome {
    /// `undone_by` was moved before `ensures`.
    Reordered,
    /// Already in a safe order (`undone_by` runs first).
    InOrder,
    /// Left in the domain's order (`--no-reorder`): the policy chatters.
    Left,
    /// Part of a cycle no order resolves.
    Cycle,
}

impl std::fmt::Display for Conflict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use btfsm_core::sanitize::shown;
        let what = match self.outcome {
            Outcome::Reordered => "moved before it",
            Outcome::InOrder => "already runs first",
            Outcome::Left => "left after it (--no-reorder): the Sequence re-ticks it and chatters",
            Outcome::Cycle => "they undo each other: no order resolves it",
        };
        write!(
            f,
            "`{}` undoes {}, which `{}` ensures: {what}",
            shown(&self.undone_by),
            shown(&self.fact),
            shown(&self.ensures)
        )
    }
}

/// The facts of `ensured` that `step` deletes (explicitly, or by adding a
/// fact of an `exclusive` predicate that excludes them).
pub fn undone_by(d: &Domain, step: &Step<'_>, ensured: &[Option<Fact>]) -> Vec<Fact> {
    let dels = step.deletes();
    let adds = step.adds();
    let mut out = Vec::new();
    for f in ensured.iter().flatten() {
        if adds.contains(f) {
            continue;
        }
        let excluded = d
            .predicate(&f.pred)
            .and_then(|p| p.exclusive)
            .is_some_and(|k| {
                adds.iter().any(|a| {
                    a.pred == f.pred
                        && a.args.len() == f.args.len()
                        && a.args[k] != f.args[k]
                        && a.args
                            .iter()
                            .zip(&f.args)
                            .enumerate()
                            .all(|(i, (x, y))| i == k || x == y)
                })
            });
        if excluded || dels.contains(f) {
            out.push(f.clone());
        }
    }
    out
}

/// The order of siblings `0..n` (as positions into the input) and the
/// conflicts found. `ensured[i]`: the fact sibling i ensures; `undoes[j]`:
/// the facts sibling j's actions delete.
pub(super) fn order(
    ensured: &[Option<Fact>],
    undoes: &[BTreeSet<Fact>],
    names: &[String],
    reorder: bool,
) -> (Vec<usize>, Vec<Conflict>) {
    let n = ensured.len();
    // first[i]: the siblings that must run before i (they undo i's fact).
    let first: Vec<Vec<usize>> = (0..n)
        .map(|i| {
            (0..n)
                .filter(|&j| j != i && ensured[i].as_ref().is_some_and(|f| undoes[j].contains(f)))
                .collect()
        })
        .collect();
    let conflict = |i: usize, j: usize, outcome| Conflict {
        ensures: names[i].clone(),
        fact: ensured[i]
            .as_ref()
            .map(ToString::to_string)
            .unwrap_or_default(),
        undone_by: names[j].clone(),
        outcome,
    };
    let mut found = Vec::new();
    if !reorder {
        for (i, before) in first.iter().enumerate() {
            for &j in before {
                found.push(conflict(
                    i,
                    j,
                    if j < i {
                        Outcome::InOrder
                    } else {
                        Outcome::Left
                    },
                ));
            }
        }
        return ((0..n).collect(), found);
    }
    let mut placed = vec![false; n];
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let ready = (0..n).find(|&i| !placed[i] && first[i].iter().all(|&j| placed[j]));
        match ready {
            Some(i) => {
                placed[i] = true;
                out.push(i);
            }
            None => {
                // A cycle: the rest keep the domain's order, reported.
                let rest: Vec<usize> = (0..n).filter(|&i| !placed[i]).collect();
                for &i in &rest {
                    for &j in &first[i] {
                        if !placed[j] {
                            found.push(conflict(i, j, Outcome::Cycle));
                        }
                    }
                }
                for i in rest {
                    placed[i] = true;
                    out.push(i);
                }
            }
        }
    }
    let pos: Vec<usize> = {
        let mut p = vec![0; n];
        for (k, &i) in out.iter().enumerate() {
            p[i] = k;
        }
        p
    };
    for (i, before) in first.iter().enumerate() {
        for &j in before {
            if found
                .iter()
                .any(|c: &Conflict| c.ensures == names[i] && c.undone_by == names[j])
            {
                continue;
            }
            let outcome = if j < i {
                Outcome::InOrder
            } else {
                Outcome::Reordered
            };
            debug_assert!(pos[j] < pos[i]);
            found.push(conflict(i, j, outcome));
        }
    }
    (out, found)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fact(p: &str) -> Option<Fact> {
        Some(Fact {
            pred: p.into(),
            args: vec![],
        })
    }

    #[test]
    fn a_later_sibling_that_undoes_an_earlier_one_moves_before_it() {
        // 0 ensures A, 1 ensures B and deletes A: 1 runs first.
        let ensured = [fact("A"), fact("B")];
        let undoes = [BTreeSet::new(), [fact("A").unwrap()].into()];
        let names = ["a".to_string(), "b".to_string()];
        let (o, c) = order(&ensured, &undoes, &names, true);
        assert_eq!(o, [1, 0]);
        assert_eq!(c.len(), 1);
        assert_eq!(c[0].outcome, Outcome::Reordered);
        let (o, c) = order(&ensured, &undoes, &names, false);
        assert_eq!(o, [0, 1]);
        assert_eq!(c[0].outcome, Outcome::Left);
    }

    #[test]
    fn siblings_undoing_each_other_are_a_reported_cycle() {
        let ensured = [fact("A"), fact("B"), fact("C")];
        let undoes = [
            [fact("B").unwrap()].into(),
            [fact("A").unwrap()].into(),
            BTreeSet::new(),
        ];
        let names = ["a".to_string(), "b".to_string(), "c".to_string()];
        let (o, c) = order(&ensured, &undoes, &names, true);
        // c has no conflict and goes first; a and b keep their order.
        assert_eq!(o, [2, 0, 1]);
        assert_eq!(c.iter().filter(|c| c.outcome == Outcome::Cycle).count(), 2);
    }
}
