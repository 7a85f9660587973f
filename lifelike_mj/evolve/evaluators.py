"""Evaluate batches of candidates: in-process, on a pool of local processes, or on a ray cluster.

Because :meth:`Problem.evaluate` is pure, every executor gives bit-identical fitness arrays; they differ
only in speed. A batch ``X`` of ``n`` rows is split into contiguous chunks (one per worker) and the
results are concatenated in order.
"""

from __future__ import annotations

import concurrent.futures
import multiprocessing
import os
import pickle
import signal
import sys
import time
import warnings
from typing import Any

import numpy as np

from lifelike_mj import checks
from lifelike_mj.errors import UserError
from lifelike_mj.evolve.problem import check_problem

#: Names accepted by :func:`make_evaluator`.
EXECUTORS = ("serial", "process", "ray")


def as_fitness(values: Any, n: int, outputs: int = 1) -> np.ndarray:
    """``values`` as an ``(n,)`` float64 array, or ``(n, outputs)`` for a problem with several outputs
    per row (``problem.n_outputs``, e.g. a parameter sweep); ``ValueError`` if the problem returned a
    different number of values."""
    f = np.asarray(values, dtype=np.float64)
    if f.size != n * outputs:
        want = f"({n},)" if outputs == 1 else f"({n}, {outputs})"
        raise ValueError(f"problem.evaluate returned shape {f.shape} for {n} candidates; expected {want}")
    return f.reshape(n) if outputs == 1 else f.reshape(n, outputs)


def n_outputs(problem: Any) -> int:
    """Values per row that ``problem.evaluate`` returns: its ``n_outputs`` attribute, else 1 (a fitness)."""
    return int(getattr(problem, "n_outputs", 1))


def _limit_threads() -> None:
    """One thread per worker for numba (when installed), so workers do not oversubscribe the cores."""
    try:
        import numba

        numba.set_num_threads(1)
    except Exception:  # numba missing, or its threading layer unavailable: nothing to limit
        pass


class Evaluator:
    """Base of all evaluators: a context manager whose call maps ``X (n, dim)`` to fitness ``(n,)``
    (or to ``(n, problem.n_outputs)`` values for a problem with several outputs per row).

    Counters: ``calls`` (batches evaluated), ``evaluations`` (rows evaluated), ``busy_s`` (wall seconds
    spent inside calls).
    """

    executor = "base"

    def __init__(self, problem: Any, workers: int = 1) -> None:
        dim, _, _ = check_problem(problem, needs_bounds=False)
        self.problem = problem
        self.dim = dim
        self.workers = int(workers)
        self.calls = 0
        self.evaluations = 0
        self.busy_s = 0.0
        self.closed = False

    def __call__(self, X: np.ndarray) -> np.ndarray:
        """Fitness of each row of ``X`` (converted to a C-contiguous ``(n, dim)`` float64 array)."""
        if self.closed:
            raise RuntimeError(f"the {self.executor} evaluator is closed")
        X = np.ascontiguousarray(X, dtype=np.float64)
        if X.ndim != 2 or X.shape[1] != self.dim:
            raise ValueError(f"expected candidates of shape (n, {self.dim}), got {X.shape}")
        n = X.shape[0]
        if n == 0:
            return np.empty(0, dtype=np.float64)
        t0 = time.perf_counter()
        try:
            f = self._evaluate(X)
        finally:
            self.busy_s += time.perf_counter() - t0
        self.calls += 1
        self.evaluations += n
        return as_fitness(f, n, n_outputs(self.problem))

    def _chunks(self, X: np.ndarray) -> list[np.ndarray]:
        """Split ``X`` into ``min(workers, n)`` contiguous chunks of near-equal size."""
        return [np.ascontiguousarray(c) for c in np.array_split(X, min(self.workers, X.shape[0]))]

    def _evaluate(self, X: np.ndarray) -> np.ndarray:  # pragma: no cover - overridden
        raise NotImplementedError

    def close(self) -> None:
        """Release workers (idempotent)."""
        self.closed = True

    def __enter__(self) -> Evaluator:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<{type(self).__name__} workers={self.workers} calls={self.calls} evaluations={self.evaluations}>"


class SerialEvaluator(Evaluator):
    """Evaluate in this process: one ``problem.evaluate(X)`` call per batch."""

    executor = "serial"

    def _evaluate(self, X: np.ndarray) -> np.ndarray:
        return self.problem.evaluate(X)


# --- process pool ----------------------------------------------------------------------------------

_WORKER_PROBLEM: Any = None


