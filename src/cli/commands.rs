//! Runs each command: loads and validates inputs, calls the library, prints.

use super::args::{Cli, Command, ConvertTarget};
use super::{EXIT_BAD_INPUT, EXIT_CHECK_FAILED, EXIT_OK};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_core::sanitize::shown;
use btfsm_format::{self as format, Limits, Loaded};
use btfsm_report::gate::{Baseline, Gate, Limit};
use btfsm_report::{self as report, analyze, render_analysis};
use std::io::Write;
use std::path::{Path, PathBuf};

#[expect(clippy::too_many_lines, reason = "to be split: issue 28")]
pub(super) fn execute(cli: Cli) -> u8 {
    match cli.command {
        Command::Analyze {
            files,
            format,
            max,
            baseline,
            max_increase,
            limits,
        } => {
            let limits = limits.limits();
            let Some(gate) = gate(max, baseline.as_deref(), max_increase, &limits) else {
                return EXIT_BAD_INPUT;
            };
            // A report for the files that load, an error for each that
            // does not, and exit 2 at the end when any failed.
            let Some((loaded, failed)) = load_inputs(&files, &limits) else {
                return EXIT_BAD_INPUT;
            };
            let reports: Vec<_> = loaded.iter().map(analyze).collect();
            let code = emit_text(None, render_analysis(&reports, format));
            if failed {
                return EXIT_BAD_INPUT;
            }
            if code != EXIT_OK || gate.is_empty() {
                return code;
            }
            check_gate(&gate, &reports)
        }
        Command::Validate { files, limits } => {
            let limits = limits.limits();
            let stderr = std::io::stderr();
            let mut err = stderr.lock();
            let mut failed = false;
            let inputs = match format::discover::expand(&files) {
                Ok(i) => i,
                Err(d) => {
                    print_diagnostics(&mut err, &[d]);
                    return EXIT_BAD_INPUT;
                }
            };
            let mut skipped = 0usize;
            for input in &inputs {
                let f = &input.path;
                // Read once; a scenario is validated as `sim` reads it (its
                // policies included), without running it.
                let read = format::discover::read(input, &limits);
                let (file, input) = match read {
                    Ok((file, Some(i))) => (file, i),
                    Ok((_, None)) => {
                        skipped += 1;
                        continue;
                    }
                    Err(diags) => {
                        failed = true;
                        print_diagnostics(&mut err, &diags);
                        continue;
                    }
                };
                let fmt = match input {
                    format::Input::Policy(fmt) => fmt,
                    format::Input::Domain => {
                        match btfsm_plan::load(&file) {
                            Ok(d) => {
                                let _ = writeln!(
                                    err,
                                    "{}: ok (action domain `{}`, {} predicates, {} actions, {} task{})",
                                    shown(&f.display().to_string()),
                                    shown(&d.name),
                                    d.predicates.len(),
                                    d.actions.len(),
                                    d.tasks.len() + 1,
                                    if d.tasks.is_empty() { "" } else { "s" }
                                );
                            }
                            Err(diags) => {
                                failed = true;
                                print_diagnostics(&mut err, &diags);
                            }
                        }
                        continue;
                    }
                    format::Input::Scenario if btfsm_sim::symbolic::looks_symbolic(&file.text) => {
                        let base = f.parent().unwrap_or(Path::new(""));
                        match btfsm_sim::symbolic::scenario::parse(&file, base, &limits) {
                            Ok(s) => {
                                let _ = writeln!(
                                    err,
                                    "{}: ok (symbolic scenario `{}`, domain `{}`, {} polic{})",
                                    shown(&f.display().to_string()),
                                    shown(&s.name),
                                    shown(&s.domain.name),
                                    s.policies.len(),
                                    if s.policies.len() == 1 { "y" } else { "ies" }
                                );
                            }
                            Err(diags) => {
                                failed = true;
                                print_diagnostics(&mut err, &diags);
                            }
                        }
                        continue;
                    }
                    format::Input::Scenario => {
                        let base = f.parent().unwrap_or(Path::new(""));
                        match btfsm_sim::scenario::parse(&file, base, &limits) {
                            Ok(s) => {
                                print_diagnostics(&mut err, &s.warnings);
                                let _ = writeln!(
                                    err,
                                    "{}: ok (scenario `{}`, {} polic{})",
                                    shown(&f.display().to_string()),
                                    shown(&s.name),
                                    s.policies.len(),
                                    if s.policies.len() == 1 { "y" } else { "ies" }
                                );
                            }
                            Err(diags) => {
                                failed = true;
                                print_diagnostics(&mut err, &diags);
                            }
                        }
                        continue;
                    }
                };
                match reported(format::load_read(file, f, fmt, &limits), &mut err) {
                    Some(l) => {
                        let _ = writeln!(
                            err,
                            "{}: ok ({} `{}`, {} warning{})",
                            shown(&l.path),
                            l.policy.kind(),
                            shown(&l.policy.name),
                            l.warnings.len(),
                            if l.warnings.len() == 1 { "" } else { "s" },
                        );
                    }
                    None => failed = true,
                }
            }
            note_skipped(&mut err, skipped);
            if failed || inputs.len() == skipped {
                if inputs.len() == skipped {
                    let _ = writeln!(
                        err,
                        "error: no policy or scenario file below the directories given"
                    );
                }
                EXIT_BAD_INPUT
            } else {
                EXIT_OK
            }
        }
        Command::Dot {
            file,
            output,
            render,
            timeout_ms,
            trace,
            look,
            limits,
        } => {
            let Some(l) = load_one(&file, &limits.limits()) else {
                return EXIT_BAD_INPUT;
            };
            let Some((policy, mut opts)) =
                super::sim::dot_trace(&trace, &file, l.policy, &limits.limits())
            else {
                return EXIT_BAD_INPUT;
            };
            look.apply(&mut opts);
            if let Err(e) = btfsm_render::dot::check_fold(&policy, &opts) {
                eprintln!("error: {e}");
                return EXIT_BAD_INPUT;
            }
            let timeout = std::time::Duration::from_millis(timeout_ms);
            draw(&policy, &opts, output.as_deref(), render, timeout)
        }
        Command::Compare {
            a,
            b,
            mode,
            timeout_ms,
            work,
            tree_max_work,
            format,
            dot,
            render,
            limits,
        } => super::compare::execute(super::compare::CompareArgs {
            a,
            b,
            mode,
            timeout_ms,
            work,
            tree_max_work,
            format,
            dot,
            render,
            limits: limits.limits(),
        }),
        Command::Convert {
            file,
            to,
            output,
            domain,
            limits,
        } => {
            if domain.is_some() && to != ConvertTarget::FaultTolerant {
                eprintln!("error: --domain applies to --to fault-tolerant only");
                return EXIT_BAD_INPUT;
            }
            let domain = match &domain {
                None => None,
                Some(path) => match super::plan::read_domain(path, &limits.limits()) {
                    Some(d) => Some(d),
                    None => return EXIT_BAD_INPUT,
                },
            };
            let Some(l) = load_one(&file, &limits.limits()) else {
                return EXIT_BAD_INPUT;
            };
            let policy = match to {
                ConvertTarget::Toml => l.policy,
                ConvertTarget::BtcppXml | ConvertTarget::Scxml => {
                    return super::convert::to_xml(&l.policy, to, output.as_deref());
                }
                ConvertTarget::Mermaid => {
                    return emit_text(
                        output.as_deref(),
                        btfsm_render::mermaid::policy_mermaid(&l.policy),
                    );
                }
                ConvertTarget::FaultTolerant => {
                    use btfsm_transform::fault_tolerant as ft;
                    let d = domain
                        .as_ref()
                        .unwrap_or_else(|| btfsm_plan::domain::builtin());
                    match ft::fault_tolerant_policy_with(&l.policy, d) {
                        Ok(p) => p,
                        Err(errs) => {
                            for e in errs {
                                eprintln!(
                                    "error: {}: {}\n  = hint: the construction needs a flat FSM whose action states run skills the domain has actions for (--domain; built in: policies/domains/moma.toml)",
                                    shown(&l.path),
                                    btfsm_core::sanitize::shown_max(&e.to_string(), 1000)
                                );
                            }
                            return EXIT_BAD_INPUT;
                        }
                    }
                }
                ConvertTarget::Hfsm => {
                    if let btfsm_model::PolicyBody::Bt(bt) = &l.policy.body {
                        for n in btfsm_transform::bt_to_hfsm::memory_nodes(bt) {
                            let node = &bt.nodes[n];
                            eprintln!(
                                "warning: {}: `{}` node `{}` becomes a container re-entered at its first state every tick: the HFSM counts as the paper's construction but does not keep the node's memory",
                                shown(&l.path),
                                node.kind.keyword(),
                                shown(&node.id)
                            );
                        }
                    }
                    match btfsm_transform::bt_to_hfsm::bt_policy_to_hfsm(&l.policy) {
                        Ok(p) => p,
                        Err(errs) => {
                            for e in errs {
                                eprintln!(
                                    "error: {}\n  = hint: the construction covers sequence, fallback (with or without memory), inverter, force_success, force_failure and leaves",
                                    btfsm_core::sanitize::shown_max(&e.to_string(), 1000)
                                );
                            }
                            return EXIT_BAD_INPUT;
                        }
                    }
                }
            };
            // Only what reads back: a machine the TOML format can nest,
            // within the file size limit.
            match btfsm_format::toml_write::write_policy_within(&policy, limits.max_file_bytes) {
                Ok(text) => emit_text(output.as_deref(), text),
                Err(e) => {
                    eprintln!(
                        "error: {}: {e}\n  = hint: SCXML has no nesting limit: convert a machine with --to scxml (a BT more than 39 levels deep has no HFSM in TOML)",
                        shown(&l.path)
                    );
                    EXIT_BAD_INPUT
                }
            }
        }
        Command::Effort {
            files,
            format,
            timeout_ms,
            limits,
        } => super::paper::effort(&files, format, timeout_ms, &limits.limits()),
        Command::Paper(args) => super::paper::paper(&args),
        Command::Edit(args) => super::edit::edit(&args),
        Command::Sim(args) => super::sim::execute(args),
        Command::Tick(args) => super::tick::execute(args),
        Command::Plan(args) => super::plan::execute(args),
        Command::Lint(args) => super::lint::execute(args),
        Command::Log(args) => super::log::execute(args),
        Command::View(args) => super::view::execute(args),
        Command::TedPairs(args) => super::ted_pairs::execute(args),
        Command::Completions { shell } => {
            use clap::CommandFactory;
            let mut out = Vec::new();
            clap_complete::generate(shell, &mut super::args::Cli::command(), "btfsm", &mut out);
            emit(None, &out)
        }
        Command::Man { subcommand } => {
            use clap::CommandFactory;
            let top = super::args::Cli::command();
            let cmd = match subcommand.as_deref() {
                None => top,
                Some(name) => match top.find_subcommand(name) {
                    Some(c) => c
                        .clone()
                        .name(format!("btfsm-{name}"))
                        .version(env!("CARGO_PKG_VERSION")),
                    None => {
                        eprintln!("error: no subcommand `{}`", shown(name));
                        return EXIT_BAD_INPUT;
                    }
                },
            };
            let mut out = Vec::new();
            match clap_mangen::Man::new(cmd).render(&mut out) {
                Ok(()) => emit(None, &out),
                Err(e) => {
                    eprintln!("error: cannot write the man page: {e}");
                    EXIT_BAD_INPUT
                }
            }
        }
    }
}

