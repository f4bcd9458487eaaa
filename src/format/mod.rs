//! Policy file formats. Each format reads a file into a [`crate::model::Policy`],
//! collecting every problem it finds as a positioned [`Diagnostic`].

pub mod toml;
pub mod toml_write;

use crate::diagnostic::Diagnostic;
use crate::model::Policy;
use std::path::Path;

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
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_file_bytes: 64 * 1024 * 1024,
            max_nodes: 2_000_000,
            max_include_depth: 64,
        }
    }
}

/// Reads a policy from any supported format (chosen by extension).
pub fn load(path: &Path, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    toml::load_file(path, limits)
}
