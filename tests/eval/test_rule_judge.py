"""The rule judge: claims read from descriptions, checked against simulator facts."""

from __future__ import annotations

import numpy as np
import pytest

from rover.episode import FrameFacts, ObjectFacts
from rover.eval.claims import extract_claims, names_match
from rover.eval.rule_judge import judge_description

OBJECTS = ["can", "milk carton", "cereal box"]


def random_facts(rng: np.random.Generator) -> FrameFacts:
    obj = OBJECTS[int(rng.integers(len(OBJECTS)))]
    holding = obj if rng.random() < 0.4 else None
    state = "held" if holding else rng.choice(["table", "bin"])
    return FrameFacts(
        gripper="closed" if holding or rng.random() < 0.2 else "open",
        contacts=[obj] if holding or rng.random() < 0.2 else [],
        holding=holding,
        objects={
            obj: ObjectFacts(
                lifted=state == "held",
                on="table" if state == "table" else None,
                inside=f"bin {int(rng.integers(1, 3))}" if state == "bin" else None,
            )
        },
        articulations={"door": float(rng.choice([0.0, 0.25, 0.5, 1.0]))},
        pressed=["button"] if rng.random() < 0.5 else [],
    )


def claims_for(f: FrameFacts, rng: np.random.Generator) -> list[tuple[str, str]]:
    """(true sentence, false sentence) per claim, in several paraphrases."""
    pick = lambda *opts: opts[int(rng.integers(len(opts)))]  # noqa: E731
    obj, o = next(iter(f.objects.items()))
    other = "closed" if f.gripper == "open" else "open"
    out = [
        (
            pick(
                f"The gripper is {f.gripper}.",
                f"The robot's gripper is {f.gripper}.",
                f"An {f.gripper} gripper is visible.",
            ),
            pick(f"The gripper is {other}.", f"The gripper is still {other}."),
        )
    ]
    if f.holding:
        out.append(
            (
                pick(
                    f"The robot is holding the {obj}.",
                    f"The robot is grasping the {obj}.",
                    f"The {obj} is in the gripper.",
                ),
                pick("The robot is not holding anything.", "The gripper is empty."),
            )
        )
    else:
        out.append(
            (
                pick(
                    "The robot is not holding anything.",
                    "The gripper is empty.",
                    "The robot is holding nothing.",
                ),
                f"The robot is holding the {obj}.",
            )
        )
    touch = f"The gripper is touching the {obj}."
    no_touch = pick(
        f"The gripper is not touching the {obj}.", f"The gripper is not in contact with the {obj}."
    )
    out.append((touch, no_touch) if f.contacts else (no_touch, touch))
    if o.lifted:
        out.append(
            (
                pick(f"The {obj} is lifted.", f"The {obj} is in the air."),
                f"The {obj} is not lifted.",
            )
        )
    elif o.inside:
        wrong = "bin 1" if o.inside == "bin 2" else "bin 2"
        out.append(
            (
                pick(f"The {obj} is in {o.inside}.", f"The {obj} is inside {o.inside}."),
                f"The {obj} is in {wrong}.",
            )
        )
    else:
        out.append((f"The {obj} is on the table.", f"The {obj} is not on the table."))
    door = f.articulations["door"]
    wrong_door = 1.0 - door if abs(1.0 - 2 * door) > 0.4 else door + 0.5
    out.append(
        (f"The door is {round(100 * door)}% open.", f"The door is {round(100 * wrong_door)}% open.")
    )
    pressed = bool(f.pressed)
    p_true = "The button is pressed." if pressed else "The button is not pressed."
    p_false = "The button is not pressed." if pressed else "The button is pressed."
    out.append((p_true, p_false))
    return out


def test_injected_error_rate_is_measured_exactly() -> None:
    rng = np.random.default_rng(7)
    n_frames, flip_p = 500, 0.2
    injected = measured_false = measured_true = total_claims = frames_with_error = 0
    judged_error_frames = 0
    for _ in range(n_frames):
        facts = random_facts(rng)
        sentences, flips = [], 0
        for true_s, false_s in claims_for(facts, rng):
            flip = rng.random() < flip_p
            flips += flip
            sentences.append(false_s if flip else true_s)
        total_claims += len(sentences)
        injected += flips
        frames_with_error += flips > 0
        j = judge_description(" ".join(sentences), facts)
        measured_false += len(j.false_claims)
        measured_true += len(j.true_claims)
        judged_error_frames += j.verdict == "false"
        assert len(j.false_claims) == flips, (sentences, j)
    # exact counting: every injected error found, every other claim confirmed
    assert measured_false == injected
    assert measured_true == total_claims - injected
    assert judged_error_frames == frames_with_error
    # and the claim-level rate is the injected 20% within binomial noise
    assert abs(measured_false / total_claims - flip_p) < 0.03
    # frame error rate = P(at least one of ~6 claims flipped) = 1 - 0.8^6 ~ 0.74
    assert abs(judged_error_frames / n_frames - (1 - 0.8**6)) < 0.06


def test_oracle_vocabulary_with_its_own_noise() -> None:
    oracle = pytest.importorskip("rover.vlm.oracle")
    rng = np.random.default_rng(3)
    flipped_total = false_total = 0
    for i in range(200):
        facts = random_facts(rng)
        clean = oracle.describe(facts, 0.0)
        noisy = oracle.describe(facts, 0.3, np.random.default_rng(i))
        j_clean = judge_description(clean, facts)
        assert j_clean.verdict == "true" and not j_clean.false_claims, (clean, j_clean)
        # sentences that differ from the clean description are the flipped claims
        a = [s for s in clean.split(". ")]
        b = [s for s in noisy.split(". ")]
        flipped = sum(x != y for x, y in zip(a, b, strict=False)) if len(a) == len(b) else None
        j = judge_description(noisy, facts)
        if flipped is not None:
            assert len(j.false_claims) == flipped, (noisy, j)
            flipped_total += flipped
            false_total += len(j.false_claims)
    assert flipped_total > 20 and false_total == flipped_total


