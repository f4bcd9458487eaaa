//! Log benchmark (issue 18): `btfsm log report` on a 10-million-record
//! BehaviorTree.CPP `FileLogger2` log (90 MB), generated here at bench time
//! after the header (tree XML) of tests/fixtures/logs/fig01.btlog, which
//! BehaviorTree.CPP wrote; the target is under 2 s. Also times `log
//! compare` of the log with itself (every action execution told and
//! compared) and `log timeline` (two passes). `cargo bench --bench log`;
//! `-- --test` (make test) runs 100,000 records.

#![allow(
    clippy::print_stdout,
    clippy::print_stderr,
    reason = "benchmarks and tests report what they measured"
)]

use btfsm_log::{compare, report, timeline};
use std::io::Write;
use std::time::Instant;

fn main() {
    let quick = std::env::args().any(|a| a == "--test");
    let n: u64 = if quick { 100_000 } else { 10_000_000 };
    let fixture = std::fs::read("tests/fixtures/logs/fig01.btlog").expect("fixture");
    let xml = i32::from_le_bytes(fixture[19..23].try_into().unwrap()) as usize;
    let dir = std::env::temp_dir().join(format!("btfsm-bench-log-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("big.btlog");
    {
        let mut w = std::io::BufWriter::new(std::fs::File::create(&path).expect("create"));
        w.write_all(&fixture[..23 + xml + 8]).unwrap();
        // Each of Fig. 1's 14 nodes in turn: RUNNING, SUCCESS, FAILURE, IDLE.
        for i in 0..n {
            let mut rec = [0u8; 9];
            rec[..6].copy_from_slice(&(i * 10).to_le_bytes()[..6]);
            rec[6..8].copy_from_slice(&((i % 14) as u16 + 1).to_le_bytes());
            rec[8] = [1, 2, 3, 0][(i / 14 % 4) as usize];
            w.write_all(&rec).unwrap();
        }
        w.flush().unwrap();
    }
    let size = std::fs::metadata(&path).unwrap().len();
    let open = || std::fs::File::open(&path).expect("open");
    let t = Instant::now();
    let r = report::report("big.btlog", open(), 1 << 26).expect("report");
    let report_s = t.elapsed().as_secs_f64();
    assert_eq!(r.records, n);
    println!(
        "log report: {n} records ({:.1} MB) in {report_s:.3} s ({:.1} M records/s; target < 2 s for 10 M)",
        size as f64 / 1e6,
        n as f64 / report_s / 1e6
    );
    let t = Instant::now();
    let a = compare::open("a", open(), None, 1 << 26).expect("a");
    let b = compare::open("b", open(), None, 1 << 26).expect("b");
    let c = compare::compare(a, b, None, false).expect("compare");
    println!(
        "log compare (the log with itself): {} actions each in {:.3} s",
        c.a.actions,
        t.elapsed().as_secs_f64()
    );
    let t = Instant::now();
    let tl = timeline::timeline("big.btlog", || std::fs::File::open(&path), 1 << 26, 1000)
        .expect("timeline");
    println!(
        "log timeline: {} rows, {} bars, {} marks, {} bytes of SVG in {:.3} s",
        tl.rows,
        tl.bars,
        tl.marks,
        tl.svg.len(),
        t.elapsed().as_secs_f64()
    );
    let _ = std::fs::remove_dir_all(&dir);
    if !quick && report_s >= 2.0 {
        eprintln!("log report took {report_s:.3} s: over the 2 s target");
        std::process::exit(1);
    }
}
