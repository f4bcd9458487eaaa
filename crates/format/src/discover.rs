//! Directories as input (`btfsm analyze policies/`): every file below a
//! directory that holds a policy (or, for `validate`, a scenario), in sorted
//! path order, as fd and ripgrep walk a tree: hidden entries (`.git`),
//! `target/` and `node_modules/` are skipped, symbolic links are not
//! followed, and the walk is bounded in entries and depth.
//!
//! A file below a directory is a candidate by its extension (`.toml`,
//! `.xml`, `.scxml`, Groot2's `.btproj`, `.py`, `.dot`, `.gv`) and is kept when its content
//! is a policy: a TOML file with a top-level `kind` key, an XML file with a
//! `<BehaviorTree>`, an `<scxml>` or a yasmin `<StateMachine>` document
//! element, a Python file that is a FlexBE behavior
//! ([`super::flexbe::looks_like_flexbe`]: a class deriving `Behavior` that
//! builds an `OperatableStateMachine`), a `.dot`/`.gv` file that is a
//! py_trees render (`digraph pastafarianism`). Other files (a `Cargo.toml`, a ROS `package.xml`, a Nav2 nodes
//! model) are counted as skipped, not reported as errors; a Groot2 project
//! file found so is no policy either, but it is among the BehaviorTree.CPP
//! files given together (`btcpp_xml::Companions`), whose node models the
//! trees of the walk read. Files named on the command line are always
//! read, whatever they hold.

use super::source;
use super::{FileFormat, Limits};
use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Directory entries a walk visits at most, over all directories given.
pub const MAX_WALK_ENTRIES: usize = 100_000;
/// Directory levels a walk descends at most.
pub const MAX_WALK_DEPTH: usize = 64;

/// One input: a file named on the command line, or found below a directory.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Input {
    pub path: PathBuf,
    /// Found by walking a directory (kept only if it holds a policy).
    pub found: bool,
}

/// The inputs of a command: files as given, directories replaced by the
/// candidate files below them (sorted). An unreadable directory, a walk past
/// its bounds: an error naming the directory.
pub fn expand(paths: &[PathBuf]) -> Result<Vec<Input>, Diagnostic> {
    let mut out = Vec::new();
    let mut visited = 0usize;
    for p in paths {
        if p.as_os_str() != "-" && p.is_dir() {
            walk(p, &mut visited, &mut out)?;
        } else {
            out.push(Input {
                path: p.clone(),
                found: false,
            });
        }
    }
    Ok(out)
}

fn walk(dir: &Path, visited: &mut usize, out: &mut Vec<Input>) -> Result<(), Diagnostic> {
    let shown = |p: &Path| btfsm_core::sanitize::shown(&p.display().to_string()).into_owned();
    let mut found = Vec::new();
    let mut stack = vec![(dir.to_path_buf(), 0usize)];
    while let Some((d, depth)) = stack.pop() {
        let entries = std::fs::read_dir(&d).map_err(|e| {
            Diagnostic::error(format!("{}: cannot read this directory: {e}", shown(&d)))
        })?;
        for e in entries {
            let e = e.map_err(|e| {
                Diagnostic::error(format!("{}: cannot read this directory: {e}", shown(&d)))
            })?;
            *visited += 1;
            if *visited > MAX_WALK_ENTRIES {
                return Err(Diagnostic::error(format!(
                    "{}: more than {MAX_WALK_ENTRIES} entries below the directories given",
                    shown(dir)
                ))
                .hint("name a smaller directory, or the files themselves"));
            }
            let name = e.file_name();
            let name = name.to_string_lossy();
            if name.starts_with('.') || name == "target" || name == "node_modules" {
                continue;
            }
            // Never follows a symbolic link (no loops, nothing outside).
            let Ok(ft) = e.file_type() else { continue };
            let path = e.path();
            if ft.is_dir() {
                if depth + 1 > MAX_WALK_DEPTH {
                    return Err(Diagnostic::error(format!(
                        "{}: directories nested deeper than {MAX_WALK_DEPTH} levels",
                        shown(dir)
                    )));
                }
                stack.push((path, depth + 1));
            } else if ft.is_file()
                && path.extension().and_then(|x| x.to_str()).is_some_and(|x| {
                    ["toml", "xml", "scxml", "btproj", "py", "dot", "gv"]
                        .contains(&x.to_ascii_lowercase().as_str())
                })
            {
                found.push(path);
            }
        }
    }
    found.sort();
    out.extend(found.into_iter().map(|path| Input { path, found: true }));
    Ok(())
}

