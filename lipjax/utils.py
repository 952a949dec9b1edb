"""Small process-level helpers: the persistent compilation cache, the CPU cores a process runs on, a process of a
multi-process run, files written whole."""
from __future__ import annotations

import contextlib
import contextvars
import os
import pathlib
import sys
import warnings
from collections.abc import Callable, Iterator
from typing import TypeVar

import jax

T = TypeVar("T")


def enable_compilation_cache(path: str | os.PathLike | None = None) -> pathlib.Path:
    """Turns on JAX's persistent compilation cache (jit of a model fell from ~24 s to ~2 s on a second run here).

    The folder defaults to $LIPJAX_CACHE_DIR or ~/.cache/lipjax/jax. Called by the CLI, the experiments and the
    tests; a library import never changes global JAX settings by itself.
    """
    path = pathlib.Path(path or os.environ.get("LIPJAX_CACHE_DIR") or pathlib.Path.home() / ".cache/lipjax/jax")
    path.mkdir(parents=True, exist_ok=True)
    jax.config.update("jax_compilation_cache_dir", str(path))
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.5)
    return path


_HELD_BACK: contextvars.ContextVar[list | None] = contextvars.ContextVar("lipjax_held_back_warnings", default=None)


def warn_user(message: str, category: type[Warning] = UserWarning) -> None:
    """warnings.warn pointing at the first caller outside the lipjax package (the user's line, whatever chain of
    library calls and closures led to the warning; Python 3.12's `skip_file_prefixes`, by hand for 3.11). Within
    `holding_warnings_back` the warning is kept for the caller instead."""
    held = _HELD_BACK.get()
    if held is not None:
        held.append((message, category))
        return
    package = os.path.dirname(os.path.abspath(__file__)) + os.sep
    frame, level = sys._getframe(1), 2
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(package):
        frame, level = frame.f_back, level + 1
    warnings.warn(message, category, stacklevel=level)


def holding_warnings_back(fn: Callable[..., T], *args, **kwargs) -> tuple[T, list[tuple[str, type[Warning]]]]:
    """(fn(*args, **kwargs), the (message, category) of every `warn_user` warning it gave, not shown): for work in
    a thread of its own, whose warnings its caller shows from its own thread (at the user's line, where Python's
    registry shows each once) by passing them to `warn_user` again."""
    held: list[tuple[str, type[Warning]]] = []
    token = _HELD_BACK.set(held)
    try:
        return fn(*args, **kwargs), held
    finally:
        _HELD_BACK.reset(token)


def die_with_parent() -> None:
    """Asks Linux to send this process SIGTERM when its parent dies, even by SIGKILL (prctl PR_SET_PDEATHSIG), so
    that a worker process never outlives the run that started it; elsewhere does nothing."""
    if sys.platform == "linux":
        import ctypes
        import signal

        ctypes.CDLL(None).prctl(1, signal.SIGTERM)  # 1 = PR_SET_PDEATHSIG


def exit_when_orphaned(poll_s: float = 0.5) -> None:
    """Ends this process (exit status 0, no cleanup) once its parent has died, e.g. by SIGKILL: a daemon thread checks
    every `poll_s` seconds whether the parent pid changed. For worker processes whose parent stops them gracefully
    otherwise (PR_SET_PDEATHSIG would fire on the exit of the parent's creating thread, not of the process)."""
    import threading
    import time

    parent = os.getppid()

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(poll_s)
        os._exit(0)

    threading.Thread(target=watch, name="exit-when-orphaned", daemon=True).start()


def limit_cpu_threads(n: int) -> set[int]:
    """Runs this process on `n` CPU cores: pins every thread of it (and so every thread it starts later) to `n` of
    the cores it may use now, as `taskset` does (Linux), and sets OpenCV's thread count to `n`. Returns the cores.

    XLA sizes its CPU thread pools by the cores the process may use when JAX first runs a computation: called
    before that, this also sizes them to `n`; called later, the pools keep their size and share the `n` cores.
    (Measured with jax 0.10.2: XLA_FLAGS="--xla_cpu_multi_thread_eigen=false intra_op_parallelism_threads=1"
    changes neither the pools nor their use of the cores; there is no other thread setting for XLA's CPU client.)
    Where threads cannot be pinned (not Linux) it warns and limits OpenCV's threads only.
    """
    import cv2

    if n < 1:
        raise ValueError(f"--threads {n}: give a number of CPU cores >= 1")
    cv2.setNumThreads(n)
    if not sys.platform.startswith("linux"):
        warnings.warn("this system cannot pin threads to cores: --threads limits OpenCV's threads only; use the "
                      "system's own CPU limits for the rest", stacklevel=2)
        return set()
    cores = set(sorted(os.sched_getaffinity(0))[:n])
    for thread in os.listdir("/proc/self/task"):
        with contextlib.suppress(OSError):  # a thread that ended meanwhile
            os.sched_setaffinity(int(thread), cores)
    return cores


def start_processes(coordinator: str | None = None, num_processes: int | None = None,
                    process_id: int | None = None) -> None:
    """Makes this process one of a run of several processes (hosts), before any other JAX call:
    jax.distributed.initialize with the coordinator's address ("host:port" of process 0), the number of processes
    and this one's index; each left None is read from the cluster's environment by JAX (SLURM, Open MPI,
    Kubernetes, Cloud TPU). On CPU the processes reduce over gloo."""
    jax.config.update("jax_cpu_collectives_implementation", "gloo")
    jax.distributed.initialize(coordinator_address=coordinator, num_processes=num_processes, process_id=process_id)


@contextlib.contextmanager
def written_whole(path: str | os.PathLike) -> Iterator[pathlib.Path]:
    """Yields a temporary path beside `path` (parent folders created), ending like it (".npy", ".color.png": the
    writers choose the format by it), and renames it to `path` once the block has written it. On an error or an
    interrupt the temporary file is removed and `path` is left as it was: no reader ever sees half a file."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f".partial-{os.getpid()}-{path.name}")
    try:
        yield temporary
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)
