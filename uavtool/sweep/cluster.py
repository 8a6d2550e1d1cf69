"""Where tasks run: a Dask ``LocalCluster`` of worker processes sized to the machine (one
single-threaded worker per core: flights are CPU-bound Python), or any running Dask
scheduler given by address (``dask scheduler`` plus ``dask worker`` elsewhere, or any Dask
deployment). Nothing else about a sweep changes with the cluster. The local cluster speaks TLS
with credentials made for it alone, so no other local process can run code on it. Its workers
do not die of Ctrl-C (:mod:`~uavtool.sweep.interrupt`): the driver stops the sweep and closes
the client, then the cluster, without Dask's logs of the interrupted work."""

from __future__ import annotations

import logging
import os
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from typing import TYPE_CHECKING

from uavtool.errors import InputError
from uavtool.sweep.interrupt import PRELOAD, QuietLogs, quiet_on_sigint, sigint_ignored

if TYPE_CHECKING:
    from distributed import Client, LocalCluster


def default_workers() -> int:
    """One worker per core this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


LOCAL_DASHBOARD = "127.0.0.1:0"
"""Where the local cluster's dashboard listens unless the user asks: this machine only (it
shows the workers, their logs and call stacks, and the scheduler's address), a free port."""
_HOST_PORT_SCHEMES = ("tcp", "tls", "ws", "wss")


def check_cluster_options(
    scheduler: str | None, *, workers: int | None = None, dashboard: str | None = None
) -> None:
    """Raise InputError, without connecting to anything, unless ``scheduler`` reads as a Dask
    scheduler address (``tcp://HOST:PORT``, or ``HOST:PORT``) and the options fit together."""
    if scheduler is None:
        if dashboard is not None:
            _host_port(dashboard, "--dashboard", "127.0.0.1:8787")
        if workers is not None and workers < 1:
            raise InputError(f"--workers must be ≥ 1, got {workers}")
        return
    if workers is not None:
        raise InputError("--workers sizes the local cluster; with --scheduler, start workers there")
    if dashboard is not None:
        raise InputError(
            "--dashboard is the local cluster's; with --scheduler, it is the scheduler's"
        )
    from distributed.comm.addressing import parse_address  # noqa: PLC0415

    try:
        scheme, location = parse_address(scheduler)
    except ValueError as exc:
        raise InputError(f"--scheduler {scheduler!r}: {exc}; e.g. tcp://HOST:8786") from None
    if scheme in _HOST_PORT_SCHEMES:
        _host_port(location, "--scheduler", "tcp://HOST:8786", shown=scheduler)


def _host_port(text: str, option: str, example: str, *, shown: str | None = None) -> None:
    host, sep, port = text.rpartition(":")
    host = host.removeprefix("[").removesuffix("]")
    ok = sep and host and not any(c.isspace() for c in host) and port.isdigit()
    if not ok or not 0 <= int(port) <= 65535:
        raise InputError(
            f"{option} {shown or text!r}: expected HOST:PORT with a port 0-65535, e.g. {example}"
        )


def _refused(scheduler: str) -> None:
    """Raise InputError at once when nothing listens at a tcp:// or tls:// scheduler's
    address (the machine answers "refused"): Dask would try again for its whole timeout.
    Anything else (no answer at all, a name that does not resolve) is left to Dask."""
    import socket  # noqa: PLC0415

    from distributed.comm.addressing import parse_address, parse_host_port  # noqa: PLC0415

    try:
        scheme, location = parse_address(scheduler)
        if scheme not in ("tcp", "tls"):
            return
        host, port = parse_host_port(location)
    except (ValueError, TypeError):
        return  # Dask says what is wrong with it
    try:
        with socket.create_connection((host, port), timeout=5.0):
            return
    except ConnectionRefusedError:
        raise InputError(
            f"--scheduler {scheduler}: cannot connect: nothing listens on {host}:{port} "
            "(connection refused); start the scheduler there (dask scheduler) or give its "
            "address"
        ) from None
    except OSError:
        return


