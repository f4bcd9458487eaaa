//! Node models found as users keep them (docs/lint.md, "Node models"):
//! BehaviorTree.CPP node models live beside the trees in Groot projects
//! (a `.btproj`), in another package of the same repository in Nav2
//! (`nav2_behavior_tree/nav2_tree_nodes.xml`, the trees in
//! `nav2_bt_navigator/behavior_trees/`), and in a behavior package's
//! `config/tree_nodes_model.xml` in MoveIt Studio (MoveIt Pro) workspaces.
//!
//! The repository of a tree (its confinement root: the git work tree, or
//! `--root`) is walked once, bounded like the directory walks of
//! `btfsm_format::discover` (hidden entries, `target/`, `node_modules/`
//! skipped, no symbolic link followed, at most [`MAX_WALK_ENTRIES`]
//! entries), for regular files named `*tree_nodes*.xml` or `*.btproj`. A
//! tree reads the models of the nearest folder, from its own up to the
//! root, below which any is found, at most [`MAX_MODELS`] of them.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Directory entries one root's walk visits at most (past it, the models
/// found so far are used).
pub const MAX_WALK_ENTRIES: usize = 100_000;
/// Directory levels the walk descends at most.
pub const MAX_WALK_DEPTH: usize = 32;
/// Model files a tree reads at most.
pub const MAX_MODELS: usize = 8;
/// Model files kept per repository.
pub const MAX_FOUND: usize = 256;

/// Is `name` a node model's file name?
pub fn is_model_name(name: &str) -> bool {
    let lower = name.to_ascii_lowercase();
    (lower.contains("tree_nodes") && lower.ends_with(".xml")) || lower.ends_with(".btproj")
}

/// The models of each repository walked so far.
#[derive(Default)]
pub struct ModelSearch {
    by_root: HashMap<PathBuf, Vec<PathBuf>>,
}

impl ModelSearch {
    /// The models a tree at `tree` reads: those below the nearest folder,
    /// from the tree's up to `root` (canonical), below which any is found;
    /// sorted, the tree itself left out. Paths are as the walk found them
    /// (below `root`).
    pub fn for_tree(&mut self, tree: &Path, root: &Path) -> Vec<PathBuf> {
        let models = self
            .by_root
            .entry(root.to_path_buf())
            .or_insert_with(|| walk(root));
        if models.is_empty() {
            return Vec::new();
        }
        let dir = tree
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let dir = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
        let me = std::fs::canonicalize(tree).ok();
        for a in dir.ancestors() {
            if !a.starts_with(root) {
                break;
            }
            let here: Vec<PathBuf> = models
                .iter()
                .filter(|m| m.starts_with(a) && Some(m.as_path()) != me.as_deref())
                .take(MAX_MODELS)
                .cloned()
                .collect();
            if !here.is_empty() {
                return here;
            }
        }
        Vec::new()
    }
}

/// The model files below `root`, sorted (bounded; see the module doc).
fn walk(root: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut visited = 0usize;
    let mut stack = vec![(root.to_path_buf(), 0usize)];
    while let Some((d, depth)) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            visited += 1;
            if visited > MAX_WALK_ENTRIES || found.len() >= MAX_FOUND {
                found.sort();
                return found;
            }
            let name = e.file_name();
            let name = name.to_string_lossy();
            if name.starts_with('.') || name == "target" || name == "node_modules" {
                continue;
            }
            let Ok(ft) = e.file_type() else { continue };
            if ft.is_dir() && depth < MAX_WALK_DEPTH {
                stack.push((e.path(), depth + 1));
            } else if ft.is_file() && is_model_name(&name) {
                found.push(e.path());
            }
        }
    }
    found.sort();
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_nearest_folder_with_models_wins_up_to_the_root() {
        let d = std::env::temp_dir().join(format!("btfsm-search-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        for sub in [
            "nav/behavior_trees",
            "nav/model",
            "other/model",
            "pick/trees",
            ".hidden",
        ] {
            std::fs::create_dir_all(d.join(sub)).unwrap();
        }
        let root = std::fs::canonicalize(&d).unwrap();
        for f in [
            "nav/behavior_trees/a.xml",
            "nav/model/nav2_tree_nodes.xml",
            "other/model/tree_nodes_model.xml",
            "pick/trees/b.xml",
            "pick/p.btproj",
            ".hidden/x_tree_nodes.xml",
        ] {
            std::fs::write(d.join(f), "<root/>").unwrap();
        }
        let mut s = ModelSearch::default();
        // nav/behavior_trees: nothing there, `nav/` holds one.
        assert_eq!(
            s.for_tree(&d.join("nav/behavior_trees/a.xml"), &root),
            [root.join("nav/model/nav2_tree_nodes.xml")]
        );
        // pick/trees: `pick/` holds the Groot project.
        assert_eq!(
            s.for_tree(&d.join("pick/trees/b.xml"), &root),
            [root.join("pick/p.btproj")]
        );
        // A tree at the root reads every model below it (hidden ones not).
        assert_eq!(s.for_tree(&d.join("top.xml"), &root).len(), 3);
        std::fs::remove_dir_all(&d).ok();
    }
}
