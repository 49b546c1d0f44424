"""The Ray executor: episodes and work units as Ray tasks, on a local or existing cluster.

Tasks never write into the driver's output directory: a Ray worker may run on a node that
does not mount it, so every task returns its results (bytes, or the pydantic objects the
local code would have saved) and the driver writes them with the same atomic temp+rename
the local executor uses. Inputs travel through the object store (`put`), so worker nodes
need rover installed but no shared filesystem. API keys never travel at all: workers
read them from their own environment. A local Ray inherits the driver's; an existing
cluster's nodes must have them set (not forwarded through Ray's runtime environment,
because Ray's runtime-env agent writes those values into its log files on every node).
"""

from __future__ import annotations

import asyncio
import logging
import os
from collections.abc import Callable, Iterable, Iterator
from typing import Any

from rover.errors import InputError, RoverError

# A work unit of `rover eval` mostly waits on its VLM endpoint: half a CPU each lets two
# units share a core; endpoint budgets (below), not CPUs, bound the calls in flight.
EVAL_UNIT_CPUS = 0.5
# passed to workers on an existing cluster when set here (offscreen rendering; no secrets)
FORWARDED_ENV = ("MUJOCO_GL", "PYOPENGL_PLATFORM")


def unset_names(names: tuple[str, ...]) -> list[str]:
    """Which of these environment variables are unset here (names only, never values)."""
    return [n for n in names if not os.environ.get(n)]


class EndpointBudget:
    """A cluster-wide semaphore for one VLM endpoint (run as an async Ray actor).

    Every worker's calls to that endpoint take a permit first, so a cluster of any size
    keeps at most `permits` calls in flight, as one process with `--calls-in-flight` does.
    """

    def __init__(self, permits: int) -> None:
        self.permits = max(1, int(permits))
        self._sem: asyncio.Semaphore | None = None
        self.peak = 0
        self._held = 0

    def _semaphore(self) -> asyncio.Semaphore:
        if self._sem is None:  # made on the actor's own event loop
            self._sem = asyncio.Semaphore(self.permits)
        return self._sem

    async def acquire(self) -> None:
        await self._semaphore().acquire()
        self._held += 1
        self.peak = max(self.peak, self._held)

    async def release(self) -> None:
        self._held -= 1
        self._semaphore().release()

    async def stats(self) -> dict[str, int]:
        return {"permits": self.permits, "held": self._held, "peak": self.peak}


def _task_error(exc: BaseException) -> BaseException:
    """The user's exception a Ray task raised, or one line naming a Ray failure."""
    import ray

    if isinstance(exc, ray.exceptions.RayTaskError):
        cause = getattr(exc, "cause", None)
        if isinstance(cause, Exception) and not isinstance(cause, ray.exceptions.RayError):
            return cause
    first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    return RoverError(f"a Ray task failed: {first[:300]}")


def _check_reachable(address: str) -> None:
    """A host:port that refuses connections fails in seconds (Ray itself waits minutes)."""
    import socket

    if address == "auto":
        return  # Ray finds the local cluster's address itself, and says if there is none
    hostport = address.split("://", 1)[-1].rstrip("/")
    host, _, port = hostport.rpartition(":")
    if not host or not port.isdigit():
        raise InputError(
            f"--ray-address {address!r}: give 'auto' or host:port (e.g. 10.0.0.5:6379)"
        )
    try:
        socket.create_connection((host, int(port)), timeout=5).close()
    except OSError as exc:
        raise InputError(f"--ray-address {address}: no Ray cluster answers there ({exc})") from None


