"""The matrix on Dask (``dask.distributed``): one task per sequence, on a local cluster of
``workers`` processes with one thread each (so that BLAS and the factorisations do not
oversubscribe the cores) or on an existing cluster at ``scheduler``. Every task writes only its
own partition of the store; the driver consolidates as tasks finish. A task whose worker dies is
rerun by Dask and rewrites the same partition, so nothing is lost or duplicated. References are
built by the driver before any task starts (``run.prepare_truths``); tasks load them from the
cache, which must be shared storage for a remote cluster (``--cache``)."""

from __future__ import annotations

import asyncio
import logging
import os
import signal
import socket
import threading
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from urllib.parse import urlsplit

from bench.matrix.plugins import load_plugins
from bench.matrix.scene_files import load_scene_files
from bench.matrix.spec import SequenceSpec
from bench.matrix.store import ResultStore, SequenceWriter
from bench.matrix.task import Outcome, run_spec
from bench.sequence.memory import available_gib
from bench.truth import truth_for
from estimators import guaranteed_estimators

SINGLE_THREAD = {name: "1" for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS",
                                        "MKL_NUM_THREADS")}
WORKER_LOGGING = {"DASK_LOGGING__DISTRIBUTED": "error"}
SCHEDULER_TIMEOUT = 10.0  # seconds to wait for a scheduler to answer before refusing the run
SCHEDULER_SCHEMES = ("tcp", "tls")
EXPECTED_ADDRESS = "SCHEME://HOST:PORT with SCHEME tcp or tls, e.g. tcp://10.0.0.5:8786"


class SchedulerError(ValueError):
    """A --scheduler address that is malformed or where no scheduler answers."""


def scheduler_endpoint(address: str) -> tuple[str, int]:
    """(host, port) of a Dask scheduler address; SchedulerError if it is not one."""
    parts = urlsplit(address if "://" in address else f"tcp://{address}")
    try:
        port = parts.port
    except ValueError:
        port = None
    if parts.scheme not in SCHEDULER_SCHEMES or not parts.hostname or port is None \
            or parts.path not in ("", "/") or not 0 < port < 65536:
        raise SchedulerError(f"scheduler={address!r} is not a Dask scheduler address; "
                             f"expected {EXPECTED_ADDRESS}")
    return parts.hostname, port


def check_scheduler(address: str, timeout: float = SCHEDULER_TIMEOUT) -> None:
    """Refuse (SchedulerError) an address where no Dask scheduler completes a Dask handshake
    (its ``identity``) within ``timeout`` seconds, before any work starts: a port that
    accepts and never answers, or answers in another protocol, is refused too."""
    host, port = scheduler_endpoint(address)
    try:  # a refused connection fails at once (Dask's own connect retries until the timeout)
        socket.create_connection((host, port), timeout=timeout).close()
        identity = asyncio.run(asyncio.wait_for(_identity(address, timeout), timeout))
    except Exception as error:  # a peer speaking another protocol fails in many ways
        reason = "no answer" if isinstance(error, TimeoutError) \
            else f"{type(error).__name__}: {error}"
        raise SchedulerError(f"scheduler={address!r}: no Dask scheduler answered ({reason}; "
                             f"waited at most {timeout:g} s); expected the address of a "
                             f"running scheduler, {EXPECTED_ADDRESS}") from None
    if not isinstance(identity, dict) or identity.get("type") != "Scheduler":
        kind = identity.get("type") if isinstance(identity, dict) else type(identity).__name__
        raise SchedulerError(f"scheduler={address!r} answers as {kind!r}, not as a Dask "
                             f"scheduler; expected {EXPECTED_ADDRESS}")


async def _identity(address: str, timeout: float):
    """The ``identity`` of the Dask server at ``address`` (a Dask handshake)."""
    from distributed.core import rpc

    server = rpc(address, timeout=timeout)
    try:
        return await server.identity()
    finally:
        await server.close_rpc()


