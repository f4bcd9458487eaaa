//! `btfsm lint FILE|DIR...`: runs the lint rules (src/lint/) on every policy
//! given or found below a directory; prints findings as positioned text,
//! JSON, SARIF 2.1.0 or JUnit XML; exit 1 when an error-level finding
//! remains, 2 when an input does not load (its errors printed, the others
//! still linted).

use super::io::{emit_report, emit_text, print_diagnostics};
use super::{EXIT_BAD_INPUT, EXIT_CHECK_FAILED, EXIT_OK};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_core::diagnostic::SourceFile;
use btfsm_core::output::{Format, Report};
use btfsm_format as format;
use btfsm_lint::{self as lint, Level, config};
use clap::Args;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The help of `lint`'s formats.
const LINT_HELP: super::format::Help = &[
    (
        Format::Text,
        "Positioned messages with snippet and help, as `validate` prints",
    ),
    (Format::Sarif, "SARIF 2.1.0, for GitHub code scanning"),
    (
        Format::Junit,
        "JUnit XML, one testcase per file, for colcon test, GitLab and Jenkins",
    ),
];

#[derive(Debug, Args)]
pub(crate) struct LintArgs {
    /// Policy files (any format), `-` for stdin, or directories
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Output format
    #[arg(long, value_parser = super::format::parser(Findings::FORMATS, LINT_HELP), default_value = "text")]
    pub format: Format,
    /// Report rule CODE as an error (repeatable)
    #[arg(long, value_name = "CODE")]
    pub deny: Vec<String>,
    /// Report rule CODE as a warning (repeatable)
    #[arg(long, value_name = "CODE")]
    pub warn: Vec<String>,
    /// Do not report rule CODE (repeatable)
    #[arg(long, value_name = "CODE")]
    pub allow: Vec<String>,
    /// Do not read btfsm.toml (by default: the one in the current folder or
    /// above it, up to the repository root): for a pull request, whose
    /// btfsm.toml could allow every rule
    #[arg(long)]
    pub no_config: bool,
    /// Read the rule levels from this btfsm.toml instead of looking for one
    /// (for a pull request: the base branch's, which the pull request
    /// cannot change)
    #[arg(long, value_name = "FILE", conflicts_with = "no_config")]
    pub config: Option<PathBuf>,
    /// Skip the files named that hold no policy, as those found below a
    /// directory are (a pre-commit hook is given every changed .xml and
    /// .toml file: a ROS package.xml, a Cargo.toml)
    #[arg(long)]
    pub only_policies: bool,
    /// List the rules with their default level and summary, and exit
    #[arg(long, exclusive = true)]
    pub list: bool,
    #[command(flatten)]
    pub limits: super::args::LimitArgs,
}

pub(super) fn execute(a: LintArgs) -> u8 {
    if a.list {
        return emit_text(None, rule_table());
    }
    let stderr = std::io::stderr();
    let mut err = stderr.lock();
    let Some(cfg) = levels(&a, &mut err) else {
        return EXIT_BAD_INPUT;
    };
    let inputs = match format::discover::expand(&a.files) {
        Ok(i) => super::io::only_policies(i, a.only_policies),
        Err(d) => {
            print_diagnostics(&mut err, &[d]);
            return EXIT_BAD_INPUT;
        }
    };
    let mut limits = a.limits.limits();
    limits.for_lint = true;
    // Node models given: `--nodes-model`, btfsm.toml's `models`, model
    // files among the inputs.
    let (inputs, given) = match given_models(inputs, &cfg, &limits) {
        Ok(x) => x,
        Err(d) => {
            print_diagnostics(&mut err, &[d]);
            return EXIT_BAD_INPUT;
        }
    };
    limits.nodes_models.extend(given);
    // BehaviorTree.CPP files given together resolve each other's SubTrees
    // (and models), as `analyze` reads them.
    let (limits, only) = match super::io::with_companions(&inputs, &limits) {
        Ok(x) => x,
        Err(d) => {
            print_diagnostics(&mut err, &[d]);
            return EXIT_BAD_INPUT;
        }
    };
    let run = lint_inputs(&inputs, only.as_deref(), &limits, &cfg);
    let report = Findings { run: &run };
    let code = emit_report(None, &report, a.format);
    if a.format != Format::Text && !run.not_linted.is_empty() {
        let _ = write!(
            err,
            "{}",
            Diagnostic::error(format!(
                "{} file{} not linted: {} not load (the findings say why)",
                run.not_linted.len(),
                if run.not_linted.len() == 1 { "" } else { "s" },
                if run.not_linted.len() == 1 {
                    "it does"
                } else {
                    "they do"
                },
            ))
        );
    }
    if code != EXIT_OK
        || run
            .findings
            .iter()
            .any(|f| f.code == lint::load::LOAD_ERROR.code)
    {
        return EXIT_BAD_INPUT;
    }
    if run.findings.iter().any(|f| f.level == Level::Error) {
        EXIT_CHECK_FAILED
    } else {
        EXIT_OK
    }
}

