//! The TOML policy format (SPEC §1; documented with an example per kind in
//! docs/guide/policy-toml.md). Reads a file into the model and validates it, collecting every problem
//! at once, each with file, line, column and a hint.
//!
//! BT nodes are a flat table keyed by node id (`[nodes]`), children referenced by
//! id, so that trees of any depth parse without recursion and every node has an
//! explicit identity (used by `named` GED). Subtrees are included from other files
//! with `{ subtree = "file.toml", with = { param = "value" } }`.

mod bt;
mod include;
mod machine;
mod skills;

use super::{Limits, Loaded};
use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use btfsm_model::bt::{Arity, BtNode, BtNodeKind, NODE_KEYWORDS};
use btfsm_model::skill::{self, ArgValue, Guard, GuardTerm, SkillCall, SkillKind};
use btfsm_model::{
    Bt, Policy, PolicyBody, Region, State, StateBody, StateMachine, Target, Transition, Trigger,
};
use std::cell::Cell;
use std::collections::{BTreeMap, HashMap};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::Arc;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

type Val<'i> = Spanned<DeValue<'i>>;

/// The outcomes a task state can return.
pub const TASK_OUTCOMES: &[&str] = &["SUCCESS", "FAILURE", "RUNNING"];

/// Reads and validates a TOML policy file.
pub fn load_file(path: &Path, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    let shown = path.display().to_string();
    let file = read_source(path, &shown, limits)?;
    load_read(&file, path, limits)
}

/// Reads a TOML policy already read from `path` (includes resolve beside it).
pub fn load_read(
    file: &Arc<SourceFile>,
    path: &Path,
    limits: &Limits,
) -> Result<Loaded, Vec<Diagnostic>> {
    let base = path.parent().unwrap_or(Path::new(""));
    load_source(file, canonical(path), base, limits)
}

/// Parses a policy from text (tests, stdin); includes resolve against `base`.
pub fn parse_str(
    name: &str,
    text: &str,
    base: &Path,
    limits: &Limits,
) -> Result<Loaded, Vec<Diagnostic>> {
    let file = SourceFile::new(name, text);
    load_source(&file, PathBuf::from(name), base, limits)
}

/// Reads a policy from a source file; on failure returns every error, followed
/// by the warnings.
fn load_source(
    file: &Arc<SourceFile>,
    identity: PathBuf,
    base: &Path,
    limits: &Limits,
) -> Result<Loaded, Vec<Diagnostic>> {
    let mut loader = Loader {
        limits: limits.clone(),
        stack: vec![identity],
        diags: Vec::new(),
        node_budget: limits.max_nodes,
        include_bytes: limits.max_file_bytes,
        includes: HashMap::new(),
        dropped_errors: 0,
        dropped_warnings: 0,
        scratch: Diagnostic::error(""),
        root: super::source::root_for(limits, base),
        subst: Rc::new(SubstBudget {
            max_one: limits.max_name_bytes,
            left: Cell::new(limits.max_file_bytes),
            overflow: Cell::new(false),
        }),
    };
    let mut policy = loader.policy(file, base);
    if let Some(mut d) = policy.as_ref().and_then(|p| super::check_shape(p, limits)) {
        d.file = Some(file.clone());
        if d.span.is_none() {
            d.span = Some(0..0);
        }
        loader.diags.push(d);
        policy = None;
    }
    // Counted messages, said last (at the end of the file).
    let end = file.text.len()..file.text.len();
    if loader.dropped_errors > 0 {
        loader.diags.push(
            Diagnostic::error(format!(
                "{} more errors not shown (the first {MAX_DIAGNOSTICS} messages are)",
                loader.dropped_errors
            ))
            .at(file, end.clone()),
        );
    }
    if loader.dropped_warnings > 0 {
        loader.diags.push(
            Diagnostic::warning(format!(
                "{} more warnings not shown",
                loader.dropped_warnings
            ))
            .at(file, end),
        );
    }
    super::finish(file, policy, loader.diags, "policy")
}

pub(crate) fn canonical(p: &Path) -> PathBuf {
    super::source::canonical(p)
}

/// Reads a policy file named on the command line (a pipe or device is read
/// up to the size limit, never blocking on a FIFO with no writer).
pub fn read_source(
    path: &Path,
    shown: &str,
    limits: &Limits,
) -> Result<Arc<SourceFile>, Vec<Diagnostic>> {
    super::source::read(path, shown, limits, false)
}

