"""Writes corpus.jsonl: model replies in the styles real VLMs use, labelled with the parse
they are meant to give.

    python tests/methods/replies/make_corpus.py

The styles were written from how GPT-4o (bold labels, bullets, chatter), Gemini 2.5
(headings with the value below, bold percentages, tables) and Qwen2.5-VL (one-liners,
lowercase, JSON, missing colons) answer the App. D prompts. Each reply is built from
its content (description, percentage, subtask, plan), and the label is that content,
never the parser's output. Hand-written edge cases are appended at the end.
"""

from __future__ import annotations

import json
from pathlib import Path

OUT = Path(__file__).with_name("corpus.jsonl")

DESCRIPTIONS = [
    "The gripper is open above the can.",
    "The gripper holds the can; the robot needs to lift it next.",
    "The drawer is 40% open.",
    "To finish, the robot needs to close the gripper around the handle.",
    "The robot's gripper is closed and the can is lifted off the table.",
    "The robot is making progress toward the bin.",
]
PROGRESS = [0, 45, 12.5, -10, 100, 120]
SUBTASKS = [
    ("grasp the can", "place the can in bin 2"),
    ("grasp the robot's handle", "pull the door open"),
    ("reach the drawer handle", "pull the drawer open"),
    ("grasp the cheese", "place the cheese in the cabinet"),
    ("move to the knob", "turn the knob"),
    ("grasp the bread", "place the bread in bin 3"),
]


def pct(p: float) -> str:
    return f"{p:g}"


def pylist(items) -> str:
    return "[" + ", ".join("'" + s + "'" for s in items) + "]"


PROGRESS_STYLES = {
    "exact": "Frame description: {D}\nSubtask completion percentage: {P}%\n[next-frame]",
    "gpt-bold": "**Frame description:** {D}\n**Subtask completion percentage:** {P}%\n[next-frame]",
    "gpt-bullets": "- **Frame description:** {D}\n- **Subtask completion percentage:** {P}%\n\n"
    "[next-frame]",
    "gemini-heading": "### Frame description\n{D}\n\n### Subtask completion percentage\n{P}%\n\n"
    "[next-frame]",
    "gemini-heading-gap": "## Frame Description\n\n{D}\n\n## Subtask Completion Percentage\n\n"
    "**{P}%**\n\n[next-frame]",
    "italic": "*Frame description:* {D}\n*Subtask completion percentage:* {P}%\n[next-frame]",
    "no-colon": "Frame description {D}\nSubtask completion percentage {P}%\n[next-frame]",
    "one-line": "Frame description: {D} Subtask completion percentage: {P}% [next-frame]",
    "lowercase": "frame description: {D}\nsubtask completion percentage: {P}%\n[next-frame]",
    "uppercase": "FRAME DESCRIPTION: {D}\nSUBTASK COMPLETION PERCENTAGE: {P}%\n[NEXT-FRAME]",
    "qwen-chatter": "Sure! Here is my analysis:\n\nFrame description: {D}\n"
    "Subtask completion percentage: {P}%\n[next-frame]",
    "json": "```json\n{J}\n```\n[next-frame]",
    "space-percent": "Frame description: {D}\nSubtask completion percentage: {P} %\n[next-frame]",
    "approximately": "Frame description: {D}\nSubtask completion percentage: approximately {P}%\n"
    "[next-frame]",
    "dash-sep": "Frame description - {D}\nSubtask completion percentage - {P}%\n[next_frame]",
    "numbered": "1. Frame description: {D}\n2. Subtask completion percentage: {P}%\n"
    "3. [next-frame]",
    "bold-heading": "**Frame description**\n{D}\n\n**Subtask completion percentage**\n{P}%\n\n"
    "[next-frame]",
    "blockquote": "> Frame description: {D}\n> Subtask completion percentage: {P}%\n> [next-frame]",
    "progress-and-needs": "Frame description: {D}\nSubtask completion percentage: {P}%\n"
    "The robot needs to: {S}\n[next-frame]",
    "task-label": "Frame description: {D}\nTask completion percentage: {P}%\n[next-frame]",
    "trailing-note": "Frame description: {D}\nSubtask completion percentage: {P}%\n[next-frame]\n\n"
    "Note: the estimate reflects the arm's motion since the previous frame.",
    "progress-label": "Frame description: {D}\nProgress: {P}%\n[next-frame]",
    "bold-value-line": "**Frame description:**\n{D}\n\n**Subtask completion percentage:**\n{P}%\n"
    "[next-frame]",
}

