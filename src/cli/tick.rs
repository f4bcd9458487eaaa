//! `btfsm tick TREE --script S`: ticks a BT against scripted leaf outcomes
//! and prints every leaf ticked and halted per tick (docs/bt-semantics.md).
//! Several TREE / --script pairs run in one process (JSON: one object per
//! line), which is how tests/differential/ drives it.

use super::EXIT_BAD_INPUT;
use super::io::{emit_text, fail, print_diagnostics};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_core::output::{Format, Report};
use btfsm_format as format;
use btfsm_model::PolicyBody;
use btfsm_tick as tick;
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub(crate) struct TickArgs {
    /// BT files (TOML or BehaviorTree.CPP XML), each with its --script
    #[arg(required = true)]
    pub trees: Vec<PathBuf>,
    /// Leaf script (TOML), one per tree, in the same order
    #[arg(long = "script", required = true, value_name = "S.toml")]
    pub scripts: Vec<PathBuf>,
    /// Output format
    #[arg(long, value_parser = super::format::parser(tick::TickReport::FORMATS, &[]), default_value = "table")]
    pub format: Format,
    #[command(flatten)]
    pub limits: super::args::LimitArgs,
}

pub(super) fn execute(a: TickArgs) -> u8 {
    if a.trees.len() != a.scripts.len() {
        return fail(
            Diagnostic::error(format!(
                "{} tree{} and {} script{}",
                a.trees.len(),
                if a.trees.len() == 1 { "" } else { "s" },
                a.scripts.len(),
                if a.scripts.len() == 1 { "" } else { "s" }
            ))
            .hint("give one --script per tree, in the same order"),
        );
    }
    let limits = a.limits.limits();
    let mut out = String::new();
    let stderr = std::io::stderr();
    for (t, s) in a.trees.iter().zip(&a.scripts) {
        let r = one(t, s, &limits, a.format);
        match r {
            Ok(text) => {
                if a.format == Format::Table && !out.is_empty() {
                    out.push('\n');
                }
                out.push_str(&text);
            }
            Err(d) => {
                print_diagnostics(&mut stderr.lock(), &d);
                return EXIT_BAD_INPUT;
            }
        }
    }
    emit_text(None, out)
}

/// One tree and its script: the report, or what is wrong with them.
fn one(
    tree: &std::path::Path,
    script: &std::path::Path,
    limits: &format::Limits,
    fmt: Format,
) -> Result<String, Vec<Diagnostic>> {
    let (file, input) = format::read_input(tree, limits)?;
    let f = match input {
        format::Input::Policy(f) => f,
        format::Input::Domain => {
            return Err(vec![
                Diagnostic::error("an action domain, not a BT")
                    .in_file(&file)
                    .hint("`btfsm plan DOMAIN --to bt -o -` makes its BT"),
            ]);
        }
        format::Input::Scenario => {
            return Err(vec![
                Diagnostic::error("a scenario, not a BT")
                    .in_file(&file)
                    .hint("`tick` runs a BT file (TOML or BehaviorTree.CPP XML); `sim` runs scenarios"),
            ]);
        }
    };
    let loaded = format::load_read(file.clone(), tree, f, limits)?;
    let PolicyBody::Bt(bt) = &loaded.policy.body else {
        return Err(vec![
            Diagnostic::error(format!("a {}, not a BT", loaded.policy.kind()))
                .in_file(&file)
                .hint("`tick` runs Behavior Trees; `sim` runs FSMs and HFSMs in a world"),
        ]);
    };
    if let Some((n, what)) = btfsm_sim::exec::unsupported(bt) {
        let node = &bt.nodes[n];
        let d = Diagnostic::error(format!(
            "node `{}`: {what} cannot be ticked as BehaviorTree.CPP 4 ticks it",
            node.id
        ))
        .hint("`tick` runs the node types of docs/bt-semantics.md, not an approximation");
        let d = match &node.span {
            Some(sp) if in_this_file(&file.text, f, node, sp) => d.at(&file, sp.clone()),
            _ => d.in_file(&file),
        };
        return Err(vec![d]);
    }
    let sfile = format::source::read(script, &script.display().to_string(), limits, false)?;
    let sc = tick::script::parse(&sfile, bt)?;
    let run = tick::run(bt, &sc);
    let (tn, sn) = (tree.display().to_string(), script.display().to_string());
    let rep = tick::TickReport {
        run: &run,
        bt,
        tree: &tn,
        script: &sn,
    };
    Ok(rep.write(fmt))
}

/// Whether a node's span is in the file given on the command line (not in
/// an included one): a TOML node not from a subtree (`include/id`); an XML
/// element whose tag, at the span, is the node's type.
fn in_this_file(
    text: &str,
    f: format::FileFormat,
    node: &btfsm_model::bt::BtNode,
    sp: &std::ops::Range<usize>,
) -> bool {
    let Some(at) = text.get(sp.clone()) else {
        return false;
    };
    if f != format::FileFormat::BtcppXml {
        return !node.id.contains('/');
    }
    let tag: &str = at
        .strip_prefix('<')
        .unwrap_or("")
        .split(|c: char| c.is_whitespace() || c == '/' || c == '>')
        .next()
        .unwrap_or("");
    !tag.is_empty()
        && (node.type_name.as_deref() == Some(tag)
            || format::btcpp_xml::canonical_type(node.kind) == Some(tag)
            || node.skill.as_ref().is_some_and(|c| c.skill == tag))
}