/// Reads a file another file names, once [`super::source::resolve`] has
/// placed it inside the root: it must be a regular file and what `expect`
/// says ([`super::source::check_named`]), else it is refused with a message
/// that quotes none of it.
pub(crate) fn read_included(
    path: &Path,
    shown: &str,
    limits: &Limits,
    expect: super::source::Named,
) -> Result<Arc<SourceFile>, Vec<Diagnostic>> {
    let file = super::source::read(path, shown, limits, true)?;
    super::source::check_named(path, &file.text, expect).map_err(|r| {
        vec![
            Diagnostic::error(format!(
                "`{}`: {}",
                btfsm_core::sanitize::shown(shown),
                r.message
            ))
            .hint(r.hint),
        ]
    })?;
    Ok(file)
}

/// An included file (canonical path) with its `with` values.
type IncludeKey = (PathBuf, Vec<(String, String)>);

struct Loader {
    limits: Limits,
    /// Canonical paths of the files being read (for include cycles).
    stack: Vec<PathBuf>,
    diags: Vec<Diagnostic>,
    /// Nodes that may still be created before the node limit is hit.
    node_budget: usize,
    /// Bytes that subtree includes may still read (each include counts, so
    /// that a file included many times cannot multiply the work).
    include_bytes: u64,
    /// Subtrees already read, by file and `with` values: a file included
    /// 2^k times through k levels is read k times, not 2^k.
    includes: HashMap<IncludeKey, Option<Bt>>,
    /// Messages past [`MAX_DIAGNOSTICS`], counted, not kept.
    dropped_errors: usize,
    dropped_warnings: usize,
    scratch: Diagnostic,
    /// The directory every included file must be in (`None`: anywhere).
    root: Option<PathBuf>,
    subst: Rc<SubstBudget>,
}

/// Most messages kept per policy file (with its includes); the rest are
/// counted in one last message, so that a file with a million bad lines is
/// reported in bounded time.
pub const MAX_DIAGNOSTICS: usize = 200;

/// Per-file reading context.
struct Ctx<'a> {
    file: &'a Arc<SourceFile>,
    base: &'a Path,
    /// Subtree parameters substituted into strings as `{name}`.
    params: BTreeMap<String, String>,
    /// What substitution may still produce (shared by every file of a
    /// policy).
    subst: Rc<SubstBudget>,
}

/// Bounds on parameter substitution: each result at most `max_name_bytes`
/// (it becomes an id, label or argument, all bounded so), and all results
/// of a policy together at most `--max-file-bytes`, so that parameters
/// doubled level by level cannot multiply a few kilobytes into gigabytes.
#[derive(Debug)]
struct SubstBudget {
    max_one: usize,
    left: Cell<u64>,
    /// Set when a result was cut (reported once, at the include).
    overflow: Cell<bool>,
}

impl Ctx<'_> {
    fn subst(&self, s: &str) -> String {
        if self.params.is_empty() || !s.contains('{') {
            return s.to_string();
        }
        let b = &self.subst;
        // Built piece by piece, never longer than one byte past the limit.
        let cap = b
            .max_one
            .min(usize::try_from(b.left.get()).unwrap_or(usize::MAX));
        let mut out = String::new();
        let mut rest = s;
        while let Some(open) = rest.find('{') {
            out.push_str(&rest[..open]);
            let after = &rest[open + 1..];
            match after
                .find('}')
                .and_then(|close| self.params.get(&after[..close]).map(|v| (close, v)))
            {
                Some((close, v)) => {
                    out.push_str(v);
                    rest = &after[close + 1..];
                }
                None => {
                    out.push('{');
                    rest = after;
                }
            }
            if out.len() > cap {
                break;
            }
        }
        if out.len() <= cap {
            out.push_str(rest);
        }
        if out.len() > cap {
            let mut end = cap.saturating_add(1).min(out.len());
            while !out.is_char_boundary(end) {
                end -= 1;
            }
            out.truncate(end);
            b.overflow.set(true);
        }
        b.left.set(b.left.get().saturating_sub(out.len() as u64));
        out
    }
}

