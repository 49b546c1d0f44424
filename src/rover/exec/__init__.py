"""Executors: where generation episodes and evaluation units run.

`rover generate` and `rover eval` hand their independent pieces of work (an episode, a
work unit) to an executor and never ask which one it is: `LocalExecutor` is a process pool
on this machine (`--workers`), `RayExecutor` sends each piece to a Ray cluster (the
optional extra `ray`). What differs is stated by attributes, not by type checks:
`shares_files` says whether a task may write into the output directory itself (a local
pool may; a Ray task may run on a node that does not see the driver's disk, so it returns
bytes and the driver writes them), `remote` says whether work leaves this process.
"""

from __future__ import annotations

from typing import Any

from rover.errors import InputError
from rover.exec.local import LocalExecutor

EXECUTORS = ("local", "ray")
RAY_EXTRA_HINT = "--executor ray needs the 'ray' extra: pip install 'rover-vlm[ray]'"

__all__ = ["EXECUTORS", "LocalExecutor", "check_executor", "key_env_names", "make_executor"]


def key_env_names(config: Any) -> tuple[str, ...]:
    """Names of the environment variables the backends read keys (and a base URL) from."""
    from rover.vlm.gemini_backend import DEFAULT_KEY_ENVS
    from rover.vlm.openai_backend import DEFAULT_KEY_ENV

    named = getattr(config, "api_key_env", None)
    keys = (named,) if named else (DEFAULT_KEY_ENV, *DEFAULT_KEY_ENVS)
    return (*keys, "OPENAI_BASE_URL")


def check_executor(kind: str, address: str | None = None) -> None:
    """Refuse an unknown executor, a stray --ray-address, or a missing `ray` package.

    Called before any work, so a missing extra costs one line, not a half-made dataset.
    """
    if kind not in EXECUTORS:
        raise InputError(f"--executor must be 'local' or 'ray', got {kind!r}")
    if kind == "local":
        if address:
            raise InputError("--ray-address applies to --executor ray only")
        return
    if address is not None and not address.strip():
        raise InputError("--ray-address is empty; give 'auto' or host:port (or leave it out)")
    try:
        import ray  # noqa: F401
    except ImportError:
        raise InputError(RAY_EXTRA_HINT) from None


def make_executor(
    kind: str, *, workers: int = 1, address: str | None = None, env_keys: tuple[str, ...] = ()
) -> Any:
    """The executor `--executor KIND` names (checked first; see `check_executor`).

    `workers` sizes the local pool; for Ray the cluster's resources decide. `env_keys` are
    names of environment variables (API keys) that workers read; on an existing cluster,
    those set here but unset on a worker end up in `executor.missing_env` (never values).
    """
    check_executor(kind, address)
    if kind == "local":
        return LocalExecutor(workers)
    from rover.exec.ray_cluster import RayExecutor

    executor = RayExecutor(address=address, env_keys=env_keys)
    executor.start()  # connect now: an unreachable cluster is refused before any work
    return executor