/// Draws a policy as DOT, or renders it through Graphviz (killed past
/// `timeout`), to `output` or stdout.
pub(super) fn draw(
    policy: &btfsm_model::Policy,
    opts: &btfsm_render::dot::DotOptions,
    output: Option<&Path>,
    render: Option<btfsm_render::dot::RenderFormat>,
    timeout: std::time::Duration,
) -> u8 {
    use btfsm_render::dot::{self, RenderFormat};
    let text = dot::policy_dot(policy, opts);
    // `-o x.png` means PNG: the format follows the extension unless given.
    let render = render.or_else(|| output.and_then(RenderFormat::from_path));
    let Some(fmt) = render else {
        return emit_text(output, text);
    };
    if output.is_none() && fmt != RenderFormat::Svg {
        eprintln!("error: {fmt} output is binary; write it to a file with -o");
        return EXIT_BAD_INPUT;
    }
    match dot::render(&text, fmt, timeout) {
        Ok(bytes) => emit(output, &bytes),
        Err(e) => {
            eprintln!(
                "error: {}",
                btfsm_core::sanitize::shown_max(&e.to_string(), 2000)
            );
            EXIT_BAD_INPUT
        }
    }
}

/// Loads one file (see [`load_all`]).
pub(super) fn load_one(file: &Path, limits: &Limits) -> Option<Loaded> {
    load_all(&[file.to_path_buf()], limits).and_then(|mut v| v.pop())
}

