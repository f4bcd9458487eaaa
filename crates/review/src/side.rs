//! One file at one revision: read from that revision's [`Snapshot`] (its
//! includes, SubTrees and node models from the same revision), classified
//! as `format::discover` does (a policy, a scenario, a domain, or none),
//! loaded as `btfsm lint` loads it (docs/lint.md: unknown leaves kept as
//! actions, node models found in the repository, `for_lint`), measured as
//! `btfsm analyze` measures it (`report::analyze`) and linted with the
//! base revision's rule levels.
//!
//! Paths are shown relative to the revision's top, whichever directory it
//! was materialised in, so that the two revisions' findings compare.

use super::snapshot::Snapshot;
use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use btfsm_format::{self as format, FileFormat, Limits, Loaded};
use btfsm_lint::{self as lint, config::Config};
use btfsm_report::PolicyReport;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// What a file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Holds {
    /// A policy (BT or machine), in its format.
    Policy,
    Scenario,
    Domain,
    /// Not a policy (a node model, an included file of models, another
    /// TOML file).
    Other,
}

/// One file at one revision.
pub struct Side {
    pub holds: Holds,
    pub loaded: Option<Loaded>,
    pub metrics: Option<PolicyReport>,
    /// Lint findings (a file that does not load: its `load-error`).
    pub findings: Vec<lint::Finding>,
    /// Why a policy did not load (its first error), if it did not.
    pub load_error: Option<String>,
}

/// What reading the files of one revision shares.
pub struct Reader<'a> {
    pub snap: &'a Snapshot,
    pub limits: Limits,
    pub cfg: &'a Config,
    /// `[lint] models` of the configuration, relative to the top.
    pub models: Vec<PathBuf>,
    search: lint::search::ModelSearch,
}

impl<'a> Reader<'a> {
    pub fn new(snap: &'a Snapshot, limits: &Limits, cfg: &'a Config) -> Reader<'a> {
        let mut limits = limits.clone();
        limits.for_lint = true;
        if limits.confinement != format::source::Confinement::Off {
            limits.confinement = format::source::Confinement::Root(snap.root.clone());
        }
        let models = cfg
            .models
            .iter()
            .map(|m| snap.root.join(m))
            .filter(|m| m.is_file())
            .collect();
        Reader {
            snap,
            limits,
            cfg,
            models,
            search: lint::search::ModelSearch::default(),
        }
    }

    /// Reads `rel`: `Ok(None)` when the revision has no such file;
    /// `Err` when it cannot be read (outside the top, not a regular file,
    /// unreadable).
    pub fn read(&mut self, rel: &str) -> Result<Option<Side>, Diagnostic> {
        let root = self.snap.root.clone();
        let path = self.snap.path(rel);
        if path.symlink_metadata().is_err() {
            return Ok(None);
        }
        let path = format::source::resolve(Some(&root), &root, rel).map_err(|r| {
            Diagnostic::error(format!(
                "`{}` ({}): {}",
                btfsm_core::sanitize::shown(rel),
                self.snap.label(),
                r.message
            ))
            .hint(r.hint)
        })?;
        let input = format::discover::Input {
            path: path.clone(),
            found: true,
        };
        let (file, holds) = match format::discover::read(&input, &self.limits) {
            Ok(x) => x,
            Err(d) => return Err(self.unreadable(rel, &d)),
        };
        let file = SourceFile::new(rel, file.text.clone());
        Ok(Some(match holds {
            Some(format::Input::Policy(fmt)) => self.policy(rel, &path, file, fmt),
            Some(format::Input::Scenario) => bare(Holds::Scenario),
            Some(format::Input::Domain) => bare(Holds::Domain),
            None => bare(Holds::Other),
        }))
    }

    fn unreadable(&self, rel: &str, d: &[Diagnostic]) -> Diagnostic {
        let why = d.first().map_or_else(String::new, |d| d.message.clone());
        Diagnostic::error(format!(
            "`{}` ({}): cannot be read: {}",
            btfsm_core::sanitize::shown(rel),
            self.snap.label(),
            self.relative(&why)
        ))
        .hint("raise --max-file-bytes or --max-total-bytes if it is too large; a file must be a regular file inside the repository")
    }

    /// A policy file: loaded, measured and linted.
    fn policy(&mut self, rel: &str, path: &Path, file: Arc<SourceFile>, fmt: FileFormat) -> Side {
        let mut limits = self.tree_limits(path, &file.text, fmt);
        if fmt == FileFormat::BtcppXml
            && let Some(first) = format::btcpp_xml::root_trees(&file, &limits, 64)
                .and_then(|ids| ids.into_iter().next())
        {
            limits.tree = Some(first);
        }
        let mut side = bare(Holds::Policy);
        match format::load_read(file.clone(), path, fmt, &limits) {
            Ok(l) => {
                let subject = lint::Subject {
                    policy: &l.policy,
                    dataflow: l.dataflow.as_deref(),
                };
                side.findings = lint::lint_subject(&subject, Some(&file), rel, self.cfg);
                side.findings
                    .extend(lint::load::findings(&l.warnings, rel, self.cfg, true));
                let mut m = btfsm_report::analyze(&l);
                m.file = rel.to_string();
                side.metrics = Some(m);
                side.loaded = Some(l);
            }
            Err(d) => {
                side.findings = lint::load::findings(&d, rel, self.cfg, false);
                side.load_error = Some(
                    d.iter()
                        .find(|d| d.is_error())
                        .map_or_else(|| "it does not load".into(), |d| self.relative(&d.message)),
                );
            }
        }
        for f in &mut side.findings {
            f.file = self.relative(&f.file);
            f.message = self.relative(&f.message);
            f.at = self.relative(&f.at);
        }
        side
    }

    /// The limits a BehaviorTree.CPP file is read with, as `lint` reads it:
    /// unknown leaves as actions, the configured models, else those found
    /// in this revision.
    fn tree_limits(&mut self, path: &Path, text: &str, fmt: FileFormat) -> Limits {
        let mut l = self.limits.clone();
        if fmt != FileFormat::BtcppXml {
            return l;
        }
        l.assume_leaf = l.assume_leaf.or(Some(format::AssumeLeaf::Action));
        l.nodes_models.extend(self.models.iter().cloned());
        if l.nodes_models.is_empty() && !btfsm_lint::models::has_leaf_model(text) {
            l.found_models = self.search.for_tree(path, &self.snap.root);
        }
        l
    }

    /// The node models a tree at `rel` would read from this revision's
    /// search (for telling which trees a changed model governs).
    pub fn found_models(&mut self, rel: &str) -> Vec<String> {
        let path = self.snap.path(rel);
        self.search
            .for_tree(&path, &self.snap.root)
            .iter()
            .map(|m| self.relative(&m.display().to_string()))
            .collect()
    }

    /// `s` with this revision's top (where it was materialised) removed
    /// from the paths it quotes.
    pub fn relative(&self, s: &str) -> String {
        let top = format!("{}/", self.snap.root.display());
        s.replace(&top, "")
    }
}

fn bare(holds: Holds) -> Side {
    Side {
        holds,
        loaded: None,
        metrics: None,
        findings: Vec::new(),
        load_error: None,
    }
}