/// `lint --list`: every rule's code, default level and summary.
fn rule_table() -> String {
    let mut t = btfsm_core::table::Table::new(&["code", "level", "what it finds"]);
    for r in lint::RULES {
        t.row(vec![
            r.code.to_string(),
            r.level.as_str().to_string(),
            r.summary.to_string(),
        ]);
    }
    t.render()
}

/// The rules' levels: `btfsm.toml`'s `[lint]` table (unless `--no-config`),
/// then the flags; `None` after printing why they are invalid.
fn levels(a: &LintArgs, err: &mut impl Write) -> Option<config::Config> {
    let mut cfg = config::Config::default();
    // `--config FILE` is read as a command-line file; one found is named.
    let found = || {
        let cwd = std::env::current_dir().ok()?;
        config::find(&cwd)
    };
    let path = match &a.config {
        Some(p) => Some((p.clone(), false)),
        None if a.no_config => None,
        None => found().map(|p| (p, true)),
    };
    if let Some((path, named)) = path {
        let limits = a.limits.limits();
        let shown = path.display().to_string();
        match format::source::read(&path, &shown, &limits, named).map(|f| config::read(&f)) {
            Ok(Ok(c)) => cfg = c,
            Ok(Err(d)) | Err(d) => {
                print_diagnostics(err, &d);
                return None;
            }
        }
    }
    for (codes, level) in [
        (&a.allow, Level::Allow),
        (&a.warn, Level::Warning),
        (&a.deny, Level::Error),
    ] {
        for c in codes {
            if let Err(e) = cfg.set(c, level) {
                let _ = write!(err, "{}", Diagnostic::error(e.to_string()));
                return None;
            }
        }
    }
    Some(cfg)
}

/// Model files given: btfsm.toml's `models` (relative to it, inside its
/// repository), and the inputs named on the command line that are node
/// models (a `.btproj`, or an XML file with a `<TreeNodesModel>` and no
/// `<BehaviorTree>`), which are read as models and not linted as trees.
/// The other inputs are returned.
fn given_models(
    inputs: Vec<format::discover::Input>,
    cfg: &config::Config,
    limits: &format::Limits,
) -> Result<(Vec<format::discover::Input>, Vec<PathBuf>), Diagnostic> {
    let mut models = Vec::new();
    if let Some(toml) = &cfg.file {
        let base = toml.parent().unwrap_or(Path::new(""));
        let root = format::source::root_for(limits, base);
        for m in &cfg.models {
            let rel = m.to_string_lossy();
            match format::source::resolve(root.as_deref(), base, &rel) {
                Ok(p) => models.push(p),
                Err(r) => {
                    return Err(Diagnostic::error(format!(
                        "{}: model `{}`: {}",
                        btfsm_core::sanitize::shown(&toml.display().to_string()),
                        btfsm_core::sanitize::shown(&rel),
                        r.message
                    ))
                    .hint(format!(
                        "`models` in [lint] are node model files relative to btfsm.toml; {}",
                        r.hint
                    )));
                }
            }
        }
    }
    let mut rest = Vec::new();
    for input in inputs {
        if !input.found && is_model_file(&input.path, limits) {
            models.push(input.path);
        } else {
            rest.push(input);
        }
    }
    Ok((rest, models))
}

/// Is a file named on the command line a node model rather than a tree?
fn is_model_file(path: &Path, limits: &format::Limits) -> bool {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if ext.eq_ignore_ascii_case("btproj") {
        return true;
    }
    if !ext.eq_ignore_ascii_case("xml") || !path.is_file() {
        return false;
    }
    let shown = path.display().to_string();
    format::source::read(path, &shown, limits, false)
        .is_ok_and(|f| f.text.contains("<TreeNodesModel") && !f.text.contains("<BehaviorTree"))
}

/// What linting every input gave: the findings, the files not linted (the
/// path and why), and the node types no model declares, by file.
#[derive(Default)]
struct Run {
    /// Policy files read (linted or not), as shown.
    files: Vec<String>,
    findings: Vec<lint::Finding>,
    not_linted: Vec<(String, String)>,
    unchecked: std::collections::BTreeMap<String, Vec<String>>,
    /// SubTrees no file given defines, by file (read as opaque nodes).
    opaque: std::collections::BTreeMap<String, Vec<String>>,
}

