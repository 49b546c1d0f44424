"""A kitchen benchmark built from robosuite's parts and rover's own MJCF fixtures.

RoboCasa's kitchens cannot be downloaded here, so the kitchen suite assembles one per
episode: robosuite's `TableArena` as a long counter with a backsplash, rover's fixtures
(cabinet with a hinged door, drawer unit, microwave, coffee machine, sink, stove; MJCF
in ``assets/``) laid out along it, robosuite's textures on floor, walls, counter and
cabinets, and robosuite's light and camera modders for lighting and camera jitter. Every
choice is drawn from the episode seed and recorded (`rover.sim.kitchen.scene`).

Modules: `fixtures` (what each fixture is and where it may stand), `scene` (the seeded
scene draw), `objects` (object instances per category), `env` (the robosuite
environment ``RoverKitchen``), `tasks` (task specs of the ``kitchen`` suite), `experts`
(scripted experts the generic ones do not cover), `language` (paraphrases). Only
`env` and `experts` import robosuite; the specs load without it.
"""
