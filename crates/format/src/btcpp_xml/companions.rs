//! BehaviorTree.CPP files given together: the trees each defines, so that a
//! `<SubTree ID>` one file uses and another defines is found, as
//! BehaviorTree.CPP's `BehaviorTreeFactory` registers every tree of every
//! file it loads (`registerBehaviorTreeFromFile`) before `createTree(ID)`.
//!
//! The index is built on first use only (a command whose SubTrees are all
//! defined where they are used reads nothing more), by one pass over each
//! file: its document element's `<BehaviorTree ID>` children. A file that
//! cannot be read or parsed is left out of the index (it reports its own
//! errors when it is loaded as an input). Reading for the index counts
//! against the command's `--max-total-bytes` like any read.

use super::super::xml;
use super::super::{Limits, source};
use btfsm_core::diagnostic::SourceFile;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::OnceLock;

/// The BehaviorTree.CPP files of one command and, once asked, the trees
/// each defines.
#[derive(Debug, Default)]
pub struct Companions {
    files: Vec<PathBuf>,
    index: OnceLock<BTreeMap<String, Vec<usize>>>,
}

impl Companions {
    /// The files given together (regular files only: a pipe is read once,
    /// as the input it is).
    pub fn new(files: Vec<PathBuf>) -> Companions {
        Companions {
            files,
            index: OnceLock::new(),
        }
    }

    /// The Groot2 project files (`.btproj`) among them: their
    /// `<TreeNodesModel>` declares the project's node types (Groot2 keeps
    /// them there, not in the trees), read by every tree of the command.
    pub fn projects(&self) -> impl Iterator<Item = &Path> {
        self.files
            .iter()
            .filter(|p| {
                p.extension()
                    .is_some_and(|e| e.eq_ignore_ascii_case("btproj"))
            })
            .map(PathBuf::as_path)
    }

    /// How many files there are.
    pub fn len(&self) -> usize {
        self.files.len()
    }

    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }

    fn index(&self, limits: &Limits) -> &BTreeMap<String, Vec<usize>> {
        self.index.get_or_init(|| {
            let mut index: BTreeMap<String, Vec<usize>> = BTreeMap::new();
            for (i, path) in self.files.iter().enumerate() {
                for id in trees_of(path, limits) {
                    let at = index.entry(id).or_default();
                    if at.last() != Some(&i) {
                        at.push(i);
                    }
                }
            }
            index
        })
    }

    /// The files that define tree `id`, in the order given.
    pub fn defining(&self, id: &str, limits: &Limits) -> Vec<&Path> {
        self.index(limits)
            .get(id)
            .map(|at| at.iter().map(|&i| self.files[i].as_path()).collect())
            .unwrap_or_default()
    }

    /// Every tree ID defined by the files, sorted.
    pub fn tree_ids(&self, limits: &Limits) -> Vec<&str> {
        self.index(limits).keys().map(String::as_str).collect()
    }
}

/// Of `files`, those whose folder shares the most leading components with
/// `dir` (canonical paths compared).
fn nearest(dir: &Path, files: Vec<PathBuf>) -> Vec<PathBuf> {
    if files.len() < 2 {
        return files;
    }
    let dir = crate::source::canonical(if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    });
    let shared = |f: &PathBuf| {
        let parent = crate::source::canonical(f.parent().unwrap_or(Path::new(".")));
        dir.components()
            .zip(parent.components())
            .take_while(|(a, b)| a == b)
            .count()
    };
    let best = files.iter().map(shared).max().unwrap_or(0);
    files.into_iter().filter(|f| shared(f) == best).collect()
}

