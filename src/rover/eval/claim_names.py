"""Which simulator object a model means: "the soda can", "the red block", "the dial".

Models rarely use the simulator's names. A name from a description is reduced to a head
noun (mapped through `HEAD_ALIASES`: block -> cube, carton -> milk, dial -> knob, ...)
and its modifiers; it refers to a known name when the heads agree and no colour or shape
word contradicts ("green block" is not the "red cube"; "nut" is the only nut there is).
A trailing number must agree ("bin 2" is not "bin 1"). "handle" means the door, drawer or
knob it belongs to.
"""

from __future__ import annotations

import re

HEAD_ALIASES = {
    "block": "cube",
    "cubes": "cube",
    "blocks": "cube",
    "carton": "milk",
    "soda": "can",
    "coke": "can",
    "loaf": "bread",
    "cereal": "cereal",
    "box": "cereal",
    "dial": "knob",
    "ring": "nut",
    "post": "peg",
    "rod": "peg",
    "cylinder": "can",
}
# words that tell two objects of one kind apart; conflicting ones mean a different object
DISTINGUISHING = {
    "red",
    "green",
    "blue",
    "yellow",
    "round",
    "square",
    "left",
    "right",
    "start",
    "starting",
    "target",
    "goal",
}
PARTS = ("door", "drawer", "knob", "button")
_ARTICLES = re.compile(r"^(?:the|a|an|its|robot's|their|this|that)\s+", re.I)


def normalise_name(name: str) -> str:
    """Lower case, spaces for underscores, no leading article."""
    name = name.strip().lower().replace("_", " ")
    while True:
        new = _ARTICLES.sub("", name)
        if new == name:
            return re.sub(r"\s+", " ", name)
        name = new


def head_and_modifiers(name: str) -> tuple[str, set[str]]:
    """("cube", {"red"}) for "the red block"; a trailing number stays part of the head."""
    words = normalise_name(name).split()
    if not words:
        return "", set()
    if words[-1] == "handle" and len(words) > 1:
        words = words[:-1]
    if words[-1].isdigit() and len(words) > 1:
        return " ".join(words[-2:]), set(words[:-2])
    head = HEAD_ALIASES.get(words[-1], words[-1])
    if head == "box" or (head == "cereal" and "milk" in words):
        head = words[-1]
    mods = set(words[:-1])
    for w in list(mods):  # "milk carton", "soda can": a modifier that names the head
        if HEAD_ALIASES.get(w) == head or w == head:
            mods.discard(w)
    return head, mods


def names_match(said: str, known: str) -> bool:
    """Does a name from the text refer to a name the simulator uses?

    "can", "soda can", "the can" all match "can"; "bin 2" matches "bin_2" and "bin2" but
    not "bin 1"; "microwave door" matches "door"; "red block" matches "red cube" but
    "green block" does not; "milk carton" matches "milk".
    """
    a, b = normalise_name(said), normalise_name(known)
    if a == b or a.replace(" ", "") == b.replace(" ", ""):
        return True
    a = re.sub(r"(\D)(\d+)$", r"\1 \2", a)
    b = re.sub(r"(\D)(\d+)$", r"\1 \2", b)
    ha, ma = head_and_modifiers(a)
    hb, mb = head_and_modifiers(b)
    if not ha or not hb:
        return False
    if "handle" in (ha, hb):  # a bare "handle" is the handle of the door, drawer or knob
        return (hb if ha == "handle" else ha) in ("door", "drawer", "knob", "handle")
    if ha[-1].isdigit() or hb[-1].isdigit():
        return ha == hb
    if ha != hb:
        return False
    da, db = ma & DISTINGUISHING, mb & DISTINGUISHING
    return not (da and db and not (da & db))


def resolve(said: str | None, known: list[str]) -> str | None:
    """The one known name `said` refers to; None when none or several fit equally."""
    if not said:
        return None
    fits = [k for k in dict.fromkeys(known) if names_match(said, k)]
    if len(fits) == 1:
        return fits[0]
    if not fits:
        if normalise_name(said) == "handle":
            parts = [k for k in dict.fromkeys(known) if k in PARTS and k != "button"]
            return parts[0] if len(parts) == 1 else None
        return None
    _, mods = head_and_modifiers(said)
    exact = [k for k in fits if mods & DISTINGUISHING & head_and_modifiers(k)[1]]
    if len(exact) == 1:
        return exact[0]
    same = [k for k in fits if normalise_name(k) == normalise_name(said)]
    return same[0] if len(same) == 1 else None
