"""`btfsm.from_py_trees`: a live py_trees 2.x tree as btfsm's BT TOML.

The mapping (docs/guide/python.md): py_trees' composites and decorators
(py_trees/composites.py, py_trees/decorators.py, py_trees/common.py
ParallelPolicy) to the node types of btfsm's TOML (docs/guide/policy-toml.md,
crates/model/src/bt.rs `BtNodeKind`). py_trees is imported lazily, so
`import btfsm` works without it.
"""

from . import _toml
from ._errors import ExportError

# Leaf classes of py_trees.behaviours that check and never run: conditions.
_CONDITION_CLASSES = (
    "CheckBlackboardVariableExists",
    "CheckBlackboardVariableValue",
    "CheckBlackboardVariableValues",
    "CompareBlackboardVariables",
)
# Their subclasses that wait (RUNNING until the check holds): actions.
_WAITING_CLASSES = ("WaitForBlackboardVariable", "WaitForBlackboardVariableValue")
_CONDITION_PREFIXES = ("Check", "Is", "Has")
_DEFAULT_LABELS = {
    "sequence": "Sequence",
    "fallback": "Fallback",
    "sequence_memory": "Sequence*",
    "fallback_memory": "Fallback*",
    "parallel": "Parallel",
    "inverter": "Inverter",
    "force_success": "ForceSuccess",
    "force_failure": "ForceFailure",
    "repeat": "Repeat",
    "retry": "Retry",
    "timeout": "Timeout",
    "control": "Control",
    "decorator": "Decorator",
}


def _describe(b):
    return f"`{getattr(b, 'name', '?')}` ({type(b).__module__}.{type(b).__qualname__})"


def default_leaf_kind(behaviour):
    """The documented rule: `condition` or `action` for a py_trees leaf.

    1. a name ending in `?` is a condition, in `!` an action;
    2. py_trees' own checks (`CheckBlackboardVariableExists`,
       `CheckBlackboardVariableValue(s)`, `CompareBlackboardVariables`; not
       their `WaitFor...` subclasses, which return RUNNING) are conditions;
    3. a class whose name starts with `Check`, `Is` or `Has`, or contains
       `Condition`, is a condition;
    4. everything else is an action.
    """
    name = behaviour.name
    if name.endswith("?"):
        return "condition"
    if name.endswith("!"):
        return "action"
    mro = [c.__name__ for c in type(behaviour).__mro__]
    if mro[0] in _WAITING_CLASSES or any(c in _WAITING_CLASSES for c in mro):
        return "action"
    if any(c in _CONDITION_CLASSES for c in mro):
        return "condition"
    cls = mro[0]
    if cls.startswith(_CONDITION_PREFIXES) or "Condition" in cls:
        return "condition"
    return "action"


def _override(table, behaviour, what):
    """Looks a node up in a `{name: value}` mapping or calls a callable."""
    if table is None:
        return None
    if callable(table):
        return table(behaviour)
    try:
        return table.get(behaviour.name)
    except AttributeError:
        raise ExportError(f"{what} must be a mapping from node names or a callable, found {type(table).__name__}") from None