/// Trees a program may create from a file that holds several and names
/// none (`main_tree_to_execute`): those no other tree of the file uses as a
/// `<SubTree>` (all of them if each is used), sorted, at most `max`; `None`
/// when the file names its main tree, holds one tree, or does not parse.
/// BehaviorTree.CPP's `createTreeFromFile` refuses such a file, but a
/// program that registers it creates its trees by ID (`createTree("...")`,
/// BehaviorTree.CPP's own examples): `lint` checks each.
pub fn root_trees(file: &Arc<SourceFile>, limits: &Limits, max: usize) -> Option<Vec<String>> {
    let (doc, _) = xml::parse_lenient(file, limits.max_nodes, limits.max_nodes).ok()?;
    let root = &doc.elems[doc.root];
    if root.name != "root" || root.attr("main_tree_to_execute").is_some() {
        return None;
    }
    let trees: std::collections::BTreeSet<&str> = root
        .children
        .iter()
        .map(|&k| &doc.elems[k])
        .filter(|el| el.name == "BehaviorTree")
        .map(|el| el.attr("ID").unwrap_or("MainTree"))
        .collect();
    if trees.len() < 2 {
        return None;
    }
    let used: std::collections::HashSet<&str> = doc
        .elems
        .iter()
        .filter(|el| el.name == "SubTree" || el.name == "SubTreePlus")
        .filter_map(|el| el.attr("ID"))
        .collect();
    let roots: Vec<String> = trees
        .iter()
        .filter(|t| !used.contains(*t))
        .map(|t| t.to_string())
        .collect();
    let mut roots = if roots.is_empty() {
        trees.iter().map(|t| t.to_string()).collect()
    } else {
        roots
    };
    roots.truncate(max);
    Some(roots)
}

/// The `<BehaviorTree ID>`s directly under the `<root>` of `path` (none
/// when it cannot be read or is not a BehaviorTree.CPP document).
fn trees_of(path: &Path, limits: &Limits) -> Vec<String> {
    let shown = path.display().to_string();
    let Ok(file) = source::read(path, &shown, limits, false) else {
        return Vec::new();
    };
    let Ok((doc, _)) = xml::parse_lenient(&file, limits.max_nodes, limits.max_nodes) else {
        return Vec::new();
    };
    let root = &doc.elems[doc.root];
    if root.name != "root" {
        return Vec::new();
    }
    root.children
        .iter()
        .map(|&k| &doc.elems[k])
        .filter(|el| el.name == "BehaviorTree")
        .map(|el| el.attr("ID").unwrap_or("MainTree").to_string())
        .collect()
}

impl super::loader::Loader<'_> {
    /// Reads the companions that define the SubTree IDs no file read so far
    /// defines, with their includes, until none is missing or no companion
    /// defines what is: each document is scanned once, each file read once.
    /// A tree the files read first define is theirs (a companion's tree of
    /// the same ID is ignored). Among several companions that define an ID,
    /// the nearest to the file that uses it is read (the deepest folder
    /// shared with it: a package's own objectives before another's, as a
    /// program registers its own folder); when several are nearest alike,
    /// the ID is left undefined and its use says which files define it.
    pub(super) fn companion_trees(&mut self) {
        let Some(comp) = self.limits.companions.clone() else {
            return;
        };
        let mut scanned = 0;
        while scanned < self.docs.len() {
            let end = self.docs.len();
            // Each missing ID, with the first document that uses it.
            let mut missing: BTreeMap<String, usize> = BTreeMap::new();
            for (d, doc) in self.docs[scanned..end].iter().enumerate() {
                for el in &doc.elems {
                    if (el.name == "SubTree" || el.name == "SubTreePlus")
                        && let Some(id) = el.attr("ID")
                        && !self.trees.contains_key(id)
                    {
                        missing.entry(id.to_string()).or_insert(scanned + d);
                    }
                }
            }
            scanned = end;
            for (id, user) in missing {
                if self.trees.contains_key(&id) || self.ambiguous.contains_key(&id) {
                    continue;
                }
                let files: Vec<PathBuf> = comp
                    .defining(&id, self.limits)
                    .into_iter()
                    .filter(|p| !self.seen.contains(&crate::source::canonical(p)))
                    .map(Path::to_path_buf)
                    .collect();
                let files = nearest(&self.dirs[user], files);
                match files.as_slice() {
                    [] => {}
                    [one] => self.read_companion(one),
                    many => {
                        let shown = many
                            .iter()
                            .map(|p| xml::shown(&p.display().to_string()).into_owned())
                            .collect();
                        self.ambiguous.insert(id, shown);
                    }
                }
            }
        }
    }

    /// Reads one companion file and its includes, and collects their
    /// definitions.
    fn read_companion(&mut self, path: &Path) {
        let Some(doc) = self.read_named(path) else {
            return;
        };
        let first = self.docs.len();
        self.first_companion = self.first_companion.min(first);
        self.docs.push(doc);
        self.dirs
            .push(path.parent().unwrap_or(Path::new("")).to_path_buf());
        self.includes(first, crate::source::canonical(path));
        for d in first..self.docs.len() {
            self.definitions(d);
        }
    }
}
