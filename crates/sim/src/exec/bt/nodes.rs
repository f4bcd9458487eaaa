//! How each node type of the stack walk ticks (BehaviorTree.CPP's
//! `tick()` of its class, one step of it per visit): the composites, the
//! decorators, and Parallel, each entered or resumed with the status of the
//! child it ticked.

use super::{Frame, Next, NodeState, St, Ticking};
use crate::exec::Leaves;
use crate::exec::ops::Op;
use crate::skills::Status;

impl Ticking<'_> {
    /// One step of node `n`'s `tick()`: entered (`ret` is `None`, `f.i` is
    /// 0) or resumed with the status of its child at `f.i`.
    pub(super) fn visit<const REC: bool>(
        &mut self,
        n: usize,
        f: &mut Frame,
        ret: Option<Status>,
        leaves: &mut impl Leaves,
        rec: &mut Vec<(usize, Status)>,
    ) -> Next {
        let node = &self.bt.nodes[n];
        let len = (node.end - node.start) as usize;
        let i = f.i as usize;
        match node.op {
            Op::Sequence | Op::Fallback => self.reactive::<REC>(n, i, ret, leaves, rec),
            Op::SequenceMemory
            | Op::FallbackMemory
            | Op::SequenceWithMemory
            | Op::AsyncSequence
            | Op::AsyncFallback => self.with_memory::<REC>(n, f.prev, ret, leaves, rec),
            Op::Parallel | Op::ParallelAll => self.parallel(n, f, ret, leaves),
            Op::IfThenElse => self.if_then_else(n, i, ret, leaves),
            Op::WhileDoElse => self.while_do_else(n, i, ret, leaves),
            Op::Repeat | Op::Retry => self.repeat(n, f.prev, ret, leaves),
            Op::Timeout => self.timeout(n, ret, leaves),
            op => decorated(op, len, ret),
        }
    }

    /// ReactiveSequence and ReactiveFallback, resumed at child `i`: a
    /// RUNNING child halts the others; the node's status ends it.
    #[inline(always)]
    fn reactive<const REC: bool>(
        &mut self,
        n: usize,
        i: usize,
        ret: Option<Status>,
        leaves: &mut impl Leaves,
        rec: &mut Vec<(usize, Status)>,
    ) -> Next {
        use Status::{Failure as F, Running as R, Success as S};
        let node = &self.bt.nodes[n];
        let len = (node.end - node.start) as usize;
        let go_on = if node.op == Op::Sequence { S } else { F };
        let mut i = i;
        let mut ret = ret;
        // Leaf children are ticked in place, without a frame.
        loop {
            match ret {
                None => {}
                Some(R) => {
                    let bt = self.bt;
                    for (j, &c) in bt.kids(n).iter().enumerate() {
                        if j != i {
                            self.halt_child(c as usize, leaves);
                        }
                    }
                    return Next::Done(R);
                }
                Some(s) if s == go_on => i += 1,
                Some(s) => {
                    self.reset_children(n, 0, leaves);
                    return Next::Done(s);
                }
            }
            if i >= len {
                self.reset_children(n, 0, leaves);
                return Next::Done(go_on);
            }
            let c = self.bt.kids(n)[i] as usize;
            match self.leaf::<REC>(c, leaves, rec) {
                Some(s) => ret = Some(s),
                None => return Next::Tick(i),
            }
        }
    }

    /// Sequence, Fallback, SequenceWithMemory, AsyncSequence and
    /// AsyncFallback: resumed at the child index they keep (`prev`: the
    /// status of the child just ticked before its tick).
    #[inline(always)]
    fn with_memory<const REC: bool>(
        &mut self,
        n: usize,
        prev: St,
        ret: Option<Status>,
        leaves: &mut impl Leaves,
        rec: &mut Vec<(usize, Status)>,
    ) -> Next {
        use Status::{Failure as F, Running as R, Success as S};
        let node = &self.bt.nodes[n];
        let len = (node.end - node.start) as usize;
        let op = node.op;
        let go_on = if matches!(op, Op::FallbackMemory | Op::AsyncFallback) {
            F
        } else {
            S
        };
        let yields = matches!(
            op,
            Op::SequenceWithMemory | Op::AsyncSequence | Op::AsyncFallback
        );
        let mut ret = ret;
        let mut prev = prev;
        // Leaf children are ticked in place, without a frame.
        loop {
            match ret {
                None => {}
                Some(R) => return Next::Done(R),
                Some(s) if s == go_on => {
                    self.st[n].idx += 1;
                    if yields && prev == St::Idle && (self.st[n].idx as usize) < len {
                        return Next::Done(R);
                    }
                }
                Some(s) => {
                    if op == Op::SequenceWithMemory {
                        // The index is kept: the failed child is ticked
                        // again next time.
                        let from = self.st[n].idx as usize;
                        self.reset_children(n, from, leaves);
                    } else {
                        self.reset_children(n, 0, leaves);
                        self.st[n].idx = 0;
                    }
                    return Next::Done(s);
                }
            }
            let idx = self.st[n].idx as usize;
            if idx >= len {
                self.reset_children(n, 0, leaves);
                self.st[n].idx = 0;
                return Next::Done(go_on);
            }
            let c = self.bt.kids(n)[idx] as usize;
            prev = self.st[c].st;
            match self.leaf::<REC>(c, leaves, rec) {
                Some(s) => ret = Some(s),
                None => return Next::Tick(idx),
            }
        }
    }

    /// IfThenElse, resumed at child `i`: the condition (child 0) picks the
    /// branch it ticks next (1, else 2, else FAILURE).
    #[inline(always)]
    fn if_then_else(
        &mut self,
        n: usize,
        i: usize,
        ret: Option<Status>,
        leaves: &mut impl Leaves,
    ) -> Next {
        use Status::{Failure as F, Running as R, Success as S};
        let node = &self.bt.nodes[n];
        let len = (node.end - node.start) as usize;
        match ret {
            None => return Next::Tick(self.st[n].idx as usize),
            Some(R) => return Next::Done(R),
            Some(s) if i == 0 => {
                if s == S {
                    self.st[n].idx = 1;
                } else if len == 3 {
                    self.st[n].idx = 2;
                } else {
                    return Next::Done(F);
                }
                return Next::Tick(self.st[n].idx as usize);
            }
            Some(_) => {}
        }
        let s = ret.unwrap_or(F);
        self.reset_children(n, 0, leaves);
        self.st[n].idx = 0;
        Next::Done(s)
    }

    /// WhileDoElse, resumed at child `i`: the condition (child 0) is ticked
    /// every time, and the branch it does not pick is halted.
    #[inline(always)]
    fn while_do_else(
        &mut self,
        n: usize,
        i: usize,
        ret: Option<Status>,
        leaves: &mut impl Leaves,
    ) -> Next {
        use Status::{Running as R, Success as S};
        let node = &self.bt.nodes[n];
        let len = (node.end - node.start) as usize;
        let kid = |j: usize| self.bt.kids(n)[j] as usize;
        let s = match ret {
            None => return Next::Tick(0),
            Some(R) => return Next::Done(R),
            Some(S) if i == 0 => {
                if len == 3 {
                    self.halt_child(kid(2), leaves);
                }
                return Next::Tick(1);
            }
            Some(_) if i == 0 && len == 3 => {
                self.halt_child(kid(1), leaves);
                return Next::Tick(2);
            }
            Some(s) => s,
        };
        self.reset_children(n, 0, leaves);
        Next::Done(s)
    }

    /// Repeat (loops on SUCCESS) and RetryUntilSuccessful (on FAILURE), up
    /// to their count; `prev`: the child's status before its tick.
    #[inline(always)]
    fn repeat(
        &mut self,
        n: usize,
        prev: St,
        ret: Option<Status>,
        leaves: &mut impl Leaves,
    ) -> Next {
        use Status::{Failure as F, Running as R, Success as S};
        let node = &self.bt.nodes[n];
        let len = (node.end - node.start) as usize;
        // Repeat loops on success, Retry on failure.
        let (again, other) = if node.op == Op::Repeat {
            (S, F)
        } else {
            (F, S)
        };
        let do_loop = |ns: &NodeState| node.a < 0 || i64::from(ns.ok) < node.a;
        match ret {
            None => {}
            Some(R) => return Next::Done(R),
            Some(s) if s == again => {
                let ns = &mut self.st[n];
                ns.ok = ns.ok.saturating_add(1);
                let c = self.bt.kids(n)[0] as usize;
                self.halt_child(c, leaves);
                if prev == St::Idle && do_loop(&self.st[n]) {
                    return Next::Done(R);
                }
            }
            Some(_) => {
                self.st[n].ok = 0;
                let c = self.bt.kids(n)[0] as usize;
                self.halt_child(c, leaves);
                return Next::Done(other);
            }
        }
        if !do_loop(&self.st[n]) || len == 0 {
            self.st[n].ok = 0;
            return Next::Done(again);
        }
        Next::Tick(0)
    }

    /// Timeout, on simulated time: its child is halted and the node fails
    /// once its milliseconds have passed since it started RUNNING.
    #[inline(always)]
    fn timeout(&mut self, n: usize, ret: Option<Status>, leaves: &mut impl Leaves) -> Next {
        let node = &self.bt.nodes[n];
        let len = (node.end - node.start) as usize;
        match ret {
            Some(s) => Next::Done(s),
            None => {
                if self.st[n].st != St::Running {
                    self.st[n].t0 = self.now;
                }
                if (self.now - self.st[n].t0) * 1000.0 >= node.a as f64 || len == 0 {
                    if let Some(&c) = self.bt.kids(n).first() {
                        self.halt_child(c as usize, leaves);
                    }
                    return Next::Done(Status::Failure);
                }
                Next::Tick(0)
            }
        }
    }

    /// Parallel and ParallelAll: a child that finished is not ticked again
    /// until the node finishes (its status, SUCCESS or FAILURE, marks it).
    fn parallel(
        &mut self,
        n: usize,
        f: &mut Frame,
        ret: Option<Status>,
        leaves: &mut impl Leaves,
    ) -> Next {
        use Status::{Failure as F, Running as R, Success as S};
        let bt = self.bt;
        let node = &bt.nodes[n];
        let kids = bt.kids(n);
        let len = kids.len();
        let all = node.op == Op::ParallelAll;
        let mut i = f.i as usize;
        let mut resumed = ret.is_some();
        if let Some(s) = ret {
            let ns = &mut self.st[n];
            ns.ok += u32::from(s == S);
            ns.bad += u32::from(s == F);
        }
        while i < len {
            if !resumed {
                let c = kids[i] as usize;
                if !matches!(self.st[c].st, St::Success | St::Failure) {
                    return Next::Tick(i);
                }
            }
            resumed = false;
            if !all {
                let ns = self.st[n];
                let (ok, bad) = (i64::from(ns.ok), i64::from(ns.bad));
                let done = if ok >= node.a {
                    Some(S)
                } else if (len as i64 - bad) < node.a || bad == node.b {
                    Some(F)
                } else {
                    None
                };
                if let Some(s) = done {
                    self.st[n].ok = 0;
                    self.st[n].bad = 0;
                    self.reset_children(n, 0, leaves);
                    return Next::Done(s);
                }
            }
            i += 1;
        }
        if all {
            let ns = self.st[n];
            if ns.ok + ns.bad >= len as u32 {
                self.reset_children(n, 0, leaves);
                self.st[n].ok = 0;
                self.st[n].bad = 0;
                return Next::Done(if i64::from(ns.bad) >= node.b { F } else { S });
            }
        }
        Next::Done(R)
    }
}

/// The simple decorators (Inverter, ForceSuccess, ForceFailure,
/// KeepRunningUntilFailure, and a pass-through) with `len` children:
/// their one child's status mapped.
#[inline(always)]
fn decorated(op: Op, len: usize, ret: Option<Status>) -> Next {
    use Status::{Failure as F, Running as R, Success as S};
    match ret {
        None if len == 0 => Next::Done(F),
        None => Next::Tick(0),
        Some(s) => Next::Done(match (op, s) {
            (_, R) => R,
            (Op::Inverter, S) => F,
            (Op::Inverter, _) => S,
            (Op::ForceSuccess, _) => S,
            (Op::ForceFailure, _) => F,
            (Op::KeepRunningUntilFailure, S) => R,
            (_, s) => s,
        }),
    }
}
