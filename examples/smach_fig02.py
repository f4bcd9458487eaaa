"""Fig. 2 of Iovino et al. (the sequential MoMa FSM, policies/paper/fig02-fsm.toml)
written in SMACH, the library the paper's authors used (their
`sequential_sm.py` in ethz-asl/bt_fsm_comparison builds the same chain).

`python -m btfsm export smach examples.smach_fig02:make -o fig02.toml` writes
btfsm's TOML (tests/packaging/python_export.py checks it against the
bundled file). Needs `smach` importable: SMACH's pure-Python core, as in
tests/fixtures/smach/.
"""

import smach


class Skill(smach.State):
    """A state bound to a skill of btfsm's simulator; here it only returns SUCCESS."""

    def __init__(self, skill, outcomes, **args):
        super().__init__(outcomes=outcomes)
        self.btfsm_skill = skill
        self.btfsm_args = args

    def execute(self, userdata):
        return "SUCCESS"


def make():
    """The SMACH StateMachine of Fig. 2."""
    sm = smach.StateMachine(outcomes=["SUCCESS"])
    with sm:
        smach.StateMachine.add("Move-To cube2", Skill("Move-To", ["SUCCESS"], target="cube2"), transitions={"SUCCESS": "Pick cube2"})
        smach.StateMachine.add("Pick cube2", Skill("Pick", ["SUCCESS"], object="cube2"), transitions={"SUCCESS": "Move-To delivery"})
        smach.StateMachine.add(
            "Move-To delivery", Skill("Move-To", ["SUCCESS"], target="delivery"), transitions={"SUCCESS": "Place cube2"}
        )
        smach.StateMachine.add(
            "Place cube2", Skill("Place", ["SUCCESS"], object="cube2", at="delivery"), transitions={"SUCCESS": "SUCCESS"}
        )
    sm.btfsm_name = "Fig. 2 FSM sequential"
    return sm


if __name__ == "__main__":
    print(make().execute())
