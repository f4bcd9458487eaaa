//! The GED search's budgets (issue 34; docs/performance.md, "Budgets and
//! the CPU-time cap"): the work budget decides every reported value, the
//! same beside CPU hogs as on a quiet machine, since the safety cap counts
//! CPU time, not wall-clock time; and a pair settled with little work takes
//! the same work whatever the budget.

use crate::common::btfsm;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

const DIR: &str = "tests/fixtures/compare/ged-budget";

/// `compare --format json` with the timing fields (`millis`, `micros`)
/// removed, its exit code, and the CPU time the child used (ms).
fn compare_untimed(a: &str, b: &str, extra: &[&str]) -> (i32, serde_json::Value, u64) {
    let before = children_cpu_ms();
    let mut args = vec!["compare", a, b, "--format", "json"];
    args.extend_from_slice(extra);
    let (code, stdout, stderr) = btfsm(&args);
    let cpu = children_cpu_ms().saturating_sub(before);
    let mut v: serde_json::Value = serde_json::from_str(&stdout).unwrap_or_else(|e| {
        panic!("{e}: {stdout}{stderr}");
    });
    for mode in ["structural", "labeled", "named"] {
        if let Some(m) = v.get_mut(mode).and_then(|m| m.as_object_mut()) {
            m.remove("millis");
            m.remove("micros");
        }
    }
    (code, v, cpu)
}

/// CPU time (user + system) of the waited-for children of this process.
fn children_cpu_ms() -> u64 {
    // SAFETY: getrusage writes one rusage struct that this function owns.
    let mut ru: libc::rusage = unsafe { std::mem::zeroed() };
    let r = unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut ru) };
    assert_eq!(r, 0);
    let ms = |t: libc::timeval| t.tv_sec as u64 * 1000 + t.tv_usec as u64 / 1000;
    ms(ru.ru_utime) + ms(ru.ru_stime)
}

/// Busy-loop threads, four per core, until dropped (a few seconds: other
/// tests of the suite run beside them).
struct Hogs {
    stop: Arc<AtomicBool>,
    threads: Vec<std::thread::JoinHandle<u64>>,
}

impl Hogs {
    fn start() -> Hogs {
        let cores = std::thread::available_parallelism().map_or(2, |n| n.get());
        let stop = Arc::new(AtomicBool::new(false));
        let threads = (0..4 * cores)
            .map(|i| {
                let stop = Arc::clone(&stop);
                std::thread::spawn(move || {
                    let mut x = i as u64;
                    while !stop.load(Ordering::Relaxed) {
                        for _ in 0..10_000 {
                            x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                        }
                    }
                    x
                })
            })
            .collect();
        Hogs { stop, threads }
    }
}

impl Drop for Hogs {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

/// A pair whose structural search the work budget ends, with a safety cap
/// of three times the CPU time the quiet run took: beside four busy
/// threads per core the run takes about 4.5 times as long on the wall
/// clock (a wall-clock cap would fire: it did before issue 34), yet the
/// result, interval, work and exit code are the quiet run's.
#[test]
fn a_budget_bounded_search_gives_the_same_result_beside_cpu_hogs() {
    let (a, b) = (format!("{DIR}/hard-a.toml"), format!("{DIR}/hard-b.toml"));
    let work = ["--mode", "structural", "--work", "300000"];
    let (code, quiet, cpu) = compare_untimed(&a, &b, &work);
    assert_eq!(code, 0, "{quiet}");
    assert_eq!(quiet["structural"]["stopped_by"], "work", "{quiet}");
    assert_eq!(quiet["structural"]["exact"], false);
    let cap = (3 * cpu).max(300).to_string();
    let mut capped = work.to_vec();
    capped.extend_from_slice(&["--timeout-ms", &cap]);
    let (code, again, _) = compare_untimed(&a, &b, &capped);
    assert_eq!((code, &again), (0, &quiet));
    let hogs = Hogs::start();
    let (code, loaded, _) = compare_untimed(&a, &b, &capped);
    let (dcode, loaded_default, _) = compare_untimed(&a, &b, &work);
    drop(hogs);
    assert_eq!((code, &loaded), (0, &quiet), "capped at {cap} ms CPU");
    assert_eq!((dcode, &loaded_default), (0, &quiet), "default cap");
}

/// A cap that fires says so: `stopped_by: time` and exit code 3.
#[test]
fn a_search_ended_by_the_cpu_cap_says_so_and_exits_3() {
    let (a, b) = (format!("{DIR}/hard-a.toml"), format!("{DIR}/hard-b.toml"));
    let (code, v, _) = compare_untimed(&a, &b, &["--mode", "structural", "--timeout-ms", "1"]);
    assert_eq!(code, 3, "{v}");
    assert_eq!(v["structural"]["stopped_by"], "time", "{v}");
    assert_eq!(v["structural"]["exact"], false);
    let (code, stdout, _) = btfsm(&[
        "compare",
        &a,
        &b,
        "--mode",
        "structural",
        "--timeout-ms",
        "1",
    ]);
    assert_eq!(code, 3);
    assert!(stdout.contains("CPU-time safety cap"), "{stdout}");
}

/// A pair the search settles with under a million work units takes the
/// same work at `--work 5000000` and at the default budget (300 million):
/// no phase is sized by the budget. (Before issue 34 it took 1.6 and 2.7
/// million.)
#[test]
fn an_easy_pair_takes_the_same_work_whatever_the_budget() {
    let (a, b) = (format!("{DIR}/easy-a.toml"), format!("{DIR}/easy-b.toml"));
    let (c1, small, _) = compare_untimed(&a, &b, &["--mode", "labeled", "--work", "5000000"]);
    let (c2, default, _) = compare_untimed(&a, &b, &["--mode", "labeled"]);
    assert_eq!((c1, c2), (0, 0));
    assert_eq!(small["labeled"]["exact"], true, "{small}");
    let w = small["labeled"]["work"].as_u64().expect("work");
    assert!(w > 0 && w < 1_000_000, "{small}");
    assert_eq!(small, default);
}
