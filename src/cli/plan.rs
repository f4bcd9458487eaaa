//! `btfsm plan DOMAIN`: backchains the domain's goal into a BT, derives the
//! fault-tolerant FSM of the same plan and the HFSM of the BT (the paper's
//! BT -> HFSM construction), prints the conflicts the planner resolved or
//! left and the metrics of the three side by side, and writes the policies
//! with `-o DIR` (or one of them to stdout with `-o -`).

use super::io::{emit_text, fail, print_diagnostics};
use super::{EXIT_BAD_INPUT, EXIT_OK};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_core::output::{Format, Report};
use btfsm_format::{Limits, Loaded};
use btfsm_model::{Policy, PolicyBody};
use btfsm_plan::{self as plan, Options};
use btfsm_report::{self as report};
use clap::{Args, ValueEnum};
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum PlanTarget {
    /// The backchained Behavior Tree
    Bt,
    /// The fault-tolerant FSM of the same plan (SELECTOR with triangle-table kernels)
    Fsm,
    /// The HFSM of the BT (the paper's BT -> HFSM construction)
    Hfsm,
    /// All three
    All,
}

#[derive(Debug, Args)]
pub(crate) struct PlanArgs {
    /// Action domain (TOML, or PDDL: a `.pddl` file; docs/guide/plan.md),
    /// e.g. policies/domains/moma.toml
    pub domain: PathBuf,
    /// PDDL problem of a PDDL domain: its objects, `:init` (the facts at
    /// the start) and `:goal` (the goal)
    #[arg(long, value_name = "FILE")]
    pub problem: Option<PathBuf>,
    /// A task of the domain (`[tasks.NAME]`) instead of its `[goal]`
    #[arg(long, value_name = "NAME")]
    pub task: Option<String>,
    /// Goal fact replacing the domain's goal, e.g. "Object-At(cube2, delivery)"
    /// (repeat for several, in order)
    #[arg(long = "goal", value_name = "FACT")]
    pub goals: Vec<String>,
    /// A fact that holds at the start, replacing the goal's `init` (repeat
    /// for several; every other fact is false): the planned FSM starts at
    /// the step these facts let it resume at
    #[arg(long = "init", value_name = "FACT")]
    pub init: Vec<String>,
    /// Which policies to make
    #[arg(long, value_enum, default_value_t = PlanTarget::All)]
    pub to: PlanTarget,
    /// Write the policies (TOML) into this directory as NAME-bt.toml,
    /// NAME-fsm.toml, NAME-hfsm.toml; `-`: the one policy of --to on stdout
    #[arg(short, long, value_name = "DIR")]
    pub output: Option<PathBuf>,
    /// Keep the domain's precondition order and only report the conflicts
    /// (a later sibling undoing an earlier one's condition: the robot chatters)
    #[arg(long)]
    pub no_reorder: bool,
    /// Deepest nesting of achievers below a goal condition (1 to 256)
    #[arg(long, default_value_t = 16, value_name = "N", value_parser = clap::value_parser!(u16).range(1..=256))]
    pub max_plan_depth: u16,
    /// Output format of the report: table, json, or csv (the metrics rows,
    /// as `analyze` writes them; the conflicts are in table and json)
    #[arg(long, value_parser = super::format::parser(PlanReport::FORMATS, &[]), default_value = "table")]
    pub format: Format,
    #[command(flatten)]
    pub limits: super::args::LimitArgs,
}

/// Reads and validates a domain file, printing its errors.
pub(super) fn read_domain(path: &Path, limits: &Limits) -> Option<plan::Domain> {
    read_task(path, None, limits)
}

