"""`rover demo`: the whole pipeline offline, in minutes: dataset -> methods -> eval -> report.

Every VLM method runs on a small dataset with the *oracle* backend, which answers from the
simulator's ground truth (no network, no API key). Mild noise (claims flipped with
probability 0.1, progress jittered by 5 points) keeps the charts from being trivially
perfect. The output shows what rover measures and draws, not how good any VLM is, and it
says so on every page and in the table printed at the end.
"""

from __future__ import annotations

import asyncio
import sys
import time
from pathlib import Path
from typing import Annotated

import typer
from rich import box
from rich.console import Console
from rich.table import Table

from rover.console import esc, make_console
from rover.errors import InputError, MissingExtraError
from rover.paths import check_output_dir

FLIP_PROB = 0.1
JITTER = 5.0
GENERATE_TASKS = ["Lift", "Door"]
DEMO_ENTRIES = {"dataset", "run", "report"}  # what a demo folder holds (reruns reuse it)
ORACLE_LINE = "ORACLE OUTPUT — answers come from simulator ground truth, not a VLM"


def register(app: typer.Typer) -> None:
    app.command("demo")(demo)


def demo(
    out: Annotated[
        Path, typer.Option("--out", "-o", help="Where to write the dataset run and report.")
    ] = Path("rover-demo"),
    generate: Annotated[
        bool,
        typer.Option(
            "--generate",
            help="Generate a fresh small dataset with MuJoCo (extra 'sim') instead of "
            "using the bundled one.",
        ),
    ] = False,
    limit: Annotated[
        int | None, typer.Option("--limit", hidden=True, help="First N episodes only.")
    ] = None,
    methods: Annotated[
        str | None, typer.Option("--methods", hidden=True, help="Comma-separated subset.")
    ] = None,
) -> None:
    """Run every VLM method on a small dataset with the oracle backend, then build the report."""
    console = make_console()
    started = time.monotonic()
    out = Path(out)
    chosen = _methods(methods)
    # before any work: a folder of somebody else's is never written into
    reused = out.is_dir() and {p.name for p in out.iterdir()} <= DEMO_ENTRIES
    check_output_dir(out, "--out", allow_nonempty=reused)
    console.print(f"[bold red]{ORACLE_LINE}[/]")
    console.print(
        f"oracle noise: claims flipped with p={FLIP_PROB}, progress jitter ±{JITTER:g} points"
    )
    dataset = _generate(out / "dataset", console) if generate else _bundled()
    console.print(f"dataset: {esc(dataset)}")
    run_dir = out / "run"
    metrics = _evaluate(dataset, run_dir, chosen, limit, console)
    from rover.report import build_report

    with console.status("drawing figures and writing the report"):
        index = build_report(run_dir, out / "report")
    console.print(_table(run_dir))
    failed = (metrics.get("counts") or {}).get("failed") or 0
    if failed:
        console.print(f"[yellow]{failed} work units failed; see {esc(run_dir / 'errors.jsonl')}[/]")
    console.print(f"done in {time.monotonic() - started:.0f} s")
    console.print(f"report: {esc(index)}", soft_wrap=True)
    console.print(f"open it: {esc(index.resolve().as_uri())}", soft_wrap=True)


def demo_methods() -> list[str]:
    """Every method that talks to a VLM (clip-value needs local embedding weights)."""
    from rover.methods.registry import vlm_method_names

    return vlm_method_names()


def _methods(text: str | None) -> list[str]:
    allowed = demo_methods()
    if not text:
        return allowed
    chosen = [m.strip() for m in text.split(",") if m.strip()]
    unknown = [m for m in chosen if m not in allowed]
    if unknown or not chosen:
        raise InputError(f"demo methods must come from {', '.join(allowed)}; got {text!r}")
    return chosen


def _bundled() -> Path:
    from rover.sim import bundled_dataset_path

    path = bundled_dataset_path()
    if not (path / "dataset.json").exists():
        raise InputError(
            f"the bundled dataset is missing ({path}); reinstall rover or use --generate"
        )
    return path


def _generate(target: Path, console: Console) -> Path:
    import importlib.util

    import rover.sim  # noqa: F401  (sets MUJOCO_GL before anything imports mujoco)

    for package in ("mujoco", "robosuite"):
        if importlib.util.find_spec(package) is None:
            raise MissingExtraError(package, "sim", "rover demo --generate")
    from rover.sim.generate import GenerateConfig, generate

    cfg = GenerateConfig(tasks=GENERATE_TASKS, per_level=1, size=128, demos=1, seed=0)
    with console.status(f"generating episodes of {', '.join(GENERATE_TASKS)} with MuJoCo"):
        generate(cfg, target)
    return target


def _evaluate(
    dataset: Path, run_dir: Path, methods: list[str], limit: int | None, console: Console
) -> dict:
    from rover.eval.runner import EvalOptions, run_eval
    from rover.vlm.config import BackendConfig

    opts = EvalOptions(
        dataset=dataset,
        methods=methods,
        backends=["oracle"],
        judge="rule",
        answerer="rule",
        limit=limit,
        out=run_dir,
        resume=(run_dir / "run.json").exists(),  # a second demo run reuses finished work
        backend_config=BackendConfig(no_cache=True, flip_prob=FLIP_PROB, jitter=JITTER, seed=0),
        command=["rover", *sys.argv[1:]],
    )
    with console.status("running every method with the oracle backend") as status:

        def on_update(state) -> None:
            status.update(
                f"running every method with the oracle backend: "
                f"{state.units_done}/{state.units_total} traces"
            )

        _, metrics = asyncio.run(run_eval(opts, on_update))
    return metrics


def _table(run_dir: Path) -> Table:
    """Mean per method: the numbers the report's summary starts with."""
    from rover.report.run import load_run
    from rover.report.scores import mean_se, score_run, variants_in_order

    rows = score_run(load_run(run_dir))
    table = Table(
        box=box.SIMPLE_HEAD,
        title="ORACLE OUTPUT (noisy oracle, not a VLM): mean per video",
        title_style="bold red",
        caption="r: Pearson with ground truth; err %: frames judged false; QA %: accuracy",
    )
    table.add_column("method", no_wrap=True, min_width=20)
    for col in ("r", "L2", "err %", "QA %", "tokens", "calls"):
        table.add_column(col, justify="right")
    for v in variants_in_order(rows):
        mine = [r for r in rows if r.variant == v]

        def cell(attr: str, digits: int, mine=mine) -> str:
            m, _, n = mean_se([getattr(r, attr) for r in mine])
            return "—" if n == 0 else f"{m:,.{digits}f}"

        table.add_row(
            esc(v),
            cell("pearson", 2),
            cell("l2", 0),
            cell("error_rate", 1),
            cell("qa_accuracy", 1),
            cell("tokens", 0),
            cell("calls", 1),
        )
    return table