DECOMPOSE_STYLES = {
    "exact": ("Frame description: {D}\nThe robot needs to: {S}", False),
    "plan-first": ("Frame description: {D}\nNew subtasks: {L}\nThe robot needs to: {S}", True),
    "bold-plan": (
        "**Frame description:** {D}\n**New subtasks:** {JL}\n**The robot needs to:** {S}",
        True,
    ),
    "bullet-plan": (
        "Frame description: {D}\nNew subtasks:\n- {S}\n- {S2}\nThe robot needs to: {S}",
        True,
    ),
    "numbered-plan": (
        "Frame description: {D}\n\nNew Subtasks:\n1. {S}\n2. {S2}\n\nThe robot needs to: {S}",
        True,
    ),
    "quoted-sentence": (
        "Frame description: {D}\nThe robot needs to: '{S}'. This is the first step of the task.",
        False,
    ),
    "heading": ("### Frame description\n{D}\n\n### The robot needs to:\n{S}", False),
    "one-line": ("Frame description: {D} The robot needs to: {S}", False),
    "json": ("{JD}", True),
    "list-in-needs": ("Frame description: {D}\nThe robot needs to: {L}", True),
    "multiline-bracket": (
        "Frame description: {D}\nNew subtasks: [\n  '{S}',\n  '{S2}'\n]\nThe robot needs to: {S}",
        True,
    ),
    "lowercase-period": ("frame description: {D}\nthe robot needs to: {S}.", False),
    "heading-plan": (
        "### Frame description\n{D}\n\n### New subtasks\n1. {S}\n2. {S2}\n\n"
        "The robot needs to: {S}",
        True,
    ),
    "bold-heading-plan": (
        "**Frame description:** {D}\n**New subtasks**\n- {S}\n- {S2}\n**The robot needs to:** {S}",
        True,
    ),
    "bold-label": ("**Frame description:** {D}\n\n**The robot needs to:** {S}.", False),
}

FRAME_STYLES = {
    "exact": "Frame {k}:\nFrame description: {D}\nTask completion percentage: {P}%",
    "bold-header": "**Frame {k}:**\nFrame description: {D}\nTask completion percentage: {P}%",
    "heading": "### Frame {k}\n- **Frame description:** {D}\n"
    "- **Task completion percentage:** {P}%",
    "inline": "Frame {k}: {D} {P}%",
    "inline-paren": "Frame {k} - {D} ({P}%)",
    "one-line-labels": "Frame {k}: Frame description: {D} Task completion percentage: {P}%",
    "bold-percent": "Frame {k}:\nFrame description: {D}\nTask completion percentage: **{P}%**",
}


def step_case(style: str, reply: str, **expect) -> dict:
    full = {"description": None, "progress": None, "new_subtask": None, "plan": None}
    full.update(complete=False)
    full.update(expect)
    return {"kind": "step", "style": style, "reply": reply, "expect": full}


def progress_cases() -> list[dict]:
    out = []
    for style, tpl in PROGRESS_STYLES.items():
        for i, (d, p) in enumerate(zip(DESCRIPTIONS, PROGRESS, strict=True)):
            s = SUBTASKS[i][0]
            j = json.dumps({"frame_description": d, "subtask_completion_percentage": p})
            reply = tpl.format(D=d, P=pct(p), S=s, J=j)
            out.append(step_case(f"progress/{style}", reply, description=d, progress=p))
    # a description spread over two lines joins with a space
    for d in DESCRIPTIONS[:4]:
        head, _, tail = d.partition(" the ")
        if not tail:
            continue
        reply = f"Frame description: {head}\nthe {tail}\nSubtask completion percentage: 30%"
        out.append(
            step_case("progress/two-line", reply, description=f"{head} the {tail}", progress=30)
        )
    return out


def decompose_cases() -> list[dict]:
    out = []
    for style, (tpl, has_plan) in DECOMPOSE_STYLES.items():
        for d, (s, s2) in zip(DESCRIPTIONS, SUBTASKS, strict=True):
            jd = json.dumps(
                {"frame_description": d, "new_subtasks": [s, s2], "the_robot_needs_to": s}
            )
            reply = tpl.format(D=d, S=s, S2=s2, L=pylist([s, s2]), JL=json.dumps([s, s2]), JD=jd)
            plan = [s, s2] if has_plan else None
            out.append(
                step_case(f"decompose/{style}", reply, description=d, new_subtask=s, plan=plan)
            )
    return out


def complete_cases() -> list[dict]:
    out = []
    for d in DESCRIPTIONS:
        out.append(
            step_case(
                "complete/line",
                f"Frame description: {d}\nTask complete",
                description=d,
                complete=True,
            )
        )
        out.append(
            step_case(
                "complete/appended",
                f"Frame description: {d} Task complete.",
                description=d,
                complete=True,
            )
        )
    for reply in [
        "Task complete",
        "**Task complete.**",
        "The task is complete.",
        "The subtask is now complete.",
        "TASK COMPLETE",
        "Task completed.",
    ]:
        out.append(step_case("parent/complete", reply, complete=True))
    for s, _ in SUBTASKS:
        for tpl in [
            "The robot needs to: {S}",
            "**The robot needs to:** {S}",
            "Next subtask: {S}",
            'The robot needs to: "{S}".',
        ]:
            out.append(step_case("parent/next", tpl.format(S=s), new_subtask=s))
    return out


