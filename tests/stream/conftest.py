"""Stream tests reuse the method tests' scripted VLM (one implementation of it)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

from rover.vlm.types import Prompt

_path = Path(__file__).parents[1] / "methods" / "conftest.py"
_spec = importlib.util.spec_from_file_location("_methods_conftest", _path)
assert _spec is not None and _spec.loader is not None
_mod = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_mod)
ScriptedVLM = _mod.ScriptedVLM

TASK = "pick the can and place it in the bin"


def chatty(p: Prompt) -> str:
    """Replies shaped like a real model's: markdown, prose around the fields, a plan, a
    nested subtask, one unusable reply (re-asked) and a parent turn that adds a subtask."""
    m = p.meta
    pos = m.positions[-1] if m.positions else 0
    first = int(m.extra.get("first_position", 0))
    if m.kind == "rover.parent":
        done = m.extra.get("completed", [])
        if m.subtask_path == ["grasp the can"]:
            return "The approach is finished.\n\n**Task complete**"
        if done == ["grasp the can"]:
            return "Good, the can is held.\nThe robot needs to: place the can in the bin"
        return "Everything in the plan is done. Task complete."
    if pos == 5 and not m.extra.get("reminder"):
        return "I am not sure what I am looking at here."
    if not m.subtask_path:
        return (
            "**Frame description:** A robot arm above a red can on a grey table.\n\n"
            "New subtasks: ['grasp the can', 'place the can in the bin']\n"
            "The robot needs to: grasp the can"
        )
    if m.subtask_path == ["grasp the can"] and m.extra.get("allow_decompose") and pos == 1:
        return "Frame description: the gripper starts to move\nThe robot needs to: approach the can"
    rate = 40 if m.subtask_path[-1] == "approach the can" else 25
    value = min(rate * (pos - first), 100)
    return (
        f"Looking at frame {pos}, the arm keeps moving.\n\n"
        f"**Frame description:** the gripper is at step {pos}\n"
        f"**Subtask completion percentage:** {value}%\n\n[next-frame]"
    )


@pytest.fixture
def scripted():
    return ScriptedVLM


@pytest.fixture(name="chatty")
def chatty_fixture():
    return chatty
