//! The first divergence between two sequences of executed skills: the
//! skill comparison of the simulator's behavior verdict (`super::verdict`),
//! over any sequence read one skill at a time, so that `btfsm log compare`
//! runs the same code on logs streamed from disk (src/log/compare.rs).

use super::{Divergence, SkillRecord};

/// A sequence of executed skills read one at a time (a run's list, or a
/// log streamed: `btfsm log compare`), and when it ends.
pub trait SkillSeq {
    type Error;
    /// The next executed skill, in start order.
    fn next_skill(&mut self) -> Option<Result<SkillRecord, Self::Error>>;
    /// The end of the run, s (asked once the sequence is exhausted).
    fn end_s(&self) -> f64;
}

/// A run's executed skills as a [`SkillSeq`].
pub struct SkillSlice<'a> {
    skills: std::slice::Iter<'a, SkillRecord>,
    end: f64,
}

impl<'a> SkillSlice<'a> {
    pub fn new(skills: &'a [SkillRecord], end: f64) -> Self {
        SkillSlice {
            skills: skills.iter(),
            end,
        }
    }
}

impl SkillSeq for SkillSlice<'_> {
    type Error = std::convert::Infallible;
    fn next_skill(&mut self) -> Option<Result<SkillRecord, Self::Error>> {
        self.skills.next().cloned().map(Ok)
    }
    fn end_s(&self) -> f64 {
        self.end
    }
}

/// The first index where two sequences of executed skills differ: skill or
/// arguments (`skill`, at the earlier start), how the same call ended
/// (`outcome`, when the first of the two ended), start times more than `tol` s apart
/// (`start`; an infinite `tol` compares the order only), or one sequence
/// ended (`missing`). Reads both in step and stops there: the last skill
/// each yielded is the one that differs. The verdict's skill comparison,
/// shared with `btfsm log compare`.
pub fn first_divergence<E>(
    a: &mut impl SkillSeq<Error = E>,
    b: &mut impl SkillSeq<Error = E>,
    tol: f64,
) -> Result<Option<Divergence>, E> {
    let mut index = 0;
    loop {
        let x = a.next_skill().transpose()?;
        let y = b.next_skill().transpose()?;
        let (kind, t, starts) = match (&x, &y) {
            (Some(x), Some(y)) if x.skill == y.skill && x.args == y.args && !x.same(y) => {
                ("outcome", outcomes_part(x, y), None)
            }
            (Some(x), Some(y)) if !x.same(y) => ("skill", x.start.min(y.start), None),
            (Some(x), Some(y)) if (x.start - y.start).abs() > tol => {
                ("start", x.start.min(y.start), Some([x.start, y.start]))
            }
            (Some(_), Some(_)) => {
                index += 1;
                continue;
            }
            (Some(x), None) => ("missing", x.start.min(b.end_s()), None),
            (None, Some(y)) => ("missing", y.start.min(a.end_s()), None),
            (None, None) => return Ok(None),
        };
        let parted = if kind == "outcome" {
            Some(t)
        } else {
            [&x, &y]
                .into_iter()
                .flatten()
                .filter(|r| r.outcome == "success")
                .filter_map(|r| r.end)
                .reduce(f64::min)
        };
        return Ok(Some(Divergence {
            index,
            a: x.as_ref().map(SkillRecord::text),
            b: y.as_ref().map(SkillRecord::text),
            t,
            kind,
            starts,
            parted,
        }));
    }
}

/// When two calls of the same skill with the same arguments stopped doing
/// the same thing: the earlier end (a call still running has not ended).
fn outcomes_part(x: &SkillRecord, y: &SkillRecord) -> f64 {
    match (x.end, y.end) {
        (Some(a), Some(b)) => a.min(b),
        (Some(a), None) | (None, Some(a)) => a,
        (None, None) => x.start.max(y.start),
    }
}
