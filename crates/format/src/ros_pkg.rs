//! Where a ROS package is, for the files that name one:
//! BehaviorTree.CPP's `<include ros_pkg="PKG" path="P"/>` (`P` relative to
//! the package's share directory, as BehaviorTree.CPP's `xml_parsing.cpp`
//! resolves it through `ament_index_cpp::get_package_share_directory`;
//! Nav2 writes it, navigation2 #5811) and yasmin's
//! `<StateMachine package="PKG" file_name="F"/>` (the first file named `F`
//! below the share directory, as yasmin_factory's `create_sm` walks it).
//!
//! A package is looked for, in this order:
//!
//! 1. `--ros-pkg NAME=DIR` on the command line;
//! 2. `share/NAME/` under each prefix of `AMENT_PREFIX_PATH` (as ament's
//!    index finds an installed package), first prefix first;
//! 3. the repository: the directory holding a `package.xml` whose `<name>`
//!    is NAME, searched below the root (the git work tree of the file given,
//!    `--root`; `format::source`), without following symbolic links, past
//!    hidden directories, colcon's `build/`, `install/` and `log/` and any
//!    directory with a `COLCON_IGNORE` or `AMENT_IGNORE`, visiting at most
//!    [`MAX_WALK`] entries and reading each `package.xml` (at most 64 KiB)
//!    against the command's `--max-total-bytes`. A source package's files sit where its install
//!    rule copies them into the share directory (Nav2's `behavior_trees/`).
//!
//! Every file found so is then read under the root rules of every named
//! file (`format::source::resolve`): a package outside the root (an
//! installed `/opt/ros` one) is refused unless `--root` holds it or
//! `--allow-outside-root` is given. The repository search is done once per
//! root and command.

use super::source::{Budget, Refusal, resolve};
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Package name -> the directories of the `package.xml`s naming it.
type PackageIndex = BTreeMap<String, Vec<PathBuf>>;

/// Most directory entries one repository search (or one search for a
/// yasmin `file_name` in a package) visits.
pub const MAX_WALK: usize = 200_000;

/// Largest `package.xml` read, in bytes (a real one is a few kB).
const MAX_PACKAGE_XML: u64 = 64 << 10;

/// What the command knows of where ROS packages are.
#[derive(Debug, Default)]
pub struct RosPackages {
    /// `--ros-pkg NAME=DIR`, in the order given.
    pub given: Vec<(String, PathBuf)>,
    /// The prefixes of `AMENT_PREFIX_PATH`, in order.
    pub ament_prefixes: Vec<PathBuf>,
    /// What the `package.xml`s read may cost: the command's byte budget
    /// (`--max-total-bytes`), charged per file read; none: only
    /// 64 KiB per file and [`MAX_WALK`] entries bound it.
    pub budget: Option<Arc<Budget>>,
    /// Per root searched: package name -> directories of its `package.xml`.
    found: Mutex<HashMap<PathBuf, Arc<PackageIndex>>>,
}

impl RosPackages {
    pub fn new(
        given: Vec<(String, PathBuf)>,
        ament_prefixes: Vec<PathBuf>,
        budget: Option<Arc<Budget>>,
    ) -> Arc<Self> {
        Arc::new(RosPackages {
            given,
            ament_prefixes,
            budget,
            found: Mutex::default(),
        })
    }

    /// The directory of package `name`: given, installed or in the
    /// repository below `root` (`search` when confinement is off: where the
    /// including file is). The refusal says what was tried.
    pub fn package_dir(
        &self,
        name: &str,
        root: Option<&Path>,
        search: &Path,
    ) -> Result<PathBuf, Refusal> {
        if let Some((_, d)) = self.given.iter().find(|(n, _)| n == name) {
            return Ok(d.clone());
        }
        for p in &self.ament_prefixes {
            let d = p.join("share").join(name);
            if d.is_dir() {
                return Ok(d);
            }
        }
        let top = root.map_or_else(|| repository_of(search), Path::to_path_buf);
        let index = self.index(&top);
        match index.get(name).map(Vec::as_slice) {
            Some([one]) => Ok(one.clone()),
            Some(many) => Err(Refusal {
                message: format!(
                    "{} packages in the repository are named `{name}`",
                    many.len()
                ),
                hint: format!("say which with --ros-pkg {name}=DIR"),
            }),
            None => Err(Refusal {
                message: format!("no ROS package `{name}` found"),
                hint: format!(
                    "looked in --ros-pkg, AMENT_PREFIX_PATH's share/{name}/ and the package.xml files of the repository; give it with --ros-pkg {name}=DIR"
                ),
            }),
        }
    }

    /// The packages below `top`, searched once.
    fn index(&self, top: &Path) -> Arc<PackageIndex> {
        let key = super::source::canonical(top);
        let mut found = self.found.lock().unwrap_or_else(|e| e.into_inner());
        found
            .entry(key.clone())
            .or_insert_with(|| Arc::new(packages_below(&key, self.budget.as_deref())))
            .clone()
    }
}