/// Loads every file, printing all diagnostics (warnings too); `None` when any
/// file has an error.
pub(super) fn load_all(files: &[PathBuf], limits: &Limits) -> Option<Vec<Loaded>> {
    let mut out = Vec::new();
    let mut failed = false;
    let stderr = std::io::stderr();
    let mut err = stderr.lock();
    for f in files {
        match load_reporting(f, limits, &mut err) {
            Some(l) => out.push(l),
            None => failed = true,
        }
    }
    (!failed).then_some(out)
}

/// Loads every input, directories expanded (`format::discover`), printing
/// every file's diagnostics: the policies that loaded and whether any input
/// failed; `None` when there is nothing to report (the walk failed, or no
/// policy was found). Scenarios found below a directory are skipped.
pub(super) fn load_inputs(files: &[PathBuf], limits: &Limits) -> Option<(Vec<Loaded>, bool)> {
    use format::discover;
    let stderr = std::io::stderr();
    let mut err = stderr.lock();
    let inputs = match discover::expand(files) {
        Ok(i) => i,
        Err(d) => {
            print_diagnostics(&mut err, &[d]);
            return None;
        }
    };
    let (limits, only) = match with_companions(&inputs, limits) {
        Ok(x) => x,
        Err(d) => {
            print_diagnostics(&mut err, &[d]);
            return None;
        }
    };
    let limits = &limits;
    let (mut out, mut failed, mut skipped) = (Vec::new(), false, 0usize);
    for input in &inputs {
        if let Some(only) = &only
            && is_btcpp_candidate(&input.path)
            && !only.contains(&input.path)
        {
            continue; // a companion of the files that define `--tree`
        }
        let r = match discover::read(input, limits) {
            Ok((file, Some(format::Input::Policy(fmt)))) => {
                format::load_read(file, &input.path, fmt, limits)
            }
            // A scenario named on the command line is read as the policy
            // it is not (its errors say so); one found below is skipped.
            Ok((file, Some(format::Input::Scenario))) if !input.found => {
                format::load_read(file, &input.path, format::FileFormat::Toml, limits)
            }
            Ok((file, Some(format::Input::Domain))) if !input.found => Err(vec![
                btfsm_core::diagnostic::Diagnostic::error("an action domain, not a policy")
                    .in_file(&file)
                    .hint("`btfsm plan DOMAIN` makes its policies; `btfsm validate` checks it"),
            ]),
            Ok(_) => {
                skipped += 1;
                continue;
            }
            Err(d) => Err(d),
        };
        match reported(r, &mut err) {
            Some(l) => out.push(l),
            None => failed = true,
        }
    }
    note_skipped(&mut err, skipped);
    if out.is_empty() && !failed {
        let _ = writeln!(err, "error: no policy file below the directories given");
        return None;
    }
    Some((out, failed))
}

