//! The TOML policy format (SPEC §1; documented with an example per kind in the
//! README). Reads a file into the model and validates it, collecting every problem
//! at once, each with file, line, column and a hint.
//!
//! BT nodes are a flat table keyed by node id (`[nodes]`), children referenced by
//! id, so that trees of any depth parse without recursion and every node has an
//! explicit identity (used by `named` GED). Subtrees are included from other files
//! with `{ subtree = "file.toml", with = { param = "value" } }`.

use super::{Limits, Loaded};
use crate::diagnostic::{Diagnostic, SourceFile};
use crate::model::bt::{Arity, BtNode, BtNodeKind, NODE_KEYWORDS};
use crate::model::skill::{self, ArgValue, Guard, GuardTerm, SkillCall, SkillKind};
use crate::model::{
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
pub(crate) fn read_source(
    path: &Path,
    shown: &str,
    limits: &Limits,
) -> Result<Arc<SourceFile>, Vec<Diagnostic>> {
    super::source::read(path, shown, limits, false)
}

/// Reads a file another file names, once [`super::source::resolve`] has
/// placed it inside the root: it must be a regular file.
pub(crate) fn read_included(
    path: &Path,
    shown: &str,
    limits: &Limits,
) -> Result<Arc<SourceFile>, Vec<Diagnostic>> {
    super::source::read(path, shown, limits, true)
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
    fn err(&mut self, cx: &Ctx<'_>, span: Range<usize>, msg: impl Into<String>) -> &mut Diagnostic {
        self.push(Diagnostic::error(msg).at(cx.file, span))
    }

    fn warn(&mut self, cx: &Ctx<'_>, span: Range<usize>, msg: impl Into<String>) {
        self.push(Diagnostic::warning(msg).at(cx.file, span));
    }

    /// Keeps a message, or past [`MAX_DIAGNOSTICS`] counts it (the returned
    /// slot is then a scratch one).
    fn push(&mut self, d: Diagnostic) -> &mut Diagnostic {
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
    fn suggest<'a>(&self, wrong: &str, candidates: impl IntoIterator<Item = &'a str>) -> String {
        if self.diags.len() >= MAX_DIAGNOSTICS {
            return String::new();
        }
        crate::diagnostic::suggest(wrong, candidates)
    }

    /// Messages so far, kept or not.
    fn problems(&self) -> usize {
        self.diags.len() + self.dropped_errors + self.dropped_warnings
    }

    fn any_error(&self) -> bool {
        self.dropped_errors > 0 || self.diags.iter().any(Diagnostic::is_error)
    }

    fn hint_last(&mut self, hint: impl Into<String>) {
        if self.dropped_errors + self.dropped_warnings > 0 {
            return;
        }
        if let Some(d) = self.diags.last_mut() {
            d.hint = Some(hint.into());
        }
    }

    /// Parses the TOML syntax of a file, reporting every syntax error.
    fn parse_doc<'i>(&mut self, file: &'i Arc<SourceFile>) -> Option<Spanned<DeTable<'i>>> {
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
                    "see the TOML format in the README",
                )
            };
            self.diags
                .push(Diagnostic::error(msg).at(file, span).hint(hint));
        }
        None
    }

    /// Checks the length of every key and string (but descriptions) against
    /// `max_name_bytes`, walking the document with an explicit stack.
    fn names_within_limit(&mut self, file: &Arc<SourceFile>, doc: &Spanned<DeTable<'_>>) -> bool {
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

    fn policy(&mut self, file: &Arc<SourceFile>, base: &Path) -> Option<Policy> {
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

    fn kind(&mut self, cx: &Ctx<'_>, t: &DeTable<'_>, whole: Range<usize>) -> Option<&'static str> {
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

    fn check_keys(&mut self, cx: &Ctx<'_>, t: &DeTable<'_>, allowed: &[&str], what: &str) {
        for (k, _) in t.iter() {
            if !allowed.contains(&k.get_ref().as_ref()) {
                let h = self.suggest(k.get_ref(), allowed.iter().copied());
                self.err(cx, k.span(), format!("unknown {what} `{}`", k.get_ref()))
                    .hint = Some(h);
            }
        }
    }

    fn opt_str(&mut self, cx: &Ctx<'_>, t: &DeTable<'_>, key: &str) -> Option<String> {
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

    fn opt_uint(&mut self, cx: &Ctx<'_>, t: &DeTable<'_>, key: &str, owner: &str) -> Option<u64> {
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

    /// Reads `skill = "..."` and `args = {...}` of a leaf or state.
    fn skill_call(
        &mut self,
        cx: &Ctx<'_>,
        t: &DeTable<'_>,
        owner: &str,
        want: Option<SkillKind>,
    ) -> Option<SkillCall> {
        let (_, sv) = t.get_key_value("skill")?;
        let Some(name) = sv.get_ref().as_str() else {
            self.err(
                cx,
                sv.span(),
                format!(
                    "`skill` of {owner} must be a string, found {}",
                    type_name(sv.get_ref())
                ),
            );
            return None;
        };
        let name = cx.subst(name);
        let args = match t.get("args") {
            None => BTreeMap::new(),
            Some(a) => self.args(cx, a, owner)?,
        };
        match skill::skill_kind(&name) {
            None => {
                let cands: Vec<&str> = match want {
                    Some(k) => skill::skill_names(k),
                    None => skill::SKILLS.iter().map(|s| s.0).collect(),
                };
                let h = self.suggest(&name, cands.iter().copied());
                self.err(cx, sv.span(), format!("unknown skill `{name}` in {owner}"))
                    .hint = Some(h);
                return None;
            }
            Some(k) if want.is_some_and(|w| w != k) => {
                let w = want.expect("checked");
                let h = format!(
                    "{} skills are {}",
                    kind_word(w),
                    skill::skill_names(w)
                        .iter()
                        .map(|s| format!("`{s}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                );
                self.err(
                    cx,
                    sv.span(),
                    format!(
                        "{owner} is {} but `{name}` is {} skill",
                        article_kind(w),
                        article_kind(k)
                    ),
                )
                .hint = Some(h);
                return None;
            }
            Some(_) => {}
        }
        let params = skill::skill_params(&name).unwrap_or(&[]);
        let mut ok = true;
        for (p, required) in params {
            if *required && !args.contains_key(*p) {
                let span = t.get("args").map_or(sv.span(), |a| a.span());
                self.err(
                    cx,
                    span,
                    format!("skill `{name}` of {owner} needs argument `{p}`"),
                )
                .hint = Some(format!(
                    "write `args = {{ {} }}`",
                    params
                        .iter()
                        .map(|(p, _)| format!("{p} = ..."))
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
                ok = false;
            }
        }
        if let Some(DeValue::Table(at)) = t.get("args").map(|a| a.get_ref()) {
            for (k, _) in at.iter() {
                if !params.iter().any(|(p, _)| *p == k.get_ref().as_ref()) {
                    let h = if params.is_empty() {
                        format!("`{name}` takes no arguments")
                    } else {
                        self.suggest(k.get_ref(), params.iter().map(|p| p.0))
                    };
                    self.err(
                        cx,
                        k.span(),
                        format!("skill `{name}` has no argument `{}`", k.get_ref()),
                    )
                    .hint = Some(h);
                    ok = false;
                }
            }
        }
        ok.then_some(SkillCall { skill: name, args })
    }

    fn args(
        &mut self,
        cx: &Ctx<'_>,
        a: &Val<'_>,
        owner: &str,
    ) -> Option<BTreeMap<String, ArgValue>> {
        let DeValue::Table(t) = a.get_ref() else {
            self.err(
                cx,
                a.span(),
                format!(
                    "`args` of {owner} must be a table, found {}",
                    type_name(a.get_ref())
                ),
            )
            .hint = Some("write `args = { target = \"cube2\" }`".into());
            return None;
        };
        let mut out = BTreeMap::new();
        for (k, v) in t.iter() {
            let val = match v.get_ref() {
                DeValue::String(s) => ArgValue::Str(cx.subst(s)),
                DeValue::Boolean(b) => ArgValue::Bool(*b),
                DeValue::Integer(_) => match int_of(v.get_ref()) {
                    Some(i) => ArgValue::Int(i),
                    None => {
                        self.err(cx, v.span(), "integer out of range");
                        return None;
                    }
                },
                DeValue::Float(_) => ArgValue::Float(float_of(v.get_ref()).unwrap_or(f64::NAN)),
                other => {
                    self.err(
                        cx,
                        v.span(),
                        format!(
                            "argument `{}` of {owner} must be a string, number or boolean, found {}",
                            k.get_ref(),
                            type_name(other)
                        ),
                    );
                    return None;
                }
            };
            out.insert(k.get_ref().to_string(), val);
        }
        Some(out)
    }

    // ---------------------------------------------------------------- BT

    /// Reads a BT document. `prefix` is set for included subtrees: node ids become
    /// `prefix/id` and the root takes the id `prefix`.
    fn bt(
        &mut self,
        cx: &Ctx<'_>,
        doc: &DeTable<'_>,
        whole: Range<usize>,
        prefix: Option<&str>,
    ) -> Option<Bt> {
        let Some(nodes_v) = doc.get("nodes") else {
            self.err(cx, whole.start..whole.start, "a BT needs a `[nodes]` table")
                .hint = Some(
                "add `[nodes]` with one line per node, e.g. `root = { sequence = [\"a\", \"b\"] }`"
                    .into(),
            );
            return None;
        };
        let DeValue::Table(nodes) = nodes_v.get_ref() else {
            self.err(
                cx,
                nodes_v.span(),
                format!(
                    "`nodes` must be a table, found {}",
                    type_name(nodes_v.get_ref())
                ),
            );
            return None;
        };
        if nodes.is_empty() {
            self.err(cx, nodes_v.span(), "`[nodes]` is empty").hint =
                Some("a BT needs at least one node".into());
            return None;
        }
        let ids: Vec<(&str, Range<usize>)> = nodes
            .iter()
            .map(|(k, _)| (k.get_ref().as_ref(), k.span()))
            .collect();
        let index: HashMap<&str, usize> =
            ids.iter().enumerate().map(|(i, (k, _))| (*k, i)).collect();

        // Root: explicit `root = "id"` or the first node.
        let root = match doc.get("root") {
            Some(r) => match r.get_ref().as_str() {
                Some(s) => match index.get(s) {
                    Some(&i) => i,
                    None => {
                        let h = self.suggest(s, ids.iter().map(|(k, _)| *k));
                        self.err(cx, r.span(), format!("unknown node `{s}` given as `root`"))
                            .hint = Some(h);
                        return None;
                    }
                },
                None => {
                    self.err(cx, r.span(), "`root` must be a string naming a node");
                    return None;
                }
            },
            None => 0,
        };

        // First pass: each node's type, label, children ids, skill.
        struct Raw {
            kind: Option<BtNodeKind>,
            label: String,
            children: Vec<(String, Range<usize>)>,
            skill: Option<SkillCall>,
            include: Option<Bt>,
            type_name: Option<String>,
            ports: BTreeMap<String, String>,
        }
        let mut raws: Vec<Raw> = Vec::with_capacity(ids.len());
        for (key, v) in nodes.iter() {
            let id = key.get_ref().as_ref();
            if self.node_budget == 0 {
                self.err(
                    cx,
                    key.span(),
                    format!("more than {} nodes", self.limits.max_nodes),
                )
                .hint = Some("raise the limit with --max-nodes".into());
                return None;
            }
            self.node_budget -= 1;
            raws.push(match self.bt_node(cx, id, key.span(), v) {
                Some(((kind, label, children, skill, include), (type_name, ports))) => Raw {
                    kind,
                    label,
                    children,
                    skill,
                    include,
                    type_name,
                    ports,
                },
                None => Raw {
                    kind: None,
                    label: id.to_string(),
                    children: vec![],
                    skill: None,
                    include: None,
                    type_name: None,
                    ports: BTreeMap::new(),
                },
            });
        }

        // Second pass: resolve children, check arity and tree shape.
        let mut parent: Vec<Option<usize>> = vec![None; ids.len()];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); ids.len()];
        for (i, raw) in raws.iter().enumerate() {
            for (c, span) in &raw.children {
                match index.get(c.as_str()) {
                    None => {
                        let h = self.suggest(c, ids.iter().map(|(k, _)| *k));
                        self.err(
                            cx,
                            span.clone(),
                            format!("unknown node `{c}` in children of `{}`", ids[i].0),
                        )
                        .hint = Some(h);
                    }
                    Some(&ci) if ci == root => {
                        self.err(
                            cx,
                            span.clone(),
                            format!(
                                "the root `{}` cannot be a child of `{}`",
                                ids[ci].0, ids[i].0
                            ),
                        )
                        .hint = Some("a BT is a tree: the root has no parent".into());
                    }
                    Some(&ci) => match parent[ci] {
                        Some(p) => {
                            self.err(
                                cx,
                                span.clone(),
                                format!(
                                    "node `{c}` is a child of both `{}` and `{}`",
                                    ids[p].0, ids[i].0
                                ),
                            )
                            .hint = Some(
                                "a BT is a tree: give the second use its own node (or include a subtree file twice)"
                                    .into(),
                            );
                        }
                        None => {
                            parent[ci] = Some(i);
                            children[i].push(ci);
                        }
                    },
                }
            }
        }
        // Cycles among non-root nodes: walk up from every node (iteratively).
        let mut state = vec![0u8; ids.len()]; // 0 unknown, 1 on path, 2 reaches root
        state[root] = 2;
        for start in 0..ids.len() {
            let mut path = Vec::new();
            let mut cur = start;
            loop {
                match state[cur] {
                    2 => break,
                    1 => {
                        self.err(
                            cx,
                            ids[cur].1.clone(),
                            format!("node `{}` is its own ancestor", ids[cur].0),
                        )
                        .hint = Some("a BT is a tree: children lists must not form a cycle".into());
                        break;
                    }
                    _ => {}
                }
                state[cur] = 1;
                path.push(cur);
                match parent[cur] {
                    Some(p) => cur = p,
                    None => break,
                }
            }
            for p in path {
                state[p] = 2;
            }
        }
        // Unreachable nodes (no parent and not the root), when the tree is
        // otherwise sound (a broken node makes its children look unreachable).
        let sound =
            !self.any_error() && raws.iter().all(|r| r.kind.is_some() || r.include.is_some());
        for (i, (id, span)) in ids.iter().enumerate() {
            if sound && i != root && parent[i].is_none() {
                self.warn(
                    cx,
                    span.clone(),
                    format!(
                        "node `{id}` is not reachable from the root `{}`",
                        ids[root].0
                    ),
                );
                self.hint_last("list it in the children of a control node, or remove it");
            }
        }
        // Arity.
        for (i, raw) in raws.iter().enumerate() {
            let Some(kind) = raw.kind else { continue };
            let n = raw.children.len();
            let span = ids[i].1.clone();
            match kind.arity() {
                Arity::One if n != 1 => {
                    self.err(
                        cx,
                        span,
                        format!(
                            "decorator `{}` (`{}`) takes exactly one child, found {n}",
                            ids[i].0,
                            kind.keyword()
                        ),
                    )
                    .hint = Some(format!(
                        "write `{} = \"child\"`; wrap several children in a sequence or fallback",
                        kind.keyword()
                    ));
                }
                Arity::AtLeastOne if n == 0 => {
                    self.err(
                        cx,
                        span,
                        format!(
                            "control node `{}` (`{}`) has no children",
                            ids[i].0,
                            kind.keyword()
                        ),
                    )
                    .hint = Some(format!(
                        "write `{} = [\"child1\", \"child2\"]`",
                        kind.keyword()
                    ));
                }
                _ => {}
            }
            if let BtNodeKind::Parallel { success } = kind
                && n > 0
                && (success == 0 || success > n)
            {
                self.err(
                    cx,
                    ids[i].1.clone(),
                    format!(
                        "parallel node `{}` needs `success` between 1 and its {n} children, found {success}",
                        ids[i].0
                    ),
                );
            }
        }
        if self.any_error() || raws.iter().any(|r| r.kind.is_none() && r.include.is_none()) {
            return None;
        }

        // Build the arena in pre-order from the root, splicing included subtrees.
        // An included tree's ids are its own (`x`); the including node's
        // id is put before them when it is spliced (`moma1/x`).
        let full_id = |id: &str| match prefix {
            Some(p) if id.is_empty() => p.to_string(),
            Some(p) if !p.is_empty() => format!("{p}/{id}"),
            _ => id.to_string(),
        };
        let mut out: Vec<BtNode> = Vec::new();
        let mut new_index = vec![usize::MAX; ids.len()];
        let mut order = vec![root];
        let mut k = 0;
        while k < order.len() {
            let i = order[k];
            k += 1;
            order.extend(children[i].iter().copied());
        }
        for &i in &order {
            new_index[i] = out.len();
            let raw = &mut raws[i];
            let id = if i == root && prefix.is_some() {
                full_id("")
            } else {
                full_id(ids[i].0)
            };
            match raw.include.take() {
                Some(sub) => {
                    // The included tree's root takes this node's place and id.
                    // Ids grow by a prefix at each level: bounded here, before
                    // millions of them are built.
                    let longest = sub.nodes.iter().map(|n| n.id.len()).max().unwrap_or(0);
                    if id.len() + 1 + longest > self.limits.max_name_bytes {
                        self.err(
                            cx,
                            ids[i].1.clone(),
                            format!(
                                "the ids of subtree node `{}` would be longer than the limit of {} bytes",
                                crate::sanitize::shown(ids[i].0),
                                self.limits.max_name_bytes
                            ),
                        )
                        .hint = Some("nest fewer subtrees, or raise the limit with --max-name-bytes".into());
                        return None;
                    }
                    let offset = out.len();
                    for (j, mut n) in sub.nodes.into_iter().enumerate() {
                        n.id = if j == sub.root {
                            id.clone()
                        } else {
                            format!("{id}/{}", n.id)
                        };
                        for c in &mut n.children {
                            *c += offset;
                        }
                        // Spans are positions in this file.
                        n.span = None;
                        out.push(n);
                    }
                    new_index[i] = offset + sub.root;
                }
                None => out.push(BtNode {
                    id,
                    label: std::mem::take(&mut raw.label),
                    kind: raw.kind.expect("checked above"),
                    children: Vec::new(),
                    skill: raw.skill.take(),
                    type_name: raw.type_name.take(),
                    ports: std::mem::take(&mut raw.ports),
                    span: Some(ids[i].1.clone()),
                }),
            }
        }
        for &i in &order {
            let ni = new_index[i];
            if !children[i].is_empty() {
                out[ni].children = children[i].iter().map(|&c| new_index[c]).collect();
            }
        }
        Some(Bt {
            nodes: out,
            root: new_index[root],
        })
    }

    /// Reads one node table.
    #[allow(clippy::type_complexity)]
    fn bt_node(
        &mut self,
        cx: &Ctx<'_>,
        id: &str,
        key_span: Range<usize>,
        v: &Val<'_>,
    ) -> Option<(
        (
            Option<BtNodeKind>,
            String,
            Vec<(String, Range<usize>)>,
            Option<SkillCall>,
            Option<Bt>,
        ),
        (Option<String>, BTreeMap<String, String>),
    )> {
        let DeValue::Table(t) = v.get_ref() else {
            self.err(
                cx,
                v.span(),
                format!(
                    "node `{id}` must be a table, found {}",
                    type_name(v.get_ref())
                ),
            )
            .hint = Some(format!(
                "write `{id} = {{ action = \"Move-To cube2!\", skill = \"Move-To\", args = {{ target = \"cube2\" }} }}`"
            ));
            return None;
        };
        const FIELDS: &[&str] = &[
            "name", "skill", "args", "success", "times", "ms", "with", "type", "ports",
        ];
        let type_keys: Vec<(&str, &Val<'_>, Range<usize>)> = t
            .iter()
            .filter(|(k, _)| NODE_KEYWORDS.contains(&k.get_ref().as_ref()))
            .map(|(k, v)| (k.get_ref().as_ref(), v, k.span()))
            .collect();
        let mut unknown_keys = false;
        for (k, _) in t.iter() {
            let k_str: &str = k.get_ref();
            if !NODE_KEYWORDS.contains(&k_str) && !FIELDS.contains(&k_str) {
                unknown_keys = true;
                let h = self.suggest(k_str, NODE_KEYWORDS.iter().chain(FIELDS).copied());
                self.err(
                    cx,
                    k.span(),
                    format!("unknown node type or field `{k_str}` in node `{id}`"),
                )
                .hint = Some(h);
            }
        }
        let (tkey, tval, tspan) = match type_keys.as_slice() {
            [one] => one.clone(),
            [] if unknown_keys => return None,
            [] => {
                self.err(cx, key_span, format!("node `{id}` has no type"))
                    .hint = Some(format!(
                    "add one of {}",
                    NODE_KEYWORDS
                        .iter()
                        .map(|k| format!("`{k}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
                return None;
            }
            [_, second, ..] => {
                self.err(
                    cx,
                    second.2.clone(),
                    format!(
                        "node `{id}` has two types, `{}` and `{}`",
                        type_keys[0].0, second.0
                    ),
                )
                .hint = Some("a node has exactly one type key".into());
                return None;
            }
        };
        let name = self.opt_str(cx, t, "name");
        let uint = |s: &mut Self, key: &str| s.opt_uint(cx, t, key, id);
        let kind = match tkey {
            "sequence" => BtNodeKind::Sequence,
            "fallback" => BtNodeKind::Fallback,
            "sequence_memory" => BtNodeKind::SequenceMemory,
            "fallback_memory" => BtNodeKind::FallbackMemory,
            "parallel" => BtNodeKind::Parallel {
                success: uint(self, "success")
                    .map(|s| s as usize)
                    .unwrap_or_else(|| match tval.get_ref() {
                        DeValue::Array(a) => a.len(),
                        _ => 1,
                    }),
            },
            "inverter" => BtNodeKind::Inverter,
            "force_success" => BtNodeKind::ForceSuccess,
            "force_failure" => BtNodeKind::ForceFailure,
            "repeat" => BtNodeKind::Repeat {
                times: uint(self, "times").map(|t| t.min(u32::MAX as u64) as u32),
            },
            "retry" => BtNodeKind::Retry {
                times: uint(self, "times").map_or(1, |t| t.min(u32::MAX as u64) as u32),
            },
            "timeout" => match uint(self, "ms") {
                Some(ms) => BtNodeKind::Timeout { ms },
                None => {
                    self.err(cx, tspan, format!("timeout `{id}` needs `ms`"))
                        .hint = Some("write `ms = 5000`".into());
                    return None;
                }
            },
            "action" => BtNodeKind::Action,
            "condition" => BtNodeKind::Condition,
            "control" => BtNodeKind::Control,
            "decorator" => BtNodeKind::Decorator,
            "subtree" => {
                let sub = self.include(cx, id, t, tval)?;
                return Some((
                    (None, String::new(), vec![], None, Some(sub)),
                    (None, BTreeMap::new()),
                ));
            }
            _ => unreachable!("filtered by NODE_KEYWORDS"),
        };
        // Fields that do not belong to this type.
        for (k, _) in t.iter() {
            let k_str: &str = k.get_ref();
            let fits = match k_str {
                "name" => true,
                "skill" | "args" => matches!(kind, BtNodeKind::Action | BtNodeKind::Condition),
                "success" => matches!(kind, BtNodeKind::Parallel { .. }),
                "times" => matches!(kind, BtNodeKind::Repeat { .. } | BtNodeKind::Retry { .. }),
                "ms" => matches!(kind, BtNodeKind::Timeout { .. }),
                "with" => false,
                "type" | "ports" => true,
                _ => true,
            };
            if !fits {
                self.err(
                    cx,
                    k.span(),
                    format!("`{k_str}` does not apply to {} node `{id}`", tkey),
                );
            }
        }
        let mut children = Vec::new();
        let mut label = name.unwrap_or_else(|| kind.default_label().to_string());
        let mut skill = None;
        match kind.arity() {
            Arity::Leaf => match tval.get_ref().as_str() {
                Some(s) => {
                    label = cx.subst(s);
                    let want = if kind == BtNodeKind::Action {
                        SkillKind::Action
                    } else {
                        SkillKind::Condition
                    };
                    skill = self.skill_call(cx, t, &format!("node `{id}`"), Some(want));
                    if t.contains_key("skill") && skill.is_none() {
                        return None;
                    }
                }
                None => {
                    self.err(
                        cx,
                        tval.span(),
                        format!(
                            "`{tkey}` of node `{id}` must be its display name (a string), found {}",
                            type_name(tval.get_ref())
                        ),
                    )
                    .hint = Some(format!("write `{tkey} = \"Robot-At cube2?\"`"));
                    return None;
                }
            },
            _ => match tval.get_ref() {
                DeValue::String(s) => children.push((s.to_string(), tval.span())),
                DeValue::Array(a) => {
                    for c in a.iter() {
                        match c.get_ref().as_str() {
                            Some(s) => children.push((s.to_string(), c.span())),
                            None => {
                                self.err(
                                    cx,
                                    c.span(),
                                    format!(
                                        "children of `{id}` must be node ids (strings), found {}",
                                        type_name(c.get_ref())
                                    ),
                                );
                            }
                        }
                    }
                }
                other => {
                    self.err(
                        cx,
                        tval.span(),
                        format!(
                            "`{tkey}` of node `{id}` must list children ids, found {}",
                            type_name(other)
                        ),
                    )
                    .hint = Some(format!("write `{tkey} = [\"child1\", \"child2\"]`"));
                    return None;
                }
            },
        }
        let type_name = self.opt_str(cx, t, "type");
        if matches!(kind, BtNodeKind::Control | BtNodeKind::Decorator) && type_name.is_none() {
            self.err(cx, tspan, format!("{tkey} node `{id}` needs `type`"))
                .hint = Some(
                "write `type = \"IfThenElse\"`: the node's kind in the file it came from".into(),
            );
            return None;
        }
        let ports = self.ports(cx, t, id)?;
        Some((
            (Some(kind), label, children, skill, None),
            (type_name, ports),
        ))
    }

    /// Reads `ports = { name = "value", ... }` (values kept as text).
    fn ports(
        &mut self,
        cx: &Ctx<'_>,
        t: &DeTable<'_>,
        id: &str,
    ) -> Option<BTreeMap<String, String>> {
        let mut out = BTreeMap::new();
        let Some(pv) = t.get("ports") else {
            return Some(out);
        };
        let DeValue::Table(pt) = pv.get_ref() else {
            self.err(
                cx,
                pv.span(),
                format!(
                    "`ports` of node `{id}` must be a table, found {}",
                    type_name(pv.get_ref())
                ),
            )
            .hint = Some("write `ports = { num_cycles = \"3\" }`".into());
            return None;
        };
        for (k, v) in pt.iter() {
            match v.get_ref() {
                DeValue::String(_)
                | DeValue::Integer(_)
                | DeValue::Float(_)
                | DeValue::Boolean(_) => {
                    out.insert(k.get_ref().to_string(), scalar_text(v.get_ref()));
                }
                other => {
                    self.err(
                        cx,
                        v.span(),
                        format!(
                            "port `{}` of node `{id}` must be a string, found {}",
                            k.get_ref(),
                            type_name(other)
                        ),
                    );
                    return None;
                }
            }
        }
        Some(out)
    }

    /// Reads an included subtree file.
    fn include(&mut self, cx: &Ctx<'_>, id: &str, t: &DeTable<'_>, tval: &Val<'_>) -> Option<Bt> {
        let Some(rel) = tval.get_ref().as_str() else {
            self.err(
                cx,
                tval.span(),
                format!("`subtree` of node `{id}` must be a file path"),
            );
            return None;
        };
        let path = match super::source::resolve(self.root.as_deref(), cx.base, rel) {
            Ok(p) => p,
            Err(r) => {
                self.err(
                    cx,
                    tval.span(),
                    format!("subtree of node `{id}`: {}", r.message),
                )
                .hint = Some(r.hint);
                return None;
            }
        };
        let canon = canonical(&path);
        if let Some(pos) = self.stack.iter().position(|p| *p == canon) {
            let chain: Vec<String> = self.stack[pos..]
                .iter()
                .chain(std::iter::once(&canon))
                .map(|p| {
                    p.file_name()
                        .map_or_else(|| p.display().to_string(), |f| f.to_string_lossy().into())
                })
                .collect();
            self.err(
                cx,
                tval.span(),
                format!("cyclic subtree include: {}", chain.join(" -> ")),
            )
            .hint = Some("a subtree must not include itself, directly or through others".into());
            return None;
        }
        if self.stack.len() > self.limits.max_include_depth {
            self.err(
                cx,
                tval.span(),
                format!(
                    "subtree includes nested deeper than {}",
                    self.limits.max_include_depth
                ),
            );
            return None;
        }
        let with: Vec<(String, String)> = match t.get("with").map(|w| w.get_ref()) {
            Some(DeValue::Table(wt)) => wt
                .iter()
                .map(|(k, v)| (k.get_ref().to_string(), cx.subst(&scalar_text(v.get_ref()))))
                .collect(),
            Some(other) => vec![(String::new(), type_name(other).to_string())],
            None => Vec::new(),
        };
        let key = (canon.clone(), with);
        if let Some(done) = self.includes.get(&key) {
            // Read before: its problems are reported already.
            let size = done.as_ref()?.nodes.len();
            if size > self.node_budget || !self.limits.expansion_budget.charge(size as u64) {
                self.err(
                    cx,
                    tval.span(),
                    format!(
                        "more than {} nodes with the subtrees expanded (in this policy, or copied by this command in all)",
                        self.limits.max_nodes
                    ),
                )
                .hint = Some("raise the limit with --max-nodes".into());
                return None;
            }
            self.node_budget -= size;
            return done.clone();
        }
        let bt = self.read_include(cx, id, t, rel, &path, canon);
        if self.subst.overflow.replace(false) {
            self.err(
                cx,
                tval.span(),
                format!(
                    "substituting the parameters of subtree `{rel}` makes a string longer than {} bytes, or more than {} bytes in all",
                    self.limits.max_name_bytes, self.limits.max_file_bytes
                ),
            )
            .hint = Some("shorten the `with` values, or raise --max-name-bytes / --max-file-bytes".into());
            self.includes.insert(key, None);
            return None;
        }
        self.includes.insert(key, bt.clone());
        bt
    }

    /// Reads an included subtree file the first time (see [`Self::include`]).
    fn read_include(
        &mut self,
        cx: &Ctx<'_>,
        id: &str,
        t: &DeTable<'_>,
        rel: &str,
        path: &Path,
        canon: PathBuf,
    ) -> Option<Bt> {
        let tval = t.get("subtree").expect("a subtree node");
        let shown = path.display().to_string();
        let file = match read_included(path, &shown, &self.limits) {
            Ok(f) => f,
            Err(mut ds) => {
                let msg = ds.remove(0).message;
                self.err(cx, tval.span(), format!("subtree of node `{id}`: {msg}"));
                return None;
            }
        };
        let len = file.text.len() as u64;
        if len > self.include_bytes {
            self.err(
                cx,
                tval.span(),
                format!(
                    "subtree includes read more than {} bytes in total",
                    self.limits.max_file_bytes
                ),
            )
            .hint = Some("raise the limit with --max-file-bytes".into());
            return None;
        }
        self.include_bytes -= len;
        let doc = self.parse_doc(&file)?;
        let sub_table = doc.get_ref();
        let sub_cx0 = Ctx {
            file: &file,
            base: path.parent().unwrap_or(Path::new("")),
            params: BTreeMap::new(),
            subst: self.subst.clone(),
        };
        match self.kind(&sub_cx0, sub_table, doc.span()) {
            Some("bt") => {}
            Some(k) => {
                self.err(
                    cx,
                    tval.span(),
                    format!("subtree `{rel}` of node `{id}` is a `{k}`, not a `bt`"),
                );
                return None;
            }
            None => return None,
        }
        self.check_keys(
            &sub_cx0,
            sub_table,
            &["kind", "name", "description", "root", "nodes", "params"],
            "top-level key",
        );
        // Parameters: declared defaults in the subtree file, overridden by `with`.
        let mut params = BTreeMap::new();
        if let Some(pv) = sub_table.get("params") {
            match pv.get_ref() {
                DeValue::Table(pt) => {
                    for (k, v) in pt.iter() {
                        params.insert(k.get_ref().to_string(), scalar_text(v.get_ref()));
                    }
                }
                other => {
                    self.err(
                        &sub_cx0,
                        pv.span(),
                        format!("`params` must be a table, found {}", type_name(other)),
                    );
                }
            }
        }
        if let Some(wv) = t.get("with") {
            match wv.get_ref() {
                DeValue::Table(wt) => {
                    for (k, v) in wt.iter() {
                        if !params.contains_key(k.get_ref().as_ref()) {
                            let declared: Vec<&str> = params.keys().map(String::as_str).collect();
                            let h = if declared.is_empty() {
                                format!("`{rel}` declares no `[params]`")
                            } else {
                                self.suggest(k.get_ref(), declared)
                            };
                            self.err(
                                cx,
                                k.span(),
                                format!("subtree `{rel}` has no parameter `{}`", k.get_ref()),
                            )
                            .hint = Some(h);
                            continue;
                        }
                        params.insert(k.get_ref().to_string(), cx.subst(&scalar_text(v.get_ref())));
                    }
                }
                other => {
                    self.err(
                        cx,
                        wv.span(),
                        format!(
                            "`with` of node `{id}` must be a table, found {}",
                            type_name(other)
                        ),
                    );
                }
            }
        }
        let sub_cx = Ctx {
            file: &file,
            base: sub_cx0.base,
            params,
            subst: self.subst.clone(),
        };
        self.stack.push(canon);
        let bt = self.bt(&sub_cx, sub_table, doc.span(), Some(""));
        self.stack.pop();
        bt
    }

    // ---------------------------------------------------------------- FSM

    fn machine(
        &mut self,
        cx: &Ctx<'_>,
        doc: &DeTable<'_>,
        whole: Range<usize>,
        hierarchical: bool,
    ) -> Option<StateMachine> {
        let mut m = StateMachine {
            hierarchical,
            top: Region {
                initial: 0,
                outcomes: vec![],
                states: vec![],
            },
            states: Vec::new(),
        };
        // Regions are read breadth-first with an explicit queue (no recursion).
        struct Pending<'t, 'i> {
            table: &'t DeTable<'i>,
            span: Range<usize>,
            container: Option<usize>,
        }
        let mut queue = vec![Pending {
            table: doc,
            span: whole,
            container: None,
        }];
        let mut ok = true;
        // (state, transitions to resolve)
        type RawTr = (Trigger, String, Range<usize>);
        let mut raw_trs: Vec<Vec<RawTr>> = Vec::new();
        // Per state (as `raw_trs`): whether it names a skill at all (a state
        // whose skill is misspelled is not a state without one).
        let mut names_skill: Vec<bool> = Vec::new();
        let mut qi = 0;
        while qi < queue.len() {
            let Pending {
                table,
                span,
                container,
            } = std::mem::replace(
                &mut queue[qi],
                Pending {
                    table: doc,
                    span: 0..0,
                    container: None,
                },
            );
            qi += 1;
            let owner =
                container.map_or_else(|| "the machine".to_string(), |c| format!("`{}`", m.path(c)));
            let outcomes = self.outcomes(cx, table, &span, &owner);
            let Some(states_v) = table.get("states") else {
                self.err(
                    cx,
                    span.start..span.start,
                    format!("{owner} has no `states`"),
                )
                .hint = Some("add `[states]` (or `[states.NAME]` tables)".into());
                ok = false;
                continue;
            };
            let DeValue::Table(states) = states_v.get_ref() else {
                self.err(
                    cx,
                    states_v.span(),
                    format!(
                        "`states` must be a table, found {}",
                        type_name(states_v.get_ref())
                    ),
                );
                ok = false;
                continue;
            };
            let mut region = Region {
                initial: usize::MAX,
                outcomes: outcomes.clone(),
                states: vec![],
            };
            let mut local: Vec<(String, usize, Range<usize>)> = Vec::new();
            for (k, v) in states.iter() {
                let name = k.get_ref().to_string();
                if outcomes.contains(&name) {
                    self.err(
                        cx,
                        k.span(),
                        format!("state `{name}` has the name of an outcome of {owner}"),
                    )
                    .hint = Some("rename the state or the outcome".into());
                    ok = false;
                }
                if self.node_budget == 0 {
                    self.err(
                        cx,
                        k.span(),
                        format!("more than {} states", self.limits.max_nodes),
                    );
                    return None;
                }
                self.node_budget -= 1;
                let idx = m.states.len();
                let DeValue::Table(st) = v.get_ref() else {
                    self.err(
                        cx,
                        v.span(),
                        format!(
                            "state `{name}` must be a table, found {}",
                            type_name(v.get_ref())
                        ),
                    )
                    .hint = Some(format!(
                        "write `[states.\"{name}\"]` with `skill = ...` and `on = {{ SUCCESS = \"...\" }}`"
                    ));
                    ok = false;
                    continue;
                };
                let is_container = st.contains_key("states");
                let allowed: &[&str] = if is_container {
                    &["label", "initial", "outcomes", "states", "on", "guards"]
                } else {
                    &[
                        "label", "skill", "args", "decision", "history", "on", "guards",
                    ]
                };
                let before = self.problems();
                self.check_keys(cx, st, allowed, &format!("field of state `{name}`"));
                if self.problems() > before {
                    ok = false;
                }
                let label = self
                    .opt_str(cx, st, "label")
                    .unwrap_or_else(|| name.clone());
                let decision = match st.get("decision") {
                    None => false,
                    Some(d) => match d.get_ref().as_bool() {
                        Some(b) => b,
                        None => {
                            self.err(cx, d.span(), "`decision` must be `true` or `false`");
                            false
                        }
                    },
                };
                let pseudo = match st.get("history") {
                    None => None,
                    Some(h) => match h.get_ref().as_str() {
                        Some("shallow") => Some(crate::model::Pseudo::ShallowHistory),
                        Some("deep") => Some(crate::model::Pseudo::DeepHistory),
                        _ => {
                            self.err(cx, h.span(), "`history` must be \"shallow\" or \"deep\"")
                                .hint = Some(
                                "an SCXML history pseudo-state; it also needs `decision = true`"
                                    .into(),
                            );
                            ok = false;
                            None
                        }
                    },
                };
                if pseudo.is_some() && !decision {
                    self.err(
                        cx,
                        k.span(),
                        format!("history state `{name}` must be a decision state"),
                    )
                    .hint = Some("add `decision = true`: a history state runs no skill".into());
                    ok = false;
                }
                let body = if is_container {
                    if !hierarchical {
                        self.err(
                            cx,
                            k.span(),
                            format!(
                                "state `{name}` holds `states`, but only an `hfsm` has containers"
                            ),
                        )
                        .hint = Some("write `kind = \"hfsm\"` at the top of the file".into());
                        ok = false;
                    }
                    queue.push(Pending {
                        table: st,
                        span: v.span(),
                        container: Some(idx),
                    });
                    StateBody::Container(Region {
                        initial: usize::MAX,
                        outcomes: vec![],
                        states: vec![],
                    })
                } else if decision {
                    if st.contains_key("skill") {
                        self.err(
                            cx,
                            k.span(),
                            format!("decision state `{name}` cannot run a skill"),
                        )
                        .hint = Some("remove `skill`, or `decision = true`".into());
                        ok = false;
                    }
                    StateBody::Decision
                } else {
                    let call = self.skill_call(cx, st, &format!("state `{name}`"), None);
                    if st.contains_key("skill") && call.is_none() {
                        ok = false;
                    }
                    StateBody::Task(call)
                };
                // Transitions: guards (in order), then outcome transitions.
                let mut trs: Vec<RawTr> = Vec::new();
                if let Some(gv) = st.get("guards") {
                    match gv.get_ref() {
                        DeValue::Array(a) => {
                            for g in a.iter() {
                                match self.guard(cx, g, &name) {
                                    Some(t) => trs.push(t),
                                    None => ok = false,
                                }
                            }
                        }
                        other => {
                            self.err(
                                cx,
                                gv.span(),
                                format!(
                                    "`guards` of state `{name}` must be an array, found {}",
                                    type_name(other)
                                ),
                            )
                            .hint = Some(
                                "write `guards = [{ unless = \"Battery-Level\", args = { min = 20 }, to = \"Recharge\" }]`"
                                    .into(),
                            );
                            ok = false;
                        }
                    }
                }
                if let Some(ov) = st.get("on") {
                    match ov.get_ref() {
                        DeValue::Table(ot) => {
                            for (ok_key, tv) in ot.iter() {
                                match tv.get_ref().as_str() {
                                    Some(target) => trs.push((
                                        Trigger::Outcome(ok_key.get_ref().to_string()),
                                        target.to_string(),
                                        tv.span(),
                                    )),
                                    None => {
                                        self.err(
                                            cx,
                                            tv.span(),
                                            format!(
                                                "target of `{}` in state `{name}` must be a state or outcome name, found {}",
                                                ok_key.get_ref(),
                                                type_name(tv.get_ref())
                                            ),
                                        );
                                        ok = false;
                                    }
                                }
                            }
                        }
                        other => {
                            self.err(
                                cx,
                                ov.span(),
                                format!(
                                    "`on` of state `{name}` must be a table, found {}",
                                    type_name(other)
                                ),
                            )
                            .hint = Some(
                                "write `on = { SUCCESS = \"Next\", FAILURE = \"SELECTOR\" }`"
                                    .into(),
                            );
                            ok = false;
                        }
                    }
                }
                // Outcome keys valid for this kind of state (container outcomes
                // are checked after the container's region is read).
                m.states.push(State {
                    name: name.clone(),
                    label,
                    parent: container,
                    body,
                    transitions: Vec::new(),
                    pseudo,
                    span: Some(k.span()),
                });
                raw_trs.push(trs);
                names_skill.push(st.contains_key("skill"));
                region.states.push(idx);
                local.push((name, idx, k.span()));
            }
            if local.is_empty() {
                self.err(cx, states_v.span(), format!("{owner} has no states"));
                ok = false;
            }
            // Initial state.
            match table.get("initial") {
                None => {
                    let h = local
                        .first()
                        .map(|(n, _, _)| format!("add `initial = \"{n}\"`"))
                        .unwrap_or_else(|| "add `initial = \"STATE\"`".into());
                    let at = match container {
                        Some(c) => m.states[c].span.clone().unwrap_or(span.clone()),
                        None => span.start..span.start,
                    };
                    self.err(cx, at, format!("missing initial state of {owner}"))
                        .hint = Some(h);
                    ok = false;
                }
                Some(iv) => match iv.get_ref().as_str() {
                    Some(s) => match local.iter().find(|(n, _, _)| n == s) {
                        Some((_, idx, _)) => region.initial = *idx,
                        None => {
                            let h = self.suggest(s, local.iter().map(|(n, _, _)| n.as_str()));
                            self.err(
                                cx,
                                iv.span(),
                                format!("unknown initial state `{s}` of {owner}"),
                            )
                            .hint = Some(h);
                            ok = false;
                        }
                    },
                    None => {
                        self.err(cx, iv.span(), "`initial` must be a state name (a string)");
                        ok = false;
                    }
                },
            }
            match container {
                None => m.top = region,
                Some(c) => m.states[c].body = StateBody::Container(region),
            }
        }
        // Resolve transitions now that every region is known (even when other
        // problems were found, so that all of them are reported at once).
        let by_name: HashMap<(Option<usize>, &str), usize> = m
            .states
            .iter()
            .enumerate()
            .map(|(i, st)| ((st.parent, st.name.as_str()), i))
            .collect();
        // Targets in other regions (SCXML imports) are written as paths.
        let by_path: HashMap<String, usize> = (0..m.states.len()).map(|i| (m.path(i), i)).collect();
        let mut resolved_all: Vec<Vec<Transition>> = vec![Vec::new(); m.states.len()];
        for (si, trs) in raw_trs.into_iter().enumerate() {
            let region = m.region_of(si);
            let parent = m.states[si].parent;
            let sname = m.states[si].name.clone();
            let valid_outcomes: Vec<String> = match &m.states[si].body {
                StateBody::Container(r) => r.outcomes.clone(),
                StateBody::Decision => vec!["RUNNING".into()],
                StateBody::Task(_) => TASK_OUTCOMES.iter().map(|s| s.to_string()).collect(),
            };
            // A state without a skill (analysis only) returns whatever its
            // code does, as yasmin and SMACH states do; a near miss of
            // SUCCESS / FAILURE / RUNNING is worth a warning (yasmin's own
            // `SUCCEED` is one).
            let free = matches!(m.states[si].body, StateBody::Task(None))
                && !names_skill.get(si).copied().unwrap_or(true);
            for (trigger, target, span) in trs {
                if free
                    && let Trigger::Outcome(o) = &trigger
                    && !valid_outcomes.contains(o)
                {
                    let h = crate::diagnostic::suggest(o, TASK_OUTCOMES.iter().copied());
                    if h.starts_with("did you mean") {
                        self.warn(
                            cx,
                            span.clone(),
                            format!(
                                "state `{sname}` returns `{o}`: {h} (a state without a skill may return any outcome)"
                            ),
                        );
                    }
                } else if let Trigger::Outcome(o) = &trigger
                    && !valid_outcomes.contains(o)
                {
                    let what = match &m.states[si].body {
                        StateBody::Container(_) => "container",
                        StateBody::Decision => "decision state",
                        StateBody::Task(_) => "state",
                    };
                    let h = self.suggest(o, valid_outcomes.iter().map(String::as_str));
                    // Point at the key: the span we have is the value's; say so by message.
                    self.err(
                        cx,
                        span.clone(),
                        format!("{what} `{sname}` cannot return `{o}`"),
                    )
                    .hint = Some(h);
                    ok = false;
                    continue;
                }
                let resolved = if let Some(&t) = by_name.get(&(parent, target.as_str())) {
                    Target::State(t)
                } else if region.outcomes.contains(&target) {
                    Target::Outcome(target)
                } else if let Some(&t) = by_path.get(&target) {
                    Target::State(t)
                } else {
                    let cands: Vec<&str> = region
                        .states
                        .iter()
                        .map(|&t| m.states[t].name.as_str())
                        .chain(region.outcomes.iter().map(String::as_str))
                        .collect();
                    let h = self.suggest(&target, cands);
                    self.err(
                        cx,
                        span,
                        format!("unknown state `{target}` in transition of `{sname}`"),
                    )
                    .hint = Some(h);
                    ok = false;
                    continue;
                };
                resolved_all[si].push(Transition {
                    trigger,
                    target: resolved,
                    span: Some(span),
                });
            }
        }
        drop(by_name);
        drop(by_path);
        for (st, trs) in m.states.iter_mut().zip(resolved_all) {
            st.transitions = trs;
        }
        if !ok {
            return None;
        }
        if m.top.initial != usize::MAX {
            self.unreachable_states(cx, &m);
        }
        Some(m)
    }

    fn outcomes(
        &mut self,
        cx: &Ctx<'_>,
        table: &DeTable<'_>,
        span: &Range<usize>,
        owner: &str,
    ) -> Vec<String> {
        let Some(ov) = table.get("outcomes") else {
            self.err(
                cx,
                span.start..span.start,
                format!("{owner} has no `outcomes`"),
            )
            .hint = Some("add `outcomes = [\"SUCCESS\", \"FAILURE\"]`".into());
            return vec![];
        };
        let DeValue::Array(a) = ov.get_ref() else {
            self.err(
                cx,
                ov.span(),
                format!(
                    "`outcomes` must be an array of names, found {}",
                    type_name(ov.get_ref())
                ),
            );
            return vec![];
        };
        let mut out: Vec<String> = Vec::new();
        for o in a.iter() {
            match o.get_ref().as_str() {
                Some(s) if out.iter().any(|x| x == s) => {
                    self.err(cx, o.span(), format!("duplicate outcome `{s}`"));
                }
                Some(s) => out.push(s.to_string()),
                None => {
                    self.err(cx, o.span(), "outcome names must be strings");
                }
            }
        }
        // `outcomes = []` is a machine that never terminates (as SCXML machines
        // without `<final>` states are).
        out
    }

    fn guard(
        &mut self,
        cx: &Ctx<'_>,
        g: &Val<'_>,
        state: &str,
    ) -> Option<(Trigger, String, Range<usize>)> {
        let DeValue::Table(t) = g.get_ref() else {
            self.err(
                cx,
                g.span(),
                format!(
                    "a guard of state `{state}` must be a table, found {}",
                    type_name(g.get_ref())
                ),
            );
            return None;
        };
        let before = self.problems();
        self.check_keys(
            cx,
            t,
            &["if", "unless", "args", "all", "to", "label"],
            &format!("field of a guard of `{state}`"),
        );
        if self.problems() > before {
            return None;
        }
        let owner = format!("guard of `{state}`");
        let all = match t.get("all") {
            Some(av) => {
                if t.contains_key("if") || t.contains_key("unless") {
                    self.err(
                        cx,
                        av.span(),
                        format!("a {owner} has both `all` and `if`/`unless`"),
                    )
                    .hint = Some("put every condition inside `all`".into());
                    return None;
                }
                let DeValue::Array(items) = av.get_ref() else {
                    self.err(
                        cx,
                        av.span(),
                        format!("`all` of a {owner} must be an array of conditions"),
                    );
                    return None;
                };
                let mut terms = Vec::new();
                for item in items.iter() {
                    let DeValue::Table(it) = item.get_ref() else {
                        self.err(cx, item.span(), "a condition in `all` must be a table")
                            .hint = Some(
                            "write `{ if = \"In-Hand\", args = { object = \"cube2\" } }`".into(),
                        );
                        return None;
                    };
                    let before = self.problems();
                    self.check_keys(
                        cx,
                        it,
                        &["if", "unless", "args"],
                        &format!("field of a condition of a {owner}"),
                    );
                    if self.problems() > before {
                        return None;
                    }
                    terms.push(self.guard_term(cx, it, item.span(), &owner)?);
                }
                if terms.is_empty() {
                    self.err(cx, av.span(), format!("`all` of a {owner} is empty"));
                    return None;
                }
                terms
            }
            // A guard that names no condition of the skill library, only its
            // `label` (an SCXML event or condition, kept as text).
            None if !t.contains_key("if")
                && !t.contains_key("unless")
                && t.contains_key("label") =>
            {
                vec![]
            }
            None => vec![self.guard_term(cx, t, g.span(), &owner)?],
        };
        let Some(to_v) = t.get("to") else {
            self.err(
                cx,
                g.span(),
                format!("a guard of state `{state}` needs `to`"),
            )
            .hint = Some("write `to = \"TARGET STATE\"`".into());
            return None;
        };
        let Some(to) = to_v.get_ref().as_str() else {
            self.err(cx, to_v.span(), "`to` must be a state or outcome name");
            return None;
        };
        let label = self.opt_str(cx, t, "label").unwrap_or_else(|| {
            all.iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(" and ")
        });
        Some((
            Trigger::Guard(Guard { all, label }),
            to.to_string(),
            to_v.span(),
        ))
    }

    /// Reads one `if`/`unless` condition with its `args`.
    fn guard_term(
        &mut self,
        cx: &Ctx<'_>,
        t: &DeTable<'_>,
        span: Range<usize>,
        owner: &str,
    ) -> Option<GuardTerm> {
        let (negate, cond_v) = match (t.get("if"), t.get("unless")) {
            (Some(c), None) => (false, c),
            (None, Some(c)) => (true, c),
            _ => {
                self.err(cx, span, format!("a {owner} needs exactly one of `if` or `unless`"))
                    .hint = Some(
                    "write `{ unless = \"Battery-Level\", args = { min = 20 }, to = \"Recharge\" }`".into(),
                );
                return None;
            }
        };
        let Some(cond_name) = cond_v.get_ref().as_str() else {
            self.err(
                cx,
                cond_v.span(),
                "the guard's condition must be a skill name",
            );
            return None;
        };
        // Reuse the skill reader on a view where `skill` is the condition.
        let mut view = DeTable::new();
        view.insert(
            Spanned::new(0..0, std::borrow::Cow::Borrowed("skill")),
            Spanned::new(
                cond_v.span(),
                DeValue::String(std::borrow::Cow::Owned(cond_name.to_string())),
            ),
        );
        if let Some((k, a)) = t.get_key_value("args") {
            view.insert(k.clone(), a.clone());
        }
        let condition = self.skill_call(cx, &view, owner, Some(SkillKind::Condition))?;
        Some(GuardTerm { condition, negate })
    }

    /// Warns about states that no transition can reach.
    fn unreachable_states(&mut self, cx: &Ctx<'_>, m: &StateMachine) {
        let seen = m.reachable();
        for (i, s) in m.states.iter().enumerate() {
            if !seen[i] {
                self.warn(
                    cx,
                    s.span.clone().unwrap_or(0..0),
                    format!(
                        "state `{}` is unreachable from the initial state",
                        m.path(i)
                    ),
                );
                self.hint_last("add a transition to it, or remove it");
            }
        }
    }
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
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn parse(text: &str) -> Result<Loaded, Vec<Diagnostic>> {
        parse_str(
            "t.toml",
            text,
            Path::new("policies/paper"),
            &Limits::default(),
        )
    }

    const SEEDS: &[&str] = &[
        include_str!("../../policies/paper/fig01-bt.toml"),
        include_str!("../../policies/paper/fig04-fsm.toml"),
        include_str!("../../policies/paper/fig06-hfsm.toml"),
        include_str!("../../policies/paper/fig08e-fsm.toml"),
        include_str!("../../policies/paper/scal-bt.toml"),
    ];

    /// Everything downstream of a successful parse must work on it too (the
    /// fuzz targets' harness: graph, metrics, DOT, write-back fixpoint,
    /// transforms, effort).
    fn exercise(l: &Loaded) {
        crate::fuzzing::exercise(l);
    }

    #[test]
    fn a_state_without_a_skill_returns_any_outcome_a_near_miss_is_a_warning() {
        let fsm = |on: &str, skill: &str| {
            format!(
                "name = \"m\"\nkind = \"fsm\"\ninitial = \"a\"\noutcomes = [\"done\"]\n\n[states.a]\n{skill}on = {{ {on} = \"done\" }}\n"
            )
        };
        // yasmin-style outcomes on an unbound state: accepted, no warning.
        let l = parse(&fsm("outcome1", "")).unwrap();
        assert!(l.warnings.is_empty(), "{:?}", l.warnings);
        // A near miss of SUCCESS: accepted with a warning that says so.
        let l = parse(&fsm("SUCCEED", "")).unwrap();
        assert_eq!(l.warnings.len(), 1);
        assert!(l.warnings[0].message.contains("did you mean `SUCCESS`"));
        // A state bound to a skill returns SUCCESS, FAILURE or RUNNING only.
        let e = parse(&fsm("outcome1", "skill = \"Tuck-Arm\"\n")).unwrap_err();
        assert!(
            e[0].message.contains("cannot return `outcome1`"),
            "{}",
            e[0]
        );
    }

    #[test]
    fn seeds_parse_and_round_trip() {
        for s in SEEDS {
            let l = parse(s).unwrap_or_else(|e| panic!("{}", e[0]));
            exercise(&l);
        }
    }

    #[derive(Debug, Clone)]
    enum Mutation {
        Delete(usize, usize),
        Insert(usize, String),
        DuplicateLine(usize),
        SwapLines(usize, usize),
    }

    fn mutation() -> impl Strategy<Value = Mutation> {
        prop_oneof![
            (any::<usize>(), 1usize..12).prop_map(|(a, n)| Mutation::Delete(a, n)),
            (any::<usize>(), "[\\[\\]{}=\",.a-z0-9 \n#'\\\\]{1,6}")
                .prop_map(|(a, s)| Mutation::Insert(a, s)),
            any::<usize>().prop_map(Mutation::DuplicateLine),
            (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::SwapLines(a, b)),
        ]
    }

    fn apply(text: &str, ms: &[Mutation]) -> String {
        let mut t = text.to_string();
        for m in ms {
            match m {
                Mutation::Delete(a, n) => {
                    let mut a = a % (t.len() + 1);
                    while !t.is_char_boundary(a) {
                        a -= 1;
                    }
                    let mut b = (a + n).min(t.len());
                    while !t.is_char_boundary(b) {
                        b -= 1;
                    }
                    t.replace_range(a..b, "");
                }
                Mutation::Insert(a, s) => {
                    let mut a = a % (t.len() + 1);
                    while !t.is_char_boundary(a) {
                        a -= 1;
                    }
                    t.insert_str(a, s);
                }
                Mutation::DuplicateLine(i) | Mutation::SwapLines(i, _) => {
                    let mut lines: Vec<String> = t.lines().map(String::from).collect();
                    if lines.is_empty() {
                        continue;
                    }
                    let i = i % lines.len();
                    if let Mutation::SwapLines(_, j) = m {
                        let j = j % lines.len();
                        lines.swap(i, j);
                    } else {
                        let l = lines[i].clone();
                        lines.insert(i, l);
                    }
                    t = lines.join("\n");
                }
            }
        }
        t
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

        /// Mutated policy files never panic: they parse (and then analyze,
        /// write and read back) or give positioned errors.
        #[test]
        fn mutated_files_never_panic(seed in 0..SEEDS.len(), ms in proptest::collection::vec(mutation(), 1..4)) {
            let text = apply(SEEDS[seed], &ms);
            match parse(&text) {
                Ok(l) => exercise(&l),
                Err(diags) => {
                    prop_assert!(!diags.is_empty());
                    for d in &diags {
                        let _ = d.to_string();
                    }
                    prop_assert!(diags.iter().any(Diagnostic::is_error));
                }
            }
        }

        /// Arbitrary text never panics either.
        #[test]
        fn random_text_never_panics(text in "\\PC{0,200}") {
            if let Err(diags) = parse(&text) {
                for d in &diags {
                    let _ = d.to_string();
                }
            }
        }

        /// Arbitrary bytes through the fuzz target's body.
        #[test]
        fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..300)) {
            crate::fuzzing::toml_policy(&bytes);
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 40, ..ProptestConfig::default() })]

        /// Two mutated policies compared in every mode with a tiny budget: the
        /// `compare` fuzz target's body (certified interval, script cost).
        #[test]
        fn mutated_pairs_compare_within_their_certificates(
            a in 0..SEEDS.len(),
            b in 0..SEEDS.len(),
            ma in proptest::collection::vec(mutation(), 0..3),
            mb in proptest::collection::vec(mutation(), 0..3),
        ) {
            let pair = format!("{}\n%%\n{}", apply(SEEDS[a], &ma), apply(SEEDS[b], &mb));
            crate::fuzzing::compare(pair.as_bytes());
        }
    }
}
