"""ROVER (Algorithm 1): exact window contents, recursion and return, guards, failures."""

from __future__ import annotations

import pytest

from rover.errors import InputError
from rover.methods import get_method
from rover.vlm.types import ImagePart, Prompt, TextPart


def two_subtask_script(b_span: int = 8):
    """Root -> A (25 points per frame, done 4 frames in) -> B (100/b_span per frame)."""

    def script(p: Prompt) -> str:
        m = p.meta
        pos = m.positions[-1] if m.positions else None
        first = m.extra.get("first_position", 0)
        if m.kind == "rover.parent":
            return "The robot needs to: B" if m.extra["completed"] == ["A"] else "Task complete"
        if m.subtask_path == []:
            return "Frame description: start\nThe robot needs to: A"
        rate = 25 if m.subtask_path == ["A"] else 100 / b_span
        value = rate * (pos - first)
        return f"Frame description: f{pos}\nSubtask completion percentage: {value}%\n[next-frame]"

    return script


def windows(vlm) -> list[tuple[str, list[int]]]:
    return [(p.meta.kind, p.meta.frame_indices) for p in vlm.prompts]


async def test_window_k3_exact_frames(make_episode, scripted):
    ep = make_episode(12)
    vlm = scripted(two_subtask_script())
    trace = await get_method("rover").run(ep, vlm)
    assert windows(vlm) == [
        ("rover.step", [0]),  # c: task + first observation
        ("rover.step", [0, 1]),  # child A: its first frame + current, no previous yet
        ("rover.step", [0, 1, 2]),
        ("rover.step", [0, 2, 3]),
        ("rover.step", [0, 3, 4]),  # A reaches 100%
        ("rover.parent", [4]),  # parent turn: ψ shows A's final frame
        ("rover.step", [4, 5]),  # child B starts at A's final frame (φ)
        ("rover.step", [4, 5, 6]),
        ("rover.step", [4, 6, 7]),
        ("rover.step", [4, 7, 8]),
        ("rover.step", [4, 8, 9]),
        ("rover.step", [4, 9, 10]),
        ("rover.step", [4, 10, 11]),
    ]
    assert vlm.bound_to == [ep.id]
    assert [c.frame_indices for c in trace.calls] == [w for _, w in windows(vlm)]
    # labels and order inside the prompt: first frame, most recent previous, current
    p = vlm.prompts[3]
    labels = [x.text.split("\n")[0] for x in p.messages[1].parts() if isinstance(x, TextPart)]
    assert labels[0] == "Initial robot scene:"
    assert "Most recent previous frame:" in labels and labels[-1] == "Current frame:"
    assert [x.frame_index for x in p.images()] == [0, 2, 3]
    texts = " ".join(x.text for x in p.messages[1].parts() if isinstance(x, TextPart))
    assert "Frame description: f2" in texts and "Subtask completion percentage: 50%" in texts


async def test_window_k6_keeps_four_previous_frames(make_episode, scripted):
    ep = make_episode(12)
    vlm = scripted(two_subtask_script())
    await get_method("rover", window=6).run(ep, vlm)
    got = [w for k, w in windows(vlm) if k == "rover.step"]
    assert got == [
        [0],
        [0, 1],
        [0, 1, 2],
        [0, 1, 2, 3],
        [0, 1, 2, 3, 4],
        [4, 5],
        [4, 5, 6],
        [4, 5, 6, 7],
        [4, 5, 6, 7, 8],
        [4, 5, 6, 7, 8, 9],
        [4, 6, 7, 8, 9, 10],  # first + the 4 most recent previous + current
        [4, 7, 8, 9, 10, 11],
    ]


async def test_no_window_and_no_recursion_ablations(make_episode, scripted):
    ep = make_episode(12)
    vlm = scripted(two_subtask_script())
    await get_method("rover-no-window").run(ep, vlm)
    steps = [w for k, w in windows(vlm) if k == "rover.step"]
    assert steps[-1] == [4, 5, 6, 7, 8, 9, 10, 11]

    def flat(p: Prompt) -> str:
        assert p.meta.extra["allow_decompose"] is False
        assert "The robot needs to" not in p.messages[0].content
        return f"Frame description: x\nSubtask completion percentage: {5 * p.meta.positions[-1]}%"

    vlm2 = scripted(flat)
    trace = await get_method("rover-no-recursion").run(ep, vlm2)
    assert [p.meta.frame_indices for p in vlm2.prompts][:4] == [[0], [0, 1], [0, 1, 2], [0, 2, 3]]
    assert trace.tree is not None and trace.tree.children == []
    assert trace.progress() == pytest.approx([5.0 * t for t in range(12)])


