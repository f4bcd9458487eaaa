//! Monte Carlo episodes (`sim --runs N`, SPEC §6): seeded episodes with
//! jittered disturbances, run in parallel over the cores and combined in
//! episode order, so that the figures do not depend on the thread count.

use super::rng::SimRng;
use super::robot::round3;
use super::run::{Prepared, RunOptions, cut_short, prepare, run_policy};
use super::scenario::{Disturbance, Scenario, mc};
use super::trace::{Outcome, behavior_matches};
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
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

/// Nearest-rank quantiles 10 %, 50 %, 90 % of `v` (sorted here).
fn quantiles(v: &mut [f64]) -> Option<[f64; 3]> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let q = |p: f64| v[((p * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1];
    Some([q(0.1), q(0.5), q(0.9)])
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
/// episodes give the same figures as `monte_carlo(s, k, seed, ..)`.
pub fn monte_carlo_within(
    s: &Scenario,
    runs: u32,
    seed: u64,
    threads: usize,
    deadline: Option<Instant>,
) -> McResult {
    let prepared = prepare(s);
    let np = prepared.len();
    let pairs: Vec<(usize, usize)> = (0..np)
        .flat_map(|a| (a + 1..np).map(move |b| (a, b)))
        .collect();
    let stop = AtomicBool::new(false);
    let episodes = Episodes {
        s,
        prepared: &prepared,
        pairs: &pairs,
        runs,
        seed,
        threads: threads.max(1).min(runs.max(1) as usize),
        deadline,
        stop: &stop,
    };
    let (all, agree, runs) = complete_prefix(episodes.run(), runs);
    McResult {
        policies: policy_stats(&prepared, &all, runs),
        pairs: pair_stats(&prepared, &pairs, &agree, runs),
        runs,
    }
}

/// One policy's figures of an episode: its outcome, whether the goal was
/// met, its completion time and its recharge latencies.
type Res = (Outcome, Option<bool>, Option<f64>, Vec<f64>);
/// Per episode: its index, its seed and, per pair, whether the behavior
/// matched.
type Agree = (u32, u64, Vec<bool>);
/// What a worker made: (episode, policy, figures), and its episodes'
/// agreements.
type Results = (Vec<(u32, usize, Res)>, Vec<Agree>);

/// The episodes of a Monte Carlo run, shared by its worker threads.
struct Episodes<'a> {
    s: &'a Scenario,
    prepared: &'a [Prepared],
    pairs: &'a [(usize, usize)],
    runs: u32,
    seed: u64,
    threads: usize,
    deadline: Option<Instant>,
    /// Set by the first worker whose episode the deadline cut short.
    stop: &'a AtomicBool,
}

impl Episodes<'_> {
    /// Runs the episodes on `threads` threads; per thread what it made.
    fn run(&self) -> Vec<Results> {
        let mut per_thread: Vec<Results> = Vec::new();
        std::thread::scope(|sc| {
            let mut handles = Vec::new();
            for t in 0..self.threads {
                // A thread the system refuses (a limit on processes) does its
                // share on this one instead: the same episodes, the same figures.
                match std::thread::Builder::new().spawn_scoped(sc, move || self.work(t)) {
                    Ok(h) => handles.push(h),
                    Err(_) => per_thread.push(self.work(t)),
                }
            }
            for h in handles {
                per_thread.push(h.join().expect("episode thread"));
            }
        });
        per_thread
    }

    /// One worker's episodes: t, t + threads, ... until the deadline cuts
    /// one short (dropped, and every worker stops).
    fn work(&self, t: usize) -> Results {
        let s = self.s;
        let mut out = Vec::new();
        let mut agree = Vec::new();
        let mut i = t as u32;
        'episodes: while i < self.runs {
            if self.stop.load(Ordering::Relaxed) {
                break;
            }
            let ep_seed = episode_seed(self.seed, i);
            let (ds, rates) = episode(s, ep_seed);
            let first = out.len();
            let mut ep_runs = Vec::with_capacity(self.prepared.len());
            for (k, p) in self.prepared.iter().enumerate() {
                let r = run_policy(
                    s,
                    p,
                    s.world.clone(),
                    &ds,
                    rates.clone(),
                    ep_seed,
                    RunOptions {
                        log: false,
                        trace: false,
                        deadline: self.deadline,
                    },
                );
                if cut_short(s, &r) {
                    self.stop.store(true, Ordering::Relaxed);
                    out.truncate(first);
                    break 'episodes;
                }
                out.push((
                    i,
                    k,
                    (
                        r.outcome,
                        r.goal_met,
                        r.completion_s,
                        r.recharge_latency_s.clone(),
                    ),
                ));
                ep_runs.push(r);
            }
            let same = (self.pairs.iter())
                .map(|&(a, b)| behavior_matches(&ep_runs[a], &ep_runs[b]))
                .collect();
            agree.push((i, ep_seed, same));
            i += self.threads as u32;
        }
        (out, agree)
    }
}