impl Run {
    /// A policy that loaded: the rules' findings, then the readers' coded
    /// warnings (a Parallel threshold).
    fn loaded(&mut self, l: &format::Loaded, file: &Arc<SourceFile>, cfg: &config::Config) {
        let subject = lint::Subject {
            policy: &l.policy,
            dataflow: l.dataflow.as_deref(),
        };
        self.findings
            .extend(lint::lint_subject(&subject, Some(file), &l.path, cfg));
        self.findings
            .extend(lint::load::findings(&l.warnings, &l.path, cfg, true));
        let (types, trees) = lint::models::unchecked(&subject);
        let owned = |v: Vec<&str>| v.into_iter().map(str::to_string).collect::<Vec<_>>();
        if !types.is_empty() {
            self.unchecked.insert(l.path.clone(), owned(types));
        }
        if !trees.is_empty() {
            self.opaque.insert(l.path.clone(), owned(trees));
        }
    }

    /// Findings (from `before`) and files not linted (from `not_linted`)
    /// said once: the trees of one file share nodes.
    fn said_once(&mut self, before: usize, not_linted: usize) {
        let mut seen = std::collections::HashSet::new();
        let tail: Vec<lint::Finding> = self.findings.drain(before..).collect();
        for f in tail {
            // At one place one rule says one thing (a message names the
            // node by its path in the tree linted, which differs per tree).
            let said = if f.line.is_some() {
                String::new()
            } else {
                f.message.clone()
            };
            let key = (f.code, f.file.clone(), f.line, f.column, said);
            if seen.insert(key) {
                self.findings.push(f);
            }
        }
        let mut files = std::collections::HashSet::new();
        let tail: Vec<(String, String)> = self.not_linted.drain(not_linted..).collect();
        for (file, why) in tail {
            if files.insert(file.clone()) {
                self.not_linted.push((file, why));
            }
        }
    }

    /// An input that did not load: its errors as findings.
    fn not_loaded(&mut self, diags: &[Diagnostic], display: &str, cfg: &config::Config) {
        self.findings
            .extend(lint::load::findings(diags, display, cfg, false));
        let why = diags
            .iter()
            .find(|d| d.is_error())
            .map_or_else(|| "it does not load".to_string(), |d| d.message.clone());
        self.not_linted.push((display.to_string(), why));
    }

    /// The notes on what could not be checked: node types no model
    /// declares, SubTrees no file given defines.
    fn notes(&self) -> Vec<String> {
        let mut out = Vec::new();
        if let Some((files, n, names)) = summary(&self.unchecked) {
            out.push(format!(
                "{files} node type{} no node model declares ({names}): lint checks neither their names nor their ports; give the model with --nodes-model FILE or `models` in btfsm.toml's [lint]",
                if n == 1 { "" } else { "s" },
            ));
        }
        if let Some((files, n, names)) = summary(&self.opaque) {
            out.push(format!(
                "{files} SubTree{} no file given defines ({names}), each read as one node: give the files that define them with these",
                if n == 1 { "" } else { "s" },
            ));
        }
        out
    }
}

/// Of names by file: "N file(s) use(s) K", K, and "`A`, `B`, `C`, ...".
fn summary(
    by_file: &std::collections::BTreeMap<String, Vec<String>>,
) -> Option<(String, usize, String)> {
    if by_file.is_empty() {
        return None;
    }
    let names: std::collections::BTreeSet<&str> =
        by_file.values().flatten().map(String::as_str).collect();
    let some: Vec<String> = names
        .iter()
        .take(3)
        .map(|t| format!("`{}`", btfsm_core::sanitize::shown(t)))
        .collect();
    let n = by_file.len();
    Some((
        format!(
            "{n} file{} {} {}",
            if n == 1 { "" } else { "s" },
            if n == 1 { "uses" } else { "use" },
            names.len()
        ),
        names.len(),
        format!(
            "{}{}",
            some.join(", "),
            if names.len() > 3 { ", ..." } else { "" }
        ),
    ))
}