def nested_script(p: Prompt) -> str:
    m = p.meta
    path, done = m.subtask_path, m.extra.get("completed", [])
    if m.kind == "rover.parent":
        nxt = {("A",): {("A1",): "A2"}, (): {("A",): "B"}}.get(tuple(path), {}).get(tuple(done))
        return f"The robot needs to: {nxt}" if nxt else "Task complete"
    pos, first = m.positions[-1], m.extra["first_position"]
    if path == []:
        return "Frame description: scene\nThe robot needs to: A"
    if path == ["A"]:
        return f"Frame description: d{pos}\nThe robot needs to: A1"
    rate = {"A1": 50, "A2": 100, "B": 50}[path[-1]]
    return f"Frame description: d{pos}\nSubtask completion percentage: {rate * (pos - first)}%"


async def test_recursion_depth_two_and_return(make_episode, scripted):
    ep = make_episode(8)
    vlm = scripted(nested_script)
    trace = await get_method("rover").run(ep, vlm)
    assert windows(vlm) == [
        ("rover.step", [0]),
        ("rover.step", [0, 1]),  # A decomposes at frame 1
        ("rover.step", [1, 2]),  # A1 starts at A's last frame (φ)
        ("rover.step", [1, 2, 3]),  # A1 done
        ("rover.parent", [3]),  # A: "The robot has completed: A1" + its final frame -> A2
        ("rover.step", [3, 4]),  # A2 starts at A1's final frame (ψ)
        ("rover.parent", [4]),  # A: -> Task complete
        ("rover.parent", [4]),  # root: -> B
        ("rover.step", [4, 5]),
        ("rover.step", [4, 5, 6]),
        ("rover.parent", [6]),  # root: Task complete
    ]
    parts = vlm.prompts[4].messages[1].content
    parent_text = " ".join(p.text for p in parts if isinstance(p, TextPart))
    assert "The robot has completed: A1" in parent_text and "d3" in parent_text
    # ψ returns the child's final frame: its image sits before its final description
    assert [p.frame_index for p in parts if isinstance(p, ImagePart)] == [3]
    root = trace.tree
    assert [c.subtask for c in root.children] == ["A", "B"]
    a = root.children[0]
    assert [c.subtask for c in a.children] == ["A1", "A2"] and a.children[0].depth == 2
    assert (a.first_frame, a.last_frame, a.outcome) == (0, 4, "complete")
    assert root.outcome == "complete" and root.last_position == 6
    # A1: 0..25, A2: 25..50, B: 50..100 of the full task; frame 7 filled forward
    assert trace.progress() == pytest.approx([0, 0, 12.5, 25, 50, 75, 100, 100])
    predicted = [f.predicted for f in trace.frames]
    assert predicted == [False, False, True, True, True, True, True, False]
    assert trace.frames[3].subtask_path == ["A", "A1"] and trace.frames[3].subtask_progress == 100
    assert trace.frames[5].description == "d5"


async def test_max_depth_guard_reasks_then_records_failure(make_episode, scripted):
    ep = make_episode(8)
    vlm = scripted(nested_script)
    trace = await get_method("rover", max_depth=1).run(ep, vlm)
    # A may not decompose: its reply is unusable, re-asked once with a reminder, then failed
    a_calls = [c for c in trace.calls if c.subtask_path == ["A"]]
    assert [c.parse for c in a_calls[:2]] == ["retried", "failed"]
    assert vlm.prompts[2].meta.extra.get("reminder") is True
    assert vlm.prompts[2].messages[-2].role == "assistant"
    assert trace.totals.parse_failures >= 1 and trace.totals.parse_retries >= 1
    assert max(_depths(trace.tree)) == 1
    assert trace.frames[1].predicted is False


def _depths(node):
    yield node.depth
    for c in node.children:
        yield from _depths(c)


async def test_max_subtasks_guard(make_episode, scripted):
    def endless(p: Prompt) -> str:
        m = p.meta
        if m.kind == "rover.parent":
            return f"The robot needs to: S{len(m.extra['completed'])}"
        if m.subtask_path == []:
            return "Frame description: x\nThe robot needs to: S0"
        return "Frame description: x\nSubtask completion percentage: 100%"

    trace = await get_method("rover", max_subtasks=3).run(make_episode(12), scripted(endless))
    assert len(trace.tree.children) == 3 and trace.tree.outcome == "guard"


async def test_parse_failure_carries_last_value(make_episode, scripted):
    def flaky(p: Prompt) -> str:
        pos = p.meta.positions[-1]
        if pos == 2:
            return "I am not sure what to say."
        return f"Frame description: f{pos}\nSubtask completion percentage: {10 * pos}%"

    vlm = scripted(flaky)
    trace = await get_method("rover-no-recursion").run(make_episode(5), vlm)
    assert [c.parse for c in trace.calls] == ["ok", "ok", "retried", "failed", "ok", "ok"]
    assert trace.progress() == pytest.approx([0, 10, 10, 30, 40])
    assert trace.frames[2].predicted is False
    # the failed frame never becomes the "most recent previous frame"
    assert vlm.prompts[-2].meta.frame_indices == [0, 1, 3]


