//! Which files a review covers and in what order it reads them: the
//! changes `git diff --name-status -M` lists between the revisions (files
//! whose extension a reader takes, within the paths given), each read at
//! both revisions; then the unchanged policies of head that read a changed
//! file — a file naming the changed file (a BehaviorTree.CPP `<include>`,
//! a TOML subtree include, a yasmin include) or a BehaviorTree.CPP tree
//! that reads a changed node model found in the repository
//! (`lint::search`) — kept when either revision's reading of them differs.

use super::git::{Change, Repo, Status};
use super::side::{Holds, Reader, Side};
use super::snapshot::{Snapshot, is_candidate};
use super::{FileReview, Options, Review, Revision, gate, pair};
use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use btfsm_lint::config::Config;
use std::collections::BTreeSet;
use std::path::{Component, Path, PathBuf};

/// Runs a review.
pub(crate) fn run(opts: &Options) -> Result<Review, Diagnostic> {
    let repo = Repo::discover(&opts.cwd)?;
    let base = match &opts.base {
        Some(b) => repo.commit(b, "--base")?,
        None => repo.default_base()?,
    };
    let head = match &opts.head {
        Some(h) => Some(repo.commit(h, "--head")?),
        None => None,
    };
    let scope = scope(&repo, opts)?;
    let changes: Vec<Change> = repo
        .changes(&base, head.as_deref())?
        .into_iter()
        .filter(|c| {
            in_scope(&scope, &c.path) || c.from.as_deref().is_some_and(|f| in_scope(&scope, f))
        })
        .collect();
    let budget = opts.limits.read_budget.limit();
    let base_snap = Snapshot::materialise(&repo, &base, budget)?;
    let head_snap = match &head {
        Some(h) => Snapshot::materialise(&repo, h, budget)?,
        None => Snapshot::work_tree(&repo),
    };
    let (cfg, gates) = config(&base_snap, opts.config.as_deref(), &opts.limits)?;
    let mut rb = Reader::new(&base_snap, &opts.limits, &cfg);
    let mut rh = Reader::new(&head_snap, &opts.limits, &cfg);
    let mut review = Review {
        base: revision(&base_snap),
        head: revision(&head_snap),
        gates,
        files: Vec::new(),
        other_changes: 0,
        head_findings: Vec::new(),
    };
    let mut changed = BTreeSet::new();
    for c in &changes {
        changed.insert(c.path.clone());
        changed.extend(c.from.clone());
        if !is_candidate(&c.path) && !c.from.as_deref().is_some_and(is_candidate) {
            review.other_changes += 1;
            continue;
        }
        let old = c.from.as_deref().unwrap_or(&c.path);
        let before = if c.status == Status::Added {
            None
        } else {
            rb.read(old)?
        };
        let after = if c.status == Status::Removed {
            None
        } else {
            rh.read(&c.path)?
        };
        let is_policy = |s: &Option<Side>| s.as_ref().is_some_and(|s| s.holds != Holds::Other);
        if !is_policy(&before) && !is_policy(&after) {
            review.other_changes += 1;
            continue;
        }
        let mut f = FileReview::new(&c.path, c.from.clone(), c.status.clone());
        pair::fill(&mut f, before.as_ref(), after.as_ref(), opts);
        keep(&mut review, f, after);
    }
    dependents(&mut review, &changed, &scope, (&mut rb, &mut rh), opts)?;
    for f in &mut review.files {
        f.gate_failures = review.gates.check(f);
    }
    Ok(review)
}

/// Adds a file's review, with head's findings for SARIF.
fn keep(review: &mut Review, f: FileReview, after: Option<Side>) {
    if let Some(s) = after {
        review.head_findings.extend(s.findings);
    }
    review.files.push(f);
}

fn revision(s: &Snapshot) -> Revision {
    Revision {
        commit: s.commit.clone(),
        label: s.label(),
    }
}

/// The paths given, relative to the repository's top (`None`: all).
fn scope(repo: &Repo, opts: &Options) -> Result<Option<Vec<String>>, Diagnostic> {
    if opts.paths.is_empty() {
        return Ok(None);
    }
    let top = btfsm_format::source::canonical(&repo.top);
    let cwd = btfsm_format::source::canonical(&opts.cwd);
    let mut out = Vec::new();
    for p in &opts.paths {
        let joined = lexical(&cwd.join(p));
        let Ok(rel) = joined.strip_prefix(&top) else {
            return Err(Diagnostic::error(format!(
                "`{}` is outside the repository",
                btfsm_core::sanitize::shown(&p.display().to_string())
            ))
            .hint("name files or folders inside the repository being reviewed"));
        };
        out.push(rel.to_string_lossy().into_owned());
    }
    Ok(Some(out))
}

/// `.` and `..` removed without touching the file system.
fn lexical(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out
}