/// The git work tree holding `dir`, else `dir`.
fn repository_of(dir: &Path) -> PathBuf {
    let dir = super::source::canonical(if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    });
    dir.ancestors()
        .find(|a| a.join(".git").symlink_metadata().is_ok())
        .map_or(dir.clone(), Path::to_path_buf)
}

/// Directories a search does not enter: hidden ones, colcon's outputs and
/// those a ROS tool is told to ignore.
fn skipped(dir: &Path, name: &str) -> bool {
    name.starts_with('.')
        || matches!(
            name,
            "build" | "install" | "log" | "node_modules" | "target"
        )
        || dir.join("COLCON_IGNORE").exists()
        || dir.join("AMENT_IGNORE").exists()
}

/// Every regular file below `top` (not following links, directories in
/// name order, at most [`MAX_WALK`] entries), passed to `visit` until it
/// returns `true`.
fn walk(top: &Path, mut visit: impl FnMut(&Path) -> bool) {
    let mut stack = vec![top.to_path_buf()];
    let mut budget = MAX_WALK;
    while let Some(dir) = stack.pop() {
        let Ok(rd) = std::fs::read_dir(&dir) else {
            continue;
        };
        let mut entries: Vec<(String, PathBuf, std::fs::FileType)> = Vec::new();
        for e in rd.flatten() {
            if budget == 0 {
                return;
            }
            budget -= 1;
            if let Ok(t) = e.file_type() {
                entries.push((e.file_name().to_string_lossy().into_owned(), e.path(), t));
            }
        }
        entries.sort_by(|a, b| a.0.cmp(&b.0));
        let mut dirs = Vec::new();
        for (name, path, t) in entries {
            if t.is_file() {
                if visit(&path) {
                    return;
                }
            } else if t.is_dir() && !skipped(&path, &name) {
                dirs.push(path);
            }
        }
        // Depth first, in name order.
        stack.extend(dirs.into_iter().rev());
    }
}

/// The packages below `top`, each `package.xml` read charged to `budget`
/// (the search stops when it is spent).
fn packages_below(top: &Path, budget: Option<&Budget>) -> PackageIndex {
    let mut out = PackageIndex::new();
    walk(top, |p| {
        if p.file_name().is_none_or(|n| n != "package.xml") {
            return false;
        }
        let Ok(m) = std::fs::metadata(p) else {
            return false;
        };
        if !m.is_file() || m.len() > MAX_PACKAGE_XML {
            return false;
        }
        if budget.is_some_and(|b| !b.charge(m.len())) {
            return true;
        }
        if let Some(name) = package_name(p)
            && let Some(dir) = p.parent()
        {
            out.entry(name).or_default().push(dir.to_path_buf());
        }
        false
    });
    out
}

/// The `<name>` of a `package.xml` (REP 149), if it reads as one.
fn package_name(p: &Path) -> Option<String> {
    let mut text = String::new();
    std::io::Read::read_to_string(
        &mut std::io::Read::take(std::fs::File::open(p).ok()?, MAX_PACKAGE_XML),
        &mut text,
    )
    .ok()?;
    let opts = roxmltree::ParsingOptions {
        allow_dtd: false,
        nodes_limit: 100_000,
        ..Default::default()
    };
    let doc = roxmltree::Document::parse_with_options(&text, opts).ok()?;
    let root = doc.root_element();
    if root.tag_name().name() != "package" {
        return None;
    }
    let name = root
        .children()
        .find(|c| c.is_element() && c.tag_name().name() == "name")?
        .text()?
        .trim();
    (!name.is_empty()).then(|| name.to_string())
}

/// BehaviorTree.CPP's `<include ros_pkg="pkg" path="rel"/>`: `rel` in the
/// package's directory, under the root rules.
pub fn resolve_in_package(
    ros: &RosPackages,
    root: Option<&Path>,
    including_dir: &Path,
    pkg: &str,
    rel: &str,
) -> Result<PathBuf, Refusal> {
    let dir = ros.package_dir(pkg, root, including_dir)?;
    resolve(root, &dir, rel).map_err(|r| Refusal {
        message: format!("in package `{pkg}`: {}", r.message),
        hint: r.hint,
    })
}

