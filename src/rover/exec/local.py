"""The local executor: a spawn-context process pool, or plain calls with one worker."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from typing import Any

from rover.errors import RoverError


def _star(job: tuple[Callable[..., Any], tuple]) -> Any:
    fn, args = job
    return fn(*args)


class LocalExecutor:
    """`workers` processes on this machine (1: in this process, no spawn cost, easy to debug).

    Tasks see the same disk as the caller (`shares_files`), so they write their results in
    place. The pool lives from `__enter__` to `__exit__`. It is a `ProcessPoolExecutor`,
    not a `multiprocessing.Pool`: when a worker dies (killed, out of memory) the pool is
    marked broken and the run stops with an error, where `Pool.imap_unordered` waited
    forever for the result the dead worker would never send.
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
            from concurrent.futures import ProcessPoolExecutor

            self._pool = ProcessPoolExecutor(
                self.workers, mp_context=mp.get_context("spawn"), initializer=self.initializer
            )
        elif self.initializer is not None:
            self.initializer()
        return self

    def __exit__(self, exc_type: object, *exc: object) -> None:
        self.close(abort=exc_type is not None)

    def close(self, abort: bool = True) -> None:
        """Stop the pool; `abort` (an error or Ctrl-C) also stops work in progress (its
        finished results are on disk already: a rerun resumes from them)."""
        if self._pool is None:
            return
        pool, self._pool = self._pool, None
        procs = list(getattr(pool, "_processes", {}).values()) if abort else []
        pool.shutdown(wait=not abort, cancel_futures=True)
        for p in procs:  # (shutdown does not stop tasks already running)
            if p.is_alive():
                p.terminate()
        for p in procs:
            p.join(timeout=10)

    def map_unordered(
        self, fn: Callable[..., Any], jobs: Iterable[tuple], *, num_cpus: float = 1.0
    ) -> Iterator[Any]:
        """`fn(*job)` for every job, results in completion order (`num_cpus` is Ray's)."""
        del num_cpus
        work = [(fn, tuple(job)) for job in jobs]
        if self._pool is None:
            return map(_star, work)
        return self._results([self._pool.submit(_star, w) for w in work])

    @staticmethod
    def _results(futures: list) -> Iterator[Any]:
        from concurrent.futures import as_completed
        from concurrent.futures.process import BrokenProcessPool

        try:
            for fut in as_completed(futures):
                yield fut.result()
        except BrokenProcessPool:
            raise RoverError(
                "a worker process died (killed, or out of memory?); finished work is kept: "
                "rerun the same command to resume, with fewer --workers if memory is short"
            ) from None

    def put(self, obj: Any) -> Any:
        """A handle tasks can take instead of `obj` (locally: `obj` itself)."""
        return obj
