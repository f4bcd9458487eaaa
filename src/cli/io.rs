//! What every command shares: reading its inputs (directories expanded,
//! BehaviorTree.CPP files given together as companions), printing
//! diagnostics, and writing its outputs (atomically, or to stdout). Every
//! error a user sees goes through [`fail`] or [`print_diagnostics`]: one
//! `Diagnostic` path, sanitised, with its hint.

use super::{EXIT_BAD_INPUT, EXIT_OK};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_core::sanitize::shown;
use btfsm_format::{self as format, Limits, Loaded};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Prints one error (message, hint) on stderr and gives exit code 2: the
/// one way a command reports a problem that is not a file's.
pub(super) fn fail(d: Diagnostic) -> u8 {
    eprint!("{d}");
    EXIT_BAD_INPUT
}

/// An error whose message quotes text from the input or the system (a
/// library error's `Display`), with a hint.
pub(super) fn error_with_hint(message: impl std::fmt::Display, hint: &str) -> Diagnostic {
    Diagnostic::error(message.to_string()).hint(hint)
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
    let mut out = Vec::new();
    let failed = each_input(files, limits, &mut |l| out.push(l))?;
    Some((out, failed))
}

/// [`load_inputs`], handing each policy that loads to `each` in the order
/// of the inputs and dropping it after, so that memory is bounded by the
/// largest file, not the count (issue 34): whether any input failed;
/// `None` when there is nothing to report.
pub(super) fn each_input(
    files: &[PathBuf],
    limits: &Limits,
    each: &mut dyn FnMut(Loaded),
) -> Option<bool> {
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
    let (mut loaded, mut failed, mut skipped) = (0usize, false, 0usize);
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
            Some(l) => {
                loaded += 1;
                each(l);
            }
            None => failed = true,
        }
    }
    note_skipped(&mut err, skipped);
    if loaded == 0 && !failed {
        let _ = write!(
            err,
            "{}",
            Diagnostic::error("no policy file below the directories given")
        );
        return None;
    }
    Some(failed)
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
/// With `--only-policies`, the files named are read as those found below
/// a directory: skipped when they hold no policy (stdin is read as given).
pub(super) fn only_policies(
    mut inputs: Vec<format::discover::Input>,
    only: bool,
) -> Vec<format::discover::Input> {
    if only {
        for i in &mut inputs {
            i.found |= i.path.as_os_str() != "-";
        }
    }
    inputs
}

pub(super) fn note_skipped(err: &mut impl Write, skipped: usize) {
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
pub(super) fn reported(r: Result<Loaded, Vec<Diagnostic>>, err: &mut impl Write) -> Option<Loaded> {
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
        let _ = write!(w, "{}", Diagnostic::error(format!("{file}: {n} problems")));
    }
}

/// Writes a report in `format` (one its command's `--format` admits) to a
/// file or stdout: the one way a command prints what it computed.
pub(super) fn emit_report<R: btfsm_core::output::Report>(
    path: Option<&Path>,
    report: &R,
    format: btfsm_core::output::Format,
) -> u8 {
    emit_text(path, report.write(format))
}

/// Writes a text output (report, DOT, SVG, policy) through
/// [`super::out::text`] to a file (atomically) or stdout.
pub(super) fn emit_text(path: Option<&Path>, text: impl AsRef<str>) -> u8 {
    emit(path, super::out::text(text.as_ref()).as_bytes())
}

/// Where this command's outputs may go (`report::output::OutputRoot`), set
/// once from its `--root` and `--allow-outside-root` before it runs.
static OUTPUT_ROOT: std::sync::OnceLock<btfsm_report::output::OutputRoot> =
    std::sync::OnceLock::new();

/// Sets where the command's outputs may go (the first call wins).
pub(super) fn set_output_root(limits: Option<&super::args::LimitArgs>) {
    let root = match limits {
        Some(l) => btfsm_report::output::OutputRoot::new(l.allow_outside_root, l.root.as_deref()),
        None => btfsm_report::output::OutputRoot::new(false, None),
    };
    let _ = OUTPUT_ROOT.set(root);
}

/// Where outputs may go: what [`set_output_root`] set, else the default
/// (the git work tree of the current directory, never `.git`).
pub(super) fn output_root() -> &'static btfsm_report::output::OutputRoot {
    OUTPUT_ROOT.get_or_init(|| btfsm_report::output::OutputRoot::new(false, None))
}

/// Writes output to a file (see `report::output`: atomically, through
/// symlinks that stay inside the root, into devices and FIFOs, never into
/// `.git`) or to stdout (no path, `-`, or a path that is stdout). Every
/// file a command writes goes through here (or, streamed, through
/// [`create_output_file`]).
pub(super) fn emit(path: Option<&Path>, bytes: &[u8]) -> u8 {
    use btfsm_report::output::Destination;
    let dest = match path.map(|p| Destination::resolve_within(p, output_root())) {
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
            Err(e) => fail(Diagnostic::error(format!("cannot write to stdout: {e}"))),
        };
    }
    match dest.write(bytes) {
        Ok(()) => EXIT_OK,
        Err(e) => cannot_write(path, e),
    }
}

/// A streamed output file (`sim --trace`) under the rules of [`emit`]; an
/// error is printed (exit 2).
pub(super) fn create_output_file(path: &Path) -> Result<btfsm_report::output::OutputFile, u8> {
    btfsm_report::output::OutputFile::create(path, output_root())
        .map_err(|e| cannot_write(Some(path), e))
}

/// Creates a directory outputs go under (`plan -o DIR`) under the rules of
/// [`emit`]; an error is printed (exit 2).
pub(super) fn create_output_dir(path: &Path) -> Result<(), u8> {
    btfsm_report::output::create_dir_within(path, output_root())
        .map_err(|e| cannot_write(Some(path), e))
}

/// The error of an output that cannot be written, with the confinement's
/// hint when that is why.
pub(super) fn cannot_write(path: Option<&Path>, e: std::io::Error) -> u8 {
    let path = path.map_or_else(|| "-".into(), |p| p.display().to_string());
    let d = Diagnostic::error(format!(
        "cannot write `{}`: {}",
        shown(&path),
        btfsm_core::sanitize::shown_max(&e.to_string(), 2000)
    ));
    fail(if btfsm_report::output::is_confined(&e) {
        d.hint(btfsm_report::output::CONFINED_HINT)
    } else {
        d
    })
}

/// Refuses, before anything is computed or written, outputs of one command
/// that name one file (or the stdout where the report goes, when
/// `report_on_stdout`); `false` after saying why.
pub(super) fn outputs_distinct(outputs: &[(&str, Option<&Path>)], report_on_stdout: bool) -> bool {
    let given: Vec<(&str, &Path)> = outputs
        .iter()
        .filter_map(|&(flag, p)| Some((flag, p?)))
        .collect();
    // Confined before anything is computed (`emit` checks again).
    for &(_, p) in &given {
        if let Err(e) = btfsm_report::output::Destination::resolve_within(p, output_root())
            && btfsm_report::output::is_confined(&e)
        {
            cannot_write(Some(p), e);
            return false;
        }
    }
    match btfsm_report::output::check_distinct(&given, report_on_stdout) {
        Ok(()) => true,
        Err(e) => {
            fail(Diagnostic::error(e.to_string()));
            false
        }
    }
}
