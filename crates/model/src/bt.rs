//! Behavior Trees (SPEC §1; the paper's sec. II-A). Nodes live in an arena so that
//! trees of any depth are walked without recursion.

use super::{SkillCall, Span};
use std::collections::BTreeMap;

/// Index of a node in [`Bt::nodes`].
pub type NodeIdx = usize;

#[derive(Debug, Clone, PartialEq)]
pub struct Bt {
    pub nodes: Vec<BtNode>,
    pub root: NodeIdx,
}

#[derive(Debug, Clone, PartialEq)]
pub struct BtNode {
    /// Unique identity of the node in the tree (the TOML key; nodes of included
    /// subtrees are prefixed with the including node's id and `/`).
    pub id: String,
    /// Display name ("Move-To cube2!", "Fallback").
    pub label: String,
    pub kind: BtNodeKind,
    pub children: Vec<NodeIdx>,
    /// Skill binding of a leaf.
    pub skill: Option<SkillCall>,
    /// The node type name in the file it was read from when it says more than
    /// `kind` (a BehaviorTree.CPP type such as `IfThenElse`, `RecoveryNode`,
    /// `PipelineSequence`); kept for DOT, JSON and export.
    pub type_name: Option<String>,
    /// Ports and attributes of the node as written (BehaviorTree.CPP ports such
    /// as `num_cycles="3"`), in name order; empty for skill-bound leaves, whose
    /// arguments are in `skill`.
    pub ports: BTreeMap<String, String>,
    /// The subtree this node is the root of, where the file drew a
    /// boundary: the tree ID of a BehaviorTree.CPP `<SubTree>` (the
    /// outermost, when a SubTree's root is itself a SubTree), or the id of
    /// the TOML node that includes a `subtree` file. Kept for drawing
    /// (`dot --subtrees folded`); the graph and the metrics ignore it.
    pub subtree: Option<String>,
    /// Where [`BtNode::id`] comes from: what `compare` may take as the
    /// node's identity across two versions of a file.
    pub id_source: IdSource,
    pub span: Option<Span>,
}

/// Where a node's id comes from. An id the author gave (a TOML key, a
/// `btfsm:id`) names the node across versions; an id a reader derived from
/// a display name or from the node's place does not: adding a `name`, or
/// inserting a sibling before the node, changes it while the node stays
/// (`compare` pairs such nodes by the ordered tree mapping instead).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum IdSource {
    /// Given by the author: a TOML key, a BehaviorTree.CPP `btfsm:id`, an
    /// id a transform chose.
    #[default]
    Given,
    /// A BehaviorTree.CPP `name` attribute, unique in the tree.
    Name,
    /// The parent's id and the child's position (or the pre-order index).
    Position,
}

impl IdSource {
    /// Whether the id was derived by a reader (from a name or a position)
    /// rather than given by the author.
    pub fn is_derived(self) -> bool {
        self != IdSource::Given
    }
}

impl BtNode {
    /// A node with only an id, a label, a kind and children (no skill,
    /// type name, ports, subtree or position).
    pub fn bare(id: String, label: String, kind: BtNodeKind, children: Vec<NodeIdx>) -> Self {
        BtNode {
            id,
            label,
            kind,
            children,
            skill: None,
            type_name: None,
            ports: Default::default(),
            subtree: None,
            id_source: IdSource::Given,
            span: None,
        }
    }
}

/// Every node type the tool knows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BtNodeKind {
    /// Reactive sequence (ticked from the first child every tick).
    Sequence,
    /// Reactive fallback (selector).
    Fallback,
    /// Sequence with memory (the paper's Sequence*).
    SequenceMemory,
    /// Fallback with memory.
    FallbackMemory,
    /// Succeeds when `success` children succeed.
    Parallel {
        success: usize,
    },
    Inverter,
    ForceSuccess,
    ForceFailure,
    /// Repeats the child on success; `None` repeats forever.
    Repeat {
        times: Option<u32>,
    },
    /// Retries the child on failure up to `times` times.
    Retry {
        times: u32,
    },
    /// Fails the child after `ms` milliseconds of simulated time.
    Timeout {
        ms: u64,
    },
    Action,
    Condition,
    /// A control node of a kind the tool does not model (BehaviorTree.CPP's
    /// `IfThenElse`, `WhileDoElse`, `Switch3`, Nav2's `RecoveryNode`, ...);
    /// [`BtNode::type_name`] keeps the original kind. Counted as a control node.
    Control,
    /// A decorator of a kind the tool does not model (`RunOnce`, `Delay`,
    /// Nav2's `RateController`, ...), with its original kind in
    /// [`BtNode::type_name`].
    Decorator,
}

/// How many children a node type takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Arity {
    Leaf,
    One,
    AtLeastOne,
}