/// May `path` be a BehaviorTree.CPP file given together with others (a
/// regular `.xml` or Groot2 `.btproj` file; a pipe is read once, as the
/// input it is)?
pub(super) fn is_btcpp_candidate(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("xml") || e.eq_ignore_ascii_case("btproj"))
        && std::fs::metadata(path).is_ok_and(|m| m.is_file())
}

/// The limits with the BehaviorTree.CPP files given together as each
/// other's companions (SubTrees one defines and another uses are found, as
/// BehaviorTree.CPP's factory registers every file it loads), and, with
/// `--tree ID` and several such files, the files that define `ID` (the
/// others are read only as companions). No file defining `ID`: an error
/// listing the trees there are.
pub(super) fn with_companions(
    inputs: &[format::discover::Input],
    limits: &Limits,
) -> Result<(Limits, Option<Vec<PathBuf>>), Diagnostic> {
    let files: Vec<PathBuf> = inputs
        .iter()
        .filter(|i| is_btcpp_candidate(&i.path))
        .map(|i| i.path.clone())
        .collect();
    if files.len() < 2 {
        return Ok((limits.clone(), None));
    }
    let comp = std::sync::Arc::new(format::btcpp_xml::Companions::new(files));
    let mut limits = limits.clone();
    limits.companions = Some(comp.clone());
    let Some(id) = limits.tree.clone() else {
        return Ok((limits, None));
    };
    let only: Vec<PathBuf> = comp
        .defining(&id, &limits)
        .into_iter()
        .map(Path::to_path_buf)
        .collect();
    if only.is_empty() {
        let trees = comp.tree_ids(&limits);
        let hint = btfsm_core::diagnostic::suggest(&id, trees.iter().copied());
        return Err(Diagnostic::error(format!(
            "--tree `{}`: none of the {} BehaviorTree.CPP files given defines it",
            btfsm_core::sanitize::shown(&id),
            comp.len()
        ))
        .hint(hint));
    }
    Ok((limits, Some(only)))
}

