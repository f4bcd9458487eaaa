"""Fig. 4 of Iovino et al. (the fault-tolerant MoMa FSM, policies/paper/fig04-fsm.toml)
written in SMACH, as the authors' `fault_tolerant_sm.py`
(ethz-asl/bt_fsm_comparison) builds it: every action state has
SUCCESS -> the next state, FAILURE -> the SELECTOR (their `IDLE`),
RUNNING -> itself; the SELECTOR checks robot and world and resumes the task.

The SELECTOR is a decision state (`btfsm_decision = True`): its outcomes
other than RUNNING become btfsm guards, in the order written here.
`python -m btfsm export smach examples.smach_fig04:make -o fig04.toml`;
tests/packaging/python_export.py checks it against the bundled file.
"""

import smach

STEPS = [
    ("Move-To cube2", "Move-To", {"target": "cube2"}),
    ("Pick cube2", "Pick", {"object": "cube2"}),
    ("Move-To delivery", "Move-To", {"target": "delivery"}),
    ("Place cube2", "Place", {"object": "cube2", "at": "delivery"}),
]


class Skill(smach.State):
    """An action state bound to a skill of btfsm's simulator."""

    def __init__(self, skill, **args):
        super().__init__(outcomes=["SUCCESS", "FAILURE", "RUNNING"])
        self.btfsm_skill = skill
        self.btfsm_args = args

    def execute(self, userdata):
        return "SUCCESS"


class Selector(smach.State):
    """The paper's SELECTOR: inspects robot and world, picks where to resume."""

    btfsm_decision = True

    def __init__(self, outcomes):
        super().__init__(outcomes=outcomes)

    def execute(self, userdata):
        return "restart the task"


def make():
    """The SMACH StateMachine of Fig. 4."""
    sm = smach.StateMachine(outcomes=["SUCCESS"])
    with sm:
        for i, (label, skill, args) in enumerate(STEPS):
            after = STEPS[i + 1][0] if i + 1 < len(STEPS) else "SUCCESS"
            smach.StateMachine.add(
                label, Skill(skill, **args), transitions={"SUCCESS": after, "FAILURE": "SELECTOR", "RUNNING": label}
            )
        guards = {
            "cube2 delivered": "SUCCESS",
            "cube2 in hand at delivery": "Place cube2",
            "cube2 in hand": "Move-To delivery",
            "cube2 reached": "Pick cube2",
            "restart the task": "Move-To cube2",
            "RUNNING": "SELECTOR",
        }
        smach.StateMachine.add("SELECTOR", Selector(list(guards)), transitions=guards)
    sm.btfsm_name = "Fig. 4 FSM fault tolerant"
    return sm


if __name__ == "__main__":
    print(make().execute())
