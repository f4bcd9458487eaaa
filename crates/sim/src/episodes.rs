//! The one simulation contract of `sim --runs N` (SPEC §6; issue 28 item 4),
//! shared by the planar and the symbolic simulator: seeded episodes run on
//! `--threads` workers, handed out one at a time, and streamed back to one
//! consumer **in episode order**, so that
//!
//! - the figures are the same for every thread count (they are folded in
//!   episode order, floating-point sums included);
//! - memory is bounded by the number of threads, not of episodes: a worker
//!   waits before it starts an episode more than [`WINDOW_PER_THREAD`] ×
//!   threads ahead of the first one not yet consumed, and each episode's
//!   result is folded into the accumulators and dropped;
//! - `--timeout-ms` stops every worker (an episode cut short by the
//!   deadline is dropped, no new one starts) and the figures cover the
//!   longest prefix of episodes that completed: the same k episodes give
//!   the same figures as `--runs k`.
//!
//! Each simulator supplies what an episode is (its draw from the episode's
//! seed, its runs, its verdict) and what it folds; the hand-out, the order,
//! the stop, the first divergence and the interval are here.

use crate::monte_carlo::episode_seed;
use std::collections::BTreeMap;
use std::sync::mpsc;
use std::sync::{Condvar, Mutex, PoisonError};
use std::time::Instant;

/// How far (in episodes per thread) a worker may run ahead of the first
/// episode not yet folded: the results waiting to be folded are at most
/// this many per thread.
pub const WINDOW_PER_THREAD: u32 = 4;

/// The budget of a Monte Carlo run: how many episodes, their seed, how
/// many workers, and the wall-clock deadline (`--timeout-ms`).
#[derive(Debug, Clone, Copy)]
pub struct Budget {
    pub runs: u32,
    pub seed: u64,
    pub threads: usize,
    pub deadline: Option<Instant>,
}

impl Budget {
    /// The workers actually used: at least 1, at most one per episode.
    pub fn workers(&self) -> usize {
        self.threads.clamp(1, self.runs.max(1) as usize)
    }

    fn expired(&self) -> bool {
        self.deadline.is_some_and(|d| Instant::now() >= d)
    }
}

/// Runs the episodes of `budget`: `episode(i, seed_i)` on the workers
/// (`None` when the deadline cut it short), and `fold(i, seed_i, result)`
/// on this thread in episode order. Returns how many episodes were folded
/// (`budget.runs` unless the deadline passed).
pub fn stream<T, E, F>(budget: &Budget, episode: E, mut fold: F) -> u32
where
    T: Send,
    E: Fn(u32, u64) -> Option<T> + Sync,
    F: FnMut(u32, u64, T),
{
    let gate = Gate {
        state: Mutex::new(GateState {
            next: 0,
            folded: 0,
            stop: false,
        }),
        turn: Condvar::new(),
        window: (budget.workers() as u32).saturating_mul(WINDOW_PER_THREAD),
    };
    let (tx, rx) = mpsc::channel::<(u32, u64, T)>();
    let mut folded = 0u32;
    std::thread::scope(|sc| {
        let mut spawned = 0;
        for _ in 0..budget.workers() {
            let tx = tx.clone();
            let (gate, episode) = (&gate, &episode);
            let work = move || worker(budget, gate, episode, tx);
            // A thread the system refuses (a limit on processes) is one
            // worker fewer: the same episodes, the same figures.
            if std::thread::Builder::new().spawn_scoped(sc, work).is_ok() {
                spawned += 1;
            }
        }
        drop(tx);
        if spawned == 0 {
            // No worker at all: the episodes run here, one after another.
            folded = sequential(budget, &episode, &mut fold);
            return;
        }
        // Results come in any order; they are folded in episode order.
        let mut waiting: BTreeMap<u32, (u64, T)> = BTreeMap::new();
        for (i, seed, t) in rx {
            waiting.insert(i, (seed, t));
            while let Some((seed, t)) = waiting.remove(&folded) {
                fold(folded, seed, t);
                folded += 1;
            }
            gate.folded(folded);
        }
    });
    folded
}

/// The episodes run and folded on this thread, in order, until the
/// deadline cuts one short; how many were folded.
fn sequential<T, E, F>(budget: &Budget, episode: &E, fold: &mut F) -> u32
where
    E: Fn(u32, u64) -> Option<T>,
    F: FnMut(u32, u64, T),
{
    for i in 0..budget.runs {
        let seed = episode_seed(budget.seed, i);
        match (!budget.expired()).then(|| episode(i, seed)).flatten() {
            Some(t) => fold(i, seed, t),
            None => return i,
        }
    }
    budget.runs
}

/// The hand-out of episodes to the workers.
struct Gate {
    state: Mutex<GateState>,
    /// Signalled when an episode is folded or the run stops.
    turn: Condvar,
    window: u32,
}

struct GateState {
    /// The next episode to hand out.
    next: u32,
    /// Episodes folded so far (the first not yet folded).
    folded: u32,
    /// Set when the deadline passed or a worker ended early.
    stop: bool,
}

