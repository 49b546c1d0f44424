"""Hand-written, hand-labelled frame descriptions (free prose, not from the phrase banks).

Each names a real frame (episode id, position); the builder copies that frame's facts in.
The first five are the descriptions of issue 16 on PickPlaceCan-L7-000 frame 20 (gripper
closed, holding the can, lifted, not yet in a bin).
"""

from __future__ import annotations


def _c(episode: str, frame: int, text: str, label: str, true=(), false=()) -> dict:
    return {
        "style": "handwritten",
        "episode": episode,
        "frame": frame,
        "description": text,
        "label": label,
        "true_claims": list(true),
        "false_claims": list(false),
    }


CAN = "PickPlaceCan-L7-000"
FRAME_CASES = [
    # issue 16's table
    _c(
        CAN,
        20,
        "The can has been successfully placed in the target bin and the gripper has released it.",
        "false",
        false=["placed in the target bin", "the gripper has released it"],
    ),
    _c(
        CAN,
        20,
        "In this frame, the Panda arm lifts the cylindrical can off the surface.",
        "true",
        true=["lifts the cylindrical can off the surface"],
    ),
    _c(
        CAN,
        20,
        "The can is sitting in its original location and the gripper has not touched it.",
        "false",
        false=["sitting in its original location", "has not touched it"],
    ),
    _c(
        CAN,
        20,
        "The gripper is open and positioned above the can, which remains on the table.",
        "false",
        false=["the gripper is open", "which remains on the table"],
    ),
    _c(
        CAN,
        20,
        "The robot is moving the can. It is not yet in the bin.",
        "true",
        true=["moving the can", "not yet in the bin"],
    ),
    # more on the same frame
    _c(
        CAN,
        20,
        "The robot arm is transporting the soda can toward bin 4.",
        "true",
        true=["transporting the soda can"],
    ),
    _c(
        CAN,
        20,
        "**Frame description:** The gripper is closed around the red can, holding it "
        "above the table.",
        "true",
        true=["gripper is closed", "holding it"],
    ),
    _c(CAN, 20, "The can is already inside bin 4.", "false", false=["inside bin 4"]),
    _c(
        CAN,
        20,
        "Gripper empty, can still in the starting bin.",
        "false",
        false=["gripper empty", "can still in the starting bin"],
    ),
    _c(CAN, 20, "The arm is moving to the right.", "inconclusive"),
    _c(CAN, 20, "It looks like the robot might be about to release the can.", "inconclusive"),
    _c(
        CAN,
        0,
        "The robot has not yet interacted with the can, which sits in the start bin.",
        "true",
        true=["which sits in the start bin"],
    ),
    _c(
        CAN,
        0,
        "The gripper is open, approaching the soda can from above.",
        "true",
        true=["the gripper is open"],
    ),
    _c(
        CAN,
        0,
        "The robot is holding the can above the target bin.",
        "false",
        false=["holding the can"],
    ),
    _c(
        CAN,
        29,
        "The task appears complete: the can is in bin 4 and the gripper has opened.",
        "true",
        true=["the can is in bin 4", "the gripper has opened"],
    ),
    _c(
        CAN,
        29,
        "The can rests in the target bin. The gripper still holds it.",
        "false",
        true=["rests in the target bin"],
        false=["the gripper still holds it"],
    ),
    _c(
        CAN,
        29,
        "- Gripper: open\n- Can: in bin 4\n- Task status: complete",
        "true",
        true=["Gripper: open", "Can: in bin 4"],
    ),
    # Lift
    _c(
        "Lift-L4-000",
        19,
        "The robot has picked up the red block and is raising it.",
        "true",
        true=["picked up the red block"],
    ),
    _c(
        "Lift-L4-000",
        19,
        "The cube is still on the table; the gripper closes on it.",
        "false",
        false=["the cube is still on the table"],
    ),
    _c(
        "Lift-L4-000",
        14,
        "The gripper fingers have closed on the cube, which has not been lifted yet.",
        "true",
        true=["gripper fingers have closed", "has not been lifted yet"],
    ),
    _c("Lift-L4-000", 14, "The cube is in the air.", "false", false=["the cube is in the air"]),
    _c(
        "Lift-L4-000",
        0,
        "The block sits on the table and the gripper is open above it.",
        "true",
        true=["the block sits on the table", "the gripper is open"],
    ),
    _c(
        "Lift-L4-000",
        0,
        "The robot is grasping the cube firmly.",
        "false",
        false=["grasping the cube"],
    ),
    _c("Lift-L4-000", 0, "The arm is descending toward the red cube.", "inconclusive"),
    # Door
    _c(
        "Door-L5-000",
        20,
        "The robot is pulling the door open by its handle; the door is about halfway open.",
        "true",
        true=["the door is about halfway open"],
    ),
    _c(
        "Door-L5-000",
        20,
        "The door remains closed while the gripper grips the handle.",
        "false",
        false=["the door remains closed"],
    ),
    _c(
        "Door-L5-000",
        0,
        "The door is shut and the gripper is open.",
        "true",
        true=["the door is shut", "the gripper is open"],
    ),
    _c(
        "Door-L5-000",
        0,
        "The door has been swung wide open.",
        "false",
        false=["the door has been swung wide open"],
    ),
    _c(
        "Door-L5-000",
        28,
        "The door is fully open and the robot has let go of the handle.",
        "true",
        true=["the door is fully open", "let go of the handle"],
    ),
    _c(
        "Door-L5-000",
        28,
        "The robot is still holding the door handle.",
        "false",
        false=["still holding the door handle"],
    ),
    # Drawers
    _c(
        "OpenDrawer-L5-000",
        24,
        "The drawer has been pulled almost all the way out, and the gripper is holding its handle.",
        "true",
        true=["the gripper is holding its handle"],
    ),
    _c(
        "OpenDrawer-L5-000",
        24,
        "The drawer is still closed.",
        "false",
        false=["the drawer is still closed"],
    ),
    _c(
        "CloseDrawer-L5-000",
        0,
        "The drawer is fully open; the robot has not touched it yet.",
        "true",
        true=["the drawer is fully open", "has not touched it yet"],
    ),
    _c(
        "CloseDrawer-L5-000",
        27,
        "The drawer has been pushed shut.",
        "true",
        true=["the drawer has been pushed shut"],
    ),
    _c(
        "CloseDrawer-L5-000",
        27,
        "The drawer is still wide open.",
        "false",
        false=["the drawer is still wide open"],
    ),
    # Button
    _c(
        "PressButton-L3-000",
        24,
        "The gripper is pressing down on the button, which is now pressed.",
        "true",
        true=["which is now pressed"],
    ),
    _c(
        "PressButton-L3-000",
        0,
        "The button has already been pressed.",
        "false",
        false=["the button has already been pressed"],
    ),
    _c(
        "PressButton-L3-000",
        0,
        "The robot is moving toward the button to press it.",
        "inconclusive",
    ),
    # Knob
    _c(
        "TurnKnob-L5-000",
        19,
        "The robot grips the dial and has turned it about 50%.",
        "true",
        true=["grips the dial", "turned it about 50%"],
    ),
    _c(
        "TurnKnob-L5-000",
        19,
        "The knob has not been turned yet.",
        "false",
        false=["the knob has not been turned yet"],
    ),
    _c(
        "TurnKnob-L5-000",
        0,
        "The gripper is open and the knob has not been rotated.",
        "true",
        true=["the gripper is open", "the knob has not been rotated"],
    ),
    # Stack
    _c(
        "Stack-L7-000",
        28,
        "The red block is now stacked on top of the green block and the gripper has opened.",
        "true",
        true=["stacked on top of the green block", "the gripper has opened"],
    ),
    _c(
        "Stack-L7-000",
        28,
        "The robot is still carrying the red cube.",
        "false",
        false=["still carrying the red cube"],
    ),
    _c(
        "Stack-L7-000",
        11,
        "The red cube is held in the air above the green cube.",
        "true",
        true=["the red cube is held in the air"],
    ),
    _c(
        "Stack-L7-000",
        11,
        "The robot is holding the green block.",
        "false",
        false=["holding the green block"],
    ),
    # Nut
    _c(
        "NutAssemblyRound-L7-000",
        10,
        "The robot has lifted the round nut by its handle.",
        "true",
        true=["lifted the round nut"],
    ),
    _c(
        "NutAssemblyRound-L7-000",
        28,
        "The nut has been placed on the peg and the gripper is open.",
        "true",
        true=["placed on the peg", "the gripper is open"],
    ),
    _c(
        "NutAssemblyRound-L7-000",
        28,
        "The nut is still in the gripper.",
        "false",
        false=["the nut is still in the gripper"],
    ),
    # Milk / Restock
    _c(
        "PickPlaceMilk-L7-000",
        13,
        "The milk carton is lifted out of the starting bin.",
        "true",
        true=["the milk carton is lifted"],
    ),
    _c(
        "PickPlaceMilk-L7-000",
        29,
        "The carton now sits in bin 1 and the gripper has opened.",
        "true",
        true=["sits in bin 1", "the gripper has opened"],
    ),
    _c("PickPlaceMilk-L7-000", 29, "The milk is in bin 2.", "false", false=["in bin 2"]),
    _c(
        "Restock-L5-000",
        30,
        "The milk is already in bin 1 and the robot is now carrying the can.",
        "true",
        true=["the milk is already in bin 1", "carrying the can"],
    ),
    _c(
        "Restock-L5-000",
        30,
        "The robot is holding the milk carton.",
        "false",
        false=["holding the milk carton"],
    ),
]
