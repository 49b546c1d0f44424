"""Phrase banks for the agreement corpus: how models say each kind of statement.

Each entry is a clause template and the meaning it asserts, as a list of atoms
(`kind`, *args, polarity). `{o}` is an object as the model names it (an alias), `{t}` a
place ("bin 4", "the target bin"), `{b}` the object something rests on, `{p}` a part
(door, drawer, knob), `{pct}` a percentage. The atoms, not the words, decide the label
(see `build.atom_truth`), so the label never depends on what the rule judge can read.
"""

from __future__ import annotations

Atom = tuple  # ("holding", "{o}", True), ("gripper", "open"), ...

GRIPPER: dict[str, list[str]] = {
    "open": [
        "the gripper is open",
        "the gripper is wide open",
        "the gripper's fingers are spread apart",
        "the gripper jaws are open",
        "the gripper appears to be open",
        "the gripper remains open",
        "the gripper is not closed",
        "the two fingers of the gripper are apart",
    ],
    "closed": [
        "the gripper is closed",
        "the gripper has closed",
        "the gripper fingers are closed",
        "the gripper appears to be closed",
        "the gripper is clamped shut",
        "the gripper is shut",
        "the gripper is not open",
        "the fingers of the gripper have come together",
    ],
}

HOLD_POS: list[tuple[str, list[Atom]]] = [
    ("the robot is holding the {o}", [("holding", "{o}", True)]),
    ("the robot has grasped the {o}", [("holding", "{o}", True)]),
    ("the gripper has a firm grip on the {o}", [("holding", "{o}", True)]),
    ("the {o} is held in the gripper", [("holding", "{o}", True)]),
    ("the {o} is securely grasped by the gripper", [("holding", "{o}", True)]),
    ("the robot is carrying the {o}", [("holding", "{o}", True)]),
    ("the arm is moving the {o}", [("holding", "{o}", True)]),
    ("the robot is gripping the {o}", [("holding", "{o}", True)]),
    ("the {o} is clamped between the gripper fingers", [("holding", "{o}", True)]),
    ("the gripper is holding the {o}", [("holding", "{o}", True)]),
    ("the robot appears to be holding the {o}", [("holding", "{o}", True)]),
    ("the gripper is wrapped around the {o}", [("holding", "{o}", True)]),
]
HOLD_NEG: list[tuple[str, list[Atom]]] = [
    ("the robot is not holding the {o}", [("holding", "{o}", False)]),
    ("the robot has not grasped the {o} yet", [("holding", "{o}", False)]),
    ("the {o} is not in the gripper", [("holding", "{o}", False)]),
    ("the gripper is empty", [("holding_any", False)]),
    ("the robot is not holding anything", [("holding_any", False)]),
    ("the robot has released the {o}", [("holding", "{o}", False)]),
    ("nothing is in the gripper", [("holding_any", False)]),
    ("the robot has yet to grasp the {o}", [("holding", "{o}", False)]),
    ("the gripper holds nothing", [("holding_any", False)]),
    ("the robot has let go of the {o}", [("holding", "{o}", False)]),
]

CONTACT_POS: list[tuple[str, list[Atom]]] = [
    ("the gripper is touching the {o}", [("contact", "{o}", True)]),
    ("the gripper fingers are in contact with the {o}", [("contact", "{o}", True)]),
    ("the gripper has made contact with the {o}", [("contact", "{o}", True)]),
    ("the fingers are pressed against the {o}", [("contact", "{o}", True)]),
    ("the gripper is in contact with the {o}", [("contact", "{o}", True)]),
    ("the robot's fingers touch the {o}", [("contact", "{o}", True)]),
]
CONTACT_NEG: list[tuple[str, list[Atom]]] = [
    ("the gripper has not touched the {o}", [("contact", "{o}", False)]),
    ("the gripper is not yet touching the {o}", [("contact", "{o}", False)]),
    ("the gripper hovers near the {o} without touching it", [("contact", "{o}", False)]),
    ("there is no contact between the gripper and the {o}", [("contact", "{o}", False)]),
    ("the gripper is not in contact with the {o}", [("contact", "{o}", False)]),
    ("the gripper is not touching anything", [("contact_any", False)]),
]

LIFT_POS: list[tuple[str, list[Atom]]] = [
    ("the {o} is lifted off the table", [("lifted", "{o}", True)]),
    ("the {o} is in the air", [("lifted", "{o}", True)]),
    ("the {o} has been raised above the table", [("lifted", "{o}", True)]),
    ("the {o} is suspended above the table", [("lifted", "{o}", True)]),
    ("the {o} is off the ground", [("lifted", "{o}", True)]),
    ("the {o} is elevated", [("lifted", "{o}", True)]),
    ("the {o} appears to be lifted", [("lifted", "{o}", True)]),
]
LIFT_NEG: list[tuple[str, list[Atom]]] = [
    ("the {o} has not been lifted", [("lifted", "{o}", False)]),
    ("the {o} is not lifted yet", [("lifted", "{o}", False)]),
    ("the {o} has not been picked up yet", [("lifted", "{o}", False)]),
    ("the {o} is not in the air", [("lifted", "{o}", False)]),
]
# only for objects that stand on the table (not in a bin): "on the table" = not lifted
TABLE_POS: list[tuple[str, list[Atom]]] = [
    ("the {o} remains on the table", [("lifted", "{o}", False)]),
    ("the {o} is still resting on the table", [("lifted", "{o}", False)]),
    ("the {o} is sitting on the table", [("lifted", "{o}", False)]),
    ("the {o} has not left the table", [("lifted", "{o}", False)]),
]

