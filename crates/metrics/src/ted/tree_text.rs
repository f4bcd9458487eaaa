//! Trees in bracket notation, `{a{b}{c{d}}}`: a node is `{`, its label (any
//! characters but braces and backslash), its children, `}` — the input
//! format of the `apted` and `zss` tools' benchmarks (Pawlik & Augsten's
//! APTED distribution reads it). Used by the hidden `btfsm ted-pairs`
//! command that the differential test and the benchmark drive; parsed with
//! an explicit stack, bounded by a node count.

use super::LabelledTree;
use std::collections::BTreeMap;

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BracketError {
    #[error("column {col}: expected `{{` to open a node")]
    ExpectedOpen { col: usize },
    #[error(
        "column {col}: `{found}` is not allowed in a label (labels exclude braces and backslash)"
    )]
    BadChar { col: usize, found: char },
    #[error("column {col}: the tree is not closed (expected `}}`)")]
    Unclosed { col: usize },
    #[error("column {col}: text after the tree's closing `}}`")]
    Trailing { col: usize },
    #[error("more than {max} nodes")]
    TooLarge { max: usize },
}

/// Parses one tree; labels are interned in `ids` (shared between trees).
pub fn parse(
    text: &str,
    ids: &mut BTreeMap<String, u32>,
    max_nodes: usize,
) -> Result<LabelledTree, BracketError> {
    let mut children: Vec<Vec<usize>> = Vec::new();
    let mut labels: Vec<u32> = Vec::new();
    let mut stack: Vec<usize> = Vec::new();
    let cs: Vec<char> = text.chars().collect();
    let mut root_done = false;
    let mut k = 0;
    while k < cs.len() {
        let (c, col) = (cs[k], k + 1);
        k += 1;
        if root_done {
            if c.is_whitespace() {
                continue;
            }
            return Err(BracketError::Trailing { col });
        }
        match c {
            '{' => {
                if children.len() >= max_nodes {
                    return Err(BracketError::TooLarge { max: max_nodes });
                }
                let mut label = String::new();
                while k < cs.len() && cs[k] != '{' && cs[k] != '}' {
                    if cs[k] == '\\' {
                        return Err(BracketError::BadChar {
                            col: k + 1,
                            found: cs[k],
                        });
                    }
                    label.push(cs[k]);
                    k += 1;
                }
                let node = children.len();
                children.push(Vec::new());
                let next = ids.len() as u32;
                labels.push(*ids.entry(label).or_insert(next));
                if let Some(&p) = stack.last() {
                    children[p].push(node);
                }
                stack.push(node);
            }
            '}' if !stack.is_empty() => {
                stack.pop();
                if stack.is_empty() {
                    root_done = true;
                }
            }
            _ if c.is_whitespace() && children.is_empty() => {}
            _ => return Err(BracketError::ExpectedOpen { col }),
        }
    }
    if !root_done {
        return Err(BracketError::Unclosed { col: cs.len() + 1 });
    }
    Ok(LabelledTree {
        children,
        labels,
        root: 0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_nested_nodes_in_order() {
        let mut ids = BTreeMap::new();
        let t = parse("{a{b}{c{b}}}", &mut ids, 10).unwrap();
        assert_eq!(t.children, vec![vec![1, 2], vec![], vec![3], vec![]]);
        assert_eq!(t.labels, vec![0, 1, 2, 1]);
    }

    #[test]
    fn bad_input_is_an_error_with_its_column() {
        let mut ids = BTreeMap::new();
        assert_eq!(
            parse("{a}{b}", &mut ids, 10),
            Err(BracketError::Trailing { col: 4 })
        );
        assert_eq!(
            parse("{a{b}", &mut ids, 10),
            Err(BracketError::Unclosed { col: 6 })
        );
        assert_eq!(
            parse("x", &mut ids, 10),
            Err(BracketError::ExpectedOpen { col: 1 })
        );
        assert_eq!(
            parse("{a\\}", &mut ids, 10),
            Err(BracketError::BadChar {
                col: 3,
                found: '\\'
            })
        );
        assert_eq!(
            parse("{a{b}{c}}", &mut ids, 2),
            Err(BracketError::TooLarge { max: 2 })
        );
        assert_eq!(
            parse("", &mut ids, 2),
            Err(BracketError::Unclosed { col: 1 })
        );
    }
}