/// Says how many files found below directories held no policy.
fn note_skipped(err: &mut impl Write, skipped: usize) {
    if skipped > 0 {
        let _ = writeln!(
            err,
            "note: skipped {skipped} file{} below the directories given that hold{} no policy",
            if skipped == 1 { "" } else { "s" },
            if skipped == 1 { "s" } else { "" },
        );
    }
}

/// Reads one policy, printing its warnings or its errors to `err`.
fn load_reporting(f: &Path, limits: &Limits, err: &mut impl Write) -> Option<Loaded> {
    reported(format::load(f, limits), err)
}

/// A policy read, its warnings printed to `err`; or its errors printed.
fn reported(r: Result<Loaded, Vec<Diagnostic>>, err: &mut impl Write) -> Option<Loaded> {
    match r {
        Ok(l) => {
            for w in &l.warnings {
                let _ = write!(err, "{w}");
            }
            Some(l)
        }
        Err(diags) => {
            print_diagnostics(err, &diags);
            None
        }
    }
}

pub(super) fn print_diagnostics(w: &mut impl Write, diags: &[Diagnostic]) {
    let n = diags.iter().filter(|d| d.is_error()).count();
    for d in diags {
        let _ = write!(w, "{d}");
    }
    if n > 1 {
        let file = diags
            .iter()
            .find_map(|d| d.file.as_ref().map(|f| f.path.clone()))
            .unwrap_or_default();
        let _ = writeln!(w, "error: {}: {n} problems", shown(&file));
    }
}

/// Writes a text output (report, DOT, SVG, policy) through
/// [`super::out::text`] to a file (atomically) or stdout.
pub(super) fn emit_text(path: Option<&Path>, text: impl AsRef<str>) -> u8 {
    emit(path, super::out::text(text.as_ref()).as_bytes())
}