@contextmanager
def open_client(
    scheduler: str | None = None, *, workers: int | None = None, dashboard: str | None = None
) -> Iterator[Client]:
    """A connected client; a LocalCluster (closed on exit, its dashboard on ``dashboard``,
    default ``LOCAL_DASHBOARD``) unless ``scheduler`` is given. Raises InputError for a bad
    address or when the scheduler cannot be reached."""
    from distributed import Client, LocalCluster  # noqa: PLC0415

    check_cluster_options(scheduler, workers=workers, dashboard=dashboard)
    _quiet_dask()
    if scheduler is not None:
        # The user's scheduler: its address and Dask's own configuration say how to reach it
        # (a tls:// one takes its credentials from distributed.comm.tls.*).
        no_credentials = InputError(
            f"--scheduler {scheduler}: cannot connect: a tls:// scheduler needs TLS "
            "credentials in Dask's configuration (distributed.comm.tls.*)"
        )
        if scheduler.startswith("tls://") and not _tls_credentials():
            # Checked first: a Client that fails in its constructor for want of them can
            # hang when it is collected (distributed's LoopRunner lock).
            raise no_credentials
        _refused(scheduler)
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError(f"--scheduler {scheduler}: cannot connect: {exc}") from None
        except TypeError:  # distributed's word for incomplete TLS credentials
            raise no_credentials from None
        with _closing(client):
            yield client
        return
    n = workers if workers is not None else default_workers()
    # The workers must not hear the terminal's Ctrl-C: see uavtool.sweep.interrupt.
    with sigint_ignored():
        cluster = LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            # No fixed port by default: several clusters may run at once.
            dashboard_address=dashboard or LOCAL_DASHBOARD,
            silence_logs=logging.ERROR,
            preload=[PRELOAD],
            # TLS with credentials made for this cluster alone (Dask's Security.temporary, in
            # memory, passed to the workers it starts): another local process that finds the
            # scheduler's port cannot run code on it.
            security=True,
        )
    try:
        client = Client(cluster)
    except BaseException:
        cluster.close()
        raise
    with _closing(client, cluster):
        yield client


def _tls_credentials() -> bool:
    """Whether Dask's configuration names a CA and a client certificate and key."""
    from distributed.security import Security  # noqa: PLC0415 — heavy; sweeps only

    security = Security()  # its fields are set from the configuration at run time
    names = ("tls_ca_file", "tls_client_cert", "tls_client_key")
    return all(getattr(security, name, None) for name in names)


CLOSE_TIMEOUT_S = 10.0
"""How long closing the client, then the local cluster, may take after Ctrl-C: a worker busy
with a flight is stopped rather than waited for."""


@contextmanager
def _closing(client: Client, cluster: LocalCluster | None = None) -> Iterator[None]:
    """Close ``client``, then ``cluster``, when the block ends. After Ctrl-C that happens with
    Dask's logs quiet (its errors about the interrupted tasks and closed connections are
    expected then) and a short timeout, and the logs' levels are put back after."""
    logs = QuietLogs()
    try:
        with quiet_on_sigint(logs):
            yield
    except KeyboardInterrupt:
        logs.quiet()
        try:
            with suppress(Exception):
                client.close(timeout=CLOSE_TIMEOUT_S)
            if cluster is not None:
                with suppress(Exception):
                    cluster.close(timeout=CLOSE_TIMEOUT_S)
        finally:
            logs.restore()
        raise
    except BaseException:
        _close(client, cluster)
        raise
    _close(client, cluster)


def _close(client: Client, cluster: LocalCluster | None) -> None:
    try:
        client.close()
    finally:
        if cluster is not None:
            cluster.close()


def _quiet_dask() -> None:
    """distributed sets its loggers to INFO when imported: its start-up and shutdown chatter
    would bury the progress line. Keep it only when the user asked for -v."""
    root = logging.getLogger().getEffectiveLevel()
    logging.getLogger("distributed").setLevel(root if root <= logging.INFO else logging.ERROR)
