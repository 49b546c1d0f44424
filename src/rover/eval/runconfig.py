"""run.json: what a run was asked to do, which software did it, and how it was invoked.

Backend specs and the command line are stored through the one scrubber (rover.vlm.scrub:
keys, URL credentials, `sk-...`/`AIza...` tokens); values of options named like
keys/tokens/passwords are replaced by `***`, so a run directory can be shared as it is.
"""

from __future__ import annotations

import platform
import re
from datetime import UTC, datetime
from importlib import metadata
from typing import TYPE_CHECKING, Any

from rover import __version__

if TYPE_CHECKING:
    from rover.eval.episodes import EpisodeRef
    from rover.eval.runner import EvalOptions
    from rover.eval.variants import Variant

MASK = "***"
_SECRET_OPT = re.compile(r"^--?[\w-]*(key|token|secret|password|passwd|auth)[\w-]*$", re.I)
# key-name options whose value is the *name* of an environment variable, not a secret
_SAFE_OPTS = {"--api-key-env"}
_PACKAGES = (
    "numpy",
    "scipy",
    "pydantic",
    "av",
    "openai",
    "typer",
    "rich",
    "pillow",
    "google-genai",
    "torch",
    "transformers",
    "mujoco",
    "robosuite",
)


def scrub_text(text: str) -> str:
    """`text` through the one scrubber (rover.vlm.scrub): keys, URL credentials, tokens."""
    from rover.vlm.scrub import scrub

    return scrub(text)


def scrub_argv(argv: list[str]) -> list[str]:
    """A command line with the values of secret-looking options masked."""
    out: list[str] = []
    mask_next = False
    for arg in argv:
        if mask_next:
            out.append(MASK)
            mask_next = False
            continue
        name, eq, _ = arg.partition("=")
        if _SECRET_OPT.match(name) and name not in _SAFE_OPTS:
            if eq:
                out.append(f"{name}={MASK}")
            else:
                out.append(arg)
                mask_next = True
            continue
        out.append(scrub_text(arg))
    return out


def versions() -> dict[str, str]:
    """rover, python and the installed versions of the packages results depend on."""
    out = {"rover": __version__, "python": platform.python_version()}
    for pkg in _PACKAGES:
        try:
            out[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            continue
    return out


def run_config(
    opts: EvalOptions, variants: list[Variant], refs: list[EpisodeRef]
) -> dict[str, Any]:
    """The content of run.json for these options."""
    bc = opts.backend_config
    return {
        "schema_version": 1,
        "dataset": str(opts.dataset) if opts.dataset is not None else None,
        "sources": [scrub_text(s) for s in opts.sources],
        "episodes_per_source": opts.episodes,
        "seed": opts.seed,
        "limit": opts.limit,
        "episodes": [r.id for r in refs],
        "episode_datasets": {r.id: r.dataset for r in refs},
        "methods": list(opts.methods),
        "backends": [scrub_text(b) for b in opts.backends],
        "judge": scrub_text(opts.judge),
        "answerer": scrub_text(opts.answerer),
        "frames": list(opts.frames),
        "windows": list(opts.windows),
        "views": list(opts.views),
        "oracle": {"seed": bc.seed, "flip_prob": bc.flip_prob, "jitter": bc.jitter},
        "backend_config": {
            k: v
            for k, v in bc.model_dump(mode="json").items()
            if k not in ("cache_path", "record", "base_url")
        },
        "variants": [
            {**v.model_dump(mode="json"), "backend": scrub_text(v.backend)} for v in variants
        ],
        "concurrency": opts.concurrency,
        "command": scrub_argv(list(opts.command)),
        "versions": versions(),
        "created_at": datetime.now(UTC).isoformat(),
    }