/// Reads a domain file (TOML or PDDL) and, for a PDDL domain, its problem
/// file, printing their errors.
fn read_task(path: &Path, problem: Option<&Path>, limits: &Limits) -> Option<plan::Domain> {
    let stderr = std::io::stderr();
    let read = |p: &Path| {
        btfsm_format::source::read(p, &p.display().to_string(), limits, true).map_err(|d| {
            print_diagnostics(&mut stderr.lock(), &d);
        })
    };
    let file = read(path).ok()?;
    let loaded = if plan::pddl::looks_like_pddl(&file.path, &file.text) {
        let problem = match problem {
            Some(p) => Some(read(p).ok()?),
            None => None,
        };
        plan::pddl::load(&file, problem.as_ref())
    } else if problem.is_some() {
        Err(vec![
            Diagnostic::error("--problem is for a PDDL domain; this domain is TOML")
                .in_file(&file)
                .hint("a TOML domain holds its goal (`[goal]`, `--goal`, `--task`)"),
        ])
    } else {
        plan::load(&file)
    };
    match loaded {
        Ok(d) => Some(d),
        Err(d) => {
            print_diagnostics(&mut stderr.lock(), &d);
            None
        }
    }
}

/// The goal and start the options give (`--task`, `--goal`, `--init`),
/// or the exit code when they are wrong.
fn set_task(a: &PlanArgs, domain: &mut plan::Domain, shown: &str) -> Result<(), u8> {
    if domain.goal.facts.is_empty() && a.goals.is_empty() {
        return Err(fail(
            Diagnostic::error(format!("{shown}: the PDDL domain has no goal"))
                .hint("give its problem with --problem FILE, or the goal with --goal FACT"),
        ));
    }
    if let Some(t) = &a.task
        && let Err(e) = domain.select_task(t)
    {
        return Err(fail(Diagnostic::error(e.to_string())));
    }
    let set = |d: &mut plan::domain::Domain| {
        if !a.goals.is_empty() {
            d.set_goal(&a.goals)?;
        }
        if !a.init.is_empty() {
            d.set_init(&a.init)?;
        }
        Ok::<(), Vec<String>>(())
    };
    if let Err(es) = set(domain) {
        for e in es {
            eprint!("{}", Diagnostic::error(e.to_string()));
        }
        return Err(EXIT_BAD_INPUT);
    }
    Ok(())
}

pub(super) fn execute(a: PlanArgs) -> u8 {
    let limits = a.limits.limits();
    let shown = a.domain.display().to_string();
    let Some(mut domain) = read_task(&a.domain, a.problem.as_deref(), &limits) else {
        return EXIT_BAD_INPUT;
    };
    if let Err(code) = set_task(&a, &mut domain, &shown) {
        return code;
    }
    let opts = Options {
        reorder: !a.no_reorder,
        max_depth: usize::from(a.max_plan_depth),
        max_nodes: limits.max_nodes,
        ..Options::default()
    };
    let planned = match plan::plan_bt(&domain, &opts) {
        Ok(p) => p,
        Err(e) => {
            return fail(
                Diagnostic::error(format!("{shown}: {e}"))
                    .hint("raise --max-nodes, or lower --max-plan-depth"),
            );
        }
    };
    let policies = match policies(&domain, &planned, a.to, &limits) {
        Ok(p) => p,
        Err(e) => {
            return fail(Diagnostic::error(format!("{shown}: {e}")));
        }
    };
    if a.output.as_deref() == Some(Path::new("-")) {
        let [(_, p)] = policies.as_slice() else {
            return fail(Diagnostic::error(
                "`-o -` writes one policy: choose it with --to bt, fsm or hfsm",
            ));
        };
        return emit_text(None, btfsm_format::toml_write::write_policy(p));
    }
    let mut written: Vec<(String, &Policy)> = Vec::new();
    for (tag, p) in &policies {
        written.push((format!("{}-{tag}.toml", domain.name), p));
    }
    if let Some(dir) = &a.output {
        if let Err(code) = super::io::create_output_dir(dir) {
            return code;
        }
        for (name, p) in &written {
            let code = emit_text(
                Some(&dir.join(name)),
                btfsm_format::toml_write::write_policy(p),
            );
            if code != EXIT_OK {
                return code;
            }
        }
    }
    let rows: Vec<report::PolicyReport> = written
        .iter()
        .map(|(name, p)| {
            let path = match &a.output {
                Some(dir) => dir.join(name).display().to_string(),
                None => name.clone(),
            };
            report::analyze(&Loaded {
                path,
                policy: (*p).clone(),
                warnings: Vec::new(),
                dataflow: None,
            })
        })
        .collect();
    let text = PlanReport::new(&domain, &planned, &rows).write(a.format);
    let code = emit_text(None, text);
    let left = planned.conflicts.iter().any(|c| {
        matches!(
            c.outcome,
            plan::conflicts::Outcome::Left | plan::conflicts::Outcome::Cycle
        )
    });
    if code == EXIT_OK && left && !a.no_reorder {
        // A cycle no order resolves: the tree chatters; say so in the status.
        return super::EXIT_CHECK_FAILED;
    }
    code
}

