"""The local executor: a spawn-context process pool, or plain calls with one worker."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from typing import Any


def _star(job: tuple[Callable[..., Any], tuple]) -> Any:
    fn, args = job
    return fn(*args)


class LocalExecutor:
    """`workers` processes on this machine (1: in this process, no spawn cost, easy to debug).

    Tasks see the same disk as the caller (`shares_files`), so they write their results in
    place. The pool lives from `__enter__` to `__exit__`.
    """

    kind = "local"
    shares_files = True
    remote = False

    def __init__(self, workers: int = 1, initializer: Callable[[], None] | None = None) -> None:
        self.workers = max(1, int(workers))
        self.initializer = initializer
        self._pool: Any = None

    def __enter__(self) -> LocalExecutor:
        if self.workers > 1:
            import multiprocessing as mp

            ctx = mp.get_context("spawn")
            self._pool = ctx.Pool(self.workers, initializer=self.initializer)
        elif self.initializer is not None:
            self.initializer()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        if self._pool is not None:
            self._pool.terminate()  # as `with Pool()` does: every result was read by now
            self._pool.join()
            self._pool = None

    def map_unordered(
        self, fn: Callable[..., Any], jobs: Iterable[tuple], *, num_cpus: float = 1.0
    ) -> Iterator[Any]:
        """`fn(*job)` for every job, results in completion order (`num_cpus` is Ray's)."""
        del num_cpus
        work = [(fn, tuple(job)) for job in jobs]
        if self._pool is None:
            return map(_star, work)
        return self._pool.imap_unordered(_star, work)

    def put(self, obj: Any) -> Any:
        """A handle tasks can take instead of `obj` (locally: `obj` itself)."""
        return obj