/// The workers' results merged: the episodes that came whole (all
/// policies), up to the first that did not, ordered by policy then
/// episode, the agreements by episode; and how many episodes that is.
fn complete_prefix(
    per_thread: Vec<Results>,
    runs: u32,
) -> (Vec<(u32, usize, Res)>, Vec<Agree>, u32) {
    let mut all: Vec<(u32, usize, Res)> = Vec::new();
    let mut agree: Vec<Agree> = Vec::new();
    for (o, a) in per_thread {
        all.extend(o);
        agree.extend(a);
    }
    // Episodes come whole (all policies) or not at all: keep the prefix of
    // consecutive completed ones.
    let mut complete = vec![false; runs as usize];
    for (i, _, _) in &all {
        complete[*i as usize] = true;
    }
    let runs = complete.iter().position(|c| !c).unwrap_or(complete.len()) as u32;
    all.retain(|(i, _, _)| *i < runs);
    all.sort_by_key(|(i, k, _)| (*k, *i));
    agree.retain(|(i, _, _)| *i < runs);
    agree.sort_by_key(|(i, _, _)| *i);
    (all, agree, runs)
}

/// Per pair of policies: how often their behavior matched, and the first
/// episode where it did not.
fn pair_stats(
    prepared: &[Prepared],
    pairs: &[(usize, usize)],
    agree: &[Agree],
    runs: u32,
) -> Vec<PairStats> {
    (pairs.iter().enumerate())
        .map(|(x, &(a, b))| {
            let matches = agree.iter().filter(|e| e.2[x]).count() as u32;
            PairStats {
                a: prepared[a].name.clone(),
                b: prepared[b].name.clone(),
                runs,
                matches,
                match_rate: if runs == 0 {
                    0.0
                } else {
                    round3(matches as f64 / runs as f64)
                },
                match_ci95: wilson(matches, runs),
                first_divergence: (agree.iter().find(|e| !e.2[x])).map(|e| Diverged {
                    episode: e.0,
                    seed: e.1,
                }),
            }
        })
        .collect()
}

/// Per policy: its figures over the episodes (`all`, ordered by policy).
fn policy_stats(prepared: &[Prepared], all: &[(u32, usize, Res)], runs: u32) -> Vec<McStats> {
    prepared
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let mine: Vec<&Res> = all
                .iter()
                .filter(|(_, kk, _)| *kk == k)
                .map(|(_, _, r)| r)
                .collect();
            let ok: Vec<&&Res> = mine
                .iter()
                .filter(|r| r.0 == Outcome::Success && r.1 != Some(false))
                .collect();
            let mut comp: Vec<f64> = ok.iter().filter_map(|r| r.2).collect();
            let lat: Vec<f64> = mine.iter().flat_map(|r| r.3.iter().copied()).collect();
            let mean =
                |v: &[f64]| (!v.is_empty()).then(|| round3(v.iter().sum::<f64>() / v.len() as f64));
            let count = |o: Outcome| mine.iter().filter(|r| r.0 == o).count() as u32;
            McStats {
                policy: p.name.clone(),
                runs,
                successes: ok.len() as u32,
                success_rate: if runs == 0 {
                    0.0
                } else {
                    round3(ok.len() as f64 / runs as f64)
                },
                chattering: count(Outcome::Chattering),
                timeouts: count(Outcome::Timeout),
                failures: runs
                    - ok.len() as u32
                    - count(Outcome::Chattering)
                    - count(Outcome::Timeout),
                success_ci95: wilson(ok.len() as u32, runs),
                // The mean before the quantiles, which sort `comp`.
                mean_completion_s: mean(&comp),
                completion_quantiles_s: quantiles(&mut comp),
                mean_recharge_latency_s: mean(&lat),
                recharges: lat.len() as u32,
            }
        })
        .collect()
}
