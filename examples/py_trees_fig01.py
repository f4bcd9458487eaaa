"""Fig. 1 of Iovino et al. (the backchained MoMa BT, policies/paper/fig01-bt.toml)
written in py_trees 2.x, the library the paper's authors used.

`python -m btfsm export py_trees examples.py_trees_fig01:make --ids examples.py_trees_fig01:IDS -o fig01.toml`
writes btfsm's TOML; `btfsm compare fig01.toml policies/paper/fig01-bt.toml --mode named`
gives GED 0 (tests/packaging/python_export.py). Composites are named by the
ids of the bundled TOML; leaves carry the paper's display names, and `IDS`
maps them to the bundled file's ids (a py_trees node has one name, the TOML
both an id and a display name). The skill bindings (`btfsm_skill`,
`btfsm_args`) let `btfsm sim` run the export.
"""

import py_trees
from py_trees.common import Status


class Skill(py_trees.behaviour.Behaviour):
    """A leaf bound to a skill of btfsm's simulator; here it only returns SUCCESS."""

    def __init__(self, name, skill, **args):
        super().__init__(name=name)
        self.btfsm_skill = skill
        self.btfsm_args = args

    def update(self):
        return Status.SUCCESS


def fallback(name, *children):
    return py_trees.composites.Selector(name=name, memory=False, children=list(children))


def sequence(name, *children):
    return py_trees.composites.Sequence(name=name, memory=False, children=list(children))


IDS = {
    "Cube2 in delivery?": "cube-delivered",
    "Cube2 in Hand?": "cube-in-hand",
    "Robot-At cube2?": "at-cube",
    "Move-To cube2!": "move-to-cube",
    "Pick cube2!": "pick",
    "Robot-At delivery?": "at-delivery",
    "Move-To delivery!": "move-to-delivery",
    "Place cube2!": "place",
}


def make():
    """The root of Fig. 1: moma(2)."""
    return fallback(
        "moma",
        Skill("Cube2 in delivery?", "Object-At", object="cube2", at="delivery"),
        sequence(
            "deliver",
            fallback(
                "held",
                Skill("Cube2 in Hand?", "In-Hand", object="cube2"),
                sequence(
                    "fetch",
                    fallback(
                        "reached-cube",
                        Skill("Robot-At cube2?", "Robot-At", target="cube2"),
                        Skill("Move-To cube2!", "Move-To", target="cube2"),
                    ),
                    Skill("Pick cube2!", "Pick", object="cube2"),
                ),
            ),
            fallback(
                "reached-delivery",
                Skill("Robot-At delivery?", "Robot-At", target="delivery"),
                Skill("Move-To delivery!", "Move-To", target="delivery"),
            ),
            Skill("Place cube2!", "Place", object="cube2", at="delivery"),
        ),
    )


if __name__ == "__main__":
    root = make()
    print(py_trees.display.unicode_tree(root))