fn in_scope(scope: &Option<Vec<String>>, path: &str) -> bool {
    match scope {
        None => true,
        Some(s) => s.iter().any(|p| {
            p.is_empty()
                || path == p
                || path
                    .strip_prefix(p.as_str())
                    .is_some_and(|r| r.starts_with('/'))
        }),
    }
}

/// The base revision's `btfsm.toml` (or `--config FILE`): lint levels and
/// models (`[lint]`), and the gates (`[review]`).
fn config(
    base: &Snapshot,
    given: Option<&Path>,
    limits: &btfsm_format::Limits,
) -> Result<(Config, gate::Gates), Diagnostic> {
    let (path, shown) = match given {
        Some(p) => (p.to_path_buf(), p.display().to_string()),
        None => (
            base.path("btfsm.toml"),
            format!("btfsm.toml (base {})", base.label()),
        ),
    };
    if given.is_none() && !path.is_file() {
        return Ok((Config::default(), gate::Gates::default()));
    }
    let file = btfsm_format::source::read(&path, &shown, limits, true).map_err(first)?;
    let file = SourceFile::new(shown, file.text.clone());
    let mut cfg = btfsm_lint::config::read(&file).map_err(first)?;
    cfg.file = Some(path);
    let gates = gate::read(&file)?;
    Ok((cfg, gates))
}

fn first(mut d: Vec<Diagnostic>) -> Diagnostic {
    if d.is_empty() {
        Diagnostic::error("btfsm.toml cannot be read")
    } else {
        d.swap_remove(0)
    }
}

/// Head's unchanged policies that read a changed file, reviewed when
/// their reading differs.
fn dependents(
    review: &mut Review,
    changed: &BTreeSet<String>,
    scope: &Option<Vec<String>>,
    (rb, rh): (&mut Reader, &mut Reader),
    opts: &Options,
) -> Result<(), Diagnostic> {
    if changed.is_empty() {
        return Ok(());
    }
    // Changed files by file name: a file names another by a path ending
    // in it (`<include path="../sub/sub.xml"/>`).
    let mut names: std::collections::HashMap<&str, Vec<&str>> = std::collections::HashMap::new();
    for p in changed.iter().filter(|p| is_candidate(p)) {
        names
            .entry(p.rsplit('/').next().unwrap_or(p))
            .or_default()
            .push(p);
    }
    let models: Vec<&str> = changed
        .iter()
        .filter(|p| btfsm_lint::search::is_model_name(p.rsplit('/').next().unwrap_or(p)))
        .map(String::as_str)
        .collect();
    let root = rh.snap.root.clone();
    let inputs = btfsm_format::discover::expand(std::slice::from_ref(&root))?;
    for input in inputs {
        let Ok(rel) = input.path.strip_prefix(&root) else {
            continue;
        };
        let rel = rel.to_string_lossy().into_owned();
        if changed.contains(&rel) || !in_scope(scope, &rel) {
            continue;
        }
        let Ok(text) = std::fs::read_to_string(&input.path) else {
            continue;
        };
        let mut via: Vec<String> = file_names(&text)
            .filter_map(|n| names.get(n))
            .flatten()
            .map(|p| p.to_string())
            .collect();
        if !models.is_empty() && text.contains("<BehaviorTree") {
            let found = rh.found_models(&rel);
            via.extend(
                models
                    .iter()
                    .filter(|m| found.iter().any(|f| f == *m))
                    .map(|m| m.to_string()),
            );
        }
        if via.is_empty() {
            continue;
        }
        let (before, after) = (rb.read(&rel)?, rh.read(&rel)?);
        if !after.as_ref().is_some_and(|s| s.holds == Holds::Policy) {
            continue;
        }
        let mut f = FileReview::new(&rel, None, Status::Dependency);
        via.sort();
        via.dedup();
        f.via = via;
        pair::fill(&mut f, before.as_ref(), after.as_ref(), opts);
        let same = f.unchanged
            && f.new_findings.is_empty()
            && f.fixed_findings == 0
            && f.before == f.after;
        if !same {
            keep(review, f, after);
        }
    }
    Ok(())
}

/// The file names a text mentions: each run of characters that may be
/// part of a file name (no `/`, quote or blank) and ends in a reader's
/// extension (one pass over the text; a name with a blank is found by its
/// last word only).
fn file_names(text: &str) -> impl Iterator<Item = &str> {
    text.split(|c: char| {
        !(c.is_alphanumeric() || matches!(c, '.' | '_' | '-' | '+' | '@' | '~' | '%'))
    })
    .filter(|w| is_candidate(w))
}

#[cfg(test)]
mod tests {
    #[test]
    fn file_names_are_found_in_one_pass() {
        let t = r#"<include path="../sub/sub.xml"/> <include ros_pkg="p" path="a b.toml"/> x.xmlz"#;
        let got: Vec<&str> = super::file_names(t).collect();
        assert_eq!(got, ["sub.xml", "b.toml"]);
    }
}
