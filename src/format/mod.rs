//! Policy file formats. Each format reads a file into a [`crate::model::Policy`],
//! collecting every problem it finds as a positioned [`Diagnostic`].

pub mod btcpp_xml;
pub mod btcpp_xml_write;
pub mod scxml;
pub mod scxml_write;
pub mod toml;
pub mod toml_write;
pub mod xml;

use crate::diagnostic::{Diagnostic, SourceFile};
use crate::model::Policy;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A policy read from a file, with the warnings its validation produced.
#[derive(Debug)]
pub struct Loaded {
    pub path: String,
    pub policy: Policy,
    pub warnings: Vec<Diagnostic>,
}

/// Resource limits on input (hostile or accidental).
#[derive(Debug, Clone)]
pub struct Limits {
    /// Largest file read, in bytes.
    pub max_file_bytes: u64,
    /// Most BT nodes or FSM states after expanding subtree includes.
    pub max_nodes: usize,
    /// Deepest subtree include chain.
    pub max_include_depth: usize,
    /// BehaviorTree.CPP `<TreeNodesModel>` files (`--nodes-model`) that say
    /// which node types are actions, conditions, controls and decorators.
    pub nodes_models: Vec<PathBuf>,
    /// How to read a BehaviorTree.CPP leaf of unknown type (`--assume-leaf`);
    /// `None`: such a leaf is an error.
    pub assume_leaf: Option<AssumeLeaf>,
}

/// The kind given to BehaviorTree.CPP leaves of unknown type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AssumeLeaf {
    Action,
    Condition,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_file_bytes: 64 * 1024 * 1024,
            max_nodes: 2_000_000,
            max_include_depth: 64,
            nodes_models: Vec::new(),
            assume_leaf: None,
        }
    }
}

/// The file formats a policy is read from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileFormat {
    Toml,
    BtcppXml,
    Scxml,
}

/// The format of a file: by extension (`.toml`, `.scxml`, `.xml`), else by its
/// first bytes (`<scxml`, `<root`, ...); TOML otherwise.
pub fn detect(path: &Path) -> FileFormat {
    match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("toml") => return FileFormat::Toml,
        Some(e) if e.eq_ignore_ascii_case("scxml") => return FileFormat::Scxml,
        _ => {}
    }
    let head = read_head(path);
    let is_xml_ext = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("xml"));
    if head.contains("<scxml") {
        FileFormat::Scxml
    } else if is_xml_ext || head.trim_start().starts_with('<') {
        FileFormat::BtcppXml
    } else {
        FileFormat::Toml
    }
}

/// The first few kilobytes of a file (lossy), for sniffing.
fn read_head(path: &Path) -> String {
    use std::io::Read;
    let mut buf = vec![0u8; 4096];
    let n = std::fs::File::open(path)
        .and_then(|mut f| f.read(&mut buf))
        .unwrap_or(0);
    String::from_utf8_lossy(&buf[..n]).into_owned()
}

/// Reads a policy from any supported format (see [`detect`]).
pub fn load(path: &Path, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    match detect(path) {
        FileFormat::Toml => toml::load_file(path, limits),
        FileFormat::BtcppXml => btcpp_xml::load_file(path, limits),
        FileFormat::Scxml => scxml::load_file(path, limits),
    }
}

/// The result of reading `file`: the policy with its warnings, or every error
/// followed by the warnings (each in file and source order). `what` names the
/// policy in the fallback message when reading failed without an error.
pub(crate) fn finish(
    file: &Arc<SourceFile>,
    policy: Option<Policy>,
    mut diags: Vec<Diagnostic>,
    what: &str,
) -> Result<Loaded, Vec<Diagnostic>> {
    diags.sort_by_key(|d| {
        (
            d.file.as_ref().map(|f| f.path.clone()),
            d.span.as_ref().map_or(0, |s| s.start),
        )
    });
    let (errors, warnings): (Vec<_>, Vec<_>) = diags.into_iter().partition(Diagnostic::is_error);
    match policy {
        Some(policy) if errors.is_empty() => Ok(Loaded {
            path: file.path.clone(),
            policy,
            warnings,
        }),
        _ => {
            let mut all = errors;
            if all.is_empty() {
                all.push(Diagnostic::error(format!("invalid {what}")).in_file(file));
            }
            all.extend(warnings);
            Err(all)
        }
    }
}