impl Gate {
    /// The next episode for a worker, once it is within the window;
    /// `None` when there are no more or the run stopped.
    fn take(&self, runs: u32) -> Option<u32> {
        let mut st = self.state.lock().unwrap_or_else(PoisonError::into_inner);
        loop {
            if st.stop || st.next >= runs {
                return None;
            }
            if st.next < st.folded.saturating_add(self.window) {
                st.next += 1;
                return Some(st.next - 1);
            }
            st = self.turn.wait(st).unwrap_or_else(PoisonError::into_inner);
        }
    }

    fn folded(&self, folded: u32) {
        self.state
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .folded = folded;
        self.turn.notify_all();
    }

    fn stop(&self) {
        self.state
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .stop = true;
        self.turn.notify_all();
    }
}

/// Stops the run when a worker ends for any reason but running out of
/// episodes (a deadline, or a panic unwinding): nobody waits for the
/// episodes it would have run.
struct StopOnDrop<'a>(&'a Gate, bool);

impl Drop for StopOnDrop<'_> {
    fn drop(&mut self) {
        if !self.1 {
            self.0.stop();
        }
    }
}

/// One worker: takes episodes until there are none, the run stops, or the
/// deadline cuts one short.
fn worker<T, E>(budget: &Budget, gate: &Gate, episode: &E, tx: mpsc::Sender<(u32, u64, T)>)
where
    E: Fn(u32, u64) -> Option<T>,
{
    let mut guard = StopOnDrop(gate, false);
    while let Some(i) = gate.take(budget.runs) {
        if budget.expired() {
            return;
        }
        let seed = episode_seed(budget.seed, i);
        let Some(t) = episode(i, seed) else { return };
        if tx.send((i, seed, t)).is_err() {
            return;
        }
    }
    guard.1 = true;
}

/// A pair of policies' agreement over the episodes folded: how many
/// matched, and the first that did not (its index and seed).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PairTally {
    pub matches: u32,
    pub first_divergence: Option<(u32, u64)>,
}

impl PairTally {
    /// Folds episode `i` (seed `seed`): whether the pair matched in it.
    pub fn fold(&mut self, i: u32, seed: u64, matched: bool) {
        if matched {
            self.matches += 1;
        } else if self.first_divergence.is_none() {
            self.first_divergence = Some((i, seed));
        }
    }
}

/// The pairs (a < b) of `n` policies, in the order the reports list them.
pub fn pairs(n: usize) -> Vec<(usize, usize)> {
    (0..n)
        .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicU32, Ordering};

    fn budget(runs: u32, threads: usize) -> Budget {
        Budget {
            runs,
            seed: 7,
            threads,
            deadline: None,
        }
    }

    #[test]
    fn episodes_are_folded_in_order_whatever_the_thread_count() {
        for threads in [1, 2, 3, 8] {
            let mut seen = Vec::new();
            let n = stream(
                &budget(100, threads),
                |i, seed| {
                    // Uneven work, so that workers finish out of order.
                    std::thread::sleep(std::time::Duration::from_micros(u64::from(i % 7) * 50));
                    Some((i, seed))
                },
                |i, seed, t| seen.push((i, seed, t)),
            );
            assert_eq!(n, 100);
            for (k, (i, seed, (ti, tseed))) in seen.iter().enumerate() {
                assert_eq!((*i, *ti), (k as u32, k as u32));
                assert_eq!((*seed, *tseed), (episode_seed(7, *i), episode_seed(7, *i)));
            }
        }
    }

    #[test]
    fn no_worker_runs_more_than_the_window_ahead_of_the_fold() {
        let threads = 3;
        let folded = AtomicU32::new(0);
        let ahead = AtomicU32::new(0);
        stream(
            &budget(500, threads),
            |i, _| {
                let lag = i - folded.load(Ordering::SeqCst);
                ahead.fetch_max(lag, Ordering::SeqCst);
                Some(())
            },
            |i, _, ()| folded.store(i + 1, Ordering::SeqCst),
        );
        assert!(ahead.load(Ordering::SeqCst) < threads as u32 * WINDOW_PER_THREAD);
    }

    #[test]
    fn an_episode_cut_short_stops_the_run_at_the_prefix_before_it() {
        for threads in [1, 2, 4] {
            let mut folded = Vec::new();
            let n = stream(
                &budget(1000, threads),
                |i, _| (i != 37).then_some(i),
                |i, _, _| folded.push(i),
            );
            assert_eq!(n, 37, "{threads} threads");
            assert_eq!(folded, (0..37).collect::<Vec<_>>());
        }
    }

    #[test]
    fn a_deadline_already_past_runs_nothing() {
        let b = Budget {
            deadline: Some(Instant::now()),
            ..budget(1_000_000, 2)
        };
        assert_eq!(stream(&b, |i, _| Some(i), |_, _, _| {}), 0);
    }

    #[test]
    fn the_first_divergence_is_the_first_in_episode_order() {
        let mut t = PairTally::default();
        for (i, m) in [true, false, true, false].into_iter().enumerate() {
            t.fold(i as u32, 100 + i as u64, m);
        }
        assert_eq!(t.matches, 2);
        assert_eq!(t.first_divergence, Some((1, 101)));
        assert_eq!(pairs(3), [(0, 1), (0, 2), (1, 2)]);
    }
}
