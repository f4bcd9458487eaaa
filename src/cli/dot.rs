//! `btfsm dot FILE`: a policy drawn in the paper's visual language as
//! Graphviz DOT, or rendered to SVG/PNG/PDF through Graphviz's `dot` under
//! a deadline (`--render`, or the extension of `-o`); `--trace` colours the
//! nodes by their status at a step of a `sim --trace` file.

use super::EXIT_BAD_INPUT;
use super::args::{DotLookArgs, LimitArgs};
use super::io::{emit, emit_text, fail, load_one};
use btfsm_core::diagnostic::Diagnostic;
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Debug, Args)]
pub(crate) struct DotArgs {
    /// Policy file (any format), or `-` for stdin
    pub(super) file: PathBuf,
    /// Output file (default: stdout)
    #[arg(short, long)]
    pub(super) output: Option<PathBuf>,
    /// Render with Graphviz's `dot` instead of printing DOT (default: the
    /// extension of -o when it is .svg, .png or .pdf, else DOT text)
    #[arg(long, value_enum)]
    pub(super) render: Option<btfsm_render::dot::RenderFormat>,
    /// With --render: Graphviz's time budget; past it `dot` is killed
    /// and the run exits 2
    #[arg(long, default_value_t = btfsm_render::dot::DEFAULT_RENDER_TIMEOUT_MS, value_name = "MS")]
    pub(super) timeout_ms: u64,
    /// Colour nodes by their status at --step in a `sim --trace` file
    #[command(flatten)]
    pub(super) trace: super::sim::DotTraceArgs,
    #[command(flatten)]
    pub(super) look: DotLookArgs,
    #[command(flatten)]
    pub(super) limits: LimitArgs,
}

pub(super) fn run(a: DotArgs) -> u8 {
    let limits = a.limits.limits();
    let Some(l) = load_one(&a.file, &limits) else {
        return EXIT_BAD_INPUT;
    };
    let Some((policy, mut opts)) = super::sim::dot_trace(&a.trace, &a.file, l.policy, &limits)
    else {
        return EXIT_BAD_INPUT;
    };
    a.look.apply(&mut opts);
    if let Err(e) = btfsm_render::dot::check_fold(&policy, &opts) {
        return fail(Diagnostic::error(e.to_string()));
    }
    let timeout = std::time::Duration::from_millis(a.timeout_ms);
    draw(&policy, &opts, a.output.as_deref(), a.render, timeout)
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
        return fail(Diagnostic::error(format!(
            "{fmt} output is binary; write it to a file with -o"
        )));
    }
    match dot::render(&text, fmt, timeout) {
        Ok(bytes) => emit(output, &bytes),
        Err(e @ dot::RenderError::NotInstalled { .. }) => fail(Diagnostic::error(format!("no {fmt} made: {e}")).hint(
            "install Graphviz, or write DOT (an output path ending in .dot) and render it where Graphviz is installed",
        )),
        Err(e) => fail(Diagnostic::error(e.to_string())),
    }
}