/// Reads an input once and says what it holds: a file named on the command
/// line is whatever [`super::read_input`] makes of it; a file found below a
/// directory is a policy or a scenario by the marks above, else `None`
/// (skipped).
pub fn read(
    input: &Input,
    limits: &Limits,
) -> Result<(Arc<SourceFile>, Option<super::Input>), Vec<Diagnostic>> {
    if !input.found {
        return super::read_input(&input.path, limits).map(|(f, i)| (f, Some(i)));
    }
    let path = &input.path;
    let file = source::read(path, &path.display().to_string(), limits, true)?;
    let text = &file.text;
    let holds = match super::detect(path, text) {
        FileFormat::Toml if crate::discover::looks_like_scenario(super::head(text)) => {
            Some(super::Input::Scenario)
        }
        FileFormat::Toml if crate::discover::looks_like_domain(text) => Some(super::Input::Domain),
        FileFormat::Toml if !has_top_level_kind(text) => None,
        FileFormat::BtcppXml if !text.contains("<BehaviorTree") => None,
        FileFormat::Flexbe if !super::flexbe::looks_like_flexbe(path, text) => None,
        FileFormat::PyTreesDot if !super::py_trees_dot::looks_like_py_trees_dot(text) => None,
        f => Some(super::Input::Policy(f)),
    };
    Ok((file, holds))
}

/// Does a TOML text set `kind` before its first table header?
pub(crate) fn has_top_level_kind(text: &str) -> bool {
    for line in text.lines() {
        let l = line.trim();
        if l.starts_with('[') {
            return false;
        }
        let key = l.split('=').next().unwrap_or("").trim().trim_matches('"');
        if key == "kind" && l.contains('=') {
            return true;
        }
    }
    false
}

/// Does a TOML text look like an action domain: no top-level `kind`, and
/// a `[actions...]` or `[predicates...]` table?
pub fn looks_like_domain(text: &str) -> bool {
    let mut tables = false;
    for line in text.lines() {
        let l = line.trim();
        if let Some(h) = l.strip_prefix('[') {
            let h = h.trim_start();
            if h.starts_with("actions") || h.starts_with("predicates") {
                tables = true;
            }
            continue;
        }
        let key = l.split('=').next().unwrap_or("").trim().trim_matches('"');
        if key == "kind" && l.contains('=') && !tables {
            return false;
        }
    }
    tables
}

/// Whether a TOML text is a scenario rather than a policy, from its head:
/// TOML puts top-level keys before the first table, so a policy says `kind`
/// before any header, and a scenario has `[world]` or `[[policies]]`.
pub fn looks_like_scenario(head: &str) -> bool {
    for line in head.lines() {
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        if let Some(h) = l.strip_prefix('[') {
            let h = h.trim_start_matches('[').trim_start();
            return ["world", "policies", "disturbances"]
                .iter()
                .any(|k| h.starts_with(k));
        }
        let key = l.split('=').next().unwrap_or("").trim().trim_matches('"');
        match key {
            "kind" => return false,
            "world" | "policies" => return true,
            _ => {}
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_walk_is_sorted_skips_hidden_and_build_folders_and_follows_no_link() {
        let d = std::env::temp_dir().join(format!("btfsm-discover-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        for sub in ["b", "a/deep", ".git", "target", "node_modules"] {
            std::fs::create_dir_all(d.join(sub)).unwrap();
        }
        for f in [
            "b/z.toml",
            "a/deep/y.scxml",
            "a/x.XML",
            "a/notes.md",
            ".git/config.toml",
            "target/t.toml",
            "node_modules/n.xml",
        ] {
            std::fs::write(d.join(f), "").unwrap();
        }
        #[cfg(unix)]
        std::os::unix::fs::symlink(d.join("b"), d.join("a/link")).unwrap();
        let got: Vec<String> = expand(std::slice::from_ref(&d))
            .unwrap()
            .iter()
            .map(|i| {
                assert!(i.found);
                i.path.strip_prefix(&d).unwrap().display().to_string()
            })
            .collect();
        assert_eq!(got, ["a/deep/y.scxml", "a/x.XML", "b/z.toml"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn only_policies_and_scenarios_are_kept() {
        assert!(has_top_level_kind(
            "# c\nname = \"x\"\nkind = \"bt\"\n[nodes]\n"
        ));
        assert!(!has_top_level_kind(
            "[package]\nname = \"x\"\nkind = \"lib\"\n"
        ));
        assert!(!has_top_level_kind("[nodes]\nkind = \"bt\"\n"));
    }
}