# compound statements: one verb phrase, two facts
LIFT_ACTION: list[tuple[str, list[Atom]]] = [
    ("the robot lifts the {o} off the table", [("holding", "{o}", True), ("lifted", "{o}", True)]),
    ("the arm has picked up the {o}", [("holding", "{o}", True), ("lifted", "{o}", True)]),
    ("the robot is lifting the {o}", [("holding", "{o}", True), ("lifted", "{o}", True)]),
    ("the robot has picked the {o} up", [("holding", "{o}", True), ("lifted", "{o}", True)]),
    (
        "the {o} is being carried through the air",
        [("holding", "{o}", True), ("lifted", "{o}", True)],
    ),
]
PLACE_RELEASE: list[tuple[str, list[Atom]]] = [
    (
        "the {o} has been placed in {t} and the gripper has released it",
        [("inside", "{o}", "{t}", True), ("holding", "{o}", False)],
    ),
    (
        "the robot has set the {o} down in {t} and let go of it",
        [("inside", "{o}", "{t}", True), ("holding", "{o}", False)],
    ),
]

INSIDE_POS: list[tuple[str, list[Atom]]] = [
    ("the {o} is in {t}", [("inside", "{o}", "{t}", True)]),
    ("the {o} has been placed in {t}", [("inside", "{o}", "{t}", True)]),
    ("the {o} is now inside {t}", [("inside", "{o}", "{t}", True)]),
    ("the {o} sits in {t}", [("inside", "{o}", "{t}", True)]),
    ("the {o} rests inside {t}", [("inside", "{o}", "{t}", True)]),
]
INSIDE_NEG: list[tuple[str, list[Atom]]] = [
    ("the {o} is not yet in {t}", [("inside", "{o}", "{t}", False)]),
    ("the {o} has not reached {t}", [("inside", "{o}", "{t}", False)]),
    ("the {o} is not in {t}", [("inside", "{o}", "{t}", False)]),
]

ON_POS: list[tuple[str, list[Atom]]] = [
    ("the {o} is stacked on the {b}", [("on", "{o}", "{b}", True)]),
    ("the {o} is resting on top of the {b}", [("on", "{o}", "{b}", True)]),
    ("the {o} sits on the {b}", [("on", "{o}", "{b}", True)]),
    ("the {o} has been placed on the {b}", [("on", "{o}", "{b}", True)]),
]
ON_NEG: list[tuple[str, list[Atom]]] = [
    ("the {o} is not yet on the {b}", [("on", "{o}", "{b}", False)]),
    ("the {o} has not been stacked on the {b}", [("on", "{o}", "{b}", False)]),
]

# door / drawer opening; knob turning. State atoms: closed, open, partly, full, pct
PART_OPEN: dict[str, list[str]] = {
    "closed": [
        "the {p} is closed",
        "the {p} is still shut",
        "the {p} remains closed",
        "the {p} has not been opened",
    ],
    "partly": [
        "the {p} is partially open",
        "the {p} is partly open",
        "the {p} is ajar",
        "the {p} has been opened partway",
    ],
    "full": [
        "the {p} is fully open",
        "the {p} is wide open",
        "the {p} has been opened completely",
        "the {p} is completely open",
    ],
    "open": ["the {p} is open", "the {p} has been opened"],
    "pct": ["the {p} is about {pct}% open", "the {p} is roughly {pct}% open"],
}
PART_TURN: dict[str, list[str]] = {
    "closed": ["the {p} has not been turned yet", "the {p} has not been rotated"],
    "partly": ["the {p} has been turned partway", "the {p} is partially turned"],
    "full": ["the {p} has been turned all the way", "the {p} is fully turned"],
    "open": ["the {p} has been turned", "the {p} has been rotated"],
    "pct": ["the {p} is turned about {pct}%", "the {p} has been rotated roughly {pct}%"],
}

PRESS_POS = [
    "the button is pressed",
    "the button has been pushed down",
    "the robot has pressed the button",
    "the button is depressed",
    "the button is pressed down",
]
PRESS_NEG = [
    "the button has not been pressed yet",
    "the button is not pressed",
    "the robot has not pushed the button yet",
]

# statements the facts cannot decide: motion, intention, appearance, camera
NEUTRAL = [
    "the robotic arm is moving toward the {o}",
    "the arm is approaching the {o}",
    "the robot is preparing to grasp the {o}",
    "the end-effector is positioned above the {o}",
    "the robot seems to be planning its next move",
    "the scene shows a white tabletop under bright lighting",
    "the Panda arm is visible on the left of the image",
    "the robot is adjusting its position",
    "the camera shows the workspace from the side",
    "the robot is working on the task",
    "the arm is slowly descending",
    "the {o} is visible near the center of the image",
    "the robot is aligning itself with the {o}",
    "the movement looks smooth and deliberate",
    "the arm pauses briefly",
    "the robot is about to reach for the {o}",
]

ALIASES: dict[str, list[str]] = {
    "can": ["can", "soda can", "red soda can", "cylindrical can", "drink can"],
    "cube": ["cube", "red block", "block", "red cube", "small cube"],
    "red cube": ["red cube", "red block"],
    "green cube": ["green cube", "green block"],
    "milk": ["milk", "milk carton", "carton of milk"],
    "bread": ["bread", "loaf of bread"],
    "cereal": ["cereal box", "box of cereal"],
    "round nut": ["round nut", "nut", "ring-shaped nut"],
    "square nut": ["square nut", "nut"],
    "peg": ["peg", "round peg"],
    "door": ["door"],
    "drawer": ["drawer"],
    "knob": ["knob", "dial", "stove knob"],
    "button": ["button", "push button"],
}
