//! Findings as a JUnit XML test report, the file `colcon test`, GitLab
//! (`artifacts:reports:junit`) and Jenkins (`junit` step) read, so a ROS
//! package can run `btfsm lint` as one of its tests.
//!
//! Shape (the common subset of the Jenkins schema, `junit-10.xsd`, and of
//! the Ant task's, which allows one `failure` or `error` per testcase):
//! one `<testsuites>` holding one `<testsuite name="btfsm lint">`, one
//! `<testcase>` per file read (`classname="btfsm.lint"`, `name` and
//! `file` the path as shown). A file with error-level findings has one
//! `<failure>` whose `message` and text list each of them, one a line
//! (`file:line:col: error[code]: message (help: ...)`: colcon's
//! `test-result --verbose` prints the attribute, GitLab the text); a file
//! that does not load has one `<error>` instead (why, then its findings,
//! `load-error` among them); warnings and notes go to the testcase's
//! `<system-out>` and leave it passing. One `failure` per testcase, not
//! one per finding: GitLab reads one `failure` element's text as the
//! test's details, and the Ant schema admits only one.
//! The counts (`tests`, `failures`, `errors`, `skipped`) sit on both the
//! suite and the root, as colcon's `test-result` sums them. Every string is
//! escaped for XML (`&`, `<`, `>`, quotes; line breaks in attributes as
//! character references) after [`btfsm_core::sanitize::stream`]: no control
//! character XML 1.0 forbids is written. Checked by
//! `tests/differential/junit_check.py` (PyPI `junitparser` and
//! `colcon-test-result` read the report as their users' tools do).

use super::{Finding, Level};
use std::fmt::Write;

/// One file's testcase: its findings by level.
struct Case<'a> {
    file: &'a str,
    errors: Vec<&'a Finding>,
    others: Vec<&'a Finding>,
    /// Why it was not linted (it does not load), if it was not.
    not_linted: Option<&'a str>,
}

/// The JUnit report of `findings` over `files` (each file read, as shown;
/// a file only a finding names is added), `not_linted` the files that did
/// not load and why.
pub fn render(files: &[String], findings: &[Finding], not_linted: &[(String, String)]) -> String {
    let cases = cases(files, findings, not_linted);
    let failures = cases
        .iter()
        .filter(|c| c.not_linted.is_none() && !c.errors.is_empty())
        .count();
    let errors = cases.iter().filter(|c| c.not_linted.is_some()).count();
    let counts = format!(
        "tests=\"{}\" failures=\"{failures}\" errors=\"{errors}\" skipped=\"0\" time=\"0\"",
        cases.len()
    );
    let mut s = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(s, "<testsuites name=\"btfsm lint\" {counts}>");
    let _ = writeln!(s, "  <testsuite name=\"btfsm lint\" {counts}>");
    for c in &cases {
        case(&mut s, c);
    }
    s.push_str("  </testsuite>\n</testsuites>\n");
    s
}

/// The testcases, in the order files were read, then files only findings
/// name, in the order found.
fn cases<'a>(
    files: &'a [String],
    findings: &'a [Finding],
    not_linted: &'a [(String, String)],
) -> Vec<Case<'a>> {
    let mut order: Vec<Case<'a>> = Vec::new();
    let mut index = std::collections::HashMap::new();
    let names = files
        .iter()
        .map(String::as_str)
        .chain(findings.iter().map(|f| f.file.as_str()))
        .chain(not_linted.iter().map(|(f, _)| f.as_str()));
    for file in names {
        index.entry(file).or_insert_with(|| {
            order.push(Case {
                file,
                errors: Vec::new(),
                others: Vec::new(),
                not_linted: None,
            });
            order.len() - 1
        });
    }
    for f in findings {
        let c = &mut order[index[f.file.as_str()]];
        match f.level {
            Level::Error => c.errors.push(f),
            Level::Allow => {}
            _ => c.others.push(f),
        }
    }
    for (file, why) in not_linted {
        order[index[file.as_str()]].not_linted.get_or_insert(why);
    }
    order
}