class RayExecutor:
    """Runs tasks on Ray: a fresh local instance (no address, no `RAY_ADDRESS`) or a cluster.

    If Ray is already initialised in this process (a notebook, a test session), that
    session is used and left running on close.
    """

    kind = "ray"
    shares_files = False
    remote = True

    def __init__(
        self,
        address: str | None = None,
        env_keys: Iterable[str] = (),
        num_cpus: int | None = None,
    ) -> None:
        # RAY_ADDRESS is Ray's own default (a `ray job submit` job has it set): honoured
        self.address = address or os.environ.get("RAY_ADDRESS") or None
        self.env_keys = tuple(env_keys)
        # key variables set here but not on a cluster worker (filled in by `start`)
        self.missing_env: list[str] = []
        self.num_cpus = num_cpus
        self._owns = False
        self._started = False
        self._depth = 0
        self._remotes: dict[tuple[Callable[..., Any], float], Any] = {}
        self._budgets: dict[str, Any] = {}

    # --- lifecycle --------------------------------------------------------------------
    def __enter__(self) -> RayExecutor:
        self.start()
        self._depth += 1
        return self

    def __exit__(self, *exc: object) -> None:
        self._depth -= 1
        if self._depth <= 0:  # nested `with` blocks (a caller's and generate's) share one Ray
            self.close()

    def start(self) -> None:
        import ray

        if self._started:
            return
        self._started = True
        if ray.is_initialized():
            return
        kwargs: dict[str, Any] = {
            "include_dashboard": False,
            "logging_level": logging.WARNING,
        }
        if self.address:
            _check_reachable(self.address)
            env = {k: os.environ[k] for k in FORWARDED_ENV if os.environ.get(k)}
            if env:
                kwargs["runtime_env"] = {"env_vars": env}
            kwargs["address"] = self.address
        else:  # always a new instance, even if this machine also belongs to a cluster
            kwargs["address"] = "local"
            if self.num_cpus is not None:
                kwargs["num_cpus"] = self.num_cpus
        try:
            ray.init(**kwargs)
        except (ConnectionError, RuntimeError, ValueError) as exc:
            line = str(exc).strip().splitlines()[0][:200] if str(exc).strip() else ""
            what = (
                f"--ray-address {self.address}: cannot reach"
                if self.address
                else ("--executor ray: cannot start")
            )
            raise InputError(f"{what} Ray ({line})") from None
        self._owns = True
        here = tuple(k for k in self.env_keys if os.environ.get(k))
        if self.address and here:  # a worker of the cluster, asked for names only
            probe = ray.remote(num_cpus=0)(unset_names)
            self.missing_env = ray.get(probe.remote(here))

    def close(self) -> None:
        import ray

        for actor in self._budgets.values():
            ray.kill(actor)
        self._budgets.clear()
        self._remotes.clear()
        if self._owns and ray.is_initialized():
            ray.shutdown()
        self._owns = False
        self._started = False

    # --- work -------------------------------------------------------------------------
    def _remote(self, fn: Callable[..., Any], num_cpus: float) -> Any:
        import ray

        key = (fn, float(num_cpus))
        if key not in self._remotes:
            self._remotes[key] = ray.remote(num_cpus=num_cpus)(fn)
        return self._remotes[key]

    def cluster_cpus(self) -> float:
        import ray

        return float(ray.cluster_resources().get("CPU", 1.0))

    def map_unordered(
        self, fn: Callable[..., Any], jobs: Iterable[tuple], *, num_cpus: float = 1.0
    ) -> Iterator[Any]:
        """`fn(*job)` as Ray tasks of `num_cpus` each; results in completion order.

        At most twice the cluster's CPUs' worth of tasks are submitted ahead, so a run of
        tens of thousands of episodes does not fill the object store with results.
        """
        import ray

        self.start()
        remote = self._remote(fn, num_cpus)
        window = max(4, int(2 * self.cluster_cpus() / max(num_cpus, 1e-3)))
        todo = iter(jobs)
        pending: list[Any] = []

        def top_up() -> None:
            for job in todo:
                pending.append(remote.remote(*job))
                if len(pending) >= window:
                    break

        try:
            top_up()
            while pending:
                done, rest = ray.wait(pending, num_returns=1)
                pending[:] = rest
                top_up()
                try:
                    result = ray.get(done[0])
                except ray.exceptions.RayError as exc:
                    raise _task_error(exc) from None
                yield result
        finally:
            for ref in pending:  # an error or Ctrl-C: nothing keeps running for nobody
                ray.cancel(ref)

    async def call(self, fn: Callable[..., Any], *args: Any, num_cpus: float = 1.0) -> Any:
        """`fn(*args)` as one Ray task, awaited on the caller's event loop."""
        import ray

        self.start()
        ref = self._remote(fn, num_cpus).remote(*args)
        try:
            return await ref
        except asyncio.CancelledError:
            ray.cancel(ref)
            raise
        except ray.exceptions.RayError as exc:
            raise _task_error(exc) from None

    def put(self, obj: Any) -> Any:
        """Store `obj` once in the object store; tasks given the handle receive `obj`."""
        import ray

        self.start()
        return ray.put(obj)

    def budget(self, key: str, permits: int) -> Any:
        """The cluster-wide call budget for endpoint `key` (one actor per key and run)."""
        import ray

        self.start()
        if key not in self._budgets:
            actor_cls = ray.remote(num_cpus=0)(EndpointBudget)
            self._budgets[key] = actor_cls.remote(permits)
        return self._budgets[key]
