"""Paraphrases of the kitchen tasks' instructions (issue 10, item 5).

An episode is given one wording, picked by its seed (`TaskSpec.instruction`) and
recorded; the subtask names the value function and the levels use never change.
"""

from __future__ import annotations

PARAPHRASES: dict[str, list[str]] = {
    "OpenDrawer": [
        "Pull the drawer open by its handle.",
        "Grab the handle of the drawer and slide the drawer out.",
        "Open the kitchen drawer.",
    ],
    "CloseDrawer": [
        "Push the open drawer shut.",
        "Take the drawer's handle and slide the drawer closed.",
        "Close the kitchen drawer.",
    ],
    "OpenSingleDoor": [
        "Open the cabinet door by pulling its handle.",
        "Swing the cabinet door open.",
        "Grab the cabinet's handle and open its door.",
    ],
    "CloseSingleDoor": [
        "Push the open cabinet door shut.",
        "Swing the cabinet door closed by its handle.",
        "Close the cabinet door.",
    ],
    "TurnOnMicrowave": [
        "Turn the microwave on with its start button.",
        "Push the microwave's start button.",
        "Start the microwave.",
    ],
    "TurnOffMicrowave": [
        "Turn the running microwave off with its stop button.",
        "Push the microwave's red stop button.",
        "Stop the microwave.",
    ],
    "CoffeePressButton": [
        "Push the button on top of the coffee machine.",
        "Turn the coffee machine on.",
        "Start the coffee machine with its button.",
    ],
    "TurnOnStove": [
        "Turn the left stove knob to switch the burner on.",
        "Switch on the front-left burner of the stove.",
        "Twist the stove's left knob a quarter turn to turn the burner on.",
    ],
    "TurnOffStove": [
        "Turn the left stove knob back to switch the burner off.",
        "Switch off the front-left burner of the stove.",
        "Twist the stove's left knob back to off.",
    ],
    "TurnOnSinkFaucet": [
        "Turn the sink's handle to start the water.",
        "Switch the faucet on with its lever.",
        "Turn on the sink faucet.",
    ],
    "TurnOffSinkFaucet": [
        "Turn the sink's handle back to stop the water.",
        "Switch the faucet off with its lever.",
        "Turn off the sink faucet.",
    ],
    "ArrangeVegetables": [
        "Put both vegetables from the counter onto the cutting board.",
        "Move the two vegetables onto the cutting board, one after the other.",
        "Take the vegetables from the counter and set them on the cutting board.",
    ],
    "PreSoakPan": [
        "Put the pan in the sink, place the sponge in it and turn the water on.",
        "Set the pan in the sink with the sponge inside it, then switch the faucet on.",
        "Move the pan into the sink, put the sponge in the pan and turn on the sink.",
    ],
    "RestockPantry": [
        "Put both pantry items from the counter into the cabinet.",
        "Stock the cabinet with the two pantry items from the counter, one after the other.",
        "Take the two items off the counter and put them away in the cabinet.",
    ],
    "PrepareCoffee": [
        "Set the mug under the coffee machine's spout and press its start button.",
        "Put the mug in the coffee machine, then switch the machine on.",
        "Place the mug on the coffee machine's drip tray and start the machine.",
    ],
    "MicrowaveThawing": [
        "Put the food item in the microwave, shut its door and start it.",
        "Open the microwave, place the food inside, close the door and press start.",
        "Thaw the food item: into the microwave with it, door closed, start button pressed.",
    ],
    "TurnSinkSpout": [
        "Swivel the faucet spout to the left.",
        "Swing the sink's spout over to the left side.",
        "Rotate the sink spout to the left.",
    ],
}