def trap_cases() -> list[dict]:
    """Prose that must not start a subtask or be read as progress."""
    return [
        step_case(
            "trap/needs-prose",
            "The robot needs to lift the can next.",
            description="The robot needs to lift the can next.",
        ),
        step_case(
            "trap/needs-prose",
            "Frame description: The gripper is open.\n"
            "To finish, the robot needs to close the gripper",
            description="The gripper is open. To finish, the robot needs to close the gripper",
        ),
        step_case(
            "trap/percent-in-description",
            "Frame description: The drawer is 40% open.",
            description="The drawer is 40% open.",
        ),
        step_case(
            "trap/progress-word",
            "Frame description: The robot makes progress: it reaches.",
            description="The robot makes progress: it reaches.",
        ),
        step_case("trap/empty", ""),
        step_case("trap/refusal", "I cannot see the image.", description="I cannot see the image."),
        step_case(
            "trap/needs-midline-colon",
            "Frame description: The gripper is open, so "
            "the robot needs to: grasp. Subtask completion percentage: 10%",
            description="The gripper is open, so the robot needs to: grasp.",
            progress=10,
        ),
        step_case("compact/percent", "45% [next-frame]", progress=45),
        step_case("compact/prose", "I'd say roughly 30% done. [next-frame]", progress=30),
        step_case("compact/negative", "Subtask completion percentage: −7 %", progress=-7),
        step_case("compact/decimal-comma", "Subtask completion percentage: 37,5%", progress=37.5),
        step_case(
            "json/fraction", '{"description": "x", "progress": 0.5}', description="x", progress=0.5
        ),
        step_case(
            "json/string-pct",
            '{"frame_description": "x", "subtask_completion_percentage": "64%"}',
            description="x",
            progress=64,
        ),
    ]


def frame_cases() -> list[dict]:
    out = []
    n = len(DESCRIPTIONS)
    order = [3, 1, 4, 2, 6, 5]
    for style, tpl in FRAME_STYLES.items():
        blocks, expect = [], {}
        for k in order:
            d, p = DESCRIPTIONS[k - 1], PROGRESS[k - 1]
            blocks.append(tpl.format(k=k, D=d, P=pct(p)))
            expect[str(k)] = {"description": d, "progress": p}
        if style.startswith("inline"):
            # inline answers keep the description without the percentage
            for k in order:
                d = DESCRIPTIONS[k - 1]
                expect[str(k)]["description"] = d
        out.append(
            {
                "kind": "frames",
                "style": f"frames/{style}",
                "reply": "\n\n".join(blocks),
                "expect": expect,
            }
        )
        # the same frames again, one reply per frame: "Frame k" plus one block
        for k in order[:n]:
            d, p = DESCRIPTIONS[k - 1], PROGRESS[k - 1]
            out.append(
                {
                    "kind": "frames",
                    "style": f"frames/{style}/single",
                    "reply": tpl.format(k=k, D=d, P=pct(p)),
                    "expect": {str(k): {"description": d, "progress": p}},
                }
            )
    rows = ["| Frame | Description | Task completion percentage |", "|---|---|---|"]
    rows += [f"| {k} | {DESCRIPTIONS[k - 1]} | {pct(PROGRESS[k - 1])}% |" for k in order]
    out.append(
        {
            "kind": "frames",
            "style": "frames/table",
            "reply": "\n".join(rows),
            "expect": {
                str(k): {"description": DESCRIPTIONS[k - 1], "progress": PROGRESS[k - 1]}
                for k in order
            },
        }
    )
    items = [
        {
            "frame": k,
            "frame_description": DESCRIPTIONS[k - 1],
            "task_completion_percentage": PROGRESS[k - 1],
        }
        for k in order
    ]
    out.append(
        {
            "kind": "frames",
            "style": "frames/json",
            "reply": json.dumps(items, indent=1),
            "expect": {
                str(k): {"description": DESCRIPTIONS[k - 1], "progress": PROGRESS[k - 1]}
                for k in order
            },
        }
    )
    return out


def main() -> None:
    cases = progress_cases() + decompose_cases() + complete_cases() + trap_cases()
    cases += frame_cases()
    with OUT.open("w", encoding="utf-8") as f:
        for i, c in enumerate(cases):
            f.write(json.dumps({"id": i, **c}, ensure_ascii=False) + "\n")
    print(f"wrote {len(cases)} replies to {OUT}")


if __name__ == "__main__":
    main()