/// What `plan` prints: the goal, the conflicts and the planned policies'
/// figures (the `analyze` rows), as a table, JSON or CSV.
#[derive(serde::Serialize)]
struct PlanReport<'a> {
    domain: &'a str,
    goal: Vec<String>,
    conflicts: &'a [plan::conflicts::Conflict],
    policies: &'a [report::PolicyReport],
}

impl<'a> PlanReport<'a> {
    fn new(
        domain: &'a plan::Domain,
        planned: &'a plan::Planned,
        rows: &'a [report::PolicyReport],
    ) -> Self {
        PlanReport {
            domain: &domain.name,
            goal: domain.goal.facts.iter().map(ToString::to_string).collect(),
            conflicts: &planned.conflicts,
            policies: rows,
        }
    }

    fn table(&self) -> String {
        use btfsm_core::sanitize::shown;
        let mut s = format!(
            "domain `{}`, goal: {}\n",
            shown(self.domain),
            shown(&self.goal.join(", "))
        );
        let shown_conflicts: Vec<&plan::conflicts::Conflict> = (self.conflicts.iter())
            .filter(|c| c.outcome != plan::conflicts::Outcome::InOrder)
            .collect();
        if shown_conflicts.is_empty() {
            s.push_str("conflicts: none\n");
        } else {
            s.push_str("conflicts:\n");
            for c in shown_conflicts {
                s.push_str(&format!("  {c}\n"));
            }
        }
        s.push('\n');
        s.push_str(&report::render_analysis(self.policies, Format::Table));
        s
    }
}

impl Report for PlanReport<'_> {
    const FORMATS: &'static [Format] = &[Format::Table, Format::Json, Format::Csv];

    fn write(&self, format: Format) -> String {
        match Self::supported(format) {
            Format::Csv => report::render_analysis(self.policies, Format::Csv),
            Format::Json => {
                let mut s = btfsm_core::sanitize::json(
                    serde_json::to_string_pretty(self).expect("serializable"),
                );
                s.push('\n');
                s
            }
            _ => self.table(),
        }
    }
}

/// The policies `to` asks for, named after the domain.
fn policies(
    d: &plan::Domain,
    planned: &plan::Planned,
    to: PlanTarget,
    limits: &Limits,
) -> Result<Vec<(&'static str, Policy)>, String> {
    let desc = |what: &str| {
        Some(format!(
            "{what} generated by `btfsm plan` from domain `{}` (goal: {})",
            d.name,
            d.goal
                .facts
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ))
    };
    let bt = Policy {
        name: format!("{} (planned BT)", d.name),
        description: desc("Behavior Tree"),
        body: PolicyBody::Bt(planned.bt.clone()),
    };
    let mut out = Vec::new();
    if matches!(to, PlanTarget::Bt | PlanTarget::All) {
        out.push(("bt", bt.clone()));
    }
    if matches!(to, PlanTarget::Fsm | PlanTarget::All) {
        let m = plan::fsm::plan_fsm(d, planned).map_err(|e| e.to_string())?;
        out.push((
            "fsm",
            Policy {
                name: format!("{} (planned fault-tolerant FSM)", d.name),
                description: desc("Fault-tolerant FSM"),
                body: PolicyBody::Machine(m),
            },
        ));
    }
    if matches!(to, PlanTarget::Hfsm | PlanTarget::All) {
        let h = btfsm_transform::bt_to_hfsm::bt_policy_to_hfsm(&bt).map_err(|es| {
            es.iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join("; ")
        })?;
        out.push(("hfsm", h));
    }
    for (_, p) in &out {
        if let Some(d) = btfsm_format::check_shape(p, limits) {
            return Err(d.message);
        }
    }
    Ok(out)
}
