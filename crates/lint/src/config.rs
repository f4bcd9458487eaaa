//! Levels per rule: the defaults, a `[lint]` table of `btfsm.toml` (found
//! in the current directory or above it, up to the repository root), then
//! `--deny`/`--warn`/`--allow` (last word wins), as cargo-deny and ruff
//! configure theirs.
//!
//! ```toml
//! [lint]
//! deny = ["unguarded-fallback-action"]   # error
//! warn = ["chattering-precondition-order"]
//! allow = ["fully-connected-state"]      # not reported
//! models = ["nav2_behavior_tree/nav2_tree_nodes.xml"]  # node models
//! ```
//!
//! `models` are BehaviorTree.CPP `<TreeNodesModel>` files (paths relative
//! to the `btfsm.toml`), read with every BehaviorTree.CPP tree as if given
//! with `--nodes-model`.

use super::{Level, Rule, rule};
use btfsm_core::diagnostic::{Diagnostic, SourceFile, suggest};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The levels in force.
#[derive(Debug, Clone, Default)]
pub struct Config {
    levels: BTreeMap<&'static str, Level>,
    /// The `btfsm.toml` read, if any.
    pub file: Option<PathBuf>,
    /// Its `models`, relative to its folder (as written there).
    pub models: Vec<PathBuf>,
}

impl Config {
    /// The level of `r`.
    pub fn level(&self, r: &Rule) -> Level {
        self.levels.get(r.code).copied().unwrap_or(r.level)
    }

    /// Sets `code` to `level`; an unknown code is an error naming the
    /// closest.
    pub fn set(&mut self, code: &str, level: Level) -> Result<(), String> {
        match rule(code) {
            Some(r) if r.code == super::load::LOAD_ERROR.code && level != Level::Error => Err(
                "`load-error` stays an error: a file that does not load is never linted, and lint always says so".into(),
            ),
            Some(r) => {
                self.levels.insert(r.code, level);
                Ok(())
            }
            None => Err(format!(
                "unknown lint `{}`; {}",
                btfsm_core::sanitize::shown(code),
                suggest(code, super::RULES.iter().map(|r| r.code))
            )),
        }
    }
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile {
    #[serde(default)]
    lint: RawLint,
    /// `btfsm review`'s gates (`btfsm_review::gate`), read there.
    #[serde(default, rename = "review")]
    _review: Option<toml::Value>,
}

#[derive(serde::Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawLint {
    #[serde(default)]
    deny: Vec<toml::Spanned<String>>,
    #[serde(default)]
    warn: Vec<toml::Spanned<String>>,
    #[serde(default)]
    allow: Vec<toml::Spanned<String>>,
    #[serde(default)]
    models: Vec<String>,
}

/// `btfsm.toml` in `dir` or the nearest folder above it, stopping at the
/// repository root (a folder holding `.git`).
pub fn find(dir: &Path) -> Option<PathBuf> {
    let mut d = Some(dir);
    while let Some(x) = d {
        let f = x.join("btfsm.toml");
        if f.is_file() {
            return Some(f);
        }
        if x.join(".git").exists() {
            return None;
        }
        d = x.parent();
    }
    None
}

/// Reads the `[lint]` table of a `btfsm.toml`. A file from a pull request
/// is bounded (issue 33): its tokens are counted before it is parsed, and
/// each kind of error is one message: the first unknown code, with its
/// position and the closest code, then how many more there are (3 million
/// unknown codes wrote 1.1 GB of messages).
pub fn read(file: &Arc<SourceFile>) -> Result<Config, Vec<Diagnostic>> {
    btfsm_core::toml_budget::check(
        file,
        btfsm_core::toml_budget::DEFAULT_MAX_TOKENS,
        "btfsm.toml lists rule codes: a few hundred tokens",
    )
    .map_err(|d| vec![d])?;
    let raw: RawFile = toml::from_str(&file.text).map_err(|e| {
        let d = Diagnostic::error(format!("invalid btfsm.toml: {}", e.message().trim()))
            .hint("btfsm.toml holds `[lint]` with `deny`, `warn` and `allow` lists of rule codes, and `models`, a list of node model files");
        vec![match e.span() {
            Some(s) => d.at(file, s),
            None => d,
        }]
    })?;
    let mut cfg = Config {
        file: Some(PathBuf::from(&file.path)),
        models: raw.lint.models.iter().map(PathBuf::from).collect(),
        ..Config::default()
    };
    let mut errs = Vec::new();
    let mut unknown = 0usize;
    for (list, level) in [
        (&raw.lint.allow, Level::Allow),
        (&raw.lint.warn, Level::Warning),
        (&raw.lint.deny, Level::Error),
    ] {
        for code in list {
            if rule(code.get_ref()).is_none() {
                unknown += 1;
                if unknown > 1 {
                    continue;
                }
            }
            if let Err(e) = cfg.set(code.get_ref(), level) {
                errs.push(Diagnostic::error(e).at(file, code.span()));
            }
        }
    }
    if unknown > 1 {
        errs.push(
            Diagnostic::error(format!(
                "{} more unknown lint codes in this btfsm.toml",
                unknown - 1
            ))
            .in_file(file)
            .hint("`btfsm lint --list` lists the codes"),
        );
    }
    if errs.is_empty() { Ok(cfg) } else { Err(errs) }
}
