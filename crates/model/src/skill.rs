//! The shared skill library (SPEC §6, the paper's fairness rule: one set of skills
//! for every representation) and the bindings that policies make to it.

use std::collections::BTreeMap;

/// Whether a skill acts on the world over many steps or only checks it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SkillKind {
    Action,
    Condition,
}

/// An argument a skill takes: `(name, required)`.
pub type Param = (&'static str, bool);

/// A skill of the library: name, kind and the arguments it takes.
pub type SkillSpec = (&'static str, SkillKind, &'static [Param]);

/// Every skill of the shared library.
pub const SKILLS: &[SkillSpec] = &[
    ("Move-To", SkillKind::Action, &[("target", true)]),
    ("Safe-Move-To", SkillKind::Action, &[("target", true)]),
    ("Pick", SkillKind::Action, &[("object", true)]),
    (
        "Place",
        SkillKind::Action,
        &[("object", true), ("at", true)],
    ),
    ("Recharge", SkillKind::Action, &[]),
    ("Dock", SkillKind::Action, &[]),
    ("Tuck-Arm", SkillKind::Action, &[]),
    ("Search", SkillKind::Action, &[]),
    ("Shut-Down", SkillKind::Action, &[]),
    ("Robot-At", SkillKind::Condition, &[("target", true)]),
    ("In-Hand", SkillKind::Condition, &[("object", true)]),
    (
        "Object-At",
        SkillKind::Condition,
        &[("object", true), ("at", true)],
    ),
    ("Battery-Level", SkillKind::Condition, &[("min", true)]),
    ("Arm-Tucked", SkillKind::Condition, &[]),
    ("Found", SkillKind::Condition, &[]),
    ("No-Emergency", SkillKind::Condition, &[]),
];

/// Looks a skill up by name.
pub fn skill_kind(name: &str) -> Option<SkillKind> {
    SKILLS
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, k, _)| *k)
}

/// The argument schema of a skill, `None` when the skill is unknown.
pub fn skill_params(name: &str) -> Option<&'static [(&'static str, bool)]> {
    SKILLS
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, _, p)| *p)
}

/// Names of all skills of one kind, for "expected one of" hints.
pub fn skill_names(kind: SkillKind) -> Vec<&'static str> {
    SKILLS
        .iter()
        .filter(|(_, k, _)| *k == kind)
        .map(|(n, _, _)| *n)
        .collect()
}

/// An argument value of a skill binding.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(untagged)]
pub enum ArgValue {
    Str(String),
    Int(i64),
    Float(f64),
    Bool(bool),
}

impl std::fmt::Display for ArgValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ArgValue::Str(s) => write!(f, "{s}"),
            ArgValue::Int(i) => write!(f, "{i}"),
            ArgValue::Float(x) => write!(f, "{x}"),
            ArgValue::Bool(b) => write!(f, "{b}"),
        }
    }
}

/// A leaf's or a state's binding to a skill: the skill's name and its arguments.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SkillCall {
    pub skill: String,
    pub args: BTreeMap<String, ArgValue>,
}

impl std::fmt::Display for SkillCall {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}(", self.skill)?;
        for (i, (k, v)) in self.args.iter().enumerate() {
            if i > 0 {
                write!(f, ", ")?;
            }
            write!(f, "{k}={v}")?;
        }
        write!(f, ")")
    }
}

/// A guard on an FSM transition (the paper's Algorithm 3: checked before the
/// state's skill runs). It holds when every term holds.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Guard {
    pub all: Vec<GuardTerm>,
    /// Human text, e.g. "battery below 20%"; defaults to the terms.
    pub label: String,
}

/// One condition of a guard, possibly negated (`unless`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct GuardTerm {
    pub condition: SkillCall,
    /// `true` for `unless`: the term holds when the condition is false.
    pub negate: bool,
}

impl std::fmt::Display for GuardTerm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.negate {
            write!(f, "not ")?;
        }
        write!(f, "{}", self.condition)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn library_lookups() {
        assert_eq!(skill_kind("Move-To"), Some(SkillKind::Action));
        assert_eq!(skill_kind("Robot-At"), Some(SkillKind::Condition));
        assert_eq!(skill_kind("Fly"), None);
        assert!(skill_names(SkillKind::Condition).contains(&"Battery-Level"));
        assert_eq!(skill_params("Place").unwrap().len(), 2);
    }
}
