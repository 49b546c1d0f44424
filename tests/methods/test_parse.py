"""Reply parsing: real-world formats, and a fuzz test that nothing ever raises."""

from __future__ import annotations

import math
import random

import pytest

from rover.methods.parse import parse_frame, parse_frames, parse_percentage, parse_step


@pytest.mark.parametrize(
    ("reply", "progress"),
    [
        ("Frame description: ok\nSubtask completion percentage: 45%\n[next-frame]", 45),
        ("**Frame description:** ok\n**Subtask completion percentage:** 37.5 %", 37.5),
        ("Frame description: regressed\nSubtask completion percentage: -12%", -12),
        ("Frame description: done\nSubtask completion percentage: 120%", 120),
        ('{"frame_description": "x", "subtask_completion_percentage": "64%"}', 64),
        ('```json\n{"description": "x", "progress": 0.5}\n```', 0.5),
        ("- Frame description: x\n- Task completion percentage: 80 percent", 80),
        ("I'd say roughly 30% done. [next-frame]", 30),
        ("Subtask completion percentage: −7 %", -7),
    ],
)
def test_progress_forms(reply, progress):
    r = parse_step(reply)
    assert r.progress == pytest.approx(progress)
    assert r.usable_step


def test_subtask_forms():
    r = parse_step("Frame description: near the can\nThe robot needs to: 'grasp the can'.")
    assert (r.description, r.new_subtask, r.progress) == ("near the can", "grasp the can", None)
    r = parse_step("The robot needs to: ['grasp the cheese', 'place the cheese in the cabinet']")
    assert r.new_subtask == "grasp the cheese" and len(r.plan) == 2
    r = parse_step(
        "New Subtasks: [`grasp the cup`, `place the cup in the sink`]\n"
        "The robot needs to: grasp the cup"
    )
    assert r.plan == ["grasp the cup", "place the cup in the sink"]
    assert parse_step("**Task complete.**").task_complete
    assert not parse_step("Task completion percentage: 20%").task_complete
    r = parse_step(
        "Frame description: the arm moves\nover the table\nSubtask completion percentage: 5%"
    )
    assert r.description == "the arm moves over the table"


def test_unusable_replies():
    for reply in ["", "   ", "I cannot see the image.", "Frame description: only this", None, 42]:
        assert not parse_step(reply).usable_step
    assert parse_percentage("nan%") is None
    assert parse_percentage("1e999") == 1.0  # first number only, never inf
    assert parse_percentage(float("inf")) is None
    assert parse_percentage(True) is None


def test_multi_frame_replies():
    reply = (
        "Frame 1:\nFrame description: a\nTask completion percentage: 10%\n\n"
        "**Frame 2**\nFrame description: b\nTask completion percentage: 20.5%\n"
        "Frame 3: 50%\nFrame 4 - Frame description: d"
    )
    got = parse_frames(reply)
    assert {k: v.progress for k, v in got.items()} == {1: 10, 2: 20.5, 3: 50, 4: None}
    assert got[2].description == "b"
    got = parse_frames('[{"frame": 2, "description": "x", "progress": "7%"}, {"frame": "3"}]')
    assert got[2].progress == 7 and got[3].progress is None
    assert parse_frame("Frame description: z\nTask completion percentage: 3%").progress == 3


_PIECES = [
    "Frame description:",
    "Subtask completion percentage:",
    "Task completion percentage:",
    "The robot needs to:",
    "[next-frame]",
    "Task complete",
    "New subtasks:",
    "Frame 3:",
    "**",
    "```",
    "#",
    "{",
    "}",
    "[",
    "]",
    '"',
    "'",
    ":",
    "%",
    "-",
    "\n",
    "\n\n",
    " ",
    "45",
    "-3.5",
    "1e400",
    "nan",
    "inf",
    "١٢",
    "½",
    "−",
    "12,5",
    "0x1F",
    "None",
    "null",
    '{"progress": }',
    '{"frame": [1,2]}',
    '[{"frame": null}]',
    "Frame",
    "frame 99999999999999",
    "\x00",
    "\ud7ff",
    "😀",
    "percent",
    "completion",
    "description",
    "grasp the can",
]


def _random_reply(rng: random.Random) -> str:
    n = rng.randint(0, 25)
    return "".join(rng.choice(_PIECES) + (" " if rng.random() < 0.3 else "") for _ in range(n))


def test_fuzz_never_raises():
    rng = random.Random(1234)
    for _ in range(4000):
        reply = _random_reply(rng)
        r = parse_step(reply)
        assert r.progress is None or math.isfinite(r.progress)
        assert r.new_subtask is None or isinstance(r.new_subtask, str)
        for k, ans in parse_frames(reply).items():
            assert isinstance(k, int)
            assert ans.progress is None or math.isfinite(ans.progress)
        a = parse_frame(reply)
        assert a.progress is None or math.isfinite(a.progress)


def test_only_the_first_64_kb_and_2000_lines_are_read():
    from rover.methods.parse import MAX_PARSE_CHARS, reply_capped

    head = "Frame description: ok\nSubtask completion percentage: 45%\n"
    late = "x" * MAX_PARSE_CHARS + "\nThe robot needs to: grasp the can"
    r = parse_step(head + late)
    assert r.progress == 45 and r.new_subtask is None  # the late marker is never read
    assert reply_capped(head + late) and not reply_capped(head)
    many = "\n" * 2000 + "Subtask completion percentage: 10%"  # line 2,001
    assert parse_step(many).progress is None and reply_capped(many)
    assert parse_step("\n" * 1990 + "Subtask completion percentage: 10%").progress == 10


def test_the_trace_says_when_a_reply_was_capped():
    from rover.methods.base import Session
    from rover.vlm.types import Completion, Prompt, PromptMeta, SamplingParams

    class Stub:
        trace = type("T", (), {"calls": []})()

    long = "Frame description: x\nSubtask completion percentage: 5%\n" + "y" * 70_000
    rec = Session._record(
        Stub(),  # type: ignore[arg-type]
        Prompt(messages=[], meta=PromptMeta(kind="rover.step")),
        Completion(text=long),
        "ok",
        None,
        SamplingParams(max_tokens=100_000),
    )
    assert rec.reply_capped and not rec.truncated
