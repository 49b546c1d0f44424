"""The run directory: where each piece of an evaluation lives, written so it survives kills.

Every file is written whole (`.tmp` + rename), so finding a file means its work is done;
`units.jsonl` is an append-only log of work units started, finished or failed. The layout
is documented in docs/evaluation.md and read by `rover report`.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import time
from pathlib import Path
from typing import Any

from pydantic import BaseModel

from rover.errors import InputError

RUN_FILE = "run.json"
UNITS_LOG = "units.jsonl"
ERRORS_FILE = "errors.jsonl"
METRICS_FILE = "metrics.json"
SUMMARY_FILE = "summary.md"
STAGES = ("trace", "judge", "qa")
_STAGE_DIRS = {"trace": "traces", "judge": "judgements", "qa": "qa"}
# settings that must match for --resume to continue a run (others, like --concurrency, may change)
RESUME_KEYS = (
    "dataset",
    "sources",
    "methods",
    "backends",
    "judge",
    "answerer",
    "frames",
    "windows",
    "views",
    "episodes_per_source",
    "seed",
    "oracle",
)


def safe_name(text: str) -> str:
    """A file-name-safe rendering of an episode id."""
    return re.sub(r"[^A-Za-z0-9._=-]+", "-", text).strip("-") or "episode"


def write_json_atomic(path: Path, data: Any) -> None:
    """Write JSON (a pydantic model or plain data) so readers never see half a file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    if isinstance(data, BaseModel):
        text = data.model_dump_json(indent=1)
    else:
        text = json.dumps(data, indent=1, allow_nan=False, default=str)
    tmp.write_text(text)
    os.replace(tmp, path)


class RunDir:
    """Paths and small I/O helpers for one run directory."""

    def __init__(self, root: Path) -> None:
        self.root = Path(root)
        self._log: Any = None

    # --- paths ------------------------------------------------------------------------
    @property
    def run_file(self) -> Path:
        return self.root / RUN_FILE

    def stage_path(self, stage: str, episode_id: str, variant_id: str) -> Path:
        return self.root / _STAGE_DIRS[stage] / safe_name(episode_id) / f"{variant_id}.json"

    def trace_path(self, episode_id: str, variant_id: str) -> Path:
        return self.stage_path("trace", episode_id, variant_id)

    def error_path(self, episode_id: str, variant_id: str) -> Path:
        return self.root / "errors" / safe_name(episode_id) / f"{variant_id}.json"

    def episode_path(self, episode_id: str) -> Path:
        return self.root / "episodes" / f"{safe_name(episode_id)}.json"

    # --- lifecycle --------------------------------------------------------------------
    def prepare(self, config: dict[str, Any], resume: bool) -> None:
        """Create the directory, or check a resumed one was made with the same settings."""
        if self.root.exists() and not self.root.is_dir():
            raise InputError(f"--out {self.root}: exists and is not a directory")
        non_empty = self.root.is_dir() and any(self.root.iterdir())
        if non_empty and not resume:
            raise InputError(
                f"--out {self.root} is not empty; add --resume to continue that run, "
                "or choose a new --out"
            )
        if non_empty and self.run_file.exists():
            try:
                old = json.loads(self.run_file.read_text())
            except json.JSONDecodeError as exc:
                raise InputError(f"{self.run_file}: unreadable ({exc}); use a new --out") from exc
            for key in RESUME_KEYS:
                if old.get(key) != config.get(key):
                    raise InputError(
                        f"--resume: this run was made with {key}={old.get(key)!r}, not "
                        f"{config.get(key)!r}; use the original options or a new --out"
                    )
            config = {
                **config,
                "created_at": old.get("created_at", config.get("created_at")),
                "resumed": int(old.get("resumed", 0)) + 1,
            }
        elif non_empty:
            raise InputError(f"--resume: {self.root} has no {RUN_FILE}; it is not a rover eval run")
        self.root.mkdir(parents=True, exist_ok=True)
        for leftover in self.root.rglob("*.tmp"):
            leftover.unlink(missing_ok=True)  # a write cut short by a kill
        log = self.root / UNITS_LOG
        if log.exists() and log.stat().st_size and not log.read_bytes().endswith(b"\n"):
            with open(log, "a", encoding="utf-8") as fh:  # end a line torn by a kill
                fh.write("\n")
        write_json_atomic(self.run_file, config)

    # --- work units -------------------------------------------------------------------
    def done(self, stage: str, episode_id: str, variant_id: str) -> bool:
        return self.stage_path(stage, episode_id, variant_id).exists()

    def log_unit(
        self, episode_id: str, variant_id: str, stage: str, event: str, **extra: Any
    ) -> None:
        """Append one line to units.jsonl (flushed at once; a torn last line is skipped)."""
        line = {
            "unit": f"{episode_id}/{variant_id}",
            "stage": stage,
            "event": event,
            "time": round(time.time(), 3),
            **extra,
        }
        if self._log is None:
            self._log = open(self.root / UNITS_LOG, "a", encoding="utf-8")  # noqa: SIM115
        self._log.write(json.dumps(line) + "\n")
        self._log.flush()  # into the OS at once: a SIGKILL loses nothing written here

    def close(self) -> None:
        if self._log is not None:
            self._log.close()
            self._log = None

    def record_error(self, episode_id: str, variant_id: str, stage: str, error: str) -> None:
        write_json_atomic(
            self.error_path(episode_id, variant_id),
            {
                "episode_id": episode_id,
                "variant": variant_id,
                "stage": stage,
                "error": error,
                "time": round(time.time(), 3),
            },
        )

    def clear_error(self, episode_id: str, variant_id: str) -> None:
        path = self.error_path(episode_id, variant_id)
        if path.exists():
            path.unlink()
            parent = path.parent
            if parent.is_dir() and not any(parent.iterdir()):
                shutil.rmtree(parent, ignore_errors=True)

    def errors(self) -> list[dict[str, Any]]:
        """Every failure still standing, sorted by episode and variant."""
        out = []
        for path in sorted((self.root / "errors").rglob("*.json")):
            try:
                out.append(json.loads(path.read_text()))
            except (json.JSONDecodeError, OSError):
                continue
        return out

    def write_errors_file(self) -> list[dict[str, Any]]:
        errs = self.errors()
        tmp = self.root / (ERRORS_FILE + ".tmp")
        tmp.write_text("".join(json.dumps(e) + "\n" for e in errs))
        os.replace(tmp, self.root / ERRORS_FILE)
        return errs


def read_units_log(root: Path) -> list[dict[str, Any]]:
    """The lines of units.jsonl that parse (a line torn by a kill is skipped)."""
    path = Path(root) / UNITS_LOG
    if not path.exists():
        return []
    out = []
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            out.append(json.loads(line))
        except json.JSONDecodeError:
            continue
    return out
