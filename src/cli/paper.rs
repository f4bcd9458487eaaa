//! `btfsm paper` and `btfsm effort`: load, compute through the library, print.

use super::args::PaperArgs;
use super::io::emit_text;
use super::{EXIT_BAD_INPUT, EXIT_CHECK_FAILED, EXIT_OK};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_metrics::ged::GedOptions;
use btfsm_report::paper::{self, EXPECTED_FILE};

/// The default GED budget, with the CPU-time cap given by `--timeout-ms`.
fn ged_options(timeout_ms: Option<u64>) -> GedOptions {
    let mut o = GedOptions::default();
    if let Some(ms) = timeout_ms {
        o.timeout = std::time::Duration::from_millis(ms);
    }
    o
}

/// `btfsm paper`.
pub(super) fn paper(a: &PaperArgs) -> u8 {
    let report = match paper::build(&a.policies, &a.limits.limits(), &ged_options(a.timeout_ms)) {
        Ok(r) => r,
        Err(diags) => {
            for d in diags {
                eprint!("{d}");
            }
            return EXIT_BAD_INPUT;
        }
    };
    let expected_path = a.policies.join(EXPECTED_FILE);
    if a.record {
        let text = paper::expected_toml(&report);
        let code = emit_text(Some(&expected_path), text);
        if code == EXIT_OK {
            eprintln!(
                "recorded {} cells in `{}`",
                report.rows.len(),
                expected_path.display()
            );
        }
        return code;
    }
    if a.check {
        let expected = match paper::read_expected(&expected_path) {
            Ok(e) => e,
            Err(d) => {
                eprint!("{d}");
                return EXIT_BAD_INPUT;
            }
        };
        let departures = paper::check(&report, &expected);
        if departures.is_empty() {
            eprintln!(
                "paper check: all {} cells computed from `{}` match `{}`",
                report.rows.len(),
                a.policies.display(),
                expected_path.display()
            );
            return EXIT_OK;
        }
        for d in &departures {
            eprint!("{}", Diagnostic::error(format!("paper check: {d}")));
        }
        eprint!("{}", Diagnostic::error(format!("paper check: {} cell{} departed from `{}`", departures.len(), if departures.len() == 1 { "" } else { "s" }, expected_path.display())).hint(format!("if the change is deliberate, review it and run `btfsm paper --record --policies {}`", a.policies.display())));
        return EXIT_CHECK_FAILED;
    }
    super::io::emit_report(a.output.as_deref(), &report, a.format)
}
