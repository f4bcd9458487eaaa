//! Monte Carlo episodes (`sim --runs N`, SPEC §6): seeded episodes with
//! jittered disturbances, run in parallel over the cores and combined in
//! episode order, so that the figures do not depend on the thread count.

use super::episodes::{self, Budget, PairTally};
use super::rng::SimRng;
use super::robot::round3;
use super::run::{Prepared, RunOptions, cut_short, prepare, run_policy};
use super::scenario::{Disturbance, Scenario, mc};
use super::trace::{Outcome, verdict_without_path};
use std::collections::BTreeMap;
use std::time::Instant;

/// Per-policy figures of `--runs N`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct McStats {
    pub policy: String,
    pub runs: u32,
    pub successes: u32,
    pub success_rate: f64,
    /// 95 % Wilson score interval of the success rate.
    pub success_ci95: [f64; 2],
    pub chattering: u32,
    pub timeouts: u32,
    pub failures: u32,
    /// Mean completion time of the successful episodes, s.
    pub mean_completion_s: Option<f64>,
    /// Completion-time quantiles of the successful episodes (10 %, 50 %,
    /// 90 %, nearest rank), s.
    pub completion_quantiles_s: Option<[f64; 3]>,
    /// Mean latency from a battery-low event to the start of Recharge, s.
    pub mean_recharge_latency_s: Option<f64>,
    pub recharges: u32,
    /// The first episode the policy did not succeed in (failure,
    /// chattering or timeout): its index and its seed (`btfsm sim SCENARIO
    /// --seed SEED` replays it).
    pub first_unsuccessful: Option<Diverged>,
}

/// Per-pair figures of `--runs N`: how often the two policies' behavior
/// matched (the verdict of a single run, episode by episode).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PairStats {
    pub a: String,
    pub b: String,
    pub runs: u32,
    pub matches: u32,
    pub match_rate: f64,
    /// 95 % Wilson score interval of the match rate.
    pub match_ci95: [f64; 2],
    /// The first episode whose behavior differs: its index and its seed
    /// (`btfsm sim SCENARIO --seed SEED` replays it).
    pub first_divergence: Option<Diverged>,
    /// Episodes in which the robots moved alike (within the pose
    /// tolerance at equal times) and ended alike (outcome, goal, final
    /// world), whatever skills they called: a BT that starts a Move-To the
    /// emergency stop aborts at once, where the FSM stays in Shut Down,
    /// differs in behavior but not in motion.
    pub moved_alike: u32,
    pub moved_alike_rate: f64,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Diverged {
    pub episode: u32,
    pub seed: u64,
}

/// What `--runs N` computes.
#[derive(Debug, Clone, PartialEq)]
pub struct McResult {
    pub policies: Vec<McStats>,
    pub pairs: Vec<PairStats>,
    /// Episodes the figures cover.
    pub runs: u32,
}

/// 95 % Wilson score interval of `k` successes in `n` trials
/// (`[0, 1]` when `n` is 0), rounded to 4 decimals (10,000 successes in
/// 10,000 give `[0.9996, 1]`).
pub fn wilson(k: u32, n: u32) -> [f64; 2] {
    if n == 0 {
        return [0.0, 1.0];
    }
    let (z, n, p) = (1.959964f64, n as f64, k as f64 / n as f64);
    let z2 = z * z;
    let centre = (p + z2 / (2.0 * n)) / (1.0 + z2 / n);
    let half = z / (1.0 + z2 / n) * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt();
    let r4 = |x: f64| (x * 10_000.0).round() / 10_000.0;
    [r4((centre - half).max(0.0)), r4((centre + half).min(1.0))]
}

/// The seed of episode `i` of a Monte Carlo run with seed `seed`.
pub fn episode_seed(seed: u64, i: u32) -> u64 {
    SimRng::named(seed, &format!("episode-{i}")).next_u64()
}