@pytest.mark.parametrize(
    ("text", "verdict"),
    [
        ("The gripper is open.", "true"),
        ("The gripper is closed.", "false"),
        ("The arm moves toward the can.", "inconclusive"),
        ("", "inconclusive"),
        ("The robot is holding the can. The gripper is open.", "false"),
        ("The can sits on the table and the gripper is open.", "true"),
        ("The door is 45% open.", "true"),
        ("The door is fully open.", "false"),
        ("The door is partially open.", "true"),
        ("The button has not been pressed.", "true"),
        ("The robot pressed the button.", "false"),
        ("The gripper isn't holding anything and is not touching the can.", "true"),
    ],
)
def test_paraphrases(text: str, verdict: str) -> None:
    facts = FrameFacts(
        gripper="open", objects={"can": ObjectFacts(on="table")}, articulations={"door": 0.4}
    )
    assert judge_description(text, facts).verdict == verdict


def test_claim_extraction_and_names() -> None:
    kinds = [c.kind for c in extract_claims("The gripper is closed. The can is in bin 2.")]
    assert kinds == ["gripper", "inside"]
    assert names_match("soda can", "can") and names_match("bin 2", "bin_2")
    assert not names_match("bin 1", "bin 2")
    assert judge_description("The gripper is open.", None).verdict == "inconclusive"


def test_every_oracle_sentence_on_the_bundled_dataset_is_checked() -> None:
    """Real simulator facts: each oracle sentence is read as a claim, each flip is found."""
    oracle = pytest.importorskip("rover.vlm.oracle")
    from rover.io.dataset import load_dataset
    from rover.sim import bundled_dataset_path

    root = bundled_dataset_path()
    if not (root / "dataset.json").exists():
        pytest.skip("bundled dataset not built")
    flips = found = frames = 0
    for ep in load_dataset(root, load_frames=False):
        for i, facts in enumerate(ep.truth.facts):
            clean = oracle.describe(facts, 0.0)
            j = judge_description(clean, facts)
            assert len(j.true_claims) == len(clean.split(". ")) and not j.false_claims, clean
            noisy = oracle.describe(facts, 0.3, np.random.default_rng(i))
            a, b = clean.split(". "), noisy.split(". ")
            if len(a) == len(b):
                flips += sum(x != y for x, y in zip(a, b, strict=True))
                found += len(judge_description(noisy, facts).false_claims)
            frames += 1
    assert frames > 0 and flips > 0 and found == flips


LIFTED_CAN = FrameFacts(
    gripper="closed",
    contacts=["can"],
    holding="can",
    objects={"can": ObjectFacts(lifted=True)},
)
STACKED = FrameFacts(
    gripper="open",
    objects={
        "red cube": ObjectFacts(on="green cube"),
        "green cube": ObjectFacts(on="table"),
    },
)
HALF_DOOR = FrameFacts(
    gripper="closed", holding="door", contacts=["door"], articulations={"door": 0.6}
)


@pytest.mark.parametrize(
    ("text", "facts", "verdict"),
    [
        # aliases, hedges, pronouns, markdown, compound verbs
        (
            "**Frame description:** The soda can is held securely in the gripper.",
            LIFTED_CAN,
            "true",
        ),
        ("The gripper appears to be open.", LIFTED_CAN, "false"),
        ("The robot grips the can and lifts it off the table.", LIFTED_CAN, "true"),
        ("- Gripper: closed\n- Can: lifted", LIFTED_CAN, "true"),
        ("Gripper empty, the can rests on the table.", LIFTED_CAN, "false"),
        ("The robot is about to release the can.", LIFTED_CAN, "inconclusive"),
        ("The arm is moving toward the bin.", LIFTED_CAN, "inconclusive"),
        ("The red block is stacked on top of the green block.", STACKED, "true"),
        ("The green block sits on the red block.", STACKED, "false"),
        ("The robot is holding the red block.", STACKED, "false"),
        ("The door is about halfway open and the robot grips its handle.", HALF_DOOR, "true"),
        ("The door remains shut.", HALF_DOOR, "false"),
        ("The door is fully open.", HALF_DOOR, "false"),
    ],
)
def test_model_style_descriptions(text: str, facts: FrameFacts, verdict: str) -> None:
    assert judge_description(text, facts).verdict == verdict


def test_the_target_bin_is_the_one_the_task_names() -> None:
    facts = FrameFacts(
        objects={"can": ObjectFacts(inside="bin 4"), "milk": ObjectFacts(inside="bin 1")}
    )
    task = "Restock the shelf: put the milk in bin 1 and the can in bin 4."
    assert judge_description("The can is in the target bin.", facts, task).verdict == "true"
    assert judge_description("The milk carton sits in its goal bin.", facts, task).verdict == (
        "true"
    )
    assert judge_description("The can is still in the start bin.", facts, task).verdict == ("false")
    # without the task the target is unknown: nothing decided
    assert judge_description("The can is in the target bin.", facts).verdict == "inconclusive"


def test_names_tell_objects_apart() -> None:
    assert names_match("red block", "red cube") and names_match("milk carton", "milk")
    assert names_match("dial", "knob") and names_match("door handle", "door")
    assert not names_match("green block", "red cube")
    assert not names_match("bin 4", "bin 1")
