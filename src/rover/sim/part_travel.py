"""How far the articulated parts travel: the numbers both the fixtures and the task specs read.

A task spec names its part's target (a drawer pulled out 12 cm, a button pushed past its
switching depth) and the fixture env judges the same motion. Both read these constants,
and this module imports nothing, so a spec module can use them without importing
robosuite (the fixture modules do).
"""

from __future__ import annotations

DRAWER_OPEN_Q = 0.12  # m pulled out that counts as "completely open"
DRAWER_START_OPEN = 0.14  # m pulled out at the start of a closing task
PRESS_Q = -0.010  # m of button travel that switches the appliance on (range 16 mm)
# a button's target: progress reaches 0.9 (= reached) exactly at the switching depth
BUTTON_TARGET = PRESS_Q / 0.9
