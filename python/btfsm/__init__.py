"""btfsm's Python module: policies written in py_trees and SMACH, the paper's
own libraries, as btfsm's TOML (docs/guide/python.md).

    import btfsm
    text = btfsm.from_py_trees(root)        # a live py_trees 2.x tree
    text = btfsm.from_smach(state_machine)  # a SMACH StateMachine

`python -m btfsm export py_trees|smach MODULE:FACTORY [-o FILE]` writes the
file; the `btfsm` command of the same wheel measures it.
"""

from ._errors import ExportError
from ._py_trees import default_leaf_kind, from_py_trees
from ._smach import from_smach

__all__ = ["ExportError", "default_leaf_kind", "from_py_trees", "from_smach"]
