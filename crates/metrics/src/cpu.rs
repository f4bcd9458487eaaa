//! The safety cap of the exact searches, counted in CPU time of the thread
//! that runs them (issue 34): `clock_gettime(CLOCK_THREAD_CPUTIME_ID)`
//! (POSIX.1-2008, `time.h`), so that other processes on a loaded machine
//! cannot make it fire sooner. The work budgets (`ged::GedOptions::work`)
//! decide every reported value; this cap only stops a search whose work
//! accounting would have let it run far past what its budget takes, and a
//! result it ends says so (`ged::StopReason::Time`).
//!
//! The clock is read only once the wall clock says the cap could have
//! passed: a thread cannot use more CPU time than the wall-clock time since
//! it started measuring, so on a quiet machine each check costs one
//! `Instant::now()`, and the system call is made only past the cap's
//! wall-clock time.

use std::time::{Duration, Instant};

/// The CPU time this thread has used, or `None` where the clock is
/// unavailable (then [`Deadline`] falls back on the wall clock).
pub fn thread_cpu_time() -> Option<Duration> {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes one timespec that this function owns.
    let r = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if r != 0 {
        return None;
    }
    let secs = u64::try_from(ts.tv_sec).ok()?;
    let nanos = u32::try_from(ts.tv_nsec).ok()?;
    Some(Duration::new(secs, nanos))
}

/// A point in this thread's CPU time past which a search stops. Checked
/// only on the thread that made it (a search is single-threaded).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Deadline {
    /// The wall-clock time before which the cap cannot have passed; `None`:
    /// never.
    wall: Option<Instant>,
    /// This thread's CPU time at which the cap passes (`None`: the clock is
    /// unavailable, the wall clock decides).
    cpu: Option<Duration>,
}

impl Deadline {
    /// After `budget` more CPU time of this thread.
    pub fn after(budget: Duration) -> Deadline {
        let cpu = thread_cpu_time().and_then(|c| c.checked_add(budget));
        let wall = Instant::now().checked_add(budget);
        Deadline {
            wall: if cpu.is_some() || thread_cpu_time().is_none() {
                wall
            } else {
                None
            },
            cpu,
        }
    }

    /// A cap that never passes.
    pub fn never() -> Deadline {
        Deadline {
            wall: None,
            cpu: None,
        }
    }

    /// Whether this thread has used the budget.
    pub fn passed(&self) -> bool {
        let Some(wall) = self.wall else {
            return false;
        };
        if Instant::now() < wall {
            return false;
        }
        match (self.cpu, thread_cpu_time()) {
            (Some(cap), Some(now)) => now >= cap,
            _ => true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sleeping uses no CPU time: a cap of 20 ms outlives 60 ms of sleep,
    /// and then passes once the thread has computed for 20 ms.
    #[test]
    fn the_cap_counts_cpu_time_not_sleep() {
        if thread_cpu_time().is_none() {
            return;
        }
        let d = Deadline::after(Duration::from_millis(20));
        std::thread::sleep(Duration::from_millis(60));
        assert!(!d.passed(), "sleep counted as CPU time");
        let mut x = 0u64;
        let spin = Instant::now();
        while !d.passed() {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
            assert!(spin.elapsed() < Duration::from_secs(60), "{x}");
        }
        assert!(Deadline::after(Duration::ZERO).passed());
        assert!(!Deadline::never().passed());
        assert!(!Deadline::after(Duration::MAX).passed());
    }
}
