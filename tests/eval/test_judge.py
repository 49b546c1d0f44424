"""The LLM judge's prompt and reply handling (the HTTP round trip is in test_runner)."""

from __future__ import annotations

import pytest

from rover.episode import FrameFacts, ObjectFacts
from rover.eval.judge import facts_to_text, parse_judge_reply
from rover.eval.prompts import build_prompt
from rover.vlm.types import PromptMeta


@pytest.mark.parametrize(
    ("reply", "verdict", "n_true", "n_false"),
    [
        (
            "True statements: the gripper is open\nFalse statements: none\nVerdict: true",
            "true",
            1,
            0,
        ),
        (
            "True statements: gripper open; can lifted\nFalse statements: holding the can\n"
            "Verdict: false",
            "false",
            2,
            1,
        ),
        (
            "**True statements:** none\n**False statements:** none\n**Verdict:** inconclusive",
            "inconclusive",
            0,
            0,
        ),
        ("Verdict: FALSE", "false", 0, 0),  # lists missing: the verdict line decides
        ("I am not sure.", "inconclusive", 0, 0),
        # the lists decide over a contradicting verdict line (App. C.2's definition)
        ("True statements: a\nFalse statements: b\nVerdict: true", "false", 1, 1),
        # prose around the fields, an upper-case verdict
        (
            "Comparing with the ground truth:\n\nTrue statements: the can is lifted\n"
            "False statements: none\n\nVerdict: TRUE. The rest is inconclusive.",
            "true",
            1,
            0,
        ),
        # lists written as bullets under markdown headings
        (
            "### True statements:\n- the gripper is closed\n- the can is held\n"
            "### False statements:\n- none\n### Verdict: true",
            "true",
            2,
            0,
        ),
        # JSON in a code fence
        (
            '```json\n{"true_statements": [], "false_statements": ["the can is in bin 4"],'
            ' "verdict": "false"}\n```',
            "false",
            0,
            1,
        ),
        # cut off by max_tokens after both lists: the lists still decide
        ("True statements: gripper open\nFalse statements: none\nVerd", "true", 1, 0),
        # cut off before the false-statement list: nothing can be concluded
        ("True statements: gripper open\nFalse sta", "inconclusive", 1, 0),
    ],
)
def test_parse_judge_reply(reply, verdict, n_true, n_false) -> None:
    j = parse_judge_reply(reply)
    assert (j.verdict, len(j.true_claims), len(j.false_claims)) == (verdict, n_true, n_false)


def test_judge_prompt_carries_description_and_facts() -> None:
    facts = FrameFacts(
        gripper="closed",
        holding="can",
        contacts=["can"],
        objects={"can": ObjectFacts(lifted=True)},
        articulations={"door": 0.4},
        pressed=["button"],
    )
    text = facts_to_text(facts)
    assert "Other parts of the robot" not in text
    arm = facts_to_text(facts.model_copy(update={"robot_contacts": ["can", "table"]}))
    assert "Other parts of the robot (not the gripper) touch: table." in arm
    for s in (
        "The gripper is closed.",
        "holding the can",
        "touching: can",
        "can is lifted",
        "door is 40% open",
        "button is pressed",
    ):
        assert s in text
    p = build_prompt(
        "judge",
        PromptMeta(kind="judge.frame"),
        task="lift the can",
        description="The robot holds the can.",
        facts=text,
    )
    user = p.messages[1].content
    assert "The robot holds the can." in user and "The gripper is closed." in user
    assert "Verdict:" in user and p.messages[0].role == "system"
