//! Monte Carlo episodes (`sim --runs N`, SPEC §6): seeded episodes with
//! jittered disturbances, run in parallel over the cores and combined in
//! episode order, so that the figures do not depend on the thread count.

use super::rng::SimRng;
use super::robot::round3;
use super::run::{RunOptions, cut_short, prepare, run_policy};
use super::scenario::{Disturbance, Effect, Scenario, When};
use super::trace::Outcome;
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
    pub chattering: u32,
    pub timeouts: u32,
    pub failures: u32,
    /// Mean completion time of the successful episodes, s.
    pub mean_completion_s: Option<f64>,
    /// Mean latency from a battery-low event to the start of Recharge, s.
    pub mean_recharge_latency_s: Option<f64>,
    pub recharges: u32,
}

/// The disturbances and failure rates of episode `i`: the scenario's, with
/// timed ones jittered, plus the `monte_carlo` battery drop and rates.
pub fn episode(s: &Scenario, seed: u64, i: u32) -> (u64, Vec<Disturbance>, BTreeMap<String, f64>) {
    let ep_seed = SimRng::named(seed, &format!("episode-{i}")).next_u64();
    let mut rng = SimRng::named(ep_seed, "disturbances");
    let mut ds = s.disturbances.clone();
    // Timed disturbances happen anywhere from half to one and a half times
    // their scenario time.
    for d in &mut ds {
        if let When::At(t) = &mut d.when {
            *t = (*t * rng.range(0.5, 1.5) * 10.0).round() / 10.0;
        }
    }
    if let Some((p, (lo, hi), (t0, t1))) = s.monte_carlo.battery_drop
        && rng.chance(p)
    {
        let level = rng.range(lo, hi).round();
        let at = (rng.range(t0, t1) * 10.0).round() / 10.0;
        ds.push(Disturbance {
            when: When::At(at),
            effect: Effect::Battery(level),
            text: format!("battery set to {level}%"),
        });
    }
    let mut rates = s.rates.clone();
    for (k, v) in &s.monte_carlo.rates {
        let e = rates.entry(k.clone()).or_insert(0.0);
        *e = 1.0 - (1.0 - *e) * (1.0 - v);
    }
    (ep_seed, ds, rates)
}

/// Runs `runs` seeded episodes of every policy on `threads` threads.
pub fn monte_carlo(s: &Scenario, runs: u32, seed: u64, threads: usize) -> Vec<McStats> {
    monte_carlo_within(s, runs, seed, threads, None).0
}

/// [`monte_carlo`] under a wall-clock deadline: once it passes, every
/// thread stops (the episode in progress is cut within [`CLOCK_EVERY`]
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
) -> (Vec<McStats>, u32) {
    let prepared = prepare(s);
    let threads = threads.max(1).min(runs.max(1) as usize);
    let stop = AtomicBool::new(false);
    // results[policy][episode] = (outcome, goal, completion, latencies)
    type Res = (Outcome, Option<bool>, Option<f64>, Vec<f64>);
    let mut per_thread: Vec<Vec<(u32, usize, Res)>> = Vec::new();
    std::thread::scope(|sc| {
        let prepared = &prepared;
        let stop = &stop;
        // One worker's episodes: t, t + threads, ...
        let work = move |t: usize| {
            let mut out = Vec::new();
            let mut i = t as u32;
            'episodes: while i < runs {
                if stop.load(Ordering::Relaxed) {
                    break;
                }
                let (ep_seed, ds, rates) = episode(s, seed, i);
                let first = out.len();
                for (k, p) in prepared.iter().enumerate() {
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
                            deadline,
                        },
                    );
                    if cut_short(s, &r) {
                        stop.store(true, Ordering::Relaxed);
                        out.truncate(first);
                        break 'episodes;
                    }
                    out.push((
                        i,
                        k,
                        (r.outcome, r.goal_met, r.completion_s, r.recharge_latency_s),
                    ));
                }
                i += threads as u32;
            }
            out
        };
        let mut handles = Vec::new();
        for t in 0..threads {
            // A thread the system refuses (a limit on processes) does its
            // share on this one instead: the same episodes, the same figures.
            match std::thread::Builder::new().spawn_scoped(sc, move || work(t)) {
                Ok(h) => handles.push(h),
                Err(_) => per_thread.push(work(t)),
            }
        }
        for h in handles {
            per_thread.push(h.join().expect("episode thread"));
        }
    });
    let mut all: Vec<(u32, usize, Res)> = per_thread.into_iter().flatten().collect();
    // Episodes come whole (all policies) or not at all: keep the prefix of
    // consecutive completed ones.
    let mut complete = vec![false; runs as usize];
    for (i, _, _) in &all {
        complete[*i as usize] = true;
    }
    let runs = complete.iter().position(|c| !c).unwrap_or(complete.len()) as u32;
    all.retain(|(i, _, _)| *i < runs);
    all.sort_by_key(|(i, k, _)| (*k, *i));
    let stats = prepared
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
            let comp: Vec<f64> = ok.iter().filter_map(|r| r.2).collect();
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
                mean_completion_s: mean(&comp),
                mean_recharge_latency_s: mean(&lat),
                recharges: lat.len() as u32,
            }
        })
        .collect();
    (stats, runs)
}
