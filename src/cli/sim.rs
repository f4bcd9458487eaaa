//! `btfsm sim`: runs the policies of a scenario in the planar simulator and
//! prints outcomes, executed skills, final worlds and behavior-match verdicts
//! (SPEC §6, §7); `--runs N` runs seeded Monte Carlo episodes instead.

use super::commands::{emit, print_diagnostics};
use super::{EXIT_BAD_INPUT, EXIT_OK};
use crate::report::OutputFormat;
use crate::sim::report::{McReport, SimReport};
use crate::sim::{plot, run, scenario};
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct SimArgs {
    /// Scenario file (TOML)
    pub scenario: PathBuf,
    /// Output format (table or json)
    #[arg(long, value_enum, default_value_t = OutputFormat::Table)]
    pub format: OutputFormat,
    /// Write the full trace (every step of every run) as JSON
    #[arg(long, value_name = "OUT.json")]
    pub trace: Option<PathBuf>,
    /// Draw the room and each policy's trajectory as SVG
    #[arg(long, value_name = "OUT.svg")]
    pub plot: Option<PathBuf>,
    /// Run N seeded episodes with randomized disturbances and failure rates
    #[arg(long, value_name = "N")]
    pub runs: Option<u32>,
    /// Seed of the episodes (default: the scenario's seed)
    #[arg(long, value_name = "S")]
    pub seed: Option<u64>,
    /// Worker threads for --runs (default: the number of cores)
    #[arg(long)]
    pub threads: Option<usize>,
    #[command(flatten)]
    pub limits: super::args::LimitArgs,
}

pub fn execute(a: SimArgs) -> u8 {
    if a.format == OutputFormat::Csv {
        eprintln!("error: `sim` prints `table` or `json`, not `csv`");
        return EXIT_BAD_INPUT;
    }
    let mut s = match scenario::load(&a.scenario, &a.limits.limits()) {
        Ok(s) => s,
        Err(d) => {
            print_diagnostics(&mut std::io::stderr().lock(), &d);
            return EXIT_BAD_INPUT;
        }
    };
    let file = a.scenario.display().to_string();
    if let Some(n) = a.runs {
        if a.trace.is_some() || a.plot.is_some() {
            eprintln!("error: --trace and --plot record one run; leave them out with --runs");
            return EXIT_BAD_INPUT;
        }
        let seed = a.seed.unwrap_or(s.seed);
        let threads = a
            .threads
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
        let t0 = std::time::Instant::now();
        let stats = run::monte_carlo(&s, n, seed, threads);
        let rep = McReport {
            scenario: s.name.clone(),
            seed,
            runs: n,
            threads: threads.max(1).min(n.max(1) as usize),
            millis: t0.elapsed().as_millis(),
            policies: stats,
        };
        let text = match a.format {
            OutputFormat::Json => rep.json(),
            _ => rep.table(),
        };
        return emit(None, text.as_bytes());
    }
    if let Some(seed) = a.seed {
        s.seed = seed;
    }
    let runs = run::run_scenario(&s, a.trace.is_some());
    let rep = SimReport::new(&s.name, &file, s.seed, s.dt, runs);
    if let Some(p) = &a.trace
        && emit(Some(p), rep.trace_json().as_bytes()) != EXIT_OK
    {
        return EXIT_BAD_INPUT;
    }
    if let Some(p) = &a.plot
        && emit(Some(p), plot::svg(&s, &rep.policies).as_bytes()) != EXIT_OK
    {
        return EXIT_BAD_INPUT;
    }
    let text = match a.format {
        OutputFormat::Json => rep.json(),
        _ => rep.table(),
    };
    emit(None, text.as_bytes())
}
