"""The one error of btfsm's Python exporters (docs/guide/python.md)."""


class ExportError(ValueError):
    """A tree or state machine btfsm's TOML cannot express; the message names
    the node or state and says why."""