def die_with_parent(parent_pid: int) -> None:
    """Make this (worker) process end when ``parent_pid`` does, even if the parent is SIGKILLed and cannot
    shut its pool down: on Linux the kernel sends SIGKILL at the parent's death (``PR_SET_PDEATHSIG``);
    elsewhere, and as a second guard, a daemon thread exits once the parent is gone (checked every 0.5 s)."""
    import threading

    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG = 1
        except (OSError, AttributeError):
            pass
    if os.getppid() != parent_pid:  # the parent died before we got here
        os._exit(1)

    def watch() -> None:
        while os.getppid() == parent_pid:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, name="lifelike-mj-parent-watch", daemon=True).start()


def _process_init(problem: Any, parent_pid: int) -> None:
    """Pool initializer: die with the parent, ignore SIGINT (Ctrl-C is the parent's business), one numba
    thread, keep the problem."""
    global _WORKER_PROBLEM
    die_with_parent(parent_pid)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _limit_threads()
    _WORKER_PROBLEM = problem


def _process_chunk(X: np.ndarray) -> np.ndarray:
    return as_fitness(_WORKER_PROBLEM.evaluate(X), X.shape[0], n_outputs(_WORKER_PROBLEM))


class ProcessEvaluator(Evaluator):
    """Evaluate on a local :class:`concurrent.futures.ProcessPoolExecutor` (``spawn`` start method).

    The problem is sent once to each worker (pool initializer); each batch is split into one contiguous
    chunk per worker. Workers ignore SIGINT, so a Ctrl-C in a terminal interrupts only the parent,
    which then cancels the outstanding chunks; they die with the parent, even a SIGKILLed one
    (:func:`die_with_parent`). As with any ``spawn`` pool, a script that uses it needs the
    usual ``if __name__ == "__main__":`` guard, and the problem's class must be importable by the workers.
    """

    executor = "process"

    def __init__(self, problem: Any, workers: int) -> None:
        super().__init__(problem, workers)
        self._abandoned = False
        self._pool = concurrent.futures.ProcessPoolExecutor(
            max_workers=self.workers, mp_context=multiprocessing.get_context("spawn"),
            initializer=_process_init, initargs=(problem, os.getpid()))

    def _evaluate(self, X: np.ndarray) -> np.ndarray:
        futures = [self._pool.submit(_process_chunk, c) for c in self._chunks(X)]
        try:
            return np.concatenate([fut.result() for fut in futures])
        except concurrent.futures.process.BrokenProcessPool:
            self._abandoned = True
            raise RuntimeError("a worker process of the evaluation pool died (killed, out of memory, or the problem "
                               "could not be rebuilt there); evaluate with executor='serial' to see the cause.") from None
        except BaseException:
            for fut in futures:
                fut.cancel()
            self._abandoned = any(not fut.done() for fut in futures)
            raise

    def close(self) -> None:
        """Shut the pool down: cancel queued chunks; wait for running ones, unless a call was interrupted
        while chunks were still running (Ctrl-C): then the workers are terminated at once."""
        if not self.closed:
            self.closed = True
            if getattr(self, "_abandoned", False):
                for proc in list((getattr(self._pool, "_processes", None) or {}).values()):
                    try:
                        proc.terminate()
                    except Exception:
                        pass
            self._pool.shutdown(wait=True, cancel_futures=True)


# --- ray -----------------------------------------------------------------------------------------

_RAY_THREADS_LIMITED = False


def _ray_chunk(problem: Any, X: np.ndarray) -> np.ndarray:
    global _RAY_THREADS_LIMITED
    if not _RAY_THREADS_LIMITED:
        _limit_threads()
        _RAY_THREADS_LIMITED = True
    return as_fitness(problem.evaluate(X), X.shape[0], n_outputs(problem))