/// yasmin's `<StateMachine package="pkg" file_name="f"/>`: the first file
/// named `f` below the package's directory (directories in name order),
/// under the root rules.
pub fn find_in_package(
    ros: &RosPackages,
    root: Option<&Path>,
    including_dir: &Path,
    pkg: &str,
    file_name: &str,
) -> Result<PathBuf, Refusal> {
    if file_name.contains(['/', '\\']) || file_name == ".." || file_name == "." {
        return Err(Refusal {
            message: "`file_name` is a file name, not a path".into(),
            hint: "name the file only; yasmin looks for it anywhere in the package".into(),
        });
    }
    let dir = ros.package_dir(pkg, root, including_dir)?;
    let mut hit: Option<PathBuf> = None;
    walk(&dir, |p| {
        if p.file_name().is_some_and(|n| n == file_name) {
            hit = Some(p.to_path_buf());
            return true;
        }
        false
    });
    let Some(found) = hit else {
        return Err(Refusal {
            message: format!("no file `{file_name}` in package `{pkg}`"),
            hint: "yasmin looks for `file_name` anywhere below the package's directory".into(),
        });
    };
    let (base, name) = (
        found.parent().map(Path::to_path_buf).unwrap_or_default(),
        found
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
    );
    resolve(root, &base, &name).map_err(|r| Refusal {
        message: format!("in package `{pkg}`: {}", r.message),
        hint: r.hint,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("btfsm-rospkg-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn package(dir: &Path, name: &str) {
        std::fs::create_dir_all(dir).unwrap();
        std::fs::write(
            dir.join("package.xml"),
            format!(
                "<?xml version=\"1.0\"?>\n<package format=\"3\"><name> {name} </name></package>"
            ),
        )
        .unwrap();
    }

    #[test]
    fn a_package_is_found_given_installed_or_in_the_repository() {
        let top = scratch("find");
        std::fs::create_dir_all(top.join(".git")).unwrap();
        package(&top.join("src/nav/nav2_bt_navigator"), "nav2_bt_navigator");
        // colcon's install copy and ignored folders are not searched.
        package(
            &top.join("install/nav2_bt_navigator/share/nav2_bt_navigator"),
            "nav2_bt_navigator",
        );
        package(&top.join("src/old"), "old_pkg");
        std::fs::write(top.join("src/old/COLCON_IGNORE"), "").unwrap();
        let ros = RosPackages::new(vec![], vec![], None);
        let root = Some(top.as_path());
        assert_eq!(
            ros.package_dir("nav2_bt_navigator", root, &top).unwrap(),
            top.join("src/nav/nav2_bt_navigator")
        );
        assert!(ros.package_dir("old_pkg", root, &top).is_err());
        let miss = ros.package_dir("nope", root, &top).unwrap_err();
        assert!(miss.hint.contains("--ros-pkg nope=DIR"), "{miss:?}");
        // Given and installed come first.
        let prefix = top.join("opt");
        std::fs::create_dir_all(prefix.join("share/nav2_bt_navigator")).unwrap();
        let ros = RosPackages::new(vec![], vec![prefix.clone()], None);
        assert_eq!(
            ros.package_dir("nav2_bt_navigator", root, &top).unwrap(),
            prefix.join("share/nav2_bt_navigator")
        );
        let ros = RosPackages::new(
            vec![("nav2_bt_navigator".into(), top.join("x"))],
            vec![prefix],
            None,
        );
        assert_eq!(
            ros.package_dir("nav2_bt_navigator", root, &top).unwrap(),
            top.join("x")
        );
        // Two source packages of one name: say which.
        package(&top.join("src/copy"), "nav2_bt_navigator");
        let ros = RosPackages::new(vec![], vec![], None);
        let two = ros
            .package_dir("nav2_bt_navigator", root, &top)
            .unwrap_err();
        assert!(two.message.contains("2 packages"), "{two:?}");
        std::fs::remove_dir_all(&top).unwrap();
    }

    #[test]
    fn files_in_packages_stay_inside_the_root() {
        let top = scratch("root");
        let outside = scratch("outside");
        package(&outside.join("share/ext"), "ext");
        std::fs::write(outside.join("share/ext/t.xml"), "<root/>").unwrap();
        let ros = RosPackages::new(vec![], vec![outside.clone()], None);
        let root = super::super::source::canonical(&top);
        let r = resolve_in_package(&ros, Some(&root), &top, "ext", "t.xml").unwrap_err();
        assert!(r.message.contains("outside the root"), "{r:?}");
        // Confinement off: read.
        assert!(resolve_in_package(&ros, None, &top, "ext", "t.xml").is_ok());
        let bad = find_in_package(&ros, None, &top, "ext", "../t.xml").unwrap_err();
        assert!(bad.message.contains("not a path"), "{bad:?}");
        assert!(find_in_package(&ros, None, &top, "ext", "t.xml").is_ok());
        std::fs::remove_dir_all(&top).unwrap();
        std::fs::remove_dir_all(&outside).unwrap();
    }

    /// The `package.xml`s read are charged to the command's byte budget:
    /// spent, the search stops.
    #[test]
    fn the_search_reads_within_the_byte_budget() {
        let top = scratch("budget");
        package(&top.join("a"), "pkg_a");
        package(&top.join("b"), "pkg_b");
        let one = std::fs::metadata(top.join("a/package.xml")).unwrap().len();
        let ros = RosPackages::new(vec![], vec![], Some(Budget::new(one)));
        let root = Some(top.as_path());
        assert!(ros.package_dir("pkg_a", root, &top).is_ok());
        // pkg_b's package.xml did not fit in what was left.
        assert!(ros.package_dir("pkg_b", root, &top).is_err());
        std::fs::remove_dir_all(&top).unwrap();
    }
}
