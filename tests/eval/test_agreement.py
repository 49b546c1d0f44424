"""The labelled agreement corpus and the judges' measured agreement on it (issue 16)."""

from __future__ import annotations

import asyncio
import json
from collections import Counter
from importlib import resources

import pytest

from rover.eval.agreement import frame_cases, qa_cases, split
from rover.eval.agreement.measure import (
    llm_judge_agreement,
    llm_qa_agreement,
    rule_judge_agreement,
    rule_qa_agreement,
)
from rover.eval.agreement.scripted import scripted_answer
from rover.eval.judge_cards import judge_card, measured
from rover.eval.rule_judge import frame_verdict, judge_description

FAMILIES = {"pick", "pick_and_place", "stacking", "doors", "drawers", "buttons", "knobs"}


def test_corpus_size_styles_families_and_halves() -> None:
    frames, qa = frame_cases(), qa_cases()
    assert len(frames) >= 400 and len(qa) >= 150
    assert {c.family for c in frames} >= FAMILIES | {"composite"}
    styles = Counter(c.style for c in frames)
    assert all(styles[s] >= 100 for s in ("gpt-4o", "gemini-2.5", "qwen2.5-vl"))
    for cases in (frames, qa):
        dev, held = split(cases, "dev"), split(cases, "heldout")
        assert len(dev) + len(held) == len(cases) and min(len(dev), len(held)) > 0.4 * len(cases)
    assert Counter(c.label for c in frames).keys() == {"true", "false", "inconclusive"}
    assert Counter(c.item.answer for c in qa).keys() == {True, False}


def test_every_label_follows_from_its_deciding_statements() -> None:
    """App. C.2's rule: a false statement -> false; else a true one -> true."""
    for c in frame_cases():
        assert c.label == frame_verdict(len(c.true_claims), len(c.false_claims)), c.id
    for c in qa_cases():
        assert (c.item.frame is not None) == c.item.answer, c.id
        if c.item.answer:
            assert 0 <= c.item.frame < len(c.descriptions)


ISSUE_FRAME = ("PickPlaceCan-L7-000", 20)
ISSUE_TABLE = [
    (
        "The can has been successfully placed in the target bin and the gripper has released it.",
        "false",
    ),
    ("In this frame, the Panda arm lifts the cylindrical can off the surface.", "true"),
    ("The can is sitting in its original location and the gripper has not touched it.", "false"),
    ("The gripper is open and positioned above the can, which remains on the table.", "false"),
    ("The robot is moving the can. It is not yet in the bin.", "true"),
]


def test_issue_descriptions_get_the_right_hand_verdicts() -> None:
    case = next(c for c in frame_cases() if (c.episode, c.frame) == ISSUE_FRAME)
    assert case.facts.holding == "can" and case.facts.objects["can"].lifted
    for text, verdict in ISSUE_TABLE:
        j = judge_description(text, case.facts, task=case.task)
        assert j.verdict == verdict, (text, j)
    two = judge_description(ISSUE_TABLE[3][0], case.facts, task=case.task)
    assert len(two.false_claims) == 2


def test_rule_judge_and_answerer_reach_90_percent_on_the_held_out_half() -> None:
    judge = rule_judge_agreement(split(frame_cases(), "heldout"))
    answerer = rule_qa_agreement(split(qa_cases(), "heldout"))
    assert judge.rate >= 0.9, judge.misses
    assert answerer.rate >= 0.9, answerer.misses
    # the descriptions written in fresh words, not from the phrase banks, too
    assert (
        judge.by_group["style:handwritten-fresh"][0]
        >= 0.9 * judge.by_group["style:handwritten-fresh"][1]
    )


def test_measured_json_is_the_current_measurement() -> None:
    """Changing the rules or the corpus without re-running the benchmark fails here."""
    m = measured()
    got = {
        "rule_judge": rule_judge_agreement(split(frame_cases(), "heldout")),
        "rule_answerer": rule_qa_agreement(split(qa_cases(), "heldout")),
    }
    for key, a in got.items():
        entry = m["judges"][key]
        assert (entry["n"], entry["agreement"]) == (a.n, round(a.rate, 4)), key
        assert entry["confusion"] == a.as_json()["confusion"]
    raw = resources.files("rover.eval").joinpath("agreement", "measured.json").read_text()
    assert "misses" not in json.loads(raw)["judges"]["rule_judge"]


def test_llm_paths_through_a_loopback_server(tmp_path) -> None:
    """Prompt -> real OpenAI SDK over HTTP -> reply parsing, on model-formatted replies."""
    from rover.vlm.config import BackendConfig
    from rover.vlm.loader import load_vlm
    from rover.vlm.testing import OpenAICompatServer

    frames = split(frame_cases(), "heldout")[::12]
    qa = split(qa_cases(), "heldout")[::10]
    with OpenAICompatServer() as server:
        server.answer = scripted_answer(frames, qa)
        config = BackendConfig(
            cache_path=tmp_path / "cache.sqlite", retry_base_wait_s=0.001, concurrency=16
        )
        vlm = load_vlm(f"openai:judge-model@{server.base_url}", config)
        judged = asyncio.run(llm_judge_agreement(frames, vlm))
        answered = asyncio.run(llm_qa_agreement(qa, vlm))
        n_requests = len(server.requests)
        # judge calls are cached like method calls: a second pass sends nothing
        again = asyncio.run(llm_judge_agreement(frames, vlm))
        assert len(server.requests) == n_requests
    assert judged.rate == 1.0, judged.misses
    assert answered.rate == 1.0 and answered.frame_agree == answered.frame_n, answered.misses
    assert again.rate == 1.0 and n_requests == len(frames) + len(qa)


def test_judge_cards_name_the_judge_and_its_measured_agreement() -> None:
    m = measured()["judges"]
    rule = judge_card("judge", "rule")
    assert rule is not None and rule.agreement == m["rule_judge"]["agreement"]
    assert "rule judge" in rule.line() and f"{100 * rule.agreement:.1f}%" in rule.line()
    assert rule.fresh_n > 0 and "fresh words" in rule.line()
    assert str(rule) == rule.short() and rule.short() in rule.line()
    answerer = judge_card("answerer", "rule")
    assert answerer is not None and answerer.n == m["rule_answerer"]["n"]
    llm = judge_card("judge", "gemini:gemini-2.5-flash")
    assert llm is not None and llm.agreement is None
    assert "gemini:gemini-2.5-flash" in llm.line() and "not measured" in llm.line()
    assert judge_card("answerer", "none") is None
    with pytest.raises(ValueError):
        judge_card("grader")


def test_a_measured_model_gets_its_own_card(monkeypatch) -> None:
    from rover.eval import judge_cards

    stored = dict(measured())
    stored["models"] = {"openai:judge-x": {"judge": {"agreement": 0.9, "n": 312}}}
    monkeypatch.setattr(judge_cards, "measured", lambda: stored)
    card = judge_cards.judge_card("judge", "openai:judge-x")
    assert card is not None and card.agreement == 0.9 and "90.0% on 312" in card.line()
    other = judge_cards.judge_card("answerer", "openai:judge-x")  # only its judge measured
    assert other is not None and other.agreement is None