class RayEvaluator(Evaluator):
    """Evaluate on a ray cluster: the problem is put once in the object store, chunks run as remote tasks.

    If ray is not initialised yet, ``ray.init(address=ray_address)`` is called (``None`` starts a local
    cluster) and :meth:`close` shuts it down again; a cluster started by the caller is left running.
    ``workers`` defaults to the cluster's CPU count.
    """

    executor = "ray"

    def __init__(self, problem: Any, workers: int | None, ray_address: str | None) -> None:
        try:
            import ray
        except ImportError as exc:
            raise UserError("the ray executor needs ray, which is not installed (pip install 'lifelike-mj[ray]').") from exc
        self._ray = ray
        self._owns_ray = False
        if not ray.is_initialized():
            check_ray_address(ray_address)
            if ray_address not in (None, "local"):  # give up on a silent address after a stated time
                os.environ.setdefault("RAY_gcs_rpc_server_reconnect_timeout_s", str(int(RAY_CONNECT_TIMEOUT_S)))
            try:
                ray.init(address=ray_address, log_to_driver=False)
            except Exception as exc:  # noqa: BLE001 - ray raises many kinds; the user gets one sentence
                raise UserError(f"could not start or join Ray at {ray_address or 'a new local cluster'} "
                                f"({type(exc).__name__}: {str(exc).splitlines()[0][:160] if str(exc) else ''}).") from None
            self._owns_ray = True
        if workers is None:
            workers = max(1, int(ray.cluster_resources().get("CPU", 1)))
        super().__init__(problem, workers)
        self._problem_ref = ray.put(problem)
        self._remote = ray.remote(_ray_chunk)

    def _evaluate(self, X: np.ndarray) -> np.ndarray:
        refs = [self._remote.remote(self._problem_ref, c) for c in self._chunks(X)]
        try:
            return np.concatenate(self._ray.get(refs))
        except BaseException:
            for ref in refs:
                try:
                    self._ray.cancel(ref)
                except Exception:
                    pass
            raise

    def close(self) -> None:
        """Drop the problem reference; shut ray down if this evaluator started it."""
        if not self.closed:
            self.closed = True
            self._problem_ref = None
            if self._owns_ray and self._ray.is_initialized():
                self._ray.shutdown()


#: Seconds to wait for a Ray cluster's address to answer before giving up.
RAY_CONNECT_TIMEOUT_S = 10.0


def check_ray_address(address: str | None, timeout_s: float = RAY_CONNECT_TIMEOUT_S) -> None:
    """:class:`UserError` unless ``address`` is ``None`` (start a local cluster), ``"auto"``/``"local"``, or
    ``HOST:PORT`` / ``ray://HOST:PORT`` that accepts a connection within ``timeout_s`` seconds (Ray itself
    would retry for minutes without a word)."""
    import socket

    if address is None or address in ("auto", "local"):
        return
    text = address[len("ray://"):] if address.startswith("ray://") else address
    host, _, port = text.rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536 or any(c.isspace() for c in host):
        raise UserError(f"--ray-address must look like HOST:PORT or ray://HOST:PORT (or auto), got {address!r}.")
    try:
        socket.create_connection((host.strip("[]"), int(port)), timeout=timeout_s).close()
    except OSError as exc:
        raise UserError(f"cannot reach the Ray cluster at {address} within {timeout_s:g} s "
                        f"({exc.strerror or type(exc).__name__}).") from None


def pool_problem_error(problem: Any) -> str | None:
    """Why ``problem`` cannot be sent to the workers of a process pool, or ``None`` if it can: it must
    pickle, and its class must be importable in a fresh process (a class defined in a notebook or an
    interactive session is not)."""
    try:
        pickle.dumps(problem)
    except Exception as exc:  # noqa: BLE001 - any pickling failure is the answer
        return f"the problem cannot be pickled ({exc.__class__.__name__}: {str(exc)[:120]})"
    module = type(problem).__module__
    if module == "__main__":
        main = sys.modules.get("__main__")
        if getattr(main, "__file__", None) is None:
            return (f"the problem's class {type(problem).__qualname__} is defined in an interactive session or a "
                    "notebook, where the workers cannot import it (define it in a module)")
    return None


def make_evaluator(problem: Any, executor: str = "process", workers: int | None = None,
                   ray_address: str | None = None) -> Evaluator:
    """An evaluator of ``problem`` on ``executor``: ``"serial"``, ``"process"`` (default) or ``"ray"``.

    ``workers``: number of processes (``process``: default ``os.cpu_count()``) or of chunks per batch
    (``ray``: default the cluster's CPUs); ignored by ``serial``. ``ray_address``: cluster to join when ray
    is not initialised yet (``None``: start a local one). A problem that a process pool cannot take
    (:func:`pool_problem_error`: not picklable, or its class defined in a notebook) is evaluated
    serially instead, with a ``RuntimeWarning`` naming the cause. Raises :class:`UserError` for an
    unknown executor, ``workers < 1``, or ray missing.
    """
    if executor not in EXECUTORS:
        raise UserError(f"unknown executor {executor!r}; known executors are {', '.join(EXECUTORS)}.")
    if workers is not None and (not checks.is_whole(workers) or workers < 1):
        raise UserError(f"workers must be a positive integer, not {workers!r}.")
    if executor == "serial":
        return SerialEvaluator(problem, 1)
    if executor == "process":
        why = pool_problem_error(problem)
        if why is not None:
            warnings.warn(f"evaluating serially in this process: {why}.", RuntimeWarning, stacklevel=2)
            return SerialEvaluator(problem, 1)
        return ProcessEvaluator(problem, int(workers) if workers is not None else (os.cpu_count() or 1))
    return RayEvaluator(problem, None if workers is None else int(workers), ray_address)
