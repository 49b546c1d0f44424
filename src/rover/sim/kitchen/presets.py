"""The paper's dataset shape (App. B, Tables 4 and 5; Sec. 5), one table in code.

`rover generate --preset paper` and `rover tasks` both read this module: the 27
RoboCasa tasks in their 9 groups (Table 4), the number of videos per level of each
group (Table 5's "Dataset count" column, per task and level), 30 frames for atomic and
60 for composite tasks, and the camera views of the paper's results.

Table 5's counts add up to 547 videos over the 27 tasks, four more than the 543 the
paper states in its abstract, Sec. 5 and App. B; the table is what says how many
videos each level of each task gets, so the preset follows it (`PAPER_STATED_VIDEOS`
keeps the paper's own total for reference). Pure data: no robosuite import.
"""

from __future__ import annotations

from dataclasses import dataclass

SUITE = "kitchen"


@dataclass(frozen=True)
class PaperGroup:
    """One task group of Table 4 with its Table 5 row."""

    title: str  # the paper's name for the group
    tasks: tuple[str, ...]  # Table 4's task names (rover registers them as kitchen.<name>)
    counts: tuple[int, ...]  # Table 5: videos per level of each task, level 1 first
    composite: bool = False

    @property
    def frames(self) -> int:
        """Frames per video (App. B: 30 for atomic tasks, 60 for the composite ones)."""
        return 60 if self.composite else 30


# group id (TaskSpec.group) -> Table 4 and Table 5
PAPER_GROUPS: dict[str, PaperGroup] = {
    "pick_and_place": PaperGroup(
        "Pick-and-place",
        (
            "PickPlaceCabToCounter",
            "PickPlaceCounterToCab",
            "PickPlaceCounterToMicrowave",
            "PickPlaceCounterToSink",
            "PickPlaceCounterToStove",
            "PickPlaceMicrowaveToCounter",
            "PickPlaceSinkToCounter",
            "PickPlaceStoveToCounter",
            "CoffeeSetupMug",
            "CoffeeServeMug",
        ),
        (3, 3, 3, 3, 3, 3, 3),
    ),
    "doors_drawers": PaperGroup(
        "Open/close doors/drawers",
        ("OpenSingleDoor", "CloseSingleDoor", "OpenDrawer", "CloseDrawer"),
        (4, 4, 4, 4, 4),
    ),
    "appliances": PaperGroup(
        "Turn on/off appliances",
        ("TurnOnMicrowave", "TurnOffMicrowave", "CoffeePressButton"),
        (6, 6, 6),
    ),
    "fixtures_knobs": PaperGroup(
        "Toggle fixtures/knobs",
        ("TurnSinkSpout", "TurnOnSinkFaucet", "TurnOffSinkFaucet", "TurnOnStove", "TurnOffStove"),
        (4, 4, 4, 4, 4),
    ),
    "microwave_thawing": PaperGroup(
        "Microwave thawing", ("MicrowaveThawing",), (4, 4, 4, 4, 4), composite=True
    ),
    "restock_pantry": PaperGroup("Restock pantry", ("RestockPantry",), (7, 7, 7), composite=True),
    "arrange_vegetables": PaperGroup(
        "Arrange vegetables", ("ArrangeVegetables",), (7, 7, 7), composite=True
    ),
    "prepare_coffee": PaperGroup("Prepare coffee", ("PrepareCoffee",), (7, 7, 7), composite=True),
    "presoak_pan": PaperGroup("Pre-soak pan", ("PreSoakPan",), (5, 5, 5, 5), composite=True),
}

PAPER_STATED_VIDEOS = 543  # the total the paper's text states (Table 5 adds up to 547)
# Sec. 5 reports the wrist (eye-in-hand) view; App. J adds the fixed left and right views
PAPER_VIEWS = ("wrist", "left", "right")
PAPER_SIZE = 256  # px


def paper_task_names() -> list[str]:
    """The 27 tasks of Table 4 as rover names them ("kitchen.OpenDrawer"), in table order."""
    return [f"{SUITE}.{t}" for g in PAPER_GROUPS.values() for t in g.tasks]


def paper_group_of(task: str) -> str | None:
    """The Table 4 group id of a paper task (rover or paper name); None if not one."""
    bare = task.removeprefix(f"{SUITE}.")
    return next((gid for gid, g in PAPER_GROUPS.items() if bare in g.tasks), None)


def paper_counts(task: str) -> tuple[int, ...]:
    """Table 5's videos per level for one paper task (level 1 first)."""
    gid = paper_group_of(task)
    if gid is None:
        raise KeyError(f"{task} is not one of the paper's 27 tasks")
    return PAPER_GROUPS[gid].counts


def paper_videos(tasks: list[str] | None = None) -> int:
    """Videos the preset writes for these paper tasks (all 27: Table 5's total)."""
    names = paper_task_names() if tasks is None else tasks
    return sum(sum(paper_counts(t)) for t in names)


def group_title(group: str) -> str:
    """Display name of a task group: the paper's (Table 4) for kitchen groups."""
    g = PAPER_GROUPS.get(group)
    return g.title if g is not None else group.replace("_", " ")


def paper_plan(
    registered: list[str], available_only: bool = False
) -> tuple[list[str], dict[str, list[int]], str]:
    """Tasks, per-level counts and a one-line summary for ``rover generate --preset paper``.

    Every one of the 27 tasks must be registered, else one `InputError` names the missing
    ones, unless `available_only`: then the registered ones are planned and the summary
    says how many of the preset's videos that is.
    """
    from rover.errors import InputError

    names = paper_task_names()
    total = paper_videos()
    have = [t for t in names if t in registered]
    missing = [t for t in names if t not in registered]
    if missing and not available_only:
        raise InputError(
            f"--preset paper: {len(missing)} of the {len(names)} paper tasks do not exist yet: "
            f"{', '.join(missing)}; pass --available-only to write the other {len(have)} "
            f"({paper_videos(have)} of {total} videos)"
        )
    if not have:
        raise InputError("--preset paper: none of the paper's tasks exist")
    note = (
        f"--preset paper: {len(have)} of {len(names)} tasks, {paper_videos(have)} of the "
        f"{total} videos of Table 5 (the paper's text says {PAPER_STATED_VIDEOS})"
    )
    return have, {t: list(paper_counts(t)) for t in have}, note