class _Walk:
    def __init__(self, py_trees, leaf_kind, ids, strict):
        self.pt = py_trees
        self.leaf_kind = leaf_kind
        self.ids = ids
        self.strict = strict
        self.used = set()
        self.seen = set()
        self.lines = []

    def node_id(self, b):
        given = _override(self.ids, b, "`ids`")
        if given is not None:
            if not isinstance(given, str) or not given:
                raise ExportError(f"the id given for {_describe(b)} must be a non-empty string, found {given!r}")
            if given in self.used:
                raise ExportError(f"the id `{given}` given for {_describe(b)} is already used by another node")
            self.used.add(given)
            return given
        base = b.name if isinstance(b.name, str) and b.name else type(b).__name__
        nid, n = base, 1
        while nid in self.used:
            n += 1
            nid = f"{base} ({n})"
        self.used.add(nid)
        return nid

    def unsupported(self, b, why):
        if self.strict:
            raise ExportError(f"node {_describe(b)}: {why}")

    def walk(self, b):
        """Writes `b` and its subtree; returns its id (pre-order ids, post-order lines kept in pre-order)."""
        pt = self.pt
        if not isinstance(b, pt.behaviour.Behaviour):
            raise ExportError(f"{b!r} is not a py_trees behaviour (py_trees.behaviour.Behaviour)")
        if id(b) in self.seen:
            raise ExportError(f"node {_describe(b)} occurs twice in the tree: a BT node has one parent")
        self.seen.add(id(b))
        nid = self.node_id(b)
        slot = len(self.lines)
        self.lines.append(None)
        fields = self.fields(b, nid)
        self.lines[slot] = (nid, fields)
        return nid

    def fields(self, b, nid):
        pt = self.pt
        if isinstance(b, pt.composites.Composite):
            return self.composite(b, nid)
        if isinstance(b, pt.decorators.Decorator):
            return self.decorator(b, nid)
        return self.leaf(b)

    def named(self, kind, b, nid, fields):
        # The name is kept where the id does not already hold it.
        if b.name != nid and b.name != _DEFAULT_LABELS[kind]:
            fields.append(("name", _toml.string(b.name, "a node name")))
        return fields

    def composite(self, b, nid):
        pt = self.pt
        if not b.children:
            raise ExportError(f"node {_describe(b)} has no children: btfsm's control nodes take at least one")
        memory = bool(getattr(b, "memory", False))
        extra = []
        if isinstance(b, pt.composites.Sequence):
            kind = "sequence_memory" if memory else "sequence"
        elif isinstance(b, pt.composites.Selector):
            kind = "fallback_memory" if memory else "fallback"
        elif isinstance(b, pt.composites.Parallel):
            kind, extra = self.parallel(b)
        else:
            self.unsupported(b, "a composite of its own kind: btfsm has no node type with its semantics")
            kind, extra = "control", [("type", _toml.string(type(b).__name__))]
        children = [self.walk(c) for c in b.children]
        fields = [(kind, "[" + ", ".join(_toml.string(c) for c in children) + "]")]
        return self.named(kind, b, nid, fields + extra)

    def parallel(self, b):
        policy = b.policy
        pp = self.pt.common.ParallelPolicy
        n = len(b.children)
        if isinstance(policy, pp.SuccessOnAll):
            return "parallel", [("success", str(n))]
        if isinstance(policy, pp.SuccessOnOne):
            # py_trees fails at any child's failure; btfsm's parallel by
            # default when success is out of reach (n - k + 1 failures), so
            # the BehaviorTree.CPP port says 1 (crates/sim/src/exec/ops.rs).
            extra = [("ports", '{ failure_count = "1" }')] if n > 1 else []
            return "parallel", [("success", "1")] + extra
        if isinstance(policy, pp.SuccessOnSelected):
            selected = {id(c) for c in policy.children}
            if selected == {id(c) for c in b.children}:
                return "parallel", [("success", str(n))]
            why = (
                "Parallel with SuccessOnSelected over some of its children: btfsm's `parallel` "
                "takes a number of children (`success = k`), not which ones"
            )
            self.unsupported(b, why)
            names = [c.name for c in policy.children]
            ports = {"policy": "SuccessOnSelected", "selected": ", ".join(names)}
            return "control", [("type", '"Parallel"'), ("ports", _toml.inline_table(ports))]
        self.unsupported(b, f"Parallel with policy {type(policy).__name__}: not one of py_trees' three")
        return "control", [("type", '"Parallel"'), ("ports", _toml.inline_table({"policy": type(policy).__name__}))]

    def decorator(self, b, nid):
        d = self.pt.decorators
        extra = []
        if isinstance(b, d.Inverter):
            kind = "inverter"
        elif isinstance(b, d.FailureIsSuccess):
            kind = "force_success"
        elif isinstance(b, d.SuccessIsFailure):
            kind = "force_failure"
        elif isinstance(b, d.Repeat):
            kind = "repeat"
            if b.num_success >= 0:
                extra = [("times", str(b.num_success))]
        elif isinstance(b, d.Retry):
            kind, extra = "retry", [("times", str(max(b.num_failures, 1)))]
        elif isinstance(b, d.Timeout):
            kind, extra = "timeout", [("ms", str(max(round(b.duration * 1000), 0)))]
        else:
            cls = type(b).__name__
            self.unsupported(b, f"decorator {cls} has no btfsm node type with its semantics")
            kind, extra = "decorator", [("type", _toml.string(cls))] + self.decorator_ports(b)
        child = self.walk(b.decorated)
        return self.named(kind, b, nid, [(kind, _toml.string(child))] + extra)

    def decorator_ports(self, b):
        ports = {}
        for attr, port in (("succeed_status", "status"), ("policy", "policy"), ("variable_name", "variable")):
            v = getattr(b, attr, None)
            if v is not None:
                ports[port] = str(getattr(v, "value", v))
        return [("ports", _toml.inline_table(ports))] if ports else []

    def leaf(self, b):
        kind = _override(self.leaf_kind, b, "`leaf_kind`")
        if kind is None:
            kind = default_leaf_kind(b)
        if kind not in ("action", "condition"):
            raise ExportError(f"leaf_kind gave {kind!r} for node {_describe(b)}: expected \"action\" or \"condition\"")
        fields = [(kind, _toml.string(b.name, "a node name"))]
        skill = getattr(b, "btfsm_skill", None)
        if skill is not None:
            fields.append(("skill", _toml.string(skill, f"the skill of {_describe(b)}")))
            args = getattr(b, "btfsm_args", None)
            if args:
                if not isinstance(args, dict):
                    raise ExportError(f"btfsm_args of {_describe(b)} must be a dict, found {type(args).__name__}")
                fields.append(("args", _toml.inline_table(args, f"the skill arguments of {_describe(b)}")))
        return fields


def from_py_trees(root, *, leaf_kind=None, ids=None, strict=False, name=None, description=None):
    """btfsm's TOML text for the py_trees 2.x tree under `root`.

    `root` may be a behaviour or a `py_trees.trees.BehaviourTree`.
    `leaf_kind`: `{node name: "action" | "condition"}` or a callable
    `behaviour -> "action" | "condition" | None` (None: the default rule,
    `default_leaf_kind`). `ids`: `{node name: id}` or a callable
    `behaviour -> id | None`; without one, a node's id is its name, made
    unique by ` (2)`, ` (3)`, ... in pre-order. `strict`: refuse
    (ExportError) nodes written as btfsm's generic `decorator`/`control`.
    """
    try:
        import py_trees
    except ImportError as e:  # pragma: no cover - needs py_trees absent
        raise ExportError("from_py_trees needs py_trees 2.x installed (pip install py_trees)") from e
    if isinstance(root, py_trees.trees.BehaviourTree):
        root = root.root
    w = _Walk(py_trees, leaf_kind, ids, strict)
    root_id = w.walk(root)
    out = ['kind = "bt"']
    out.append(f"name = {_toml.string(name if name is not None else root.name, 'the policy name')}")
    if description is not None:
        out.append(f"description = {_toml.string(description, 'the description')}")
    out.append(f"root = {_toml.string(root_id)}")
    out.append("")
    out.append("[nodes]")
    for nid, fields in w.lines:
        body = ", ".join(f"{k} = {v}" for k, v in fields)
        out.append(f"{_toml.key(nid, 'a node id')} = {{ {body} }}")
    return "\n".join(out) + "\n"