fn case(s: &mut String, c: &Case) {
    let file = attr(c.file);
    let _ = write!(
        s,
        "    <testcase name=\"{file}\" classname=\"btfsm.lint\" file=\"{file}\" time=\"0\""
    );
    if c.errors.is_empty() && c.others.is_empty() && c.not_linted.is_none() {
        s.push_str("/>\n");
        return;
    }
    s.push_str(">\n");
    let listed = |fs: &[&Finding]| fs.iter().map(|f| line(f)).collect::<String>();
    // colcon's `test-result --verbose` prints the `message` attribute
    // only, GitLab the text only: both carry the positioned findings.
    let (element, kind, message) = match c.not_linted {
        Some(why) => (
            "error",
            c.errors.first().map_or("load-error", |f| f.code),
            format!("not linted: {why}\n{}", listed(&c.errors)),
        ),
        None if !c.errors.is_empty() => ("failure", c.errors[0].code, listed(&c.errors)),
        None => ("", "", String::new()),
    };
    if !element.is_empty() {
        let message = message.trim_end();
        let _ = writeln!(
            s,
            "      <{element} type=\"{}\" message=\"{}\">{}</{element}>",
            attr(kind),
            attr(message),
            text(message),
        );
    }
    if !c.others.is_empty() {
        let _ = writeln!(
            s,
            "      <system-out>{}</system-out>",
            text(&listed(&c.others))
        );
    }
    s.push_str("    </testcase>\n");
}

/// A finding on one line: `file:line:col: level[code]: message (help: ...)`.
fn line(f: &Finding) -> String {
    let mut s = f.file.replace('\n', " ");
    if let (Some(l), Some(c)) = (f.line, f.column) {
        let _ = write!(s, ":{l}:{c}");
    }
    let _ = write!(s, ": {}[{}]: {}", f.level.as_str(), f.code, f.message);
    if !f.help.is_empty() {
        let _ = write!(s, " (help: {})", f.help);
    }
    s.push('\n');
    s
}

/// Element text: control characters escaped as text, then `&`, `<`, `>`.
fn text(s: &str) -> String {
    escape(s, false)
}

/// An attribute value: [`text`], quotes too, and line breaks and tabs as
/// character references (a parser would otherwise read them as spaces).
fn attr(s: &str) -> String {
    escape(s, true)
}

fn escape(s: &str, attribute: bool) -> String {
    let clean = btfsm_core::sanitize::stream(s);
    let mut out = String::with_capacity(clean.len());
    for ch in clean.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' if attribute => out.push_str("&quot;"),
            '\'' if attribute => out.push_str("&apos;"),
            '\n' if attribute => out.push_str("&#10;"),
            '\t' if attribute => out.push_str("&#9;"),
            // Not characters XML 1.0 admits.
            '\u{fffe}' | '\u{ffff}' => out.push_str(if ch == '\u{fffe}' {
                "\\u{fffe}"
            } else {
                "\\u{ffff}"
            }),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn finding(file: &str, level: Level, message: &str) -> Finding {
        Finding {
            code: "unreachable-child",
            level,
            file: file.to_string(),
            line: Some(3),
            column: Some(7),
            at: String::new(),
            message: message.to_string(),
            help: "remove it".to_string(),
            source: None,
        }
    }

    #[test]
    fn each_file_is_a_testcase_failing_on_its_errors_only() {
        let files = vec!["a.xml".to_string(), "b.xml".to_string()];
        let fs = vec![
            finding("a.xml", Level::Error, "one"),
            finding("a.xml", Level::Error, "two"),
            finding("b.xml", Level::Warning, "three"),
        ];
        let x = render(&files, &fs, &[]);
        assert!(x.contains("tests=\"2\" failures=\"1\" errors=\"0\""), "{x}");
        assert_eq!(x.matches("<failure ").count(), 1, "{x}");
        assert!(
            x.contains(
                "message=\"a.xml:3:7: error[unreachable-child]: one (help: remove it)&#10;a.xml"
            ),
            "{x}"
        );
        assert!(
            x.contains("a.xml:3:7: error[unreachable-child]: one (help: remove it)\n"),
            "{x}"
        );
        assert!(
            x.contains("<system-out>b.xml:3:7: warning[unreachable-child]: three"),
            "{x}"
        );
    }

    #[test]
    fn a_file_that_does_not_load_is_an_error_and_text_is_escaped() {
        let files = vec!["x<&>\"'\u{1b}\u{ffff}.xml".to_string()];
        let mut f = finding(&files[0], Level::Error, "bad <tag> & \"q\"\n]]>");
        f.code = "load-error";
        let x = render(&files, &[f], &[(files[0].clone(), "it ends early".into())]);
        assert!(x.contains("errors=\"1\""), "{x}");
        assert!(
            x.contains("name=\"x&lt;&amp;&gt;&quot;&apos;\\u{1b}\\u{ffff}.xml\""),
            "{x}"
        );
        assert!(x.contains("bad &lt;tag&gt; &amp; \"q\"\n]]&gt;"), "{x}");
        assert!(
            !x.chars().any(|c| (c < ' ' && c != '\n') || c == '\u{ffff}'),
            "{x}"
        );
    }
}