async def test_on_change_prev_frame_policy(make_episode, scripted):
    values = {1: 10, 2: 10, 3: 10, 4: 30, 5: 30}

    def stalls(p: Prompt) -> str:
        pos = p.meta.positions[-1]
        return f"Frame description: f{pos}\nSubtask completion percentage: {values.get(pos, 0)}%"

    vlm = scripted(stalls)
    await get_method("rover-no-recursion", prev_frame_policy="on_change").run(make_episode(6), vlm)
    assert [p.meta.frame_indices for p in vlm.prompts] == [
        [0],
        [0, 1],
        [0, 1, 2],
        [0, 1, 3],  # frames 2 and 3 repeated 10%: the previous frame stays at 1
        [0, 1, 4],
        [0, 4, 5],  # moved when progress changed to 30
    ]
    vlm2 = scripted(stalls)
    await get_method("rover-no-recursion").run(make_episode(6), vlm2)
    assert vlm2.prompts[3].meta.frame_indices == [0, 2, 3]


async def test_threshold_ends_a_line_early(make_episode, scripted):
    vlm = scripted(two_subtask_script())
    trace = await get_method("rover", threshold=50).run(make_episode(12), vlm)
    assert trace.tree.children[0].last_position == 2  # 50% reached at frame 2


def test_bad_params_are_input_errors():
    with pytest.raises(InputError, match="window"):
        get_method("rover", window=1)
    with pytest.raises(InputError, match="prev_frame_policy"):
        get_method("rover", prev_frame_policy="sometimes")
    with pytest.raises(InputError, match="valid methods: rover"):
        get_method("rovr")


async def test_images_are_encoded_once(make_episode, scripted):
    vlm = scripted(two_subtask_script())
    await get_method("rover").run(make_episode(12), vlm)
    by_frame: dict[int, set[int]] = {}
    for p in vlm.prompts:
        for part in p.images():
            assert isinstance(part, ImagePart)
            by_frame.setdefault(part.frame_index, set()).add(id(part.image))
    assert all(len(ids) == 1 for ids in by_frame.values())


def chatty_script(p: Prompt) -> str:
    """A model that plans two subtasks and writes "needs to" prose in every description."""
    m = p.meta
    if m.kind == "rover.parent":
        if m.extra["completed"] == ["grasp the can"]:
            return "Sure.\n\n**The robot needs to:** place the can in the bin"
        return "**Task complete.**"
    if m.subtask_path == []:
        return (
            "### Frame description\nThe arm is above the can; the robot needs to grasp it.\n\n"
            "### New subtasks\n1. grasp the can\n2. place the can in the bin\n\n"
            "The robot needs to: grasp the can"
        )
    pos, first = m.positions[-1], m.extra["first_position"]
    value = min(100, 50 * (pos - first))
    return (
        f"Frame description: The gripper moves, so the robot needs to keep going. "
        f"To finish, the robot needs to close it. Subtask completion percentage: {value}% "
        "[next-frame]"
    )


async def test_prose_needs_to_never_nests_and_the_plan_is_followed(make_episode, scripted):
    trace = await get_method("rover").run(make_episode(7), scripted(chatty_script))
    root = trace.tree
    assert root.planned_subtasks == ["grasp the can", "place the can in the bin"]
    assert [c.subtask for c in root.children] == ["grasp the can", "place the can in the bin"]
    assert all(c.children == [] for c in root.children)  # no line four deep
    assert trace.progress()[-1] == pytest.approx(100)
    assert trace.frames[1].description.startswith("The gripper moves, so the robot needs to")


async def test_implausible_first_reply_is_reasked_not_a_finished_line(make_episode, scripted):
    """A first-frame "250%" (seen from real models) must not end ROVER after one call."""

    def wild_start(p: Prompt) -> str:
        pos = p.meta.positions[-1]
        value = 250 if pos == 1 else 20 * pos
        return f"Frame description: f{pos}\nSubtask completion percentage: {value}%"

    vlm = scripted(wild_start)
    trace = await get_method("rover-no-recursion").run(make_episode(5), vlm)
    # frame 1 asked twice (reminder), then carried; the line runs to the end of the video
    assert [c.parse for c in trace.calls] == ["ok", "retried", "failed", "ok", "ok", "ok"]
    assert trace.tree.outcome == "end_of_video"
    assert trace.progress()[-1] == pytest.approx(80)
    assert trace.frames[1].predicted is False
