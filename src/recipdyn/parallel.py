"""Process pools that stop cleanly: the execution helpers under sweeps and the reproduction.

* Workers ignore SIGINT: Ctrl-C reaches the whole foreground process group, and only the
  coordinating process decides what to keep; it then cancels pending work and terminates the
  workers ([`stop_pool`][recipdyn.parallel.stop_pool]).
* Workers notice when their parent dies, even by ``kill -9``: on Linux the kernel sends them
  SIGKILL (``prctl(PR_SET_PDEATHSIG)``), and everywhere a watchdog thread exits the worker when
  its parent process id changes.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterable
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from typing import Any

__all__ = ["process_pool", "stop_pool", "worker_init", "run_unordered"]

_WATCH_INTERVAL = 0.5  # s between parent checks of the watchdog


def _die_with_parent_linux() -> None:
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        PR_SET_PDEATHSIG = 1
        libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except Exception:  # pragma: no cover - not Linux or no libc: the watchdog remains
        pass


def _watch_parent(parent: int) -> None:
    while True:
        time.sleep(_WATCH_INTERVAL)
        if os.getppid() != parent:
            os._exit(1)  # the coordinator is gone: nobody will collect our result


def worker_init(parent: int | None = None) -> None:
    """Initializer of every worker process (see the module docstring)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    parent = os.getppid() if parent is None else parent
    if sys.platform.startswith("linux"):
        _die_with_parent_linux()
    if os.getppid() != parent:  # the parent died before we got here
        os._exit(1)
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True).start()


def process_pool(workers: int) -> ProcessPoolExecutor:
    """A ``ProcessPoolExecutor`` whose workers run
    [`worker_init`][recipdyn.parallel.worker_init]."""
    return ProcessPoolExecutor(max_workers=workers, initializer=worker_init,
                               initargs=(os.getpid(),))  # fmt: skip


def stop_pool(pool: ProcessPoolExecutor, timeout: float = 5.0) -> None:
    """Cancel pending work and end the workers now (running tasks are abandoned)."""
    procs = list(getattr(pool, "_processes", {}).values())  # no public handle in Python 3.11
    pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        if p.is_alive():
            p.terminate()
    deadline = time.monotonic() + timeout
    for p in procs:
        p.join(max(0.0, deadline - time.monotonic()))
        if p.is_alive():  # pragma: no cover - a worker stuck in compiled code ignoring SIGTERM
            p.kill()
            p.join(1.0)


#: How often (s) the coordinator looks for a signal while waiting for workers.
POLL = 0.2


def _with_warnings(fn: Callable[[Any], Any], task: Any) -> tuple[Any, list]:
    """``fn(task)`` in a worker, and the warnings it raised (category and text): they are
    raised again in the coordinating process, which says them (the workers' own standard
    error would print them with their source lines in the middle of its progress bars)."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:  # (the worker's filters apply)
        result = fn(task)
    return result, [(w.category, str(w.message), w.filename, w.lineno) for w in caught]


def _raise_again(caught: list, registry: dict) -> None:
    """Raise a worker's warnings here, where they were raised there (file and line: this
    process's filters see the same origin); ``registry``: one run's, so each is said once."""
    import warnings

    for category, text, filename, lineno in caught:
        warnings.warn_explicit(text, category, filename, lineno, registry=registry)


def run_unordered(fn: Callable[[Any], Any], tasks: Iterable, workers: int,
                  on_result: Callable[[Any], None], pending) -> None:  # fmt: skip
    """``fn(task)`` for every task on a pool of ``workers`` processes.

    ``on_result`` runs in this process as each result arrives (any order); at most two tasks
    per worker are queued (bounded memory for huge task lists); ``pending.check()`` (from
    [`recipdyn.errors.deferred_signals`][recipdyn.errors.deferred_signals]) runs between results, so
    a signal stops the work promptly. On any exception or interruption the pool is stopped
    ([`stop_pool`][recipdyn.parallel.stop_pool]). The warnings a task raises in its worker are
    raised again here, before its result is handed on (`_with_warnings`).
    """
    pool = process_pool(workers)
    registry: dict = {}
    try:
        it = iter(tasks)
        in_flight: set = set()
        exhausted = False
        while True:
            while not exhausted and len(in_flight) < 2 * workers:
                try:
                    in_flight.add(pool.submit(_with_warnings, fn, next(it)))
                except StopIteration:
                    exhausted = True
            if not in_flight:
                break
            finished, in_flight = wait(in_flight, timeout=POLL, return_when=FIRST_COMPLETED)
            for fut in finished:
                result, caught = fut.result()
                _raise_again(caught, registry)
                on_result(result)
            pending.check()
    except BaseException:
        stop_pool(pool)
        raise
    pool.shutdown(wait=True)