/// Writes output to a file (see `report::output`: atomically, through
/// symlinks, into devices and FIFOs) or to stdout (no path, `-`, or a path
/// that is stdout).
pub(super) fn emit(path: Option<&Path>, bytes: &[u8]) -> u8 {
    use btfsm_report::output::Destination;
    let dest = match path.map(Destination::resolve) {
        None => Destination::Stdout,
        Some(Ok(d)) => d,
        Some(Err(e)) => return cannot_write(path, e),
    };
    if let Destination::Stdout = dest {
        let stdout = std::io::stdout();
        let mut out = stdout.lock();
        return match out.write_all(bytes).and_then(|()| out.flush()) {
            Ok(()) => EXIT_OK,
            // A closed pipe (`| head`) is not an error of ours.
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => EXIT_OK,
            Err(e) => {
                eprintln!("error: cannot write to stdout: {e}");
                EXIT_BAD_INPUT
            }
        };
    }
    match dest.write(bytes) {
        Ok(()) => EXIT_OK,
        Err(e) => cannot_write(path, e),
    }
}

fn cannot_write(path: Option<&Path>, e: std::io::Error) -> u8 {
    let path = path.map_or_else(|| "-".into(), |p| p.display().to_string());
    eprintln!(
        "error: cannot write `{}`: {}",
        shown(&path),
        btfsm_core::sanitize::shown_max(&e.to_string(), 2000)
    );
    EXIT_BAD_INPUT
}

/// Refuses, before anything is computed or written, outputs of one command
/// that name one file (or the stdout where the report goes, when
/// `report_on_stdout`); `false` after saying why.
pub(super) fn outputs_distinct(outputs: &[(&str, Option<&Path>)], report_on_stdout: bool) -> bool {
    let given: Vec<(&str, &Path)> = outputs
        .iter()
        .filter_map(|&(flag, p)| Some((flag, p?)))
        .collect();
    match btfsm_report::output::check_distinct(&given, report_on_stdout) {
        Ok(()) => true,
        Err(e) => {
            eprintln!(
                "error: {}",
                btfsm_core::sanitize::shown_max(&e.to_string(), 2000)
            );
            false
        }
    }
}

/// The complexity gate of `analyze`, with its baseline read (`None`: the
/// baseline is unreadable, said on stderr).
fn gate(
    max: Vec<Limit>,
    baseline: Option<&Path>,
    max_increase: Vec<Limit>,
    limits: &Limits,
) -> Option<Gate> {
    let baseline = match baseline {
        None => None,
        Some(p) => {
            let shown = p.display().to_string();
            let file = match format::toml::read_source(p, &shown, limits) {
                Ok(f) => f,
                Err(diags) => {
                    for d in diags {
                        eprint!("{d}");
                    }
                    return None;
                }
            };
            match Baseline::parse(&shown, &file.text) {
                Ok(b) => Some(b),
                Err(d) => {
                    eprint!("{d}");
                    return None;
                }
            }
        }
    };
    Some(Gate {
        max,
        baseline,
        max_increase,
    })
}

/// Prints the gate's verdict on stderr: exit 1 naming every metric over its
/// limit.
fn check_gate(gate: &Gate, reports: &[report::PolicyReport]) -> u8 {
    let r = gate.check(reports);
    let mut rules: Vec<String> = gate.max.iter().map(|l| format!("--max {l}")).collect();
    if let Some(b) = &gate.baseline {
        let grow: Vec<String> = gate
            .increase_limits()
            .iter()
            .map(|l| format!("{} +{}", l.metric.key(), l.value))
            .collect();
        rules.push(format!("growth over `{}`: {}", b.path, grow.join(", ")));
        for f in &r.new_policies {
            eprintln!(
                "note: `{}` is not in the baseline; only its ceilings are checked",
                shown(f)
            );
        }
    }
    let n = reports.len();
    let policies = if n == 1 { "policy" } else { "policies" };
    if r.violations.is_empty() {
        eprintln!(
            "complexity gate: {n} {policies} within limits ({})",
            rules.join("; ")
        );
        return EXIT_OK;
    }
    for v in &r.violations {
        eprintln!(
            "error: complexity gate: {}",
            btfsm_core::sanitize::shown_max(&v.to_string(), 1000)
        );
    }
    eprintln!(
        "error: complexity gate: {} limit{} exceeded in {n} {policies} ({})",
        r.violations.len(),
        if r.violations.len() == 1 { "" } else { "s" },
        rules.join("; ")
    );
    EXIT_CHECK_FAILED
}
