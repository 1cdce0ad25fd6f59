"""Worker processes that never outlive the process that started them.

``esp batch --jobs N`` analyses machines in a pool of processes, and a report made with
``jobs`` above 1 draws its PNG files in forked workers (:mod:`esp.volumetric.report`). A worker of a
:class:`concurrent.futures.ProcessPoolExecutor` waits for its next task forever: when its
parent is killed (``kill -9``, the out-of-memory killer) nothing tells it to stop, and it
would stay, adopted by the init process, holding its memory. Every pool of esp is
therefore started with :func:`die_with_parent` as its initializer:

* on Linux the kernel ends the worker with ``SIGKILL`` as soon as its parent dies
  (``prctl(PR_SET_PDEATHSIG)``, called through :mod:`ctypes`);
* everywhere, a daemon thread of the worker checks twice a second whether its parent is
  still the process that started it (:func:`os.getppid`), and ends the worker if not --
  the fallback where ``prctl`` is not available, and a second guard where it is.

And a pool that stops on an error or an interruption has its workers ended at once
(:func:`stop_pool`) instead of waiting for the machines they are still analysing. A pool is
made by :func:`start_pool`, whose workers report their process ids as they start, so that
:func:`stop_pool` finds them among :func:`multiprocessing.active_children` (the executor's
own list of its processes is not public).
:func:`terminate_on_sigterm` turns ``SIGTERM`` of the command into that path: the pool is
stopped, the staged outputs are removed, and esp exits with 143 (128 + 15).

This module imports only the standard library.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import sys
import threading
import weakref
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor
from types import FrameType
from typing import Any, NoReturn

__all__ = [
    "PARENT_POLL_S",
    "SIGTERM_EXIT",
    "die_with_parent",
    "start_pool",
    "stop_pool",
    "terminate_on_sigterm",
]

#: how often a worker checks that its parent is alive (seconds)
PARENT_POLL_S = 0.5
#: the exit code of a command ended by SIGTERM (the shell's 128 + signal number)
SIGTERM_EXIT = 128 + int(signal.SIGTERM)
_PR_SET_PDEATHSIG = 1


def _set_pdeathsig() -> bool:
    """Ask the Linux kernel to send SIGKILL to this process when its parent dies."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _watch(parent: int) -> None:
    event = threading.Event()
    while not event.wait(PARENT_POLL_S):
        if os.getppid() != parent:
            os._exit(1)


def die_with_parent(parent: int | None = None) -> None:
    """The initializer of every worker process of esp: end this process when its parent
    dies (see the module docstring). ``parent`` is the parent's process id (default
    :func:`os.getppid` now); a parent already gone ends the worker at once."""
    parent = os.getppid() if parent is None else parent
    # a forked worker inherits the parent's handler of terminate_on_sigterm: not its own
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    _set_pdeathsig()
    if os.getppid() != parent:  # died before the kernel was asked to tell us
        os._exit(1)
    threading.Thread(target=_watch, args=(parent,), name="esp-parent-watch", daemon=True).start()


#: the queue on which the workers of each pool of :func:`start_pool` report their process ids
_WORKER_IDS: weakref.WeakKeyDictionary[ProcessPoolExecutor, Any] = weakref.WeakKeyDictionary()
#: the child processes that were alive before each pool of :func:`start_pool` was made
_CHILDREN_BEFORE: weakref.WeakKeyDictionary[ProcessPoolExecutor, frozenset[int]] = (
    weakref.WeakKeyDictionary()
)


def start_pool(
    workers: int,
    initializer: Callable[..., None] = die_with_parent,
    initargs: tuple = (),
    mp_context: Any = None,
) -> ProcessPoolExecutor:
    """A :class:`~concurrent.futures.ProcessPoolExecutor` of ``workers`` processes (of
    ``mp_context``, default multiprocessing's) whose each worker first reports its process
    id, for :func:`stop_pool`, then runs ``initializer(*initargs)`` (default
    :func:`die_with_parent` with no argument: the parent is the process that started it)."""
    context = multiprocessing.get_context() if mp_context is None else mp_context
    before = frozenset(p.pid for p in multiprocessing.active_children() if p.pid is not None)
    ids = context.SimpleQueue()
    pool = ProcessPoolExecutor(
        workers, mp_context=context, initializer=_report_id, initargs=(ids, initializer, initargs)
    )
    _WORKER_IDS[pool] = ids
    _CHILDREN_BEFORE[pool] = before
    return pool


def _report_id(ids: Any, initializer: Callable[..., None], initargs: tuple) -> None:
    ids.put(os.getpid())
    initializer(*initargs)


def _workers_of(pool: ProcessPoolExecutor) -> list[Any]:
    """The live worker processes of ``pool``: those whose ids its workers reported, and
    every child process started since the pool was made -- a worker that hangs before it
    reports (a fork that inherited a lock another thread held) is one of them."""
    ids = _WORKER_IDS.get(pool)
    found = set()
    while ids is not None and not ids.empty():
        found.add(ids.get())
    before = _CHILDREN_BEFORE.get(pool, frozenset())
    return [
        p
        for p in multiprocessing.active_children()
        if p.pid in found or (before is not None and p.pid not in before)
    ]


def stop_pool(pool: ProcessPoolExecutor) -> None:
    """End the workers of ``pool`` (made by :func:`start_pool`) now (SIGTERM, then SIGKILL
    after 5 s) and shut it down, its queued tasks cancelled: for an error, an
    interruption or a pool a dead worker broke, where waiting for the tasks still running
    could take minutes, and a worker stuck before it runs Python code (its SIGTERM handler
    never runs) would keep the executor's own shutdown waiting for ever."""
    processes = _workers_of(pool)
    pool.shutdown(wait=False, cancel_futures=True)
    for p in processes:
        with contextlib.suppress(OSError, ValueError, AttributeError):
            p.terminate()
    for p in processes:
        with contextlib.suppress(OSError, ValueError, AttributeError, AssertionError):
            p.join(5.0)
            if p.is_alive():
                p.kill()
                p.join(1.0)
    pool.shutdown(wait=True)


@contextlib.contextmanager
def terminate_on_sigterm() -> Iterator[None]:
    """While inside: SIGTERM raises :class:`SystemExit` (code :data:`SIGTERM_EXIT`) in
    the main thread, so that ``finally`` blocks stop the pools and remove what is staged.
    Does nothing outside the main thread, or when a handler other than the default is
    installed (a program using esp as a library keeps its own)."""
    if (
        threading.current_thread() is not threading.main_thread()
        or signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL
    ):
        yield
        return

    def handler(signum: int, frame: FrameType | None) -> NoReturn:
        signal.signal(signal.SIGTERM, signal.SIG_IGN)  # once: the cleanup is not cut short
        raise SystemExit(SIGTERM_EXIT)

    signal.signal(signal.SIGTERM, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