/// The disturbances and failure rates of the episode with seed `ep_seed`
/// (a function of the scenario and `ep_seed` alone: `sim --seed ep_seed`
/// runs this episode).
pub fn episode(s: &Scenario, ep_seed: u64) -> (Vec<Disturbance>, BTreeMap<String, f64>) {
    (mc::draw(s, ep_seed), mc::rates(s))
}

/// Runs `runs` seeded episodes of every policy on `threads` threads.
pub fn monte_carlo(s: &Scenario, runs: u32, seed: u64, threads: usize) -> McResult {
    monte_carlo_within(s, runs, seed, threads, None)
}

/// [`monte_carlo`] under a wall-clock deadline: once it passes, every
/// thread stops (the episode in progress is cut within `CLOCK_EVERY`
/// steps and dropped, no new one starts), and the figures cover the first
/// k episodes, k the number returned (every episode before k completed for
/// every policy; `runs` when the deadline never passed). The same k
/// episodes give the same figures as `monte_carlo(s, k, seed, ..)`. The
/// episodes go through the one contract of [`crate::episodes`]: folded in
/// order as they come, in memory bounded by the threads.
pub fn monte_carlo_within(
    s: &Scenario,
    runs: u32,
    seed: u64,
    threads: usize,
    deadline: Option<Instant>,
) -> McResult {
    let prepared = prepare(s);
    let pairs = episodes::pairs(prepared.len());
    let budget = Budget {
        runs,
        seed,
        threads,
        deadline,
    };
    let mut policies: Vec<PolicyTally> = prepared.iter().map(|_| PolicyTally::default()).collect();
    let mut agree = vec![PairTally::default(); pairs.len()];
    let mut moved = vec![0u32; pairs.len()];
    let done = episodes::stream(
        &budget,
        |_, ep_seed| one_episode(s, &prepared, &pairs, ep_seed, deadline),
        |i, ep_seed, (figures, same): Episode| {
            for (t, r) in policies.iter_mut().zip(figures) {
                t.fold(i, ep_seed, r);
            }
            for ((t, k), (m, alike)) in agree.iter_mut().zip(moved.iter_mut()).zip(same) {
                t.fold(i, ep_seed, m);
                *k += u32::from(alike);
            }
        },
    );
    McResult {
        policies: (prepared.iter().zip(&policies))
            .map(|(p, t)| t.stats(&p.name, done))
            .collect(),
        pairs: (pairs.iter().zip(&agree).zip(&moved))
            .map(|((&(a, b), t), &k)| pair_stats(&prepared[a].name, &prepared[b].name, t, k, done))
            .collect(),
        runs: done,
    }
}

/// One policy's figures of an episode: its outcome, whether the goal was
/// met, its completion time and its recharge latencies.
type Res = (Outcome, Option<bool>, Option<f64>, Vec<f64>);
/// An episode: per policy its figures, per pair whether the behavior
/// matched.
type Episode = (Vec<Res>, Vec<(bool, bool)>);

/// Every policy's run of the episode with seed `ep_seed`; `None` when the
/// deadline cut one short.
fn one_episode(
    s: &Scenario,
    prepared: &[Prepared],
    pairs: &[(usize, usize)],
    ep_seed: u64,
    deadline: Option<Instant>,
) -> Option<Episode> {
    let (ds, rates) = episode(s, ep_seed);
    let mut runs = Vec::with_capacity(prepared.len());
    for p in prepared {
        let options = RunOptions {
            log: false,
            trace: false,
            deadline,
        };
        let r = run_policy(s, p, s.world.clone(), &ds, rates.clone(), ep_seed, options);
        if cut_short(s, &r) {
            return None;
        }
        runs.push(r);
    }
    let same = (pairs.iter())
        .map(|&(a, b)| {
            let v = verdict_without_path(&runs[a], &runs[b]);
            let moved = v.same_motion && v.same_outcome && v.same_final_world;
            (v.matches, moved)
        })
        .collect();
    let figures = (runs.into_iter())
        .map(|r| (r.outcome, r.goal_met, r.completion_s, r.recharge_latency_s))
        .collect();
    Some((figures, same))
}

