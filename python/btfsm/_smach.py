"""`btfsm.from_smach`: a SMACH state machine as btfsm's FSM/HFSM TOML.

Reads SMACH's containers as SMACH itself runs them (smach/state_machine.py
`_update_once`: an outcome mapped to a state label goes there, to a
container outcome ends the container with it, an outcome mapped to None or
left unmapped falls through to the container outcome of the same name;
smach/concurrence.py: every child runs at once). Mapping:
docs/guide/python.md. SMACH is not imported: containers are recognised by
their class (`StateMachine`, `Concurrence`, `Iterator` in module `smach`).
"""

from . import _toml
from ._errors import ExportError

_STATUSES = ("SUCCESS", "FAILURE", "RUNNING")


def _is(obj, cls_name):
    return any(c.__name__ == cls_name and c.__module__.split(".")[0] == "smach" for c in type(obj).__mro__)


def _container_kind(state):
    if _is(state, "StateMachine"):
        return "machine"
    if _is(state, "Concurrence"):
        return "concurrence"
    if _is(state, "Iterator"):
        return "iterator"
    if _is(state, "Container"):
        return "container"
    return None


class _Writer:
    def __init__(self, decision, strict):
        self.decision = decision
        self.strict = strict
        self.tables = []  # (path, [(key, toml value)])
        self.seen = set()
        self.nested = False

    def is_decision(self, label, state):
        d = self.decision
        if d is not None:
            if callable(d):
                r = d(label, state)
                if r is not None:
                    return bool(r)
            elif label in d:
                return True
        return getattr(state, "btfsm_decision", False) is True

    def outcomes(self, container):
        return sorted(container.get_registered_outcomes())

    def machine(self, sm, path):
        """The fields of a StateMachine (top level or nested) and its states' tables."""
        states = sm.get_children()
        if not states:
            raise ExportError(f"state machine {self.where(path)} has no states")
        initial = sm.get_initial_states()[0] if sm.get_initial_states() else None
        if initial not in states:
            raise ExportError(f"state machine {self.where(path)}: initial state {initial!r} is not one of its states")
        outcomes = self.outcomes(sm)
        for label in states:
            if label in outcomes:
                raise ExportError(f"state `{label}` of {self.where(path)} is named like one of the machine's outcomes: btfsm needs them apart")
        fields = [("initial", _toml.string(initial)), ("outcomes", _toml.value(outcomes))]
        return fields, lambda: self.children(sm, path, states, outcomes)

    def children(self, sm, path, states, outcomes):
        for label, state in states.items():
            on = self.transitions(sm, path, label, state, states, outcomes)
            self.state(path + [label], state, on)

    def transitions(self, sm, path, label, state, states, outcomes):
        on = {}
        for outcome, target in sm._transitions.get(label, {}).items():
            if target is None or target == "":
                # Falls through to the container outcome of that name; an
                # outcome the container lacks is unbound (SMACH stops with an
                # error if the state ever returns it): no transition.
                if outcome in outcomes:
                    on[outcome] = outcome
                continue
            if target not in states and target not in outcomes:
                if outcome in outcomes:
                    target = outcome  # SMACH falls through to the outcome of the same name
                else:
                    raise ExportError(
                        f"state `{label}` of {self.where(path)}: outcome `{outcome}` goes to `{target}`, "
                        f"which is neither a state nor an outcome of the machine"
                    )
            on[outcome] = target
        return on

    def where(self, path):
        return "the top-level machine" if not path else "`" + "/".join(path) + "`"

    def state(self, path, state, on):
        if id(state) in self.seen:
            raise ExportError(f"state {self.where(path)}: the same state object is added twice; btfsm needs one per place")
        self.seen.add(id(state))
        kind = _container_kind(state)
        slot = len(self.tables)
        self.tables.append(None)
        then = None
        if kind == "machine":
            self.nested = True
            fields, then = self.machine(state, path)
        elif kind == "concurrence":
            self.nested = True
            fields, then = self.concurrence(state, path)
        elif kind is not None:
            raise ExportError(
                f"state {self.where(path)} is a SMACH {type(state).__name__}: btfsm's TOML has no container that "
                f"repeats its states (an Iterator) or runs them otherwise than as a machine or in parallel"
            )
        else:
            fields = self.leaf(path, state)
        label = path[-1]
        if kind is None and self.is_decision(label, state):
            guards = [{"to": t, "label": o} for o, t in on.items() if o != "RUNNING"]
            on = {o: t for o, t in on.items() if o == "RUNNING"}
            fields = [("decision", "true")] + ([("guards", _toml.value(guards))] if guards else [])
        if on:
            fields.append(("on", _toml.inline_table(on)))
        self.tables[slot] = (path, fields)
        if then:
            then()

    def concurrence(self, cc, path):
        children = cc.get_children()
        if not children:
            raise ExportError(f"Concurrence {self.where(path)} has no states")
        fields = [("parallel", "true"), ("outcomes", _toml.value(self.outcomes(cc)))]

        def regions():
            for label, child in children.items():
                self.state(path + [label], child, {})

        return fields, regions

    def leaf(self, path, state):
        fields = []
        skill = getattr(state, "btfsm_skill", None)
        if skill is not None:
            fields.append(("skill", _toml.string(skill, f"the skill of {self.where(path)}")))
            args = getattr(state, "btfsm_args", None)
            if args:
                if not isinstance(args, dict):
                    raise ExportError(f"btfsm_args of {self.where(path)} must be a dict, found {type(args).__name__}")
                fields.append(("args", _toml.inline_table(args)))
        return fields


def from_smach(container, *, decision=None, strict=False, name=None, description=None):
    """btfsm's TOML text for a SMACH `StateMachine` (FSM, or HFSM when it nests containers).

    `decision`: labels of decision states (the paper's SELECTOR), or a
    callable `(label, state) -> bool | None`; a state whose object has
    `btfsm_decision = True` is one too. A decision state's outcomes other
    than RUNNING become label-only guards in the order SMACH holds them.
    """
    if _container_kind(container) != "machine":
        raise ExportError(f"from_smach takes a smach.StateMachine, found {type(container).__module__}.{type(container).__name__}")
    w = _Writer(decision, strict)
    fields, then = w.machine(container, [])
    then()
    out = [f'kind = "{"hfsm" if w.nested else "fsm"}"']
    title = name if name is not None else getattr(container, "btfsm_name", None)
    if title is not None:
        out.append(f"name = {_toml.string(title, 'the policy name')}")
    if description is not None:
        out.append(f"description = {_toml.string(description, 'the description')}")
    out += [f"{k} = {v}" for k, v in fields]
    for path, fields in w.tables:
        out.append("")
        out.append("[" + ".".join(_toml.key(p, "a state name") for p in _header(path)) + "]")
        out += [f"{k} = {v}" for k, v in fields]
    return "\n".join(out) + "\n"


def _header(path):
    parts = []
    for p in path:
        parts += ["states", p]
    return parts