impl BtNodeKind {
    /// The TOML key of this node type.
    pub fn keyword(self) -> &'static str {
        match self {
            BtNodeKind::Sequence => "sequence",
            BtNodeKind::Fallback => "fallback",
            BtNodeKind::SequenceMemory => "sequence_memory",
            BtNodeKind::FallbackMemory => "fallback_memory",
            BtNodeKind::Parallel { .. } => "parallel",
            BtNodeKind::Inverter => "inverter",
            BtNodeKind::ForceSuccess => "force_success",
            BtNodeKind::ForceFailure => "force_failure",
            BtNodeKind::Repeat { .. } => "repeat",
            BtNodeKind::Retry { .. } => "retry",
            BtNodeKind::Timeout { .. } => "timeout",
            BtNodeKind::Action => "action",
            BtNodeKind::Condition => "condition",
            BtNodeKind::Control => "control",
            BtNodeKind::Decorator => "decorator",
        }
    }

    pub fn arity(self) -> Arity {
        match self {
            BtNodeKind::Action | BtNodeKind::Condition => Arity::Leaf,
            BtNodeKind::Inverter
            | BtNodeKind::ForceSuccess
            | BtNodeKind::ForceFailure
            | BtNodeKind::Repeat { .. }
            | BtNodeKind::Retry { .. }
            | BtNodeKind::Timeout { .. }
            | BtNodeKind::Decorator => Arity::One,
            _ => Arity::AtLeastOne,
        }
    }

    pub fn is_control(self) -> bool {
        self.arity() == Arity::AtLeastOne
    }

    pub fn is_decorator(self) -> bool {
        self.arity() == Arity::One
    }

    /// Default display name of a node of this type.
    pub fn default_label(self) -> &'static str {
        match self {
            BtNodeKind::Sequence => "Sequence",
            BtNodeKind::Fallback => "Fallback",
            BtNodeKind::SequenceMemory => "Sequence*",
            BtNodeKind::FallbackMemory => "Fallback*",
            BtNodeKind::Parallel { .. } => "Parallel",
            BtNodeKind::Inverter => "Inverter",
            BtNodeKind::ForceSuccess => "ForceSuccess",
            BtNodeKind::ForceFailure => "ForceFailure",
            BtNodeKind::Repeat { .. } => "Repeat",
            BtNodeKind::Retry { .. } => "Retry",
            BtNodeKind::Timeout { .. } => "Timeout",
            BtNodeKind::Action => "Action",
            BtNodeKind::Condition => "Condition",
            BtNodeKind::Control => "Control",
            BtNodeKind::Decorator => "Decorator",
        }
    }
}

/// All node-type keywords, for "expected one of" hints.
pub const NODE_KEYWORDS: &[&str] = &[
    "sequence",
    "fallback",
    "sequence_memory",
    "fallback_memory",
    "parallel",
    "inverter",
    "force_success",
    "force_failure",
    "repeat",
    "retry",
    "timeout",
    "action",
    "condition",
    "control",
    "decorator",
    "subtree",
];

impl Bt {
    /// Node indices in pre-order (parent before children, children in order),
    /// computed without recursion.
    pub fn preorder(&self) -> Vec<NodeIdx> {
        let mut out = Vec::with_capacity(self.nodes.len());
        let mut stack = vec![self.root];
        while let Some(n) = stack.pop() {
            out.push(n);
            stack.extend(self.nodes[n].children.iter().rev().copied());
        }
        out
    }

    /// Parent of every node (`None` for the root).
    pub fn parents(&self) -> Vec<Option<NodeIdx>> {
        let mut parent = vec![None; self.nodes.len()];
        for (i, n) in self.nodes.iter().enumerate() {
            for &c in &n.children {
                parent[c] = Some(i);
            }
        }
        parent
    }

    /// Number of action leaves (the paper's M).
    pub fn action_count(&self) -> usize {
        self.nodes
            .iter()
            .filter(|n| n.kind == BtNodeKind::Action)
            .count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn leaf(id: &str) -> BtNode {
        BtNode::bare(id.into(), id.into(), BtNodeKind::Action, vec![])
    }

    #[test]
    fn preorder_visits_parent_before_children_in_order() {
        let mut root = leaf("r");
        root.kind = BtNodeKind::Sequence;
        root.children = vec![1, 2];
        let bt = Bt {
            nodes: vec![root, leaf("a"), leaf("b")],
            root: 0,
        };
        assert_eq!(bt.preorder(), vec![0, 1, 2]);
        assert_eq!(bt.parents(), vec![None, Some(0), Some(0)]);
        assert_eq!(bt.action_count(), 2);
    }

    #[test]
    fn arities() {
        assert_eq!(BtNodeKind::Inverter.arity(), Arity::One);
        assert_eq!(BtNodeKind::Condition.arity(), Arity::Leaf);
        assert!(BtNodeKind::Parallel { success: 1 }.is_control());
    }
}