/// A policy's figures folded over the episodes, in episode order: counts,
/// sums, and the completion times as a histogram of their (rounded)
/// values, which are at most a scenario's steps apart, so that the
/// quantiles are exact in memory independent of the episodes.
#[derive(Debug, Default)]
struct PolicyTally {
    successes: u32,
    chattering: u32,
    timeouts: u32,
    completion_sum: f64,
    completions: BTreeMap<TotalF64, u32>,
    latency_sum: f64,
    latencies: u32,
    first_unsuccessful: Option<Diverged>,
}

/// An `f64` ordered by `total_cmp`, as a map key.
#[derive(Debug, Clone, Copy)]
struct TotalF64(f64);

impl PartialEq for TotalF64 {
    fn eq(&self, o: &Self) -> bool {
        self.0.total_cmp(&o.0).is_eq()
    }
}
impl Eq for TotalF64 {}
impl PartialOrd for TotalF64 {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for TotalF64 {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&o.0)
    }
}

impl PolicyTally {
    fn fold(&mut self, episode: u32, seed: u64, (outcome, goal_met, completion, latencies): Res) {
        let success = outcome == Outcome::Success && goal_met != Some(false);
        if !success && self.first_unsuccessful.is_none() {
            self.first_unsuccessful = Some(Diverged { episode, seed });
        }
        match outcome {
            Outcome::Success if goal_met != Some(false) => {
                self.successes += 1;
                if let Some(c) = completion {
                    self.completion_sum += c;
                    *self.completions.entry(TotalF64(c)).or_insert(0) += 1;
                }
            }
            Outcome::Chattering => self.chattering += 1,
            Outcome::Timeout => self.timeouts += 1,
            _ => {}
        }
        for l in latencies {
            self.latency_sum += l;
            self.latencies += 1;
        }
    }

    /// Nearest-rank quantiles 10 %, 50 %, 90 % of the completion times.
    fn quantiles(&self) -> Option<[f64; 3]> {
        let n: u32 = self.completions.values().sum();
        if n == 0 {
            return None;
        }
        let q = |p: f64| {
            let rank = ((p * f64::from(n)).ceil() as u32).clamp(1, n);
            let mut below = 0;
            for (v, k) in &self.completions {
                below += k;
                if below >= rank {
                    return v.0;
                }
            }
            unreachable!("the ranks are at most the count")
        };
        Some([q(0.1), q(0.5), q(0.9)])
    }

    fn stats(&self, policy: &str, runs: u32) -> McStats {
        let n_comp: u32 = self.completions.values().sum();
        let mean = |sum: f64, n: u32| (n > 0).then(|| round3(sum / f64::from(n)));
        McStats {
            policy: policy.to_string(),
            runs,
            successes: self.successes,
            success_rate: rate(self.successes, runs),
            chattering: self.chattering,
            timeouts: self.timeouts,
            failures: runs - self.successes - self.chattering - self.timeouts,
            success_ci95: wilson(self.successes, runs),
            mean_completion_s: mean(self.completion_sum, n_comp),
            completion_quantiles_s: self.quantiles(),
            mean_recharge_latency_s: mean(self.latency_sum, self.latencies),
            recharges: self.latencies,
            first_unsuccessful: self.first_unsuccessful.clone(),
        }
    }
}

/// `k / n` to 3 decimals (0 when `n` is 0).
fn rate(k: u32, n: u32) -> f64 {
    if n == 0 {
        0.0
    } else {
        round3(f64::from(k) / f64::from(n))
    }
}

/// A pair's figures: how often their behavior matched, and the first
/// episode where it did not.
fn pair_stats(a: &str, b: &str, t: &PairTally, moved_alike: u32, runs: u32) -> PairStats {
    PairStats {
        a: a.to_string(),
        b: b.to_string(),
        runs,
        matches: t.matches,
        match_rate: rate(t.matches, runs),
        match_ci95: wilson(t.matches, runs),
        first_divergence: t
            .first_divergence
            .map(|(episode, seed)| Diverged { episode, seed }),
        moved_alike,
        moved_alike_rate: rate(moved_alike, runs),
    }
}
