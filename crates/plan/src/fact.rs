//! Facts of an action domain: `Pred(a, b)` patterns over an action's or a
//! predicate's parameters and constants, and the ground facts they become
//! (STRIPS atoms, Fikes & Nilsson 1971).

use std::fmt;

/// A fact as written in a domain: a predicate applied to terms, each a
/// parameter name of the enclosing action or a constant (an object).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pattern {
    pub pred: String,
    pub args: Vec<String>,
}

/// A fact with every argument an object.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Fact {
    pub pred: String,
    pub args: Vec<String>,
}

impl fmt::Display for Fact {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.args.is_empty() {
            write!(f, "{}", self.pred)
        } else {
            write!(f, "{}({})", self.pred, self.args.join(", "))
        }
    }
}

/// Is `s` a name (predicate, parameter, object): letters, digits, `-`, `_`?
pub fn is_name(s: &str) -> bool {
    !s.is_empty()
        && s.len() <= 128
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
}

/// Parses `Pred(a, b)` or `Pred` (no arguments). The error says what is
/// wrong and what would be valid.
pub fn parse(text: &str) -> Result<Pattern, String> {
    let t = text.trim();
    let (pred, args) = match t.find('(') {
        None => (t, ""),
        Some(open) => {
            let Some(inner) = t[open + 1..].strip_suffix(')') else {
                return Err(format!(
                    "`{}`: a fact is `Predicate(arg, ...)`, closed by `)`",
                    btfsm_core::sanitize::shown(t)
                ));
            };
            (t[..open].trim(), inner)
        }
    };
    if !is_name(pred) {
        return Err(format!(
            "`{}`: a predicate name is letters, digits, `-` and `_`",
            btfsm_core::sanitize::shown(pred)
        ));
    }
    let args: Vec<String> = if args.trim().is_empty() {
        Vec::new()
    } else {
        args.split(',').map(|a| a.trim().to_string()).collect()
    };
    if let Some(bad) = args.iter().find(|a| !is_name(a)) {
        return Err(format!(
            "`{}`: argument `{}` is not a name (letters, digits, `-`, `_`)",
            btfsm_core::sanitize::shown(t),
            btfsm_core::sanitize::shown(bad)
        ));
    }
    Ok(Pattern {
        pred: pred.to_string(),
        args,
    })
}

impl Pattern {
    /// The ground fact under `bind` (parameter -> object); a term that is
    /// not a parameter is a constant.
    pub fn ground(&self, bind: &dyn Fn(&str) -> Option<String>) -> Fact {
        Fact {
            pred: self.pred.clone(),
            args: self
                .args
                .iter()
                .map(|a| bind(a).unwrap_or_else(|| a.clone()))
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn facts_parse_with_and_without_arguments() {
        let p = parse(" Object-At( object , delivery ) ").unwrap();
        assert_eq!(p.pred, "Object-At");
        assert_eq!(p.args, ["object", "delivery"]);
        assert!(parse("Found").unwrap().args.is_empty());
        assert!(parse("Robot-At(x").unwrap_err().contains("closed by `)`"));
        assert!(parse("Robot At(x)").unwrap_err().contains("predicate name"));
        assert!(parse("P(a b)").unwrap_err().contains("not a name"));
    }
}
