//! Runs each command: loads and validates inputs, calls the library, prints.

use super::args::{Cli, Command, ConvertTarget};
use super::{EXIT_BAD_INPUT, EXIT_OK};
use crate::diagnostic::Diagnostic;
use crate::format::{self, Limits, Loaded};
use crate::report::{self, analyze, render_analysis};
use std::io::Write;
use std::path::{Path, PathBuf};

pub fn execute(cli: Cli) -> u8 {
    match cli.command {
        Command::Analyze {
            files,
            format,
            limits,
        } => {
            let Some(loaded) = load_all(&files, &limits.limits()) else {
                return EXIT_BAD_INPUT;
            };
            let reports: Vec<_> = loaded.iter().map(analyze).collect();
            emit(None, render_analysis(&reports, format).as_bytes())
        }
        Command::Validate { files, limits } => {
            let Some(loaded) = load_all(&files, &limits.limits()) else {
                return EXIT_BAD_INPUT;
            };
            for l in &loaded {
                eprintln!(
                    "{}: ok ({} `{}`, {} warning{})",
                    l.path,
                    l.policy.kind(),
                    l.policy.name,
                    l.warnings.len(),
                    if l.warnings.len() == 1 { "" } else { "s" },
                );
            }
            EXIT_OK
        }
        Command::Dot {
            file,
            output,
            render,
            limits,
        } => {
            let Some(l) = load_one(&file, &limits.limits()) else {
                return EXIT_BAD_INPUT;
            };
            let dot = crate::render::dot::policy_dot(&l.policy, &Default::default());
            match render {
                None => emit(output.as_deref(), dot.as_bytes()),
                Some(fmt) => match crate::render::dot::render(&dot, fmt) {
                    Ok(bytes) => {
                        if output.is_none() && fmt != crate::render::dot::RenderFormat::Svg {
                            eprintln!("error: {fmt} output is binary; write it to a file with -o");
                            return EXIT_BAD_INPUT;
                        }
                        emit(output.as_deref(), &bytes)
                    }
                    Err(e) => {
                        eprintln!("error: {e}");
                        EXIT_BAD_INPUT
                    }
                },
            }
        }
        Command::Convert {
            file,
            to,
            output,
            limits,
        } => {
            let Some(l) = load_one(&file, &limits.limits()) else {
                return EXIT_BAD_INPUT;
            };
            let policy = match to {
                ConvertTarget::Toml => l.policy,
                ConvertTarget::BtcppXml | ConvertTarget::Scxml => {
                    return super::convert::to_xml(&l.policy, to, output.as_deref());
                }
                ConvertTarget::Hfsm => {
                    match crate::transform::bt_to_hfsm::bt_policy_to_hfsm(&l.policy) {
                        Ok(p) => p,
                        Err(errs) => {
                            for e in errs {
                                eprintln!(
                                    "error: {e}\n  = hint: the construction covers sequence, fallback (with or without memory), inverter, force_success, force_failure and leaves"
                                );
                            }
                            return EXIT_BAD_INPUT;
                        }
                    }
                }
            };
            let text = crate::format::toml_write::write_policy(&policy);
            emit(output.as_deref(), text.as_bytes())
        }
    }
}

/// Loads one file (see [`load_all`]).
fn load_one(file: &Path, limits: &Limits) -> Option<Loaded> {
    load_all(&[file.to_path_buf()], limits).and_then(|mut v| v.pop())
}

/// Loads every file, printing all diagnostics (warnings too); `None` when any
/// file has an error.
fn load_all(files: &[PathBuf], limits: &Limits) -> Option<Vec<Loaded>> {
    let mut out = Vec::new();
    let mut failed = false;
    let stderr = std::io::stderr();
    let mut err = stderr.lock();
    for f in files {
        match format::load(f, limits) {
            Ok(l) => {
                for w in &l.warnings {
                    let _ = write!(err, "{w}");
                }
                out.push(l);
            }
            Err(diags) => {
                failed = true;
                print_diagnostics(&mut err, &diags);
            }
        }
    }
    (!failed).then_some(out)
}

fn print_diagnostics(w: &mut impl Write, diags: &[Diagnostic]) {
    let n = diags.iter().filter(|d| d.is_error()).count();
    for d in diags {
        let _ = write!(w, "{d}");
    }
    if n > 1 {
        let file = diags
            .iter()
            .find_map(|d| d.file.as_ref().map(|f| f.path.clone()))
            .unwrap_or_default();
        let _ = writeln!(w, "error: {file}: {n} problems");
    }
}

/// Writes output to a file (atomically) or stdout.
pub(super) fn emit(path: Option<&Path>, bytes: &[u8]) -> u8 {
    match path {
        Some(p) => match report::write_atomically(p, bytes) {
            Ok(()) => EXIT_OK,
            Err(e) => {
                eprintln!("error: cannot write `{}`: {e}", p.display());
                EXIT_BAD_INPUT
            }
        },
        None => {
            let stdout = std::io::stdout();
            let mut out = stdout.lock();
            match out.write_all(bytes).and_then(|()| out.flush()) {
                Ok(()) => EXIT_OK,
                // A closed pipe (`| head`) is not an error of ours.
                Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => EXIT_OK,
                Err(e) => {
                    eprintln!("error: cannot write to stdout: {e}");
                    EXIT_BAD_INPUT
                }
            }
        }
    }
}