def sequence_task(spec: SequenceSpec, out: str, run: dict, cache: str | None,
                  max_memory_gib: float | None, scene_files: tuple[str, ...] = ()) -> Outcome:
    """One sequence on a worker: its rows go to its own partition as they finish (the user's
    plugins and scene files imported first, as in the driver)."""
    load_plugins()
    load_scene_files(scene_files)
    writer = SequenceWriter(Path(out) / "sequences" / f"{spec.key}.parquet")
    rows = []

    def record(result) -> None:
        writer.append(result.row)
        rows.append(result.row)

    end = run_spec(spec, run, out, lambda scene: truth_for(scene, spec.reference_dofs,
                                                           spec.max_dofs, spec.order,
                                                           cache=cache),
                   record, max_memory_gib)
    writer.finish(end)
    return Outcome(spec.key, end, tuple(replace(r, sequence_end=end) for r in rows))


@contextmanager
def interrupt_ignored():
    """SIGINT ignored while the worker processes start, which keep it (an ignored signal stays
    ignored across exec): Ctrl-C reaches the whole process group, and the driver alone ends
    the run (``cluster.close`` stops the workers), in one line instead of a traceback per
    worker. SIGTERM and SIGHUP stay the driver's: a Ctrl-C while the cluster starts (about
    two seconds) is the one signal lost."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    saved = signal.signal(signal.SIGINT, signal.SIG_IGN)
    # the workers read their logging level when they import dask: only errors, so that a
    # worker ended with the run does not log its closed connections
    quiet = {name: os.environ.get(name) for name in WORKER_LOGGING}
    os.environ.update(WORKER_LOGGING)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, saved)
        for name, value in quiet.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


def client_for(config):
    """A client of the cluster at ``config.scheduler``, or of a new local cluster."""
    from dask.distributed import Client, LocalCluster

    if config.scheduler:
        return Client(config.scheduler, timeout=SCHEDULER_TIMEOUT), None
    try:
        with interrupt_ignored():  # the workers inherit it: the driver alone answers Ctrl-C
            cluster = LocalCluster(n_workers=config.workers, threads_per_worker=1,
                                   processes=True, env=SINGLE_THREAD, dashboard_address=":0",
                                   silence_logs=logging.ERROR)
        client = Client(cluster)
    except BaseException:  # a signal while the cluster starts: its half-started tasks'
        # errors would print as tracebacks when collected; the run ends in one line instead
        logging.getLogger("asyncio").setLevel(logging.CRITICAL)
        raise
    print(f"Dask dashboard: {client.dashboard_link}", flush=True)
    return client, cluster


def expected_work(spec: SequenceSpec) -> tuple:
    """A rough order of a sequence's cost, so that the longest start first and the last
    minutes of a run are not one worker finishing a long sequence alone: the order, then a
    guaranteed bound's estimator (its local problems dominate), then the DOF budget."""
    return (spec.order, spec.estimator in guaranteed_estimators(), spec.max_dofs)


def run_on_dask(specs: list[SequenceSpec], store: ResultStore, run: dict, config,
                on_sequence=None) -> list:
    """Run ``specs`` as Dask tasks; returns the rows they computed."""
    from dask.distributed import as_completed

    client, cluster = client_for(config)
    workers = max(len(client.scheduler_info()["workers"]), 1)
    memory = config.max_memory_gib
    if memory is None and not config.scheduler:  # the local workers share this machine
        memory = available_gib() / workers
    # the driver's cache folder, given to each task (None: each worker's own default)
    cache = config.cache if config.cache is not None else os.environ.get("SIGNORINI_BENCH_CACHE")
    try:
        files = tuple(str(Path(f).expanduser().resolve()) for f in config.scene_files)
        futures = {client.submit(sequence_task, spec, str(store.out), run, cache, memory, files,
                                 key=f"sequence-{spec.key}-{run['run_id']}", pure=False): spec
                   for spec in sorted(specs, key=expected_work, reverse=True)}
        rows = []
        for future in as_completed(futures):
            outcome = future.result()
            rows += outcome.rows
            store.finish(outcome.key, outcome.end)
            if on_sequence is not None:
                on_sequence(futures[future], outcome.end)
        return rows
    finally:  # closing after a signal logs the connections it cuts: only errors are news
        logger = logging.getLogger("distributed")
        level = logger.level
        logger.setLevel(logging.ERROR)
        try:
            client.close()
            if cluster is not None:
                cluster.close()
        finally:
            logger.setLevel(level)
