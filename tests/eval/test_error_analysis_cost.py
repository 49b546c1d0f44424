"""App. D error categories derived per video, and App. G cost tables."""

from __future__ import annotations

from rover.eval.cost import cost_row, cost_table
from rover.eval.error_analysis import error_table, video_errors
from rover.eval.judge import FrameVerdictRecord, Judgements
from rover.methods.trace import CallRecord, FrameRecord, LineNode, Trace


def _trace(progress: list[float], tree: LineNode | None = None) -> Trace:
    n = len(progress)
    return Trace(
        method="rover",
        backend="b",
        model="m",
        episode_id="ep0",
        task="t",
        num_frames=n,
        frame_indices=list(range(n)),
        tree=tree,
        frames=[
            FrameRecord(index=i, position=i, progress=p, predicted=True)
            for i, p in enumerate(progress)
        ],
    )


def _judged(n: int, false_at: set[int] = frozenset()) -> Judgements:
    return Judgements(
        episode_id="ep0",
        variant="v",
        judge="rule",
        verdicts=[
            FrameVerdictRecord(index=i, position=i, verdict="false" if i in false_at else "true")
            for i in range(n)
        ],
    )


def _with_truth(ep, progress: list[float]):
    return ep.model_copy(update={"truth": ep.truth.model_copy(update={"progress": progress})})


def test_perception_and_reasoning_errors(make_episode) -> None:
    ep = make_episode(n=6)
    good = [0.0, 20.0, 40.0, 60.0, 80.0, 100.0]
    assert video_errors(_trace(good), ep, _judged(6)) == {
        "incorrect_subtask": None,
        "redundant_subtask": None,
        "perception": 0,
        "reasoning": 0,
    }
    assert video_errors(_trace(good), ep, _judged(6, {3}))["perception"] == 1
    # the robot drops the can at frame 3 (truth falls), the method says progress went up
    ep2 = _with_truth(ep, [0.0, 0.2, 0.4, 0.1, 0.3, 0.5])
    bad = [0.0, 20.0, 40.0, 55.0, 70.0, 80.0]
    assert video_errors(_trace(bad), ep2, _judged(6))["reasoning"] == 1
    # ... unless its description was already wrong there: that is a perception error
    flags = video_errors(_trace(bad), ep2, _judged(6, {3}))
    assert flags["reasoning"] == 0 and flags["perception"] == 1


def _tree(*children: LineNode) -> LineNode:
    return LineNode(
        id=0,
        subtask="pick the can and place it in the bin",
        depth=0,
        first_frame=0,
        last_frame=9,
        children=list(children),
    )


def test_subtask_errors_from_the_reasoning_tree(make_episode) -> None:
    ep = make_episode(n=10)  # GT: "grasp the can" 0-4, "place the can in the bin" 5-9
    prog = [10.0 * i for i in range(10)]
    ok = _tree(
        LineNode(id=1, subtask="grasp the can", depth=1, first_frame=0, last_frame=4),
        LineNode(id=2, subtask="place the can in the bin", depth=1, first_frame=5, last_frame=9),
    )
    f = video_errors(_trace(prog, ok), ep, _judged(10))
    assert (f["incorrect_subtask"], f["redundant_subtask"]) == (0, 0)
    wrong = _tree(
        LineNode(id=1, subtask="open the cabinet door", depth=1, first_frame=0, last_frame=4)
    )
    assert video_errors(_trace(prog, wrong), ep, _judged(10))["incorrect_subtask"] == 1
    # App. D: "place" decomposed again into "grasp the can" after the grasp was done
    again = _tree(
        LineNode(id=1, subtask="grasp the can", depth=1, first_frame=0, last_frame=4),
        LineNode(
            id=2,
            subtask="place the can in the bin",
            depth=1,
            first_frame=5,
            last_frame=9,
            children=[
                LineNode(id=3, subtask="grasp the can", depth=2, first_frame=6, last_frame=7)
            ],
        ),
    )
    assert video_errors(_trace(prog, again), ep, _judged(10))["redundant_subtask"] == 1


def test_error_table_shares_of_videos() -> None:
    rows = [
        {
            "variant": "v",
            "method": "gvl",
            "err_perception": p,
            "err_reasoning": 0,
            "err_incorrect_subtask": None,
            "err_redundant_subtask": None,
        }
        for p in (1, 0, 0, 1)
    ]
    table = {r["error_type"]: r for r in error_table(rows)}
    assert table["perception"]["mean"] == 50.0 and table["total"]["mean"] == 50.0  # % of videos
    assert table["incorrect_subtask"]["mean"] is None  # NA, as in the paper for GVL


def test_cost_rows_and_table() -> None:
    tr = _trace([0.0, 50.0, 100.0])
    tr.calls = [
        CallRecord(id=i, kind="k", prompt_tokens=100 * (i + 1), completion_tokens=10)
        for i in range(3)
    ]
    row = cost_row(tr)  # totals were never filled in: recomputed from the calls
    assert row["calls"] == 3 and row["total_tokens"] == 600 + 30
    rows = [
        {"variant": "v", "method": "rover", "n_frames": 30, "total_tokens": t, "calls": c}
        for t, c in ((1000, 30), (3000, 34))
    ]
    t = {r["metric"]: r for r in cost_table(rows)}
    assert t["total_tokens"]["mean"] == 2000 and t["calls"]["mean"] == 32
    assert t["total_tokens"]["se"] == 1000.0  # sd 1414.2 / sqrt(2)
