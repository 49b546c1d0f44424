"""Task 3: the rule answerer, the LLM answerer's prompt/reply handling, and QA metrics."""

from __future__ import annotations

import math

import pytest

from rover.episode import QAItem
from rover.eval.qa import QAAnswer, parse_qa_reply, qa_scores
from rover.eval.qa_events import asserted_states, first_event_position


def _a(truth: bool, pred: bool | None, tf: int | None = None, pf: int | None = None) -> QAAnswer:
    return QAAnswer(question="q", truth=truth, predicted=pred, truth_frame=tf, predicted_frame=pf)


def test_qa_scores_hand_computed() -> None:
    answers = [
        _a(True, True, 10, 7),  # TP, 3 frames early
        _a(True, True, 4, 5),  # TP, 1 frame late
        _a(False, True),  # FP (hallucinated event)
        _a(False, False),  # TN
        _a(True, False, 8),  # FN
        _a(True, None, 3),  # unreadable: wrong, counts as "no"
    ]
    s = qa_scores(answers)
    # percentages; the unreadable answer is wrong, never dropped
    assert s["accuracy"] == pytest.approx(100 * 3 / 6)
    assert s["precision"] == pytest.approx(100 * 2 / 3)
    assert s["recall"] == pytest.approx(100 * 2 / 4)
    assert s["unreadable"] == 1
    assert s["signed_distance"] == pytest.approx((-3 + 1) / 2)
    assert s["abs_distance"] == pytest.approx((3 + 1) / 2)
    assert s["distance_n"] == 2
    empty = qa_scores([])
    assert empty["qa_n"] == 0 and math.isnan(empty["accuracy"])


@pytest.mark.parametrize(
    ("reply", "expected"),
    [
        ("Answer: yes\nFrame: 5", (True, 4)),
        ("**Answer:** Yes\n**Frame:** 7", (True, 6)),
        ("Answer: no\nFrame: none", (False, None)),
        ("Yes, it happens in frame 3.", (True, 2)),
        ("I cannot tell.", (None, None)),
        ("Answer: yes\nFrame: 99", (True, 9)),  # clamped to the video
    ],
)
def test_parse_qa_reply(reply, expected) -> None:
    assert parse_qa_reply(reply, 10) == expected


DESCRIPTIONS = [
    "The gripper is open. The robot is not holding anything. The can is on the table.",
    "The gripper is touching the can.",
    "The gripper is closed. The robot is holding the can.",
    "The robot is holding the can. The can is lifted.",
    "The gripper is open. The robot is not holding anything. The can is on the table.",
    "The robot is holding the can. The can is lifted.",
    "The can is in bin 2. The gripper is empty.",
]


@pytest.mark.parametrize(
    ("question", "event", "expected"),
    [
        ("Did the robot contact the can? If so, when?", "contact", 1),
        ("Did the robot grasp the can? If so, when?", "grasp", 2),
        ("Did the robot pick up the can? If so, when?", "pick_up", 3),
        ("Did the robot drop the can? If so, when?", "drop", 4),
        ("Did the robot place the can in bin 2? If so, when?", "place", 6),
        ("Did the robot place the can in bin 1? If so, when?", "place", None),
        ("Did the robot press the button? If so, when?", "press", None),
    ],
)
def test_rule_answerer_finds_first_asserting_frame(question, event, expected) -> None:
    states = asserted_states(DESCRIPTIONS)
    item = QAItem(question=question, answer=True, event=event, object="can")
    qa = [
        QAItem(
            question="Did the robot place the can in bin 2? If so, when?",
            answer=True,
            event="place",
            object="can",
        )
    ]
    assert first_event_position(item, states, qa) == expected


def test_rule_answerer_reads_event_from_question_text() -> None:
    states = asserted_states(
        ["The door is 5% open.", "The door is 40% open.", "The door is 95% open."]
    )
    start = QAItem(question="Did the robot start opening the door? If so, when?", answer=True)
    done = QAItem(question="Did the robot completely open the door? If so, when?", answer=True)
    assert first_event_position(start, states, []) == 1
    assert first_event_position(done, states, []) == 2


def test_rule_answerer_reads_turning_an_appliance_on_from_the_button() -> None:
    states = asserted_states(
        [
            "The button is not pressed.",
            "The gripper is touching the button.",
            "The button is pressed.",
        ]
    )
    on = QAItem(
        question="Did the robot turn the appliance on? If so, when?",
        answer=True,
        event="turn_on",
        object="button",
    )
    assert first_event_position(on, states, []) == 2


def test_rule_answerer_reads_model_style_sequences() -> None:
    """Drops belong to the object dropped; intentions are not events; target bins."""
    task = "Restock the shelf: put the milk in bin 1 and the can in bin 4."
    descriptions = [
        "The robot is preparing to grasp the soda can.",
        "The gripper grabs the milk carton and lifts it.",
        "The robot drops the carton of milk.",
        "The can has been placed in the target bin.",
    ]
    states = asserted_states(descriptions, task=task)

    def ask(event: str, obj: str, target: str = "") -> int | None:
        where = f" in {target}" if target else ""
        item = QAItem(
            question=f"Did the robot {event} the {obj}{where}?",
            answer=True,
            event=event,
            object=obj,
        )
        qa = [
            QAItem(
                question=f"Did the robot place the {obj} in {target or 'bin 4'}?",
                answer=True,
                event="place",
                object=obj,
            )
        ]
        return first_event_position(item, states, qa)

    assert ask("contact", "can") is None  # "preparing to grasp" is not a contact
    assert ask("pick_up", "milk") == 1
    assert ask("drop", "milk", "bin 1") == 2
    assert ask("drop", "can", "bin 4") is None  # the milk was dropped, not the can
    assert ask("place", "can", "bin 4") == 3
    assert ask("place", "milk", "bin 1") is None