/// Where brackets and braces (outside strings and comments) first nest
/// more than 80 deep: the place to point at when the TOML parser refuses
/// deep nesting without a position.
fn deep_nesting_at(text: &str) -> Range<usize> {
    let b = text.as_bytes();
    let (mut depth, mut i) = (0usize, 0usize);
    while i < b.len() {
        match b[i] {
            b'#' => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            q @ (b'"' | b'\'') => {
                i += 1;
                while i < b.len() && b[i] != q && b[i] != b'\n' {
                    if q == b'"' && b[i] == b'\\' {
                        i += 1;
                    }
                    i += 1;
                }
            }
            b'[' | b'{' => {
                depth += 1;
                if depth > 80 {
                    return i..i + 1;
                }
            }
            b']' | b'}' => depth = depth.saturating_sub(1),
            b'\n' => {}
            _ => {}
        }
        i += 1;
    }
    0..0
}

fn type_name(v: &DeValue<'_>) -> &'static str {
    match v {
        DeValue::String(_) => "a string",
        DeValue::Integer(_) => "an integer",
        DeValue::Float(_) => "a float",
        DeValue::Boolean(_) => "a boolean",
        DeValue::Datetime(_) => "a datetime",
        DeValue::Array(_) => "an array",
        DeValue::Table(_) => "a table",
    }
}

fn int_of(v: &DeValue<'_>) -> Option<i64> {
    match v {
        DeValue::Integer(i) => {
            let s: String = i.as_str().chars().filter(|&c| c != '_').collect();
            let (neg, s) = match s.strip_prefix('-') {
                Some(r) => (true, r.to_string()),
                None => (false, s.trim_start_matches('+').to_string()),
            };
            let digits = s
                .strip_prefix("0x")
                .or_else(|| s.strip_prefix("0o"))
                .or_else(|| s.strip_prefix("0b"))
                .unwrap_or(&s);
            let n = i64::from_str_radix(digits, i.radix()).ok()?;
            Some(if neg { -n } else { n })
        }
        _ => None,
    }
}

fn float_of(v: &DeValue<'_>) -> Option<f64> {
    match v {
        DeValue::Float(f) => f.as_str().replace('_', "").parse().ok(),
        _ => int_of(v).map(|i| i as f64),
    }
}

impl Loader {
    pub(super) fn err(
        &mut self,
        cx: &Ctx<'_>,
        span: Range<usize>,
        msg: impl Into<String>,
    ) -> &mut Diagnostic {
        self.push(Diagnostic::error(msg).at(cx.file, span))
    }

    pub(super) fn warn(&mut self, cx: &Ctx<'_>, span: Range<usize>, msg: impl Into<String>) {
        self.push(Diagnostic::warning(msg).at(cx.file, span));
    }

    /// Keeps a message, or past [`MAX_DIAGNOSTICS`] counts it (the returned
    /// slot is then a scratch one).
    pub(super) fn push(&mut self, d: Diagnostic) -> &mut Diagnostic {
        if self.diags.len() >= MAX_DIAGNOSTICS {
            if d.is_error() {
                self.dropped_errors += 1;
            } else {
                self.dropped_warnings += 1;
            }
            self.scratch = d;
            return &mut self.scratch;
        }
        self.diags.push(d);
        self.diags.last_mut().expect("just pushed")
    }

    /// A did-you-mean hint; once messages are only counted (past
    /// [`MAX_DIAGNOSTICS`]) none is computed.
    pub(super) fn suggest<'a>(
        &self,
        wrong: &str,
        candidates: impl IntoIterator<Item = &'a str>,
    ) -> String {
        if self.diags.len() >= MAX_DIAGNOSTICS {
            return String::new();
        }
        btfsm_core::diagnostic::suggest(wrong, candidates)
    }

    /// Messages so far, kept or not.
    pub(super) fn problems(&self) -> usize {
        self.diags.len() + self.dropped_errors + self.dropped_warnings
    }

    pub(super) fn any_error(&self) -> bool {
        self.dropped_errors > 0 || self.diags.iter().any(Diagnostic::is_error)
    }

    pub(super) fn hint_last(&mut self, hint: impl Into<String>) {
        if self.dropped_errors + self.dropped_warnings > 0 {
            return;
        }
        if let Some(d) = self.diags.last_mut() {
            d.hint = Some(hint.into());
        }
    }

    /// Parses the TOML syntax of a file, reporting every syntax error.
    pub(super) fn parse_doc<'i>(
        &mut self,
        file: &'i Arc<SourceFile>,
    ) -> Option<Spanned<DeTable<'i>>> {
        // Counted before the parser allocates 70-112 bytes per token.
        if let Err(d) = btfsm_core::toml_budget::check(
            file,
            self.limits.max_toml_tokens(),
            "a policy of --max-nodes nodes needs fewer: raise --max-nodes",
        ) {
            self.diags.push(d);
            return None;
        }
        // The parser keeps the first error only (the recoverable parser
        // keeps every one: millions for a large bad file).
        let errors = match DeTable::parse(&file.text) {
            Ok(doc) => return self.names_within_limit(file, &doc).then_some(doc),
            Err(e) => vec![e],
        };
        let mut last_dup_line = None;
        let mut seen = std::collections::HashSet::new();
        for e in errors.iter().take(20) {
            let msg = e.message().trim().trim_end_matches('.').to_string();
            let span = match e.span() {
                Some(span) => span,
                None if msg.contains("recursion") => deep_nesting_at(&file.text),
                None => 0..0,
            };
            if !seen.insert((span.start, msg.clone())) {
                continue;
            }
            let (line, _) = file.line_col(span.start);
            let (msg, hint) = if msg.contains("recursion") {
                (
                    "invalid TOML: tables, arrays or dotted keys nested too deeply".to_string(),
                    "the TOML reader accepts at most 80 levels of nesting (an HFSM's `[states.a.states.b...]` headers about 39 containers)",
                )
            } else if msg.starts_with("duplicate key") {
                // The keys of a duplicated table repeat too: report the table once.
                if last_dup_line.is_some_and(|l| line <= l + 1) {
                    last_dup_line = Some(line);
                    continue;
                }
                last_dup_line = Some(line);
                let key = file.text.get(span.clone()).unwrap_or("").trim();
                (
                    format!("duplicate key `{key}`"),
                    "every node, state and field name may appear only once in its table; rename or merge one of them",
                )
            } else {
                (
                    format!("invalid TOML: {}", lower_first(&msg)),
                    "see the TOML policy format in docs/guide/policy-toml.md",
                )
            };
            self.diags
                .push(Diagnostic::error(msg).at(file, span).hint(hint));
        }
        None
    }

    /// Checks the length of every key and string (but descriptions) against
    /// `max_name_bytes`, walking the document with an explicit stack.
    pub(super) fn names_within_limit(
        &mut self,
        file: &Arc<SourceFile>,
        doc: &Spanned<DeTable<'_>>,
    ) -> bool {
        let max = self.limits.max_name_bytes;
        let mut found = 0;
        let mut report = |diags: &mut Vec<Diagnostic>, what: &str, text: &str, span| {
            found += 1;
            if found <= 20 {
                let mut shown: String = text.chars().take(24).collect();
                if shown.len() < text.len() {
                    shown.push('…');
                }
                diags.push(
                    Diagnostic::error(format!(
                        "{what} `{shown}` is {} bytes long, more than the limit of {max} bytes",
                        text.len()
                    ))
                    .at(file, span)
                    .hint("shorten it, or raise the limit with --max-name-bytes"),
                );
            }
        };
        let mut stack: Vec<&Val<'_>> = Vec::new();
        let mut tables: Vec<&DeTable<'_>> = vec![doc.get_ref()];
        loop {
            if let Some(t) = tables.pop() {
                for (k, v) in t.iter() {
                    if k.get_ref().len() > max {
                        report(&mut self.diags, "key", k.get_ref(), k.span());
                    }
                    if k.get_ref() != "description" {
                        stack.push(v);
                    }
                }
            } else if let Some(v) = stack.pop() {
                match v.get_ref() {
                    DeValue::String(text) if text.len() > max => {
                        report(&mut self.diags, "string", text, v.span());
                    }
                    DeValue::Table(t) => tables.push(t),
                    DeValue::Array(a) => stack.extend(a.iter()),
                    _ => {}
                }
            } else {
                break;
            }
        }
        found == 0
    }

    pub(super) fn policy(&mut self, file: &Arc<SourceFile>, base: &Path) -> Option<Policy> {
        let doc = self.parse_doc(file)?;
        let cx = Ctx {
            file,
            base,
            params: BTreeMap::new(),
            subst: self.subst.clone(),
        };
        let table = doc.get_ref();
        let kind = self.kind(&cx, table, doc.span())?;
        let allowed: &[&str] = match kind {
            "bt" => &["kind", "name", "description", "root", "nodes", "params"],
            "fsm" => &[
                "kind",
                "name",
                "description",
                "initial",
                "outcomes",
                "states",
            ],
            _ => &[
                "kind",
                "name",
                "description",
                "initial",
                "outcomes",
                "states",
            ],
        };
        self.check_keys(&cx, table, allowed, "top-level key");
        let name = self
            .opt_str(&cx, table, "name")
            .unwrap_or_else(|| file_stem(&file.path));
        let description = self.opt_str(&cx, table, "description");
        let body = match kind {
            "bt" => PolicyBody::Bt(self.bt(&cx, table, doc.span(), None)?),
            k => PolicyBody::Machine(self.machine(&cx, table, doc.span(), k == "hfsm")?),
        };
        Some(Policy {
            name,
            description,
            body,
        })
    }

    pub(super) fn kind(
        &mut self,
        cx: &Ctx<'_>,
        t: &DeTable<'_>,
        whole: Range<usize>,
    ) -> Option<&'static str> {
        let Some((_, v)) = t.get_key_value("kind") else {
            let scenario = t.contains_key("world") || t.contains_key("policies");
            self.err(cx, whole.start..whole.start, "missing `kind`")
                .hint = Some(if scenario {
                "this looks like a simulator scenario (`[world]`, `[[policies]]`): run it with `btfsm sim FILE`; `btfsm validate` checks scenarios too".into()
            } else {
                "start the file with `kind = \"bt\"`, `\"fsm\"` or `\"hfsm\"`".into()
            });
            return None;
        };
        match v.get_ref().as_str() {
            Some("bt") => Some("bt"),
            Some("fsm") => Some("fsm"),
            Some("hfsm") => Some("hfsm"),
            Some(other) => {
                let h = self.suggest(other, ["bt", "fsm", "hfsm"]);
                self.err(cx, v.span(), format!("unknown policy kind `{other}`"))
                    .hint = Some(h);
                None
            }
            None => {
                self.err(
                    cx,
                    v.span(),
                    format!("`kind` must be a string, found {}", type_name(v.get_ref())),
                )
                .hint = Some("expected `\"bt\"`, `\"fsm\"` or `\"hfsm\"`".into());
                None
            }
        }
    }

    pub(super) fn check_keys(
        &mut self,
        cx: &Ctx<'_>,
        t: &DeTable<'_>,
        allowed: &[&str],
        what: &str,
    ) {
        for (k, _) in t.iter() {
            if !allowed.contains(&k.get_ref().as_ref()) {
                let h = self.suggest(k.get_ref(), allowed.iter().copied());
                self.err(cx, k.span(), format!("unknown {what} `{}`", k.get_ref()))
                    .hint = Some(h);
            }
        }
    }

    pub(super) fn opt_str(&mut self, cx: &Ctx<'_>, t: &DeTable<'_>, key: &str) -> Option<String> {
        let v = t.get(key)?;
        match v.get_ref().as_str() {
            Some(s) => Some(cx.subst(s)),
            None => {
                self.err(
                    cx,
                    v.span(),
                    format!("`{key}` must be a string, found {}", type_name(v.get_ref())),
                );
                None
            }
        }
    }

    pub(super) fn opt_uint(
        &mut self,
        cx: &Ctx<'_>,
        t: &DeTable<'_>,
        key: &str,
        owner: &str,
    ) -> Option<u64> {
        let v = t.get(key)?;
        match int_of(v.get_ref()) {
            Some(i) if i >= 0 => Some(i as u64),
            _ => {
                self.err(
                    cx,
                    v.span(),
                    format!(
                        "`{key}` of `{owner}` must be a non-negative integer, found {}",
                        type_name(v.get_ref())
                    ),
                );
                None
            }
        }
    }

    // ---------------------------------------------------------------- skills
}

fn scalar_text(v: &DeValue<'_>) -> String {
    match v {
        DeValue::String(s) => s.to_string(),
        DeValue::Integer(i) => i.as_str().to_string(),
        DeValue::Float(f) => f.as_str().to_string(),
        DeValue::Boolean(b) => b.to_string(),
        other => type_name(other).to_string(),
    }
}

fn kind_word(k: SkillKind) -> &'static str {
    match k {
        SkillKind::Action => "action",
        SkillKind::Condition => "condition",
    }
}

fn article_kind(k: SkillKind) -> &'static str {
    match k {
        SkillKind::Action => "an action",
        SkillKind::Condition => "a condition",
    }
}

fn lower_first(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_lowercase().chain(c).collect(),
        None => String::new(),
    }
}

fn file_stem(path: &str) -> String {
    Path::new(path)
        .file_stem()
        .map_or_else(|| path.to_string(), |s| s.to_string_lossy().into_owned())
}

#[cfg(test)]
mod tests;
