//! Fixture provenance: every third-party file the tests carry has a
//! recorded source and a licence that allows redistribution
//! (tests/fixtures/README.md, tests/fixtures/corpus/README.md).

use std::path::{Path, PathBuf};

const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures");

/// Licences that allow the files to be redistributed (with their notices).
const REDISTRIBUTABLE: [&str; 5] = [
    "Apache-2.0",
    "MIT",
    "BSD-3-Clause",
    "BSD-2-Clause",
    "W3C 3-clause BSD",
];

/// Files below `dir`, relative to tests/fixtures, sorted.
fn files_below(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).expect("fixture dir") {
            let p: PathBuf = e.expect("entry").path();
            if p.is_dir() {
                todo.push(p);
            } else {
                let rel = p.strip_prefix(FIXTURES).expect("under fixtures");
                out.push(rel.display().to_string());
            }
        }
    }
    out.sort();
    out
}

/// The cells of the markdown table rows of a file (header and separator
/// rows left out).
fn rows(text: &str) -> Vec<Vec<String>> {
    text.lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("|---"))
        .map(|l| {
            l.trim_matches('|')
                .split(" | ")
                .map(|c| c.trim().to_string())
                .collect::<Vec<String>>()
        })
        .filter(|cells| cells.len() == 5 && cells[2] != "commit")
        .collect()
}

#[test]
fn every_corpus_file_has_a_provenance_row_with_a_redistributable_licence() {
    let readme = std::fs::read_to_string(format!("{FIXTURES}/corpus/README.md")).expect("README");
    let rows = rows(&readme);
    assert!(rows.len() > 50, "{} rows", rows.len());
    for row in &rows {
        let licence = &row[4];
        assert!(
            REDISTRIBUTABLE.iter().any(|l| licence.contains(l)),
            "{}: licence `{licence}` is not one that allows redistribution",
            row[0]
        );
        // Every licence text named is there.
        let named: Vec<&str> = licence
            .split('`')
            .filter(|s| s.starts_with("LICENSES/"))
            .collect();
        assert!(!named.is_empty(), "{}: no licence text named", row[0]);
        for n in named {
            assert!(
                Path::new(&format!("{FIXTURES}/corpus/{n}")).is_file(),
                "{}: {n} missing",
                row[0]
            );
        }
    }
    let mut files = Vec::new();
    for dir in ["corpus", "corpus-pending", "corpus-rejected"] {
        files.extend(files_below(&Path::new(FIXTURES).join(dir)));
    }
    assert!(files.len() > 80, "{files:?}");
    let mut missing = Vec::new();
    for f in &files {
        if f.ends_with("README.md") || f.starts_with("corpus/LICENSES/") {
            continue;
        }
        let name = f.rsplit('/').next().unwrap();
        let ext = name.rsplit('.').next().unwrap();
        let covered = rows.iter().any(|r| {
            // Its own row, or its folder's row naming it or its pattern.
            r[0] == *f
                || (r[0].ends_with('/')
                    && f.strip_prefix("corpus/")
                        .is_some_and(|rel| rel.starts_with(r[0].as_str()))
                    && (r[3].contains(name) || r[3].contains(&format!("*.{ext}"))))
        });
        if !covered {
            missing.push(f.clone());
        }
    }
    assert!(
        missing.is_empty(),
        "no provenance row in tests/fixtures/corpus/README.md for {missing:?}"
    );
}

#[test]
fn every_fixture_folder_is_in_the_provenance_table() {
    let readme = std::fs::read_to_string(format!("{FIXTURES}/README.md")).expect("README");
    let listed: Vec<String> = readme
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| folder"))
        .flat_map(|l| {
            let first = l.trim_matches('|').split(" | ").next().unwrap_or("");
            first
                .split(", ")
                .map(|s| s.trim().trim_end_matches('/').to_string())
                .collect::<Vec<_>>()
        })
        .collect();
    for e in std::fs::read_dir(FIXTURES).expect("fixtures") {
        let p = e.expect("entry").path();
        if p.is_dir() {
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            assert!(
                listed.contains(&name),
                "tests/fixtures/{name}/ has no row in tests/fixtures/README.md"
            );
        }
    }
}

/// Every file of `tests/fixtures/field/` that comes from a public project
/// has a row in `field/README.md` naming its repository, commit and a
/// licence text that exists; the folders written for btfsm are named there.
#[test]
fn every_field_file_has_a_provenance_row() {
    let readme = std::fs::read_to_string(format!("{FIXTURES}/field/README.md")).expect("README");
    let rows = rows(&readme);
    for row in &rows {
        assert!(
            REDISTRIBUTABLE.iter().any(|l| row[4].contains(l)),
            "{}: licence `{}`",
            row[0],
            row[4]
        );
        for n in row[4]
            .split('`')
            .filter(|s| s.starts_with("../corpus/LICENSES/"))
        {
            assert!(
                Path::new(&format!("{FIXTURES}/field/{n}")).is_file(),
                "{}: {n} missing",
                row[0]
            );
        }
    }
    let ours = ["field/ros-ws/", "field/groot2-project/"];
    for f in files_below(&Path::new(FIXTURES).join("field")) {
        if f.ends_with("README.md") || ours.iter().any(|o| f.starts_with(o)) {
            continue;
        }
        let rel = f.strip_prefix("field/").expect("under field/");
        assert!(
            rows.iter().any(|r| r[0] == rel),
            "no provenance row in tests/fixtures/field/README.md for {f}"
        );
    }
    for o in ours {
        assert!(
            readme.contains(&format!("`{}`", &o["field/".len()..])),
            "{o}"
        );
    }
}