/// Lints every input (only those of `only` among BehaviorTree.CPP files,
/// when `--tree` chose some).
fn lint_inputs(
    inputs: &[format::discover::Input],
    only: Option<&[PathBuf]>,
    limits: &btfsm_format::Limits,
    cfg: &config::Config,
) -> Run {
    let mut run = Run::default();
    let mut search = lint::search::ModelSearch::default();
    for input in inputs {
        if let Some(only) = only
            && super::io::is_btcpp_candidate(&input.path)
            && !only.contains(&input.path)
        {
            continue;
        }
        let (file, fmt) = match format::discover::read(input, limits) {
            Ok((file, Some(format::Input::Policy(fmt)))) => (file, fmt),
            Ok(_) => continue,
            Err(d) => {
                run.files.push(input.path.display().to_string());
                run.not_loaded(&d, &input.path.display().to_string(), cfg);
                continue;
            }
        };
        run.files.push(file.path.clone());
        let limits = tree_limits(&mut search, &input.path, &file.text, fmt, limits);
        // A file of several trees that names none: each tree a program may
        // create from it, findings said once.
        let roots = (fmt == format::FileFormat::BtcppXml && limits.tree.is_none())
            .then(|| format::btcpp_xml::root_trees(&file, &limits, MAX_ROOT_TREES))
            .flatten();
        let Some(roots) = roots else {
            match format::load_read(file.clone(), &input.path, fmt, &limits) {
                Ok(l) => run.loaded(&l, &file, cfg),
                Err(d) => run.not_loaded(&d, &file.path, cfg),
            }
            continue;
        };
        let (before, not_linted) = (run.findings.len(), run.not_linted.len());
        for id in roots {
            let limits = format::Limits {
                tree: Some(id),
                ..limits.clone()
            };
            match format::load_read(file.clone(), &input.path, fmt, &limits) {
                Ok(l) => run.loaded(&l, &file, cfg),
                Err(d) => run.not_loaded(&d, &file.path, cfg),
            }
        }
        run.said_once(before, not_linted);
    }
    run
}

/// Trees of one file (that names none as its main tree) linted at most.
const MAX_ROOT_TREES: usize = 64;

/// The limits a BehaviorTree.CPP file is read with: unknown leaves as
/// actions unless `--assume-leaf` says otherwise (their C++ registers them,
/// lint checks what it can), and, when no model is given, the models found
/// as users keep them ([`lint::search`]).
fn tree_limits(
    search: &mut lint::search::ModelSearch,
    path: &Path,
    text: &str,
    fmt: format::FileFormat,
    limits: &format::Limits,
) -> format::Limits {
    let mut l = limits.clone();
    if fmt != format::FileFormat::BtcppXml {
        return l;
    }
    l.assume_leaf = l.assume_leaf.or(Some(format::AssumeLeaf::Action));
    if !l.nodes_models.is_empty() || btfsm_lint::models::has_leaf_model(text) {
        return l;
    }
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let auto = format::Limits {
        confinement: format::source::Confinement::Auto,
        ..format::Limits::default()
    };
    let root = format::source::root_for(limits, dir)
        .or_else(|| format::source::root_for(&auto, dir))
        .unwrap_or_else(|| dir.to_path_buf());
    let cwd = std::env::current_dir()
        .ok()
        .and_then(|c| std::fs::canonicalize(c).ok());
    l.found_models = search
        .for_tree(path, &root)
        .into_iter()
        .map(
            |m| match cwd.as_deref().and_then(|c| m.strip_prefix(c).ok()) {
                Some(rel) => rel.to_path_buf(),
                None => m,
            },
        )
        .collect();
    l
}

/// `lint`'s report: the findings of every file linted, the files that were
/// not, and what could not be checked.
struct Findings<'a> {
    run: &'a Run,
}

impl Report for Findings<'_> {
    const FORMATS: &'static [Format] = &[Format::Text, Format::Json, Format::Sarif, Format::Junit];

    /// The findings in `format`; the text ends with the counts and notes.
    fn write(&self, format: Format) -> String {
        let findings = &self.run.findings;
        match Self::supported(format) {
            Format::Sarif => {
                let inv = lint::sarif::Invocation {
                    not_linted: self.run.not_linted.clone(),
                    notes: self.run.notes(),
                };
                lint::sarif::render(findings, &inv)
            }
            Format::Junit => lint::junit::render(&self.run.files, findings, &self.run.not_linted),
            Format::Json => {
                let mut s = btfsm_core::sanitize::json(
                    serde_json::to_string_pretty(findings).expect("serializable"),
                );
                s.push('\n');
                s
            }
            _ => self.text(),
        }
    }
}

impl Findings<'_> {
    /// The findings as positioned text, then the counts (and the files not
    /// linted), then the note on what could not be checked.
    fn text(&self) -> String {
        let (findings, files) = (&self.run.findings, self.run.files.len());
        let plural =
            |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
        let mut s: String = findings.iter().map(lint::render_text).collect();
        let count = |l: Level| findings.iter().filter(|f| f.level == l).count();
        s.push_str(&format!(
            "{}, {}, {} in {}",
            plural(count(Level::Error), "error", "errors"),
            plural(count(Level::Warning), "warning", "warnings"),
            plural(count(Level::Note), "note", "notes"),
            plural(files, "file", "files"),
        ));
        match self.run.not_linted.len() {
            0 => s.push('\n'),
            n => s.push_str(&format!(
                " ({} not linted: {} not load)\n",
                plural(n, "file", "files"),
                if n == 1 { "it does" } else { "they do" }
            )),
        }
        for note in self.run.notes() {
            s.push_str(&format!("note: {note}\n"));
        }
        s
    }
}
