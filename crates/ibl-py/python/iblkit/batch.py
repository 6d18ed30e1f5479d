"""Batches at dataset scale on Dask: ``python -m iblkit.batch SPEC.toml``.

The spec is ``ibl batch``'s (docs/BATCH.md): the probes (a folder, a glob, a list file or a
list of files), the output folder, and the per-probe steps (info, lights, sh, irradiance,
prefilter, preview, eval) with the settings of the ``ibl`` commands of those names. The work
of each probe is one call into the Rust library (``iblkit.batch_run_item``), so its files and
row equal ``ibl batch``'s and the ``ibl`` commands' on the same inputs.

Why Dask (``dask.distributed``) and not Ray: a batch here is an embarrassingly parallel map of
one function over file paths, which ``Client.map`` is; Dask is pure Python (a few MB of wheels
against Ray's ~70 MB and its own object store and raylet daemons), starts a local two-worker
cluster in about a second on two cores, and the same code runs on a multi-machine cluster by
passing ``--scheduler tcp://host:8786`` (workers started with ``dask worker`` on each machine,
all seeing the spec and the probes at the same paths, e.g. on a shared file system).

Restarts: the library writes each probe's ``row.json`` atomically after its files; a probe is
done when its row is there and was made by the same steps, so a killed batch run again does
only the rest, and ``results.jsonl`` (written at the end) holds every probe exactly once.
Failures are rows (``status: failed``, the message, ``error_kind`` bad-input or internal), not
exceptions: the batch goes on.

From Python::

    from iblkit.batch import run
    summary = run("spec.toml", workers=2)           # a local cluster of two worker processes
    summary = run("spec.toml", scheduler="tcp://scheduler:8786")   # an existing cluster
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from typing import Any, Callable, Dict, Optional

from . import _native


def _run_item(spec: str, item: Dict[str, Any]) -> Dict[str, Any]:
    """One probe on a worker: every step, its files and its row (the GIL released)."""
    return _native.batch_run_item(spec, item["id"], item["probe"])


def _set_threads(threads: int) -> None:
    """Runs on each worker before any work: rayon's pool size inside iblkit's loops."""
    os.environ["RAYON_NUM_THREADS"] = str(threads)


def run(
    spec: str,
    workers: int = 2,
    threads_per_worker: Optional[int] = None,
    scheduler: Optional[str] = None,
    retry_failed: bool = False,
    progress: Optional[Callable[[int, int, Dict[str, Any]], None]] = None,
) -> Dict[str, Any]:
    """Runs the batch ``spec`` on Dask and returns the summary (as ``ibl batch --json``).

    ``scheduler``: the address of a running Dask scheduler; without one, a local cluster of
    ``workers`` processes is started (and stopped at the end), each with
    ``threads_per_worker`` threads for iblkit's parallel loops (default: the machine's cores
    shared among the workers). ``progress(done, total, row)`` is called as each probe finishes.
    """
    spec = os.fspath(spec)
    start = time.monotonic()
    plan = _native.batch_plan(spec, retry_failed)
    pending = [item for item in plan["items"] if not item["done"]]
    if pending:
        _map_on_dask(spec, pending, workers, threads_per_worker, scheduler, progress)
    skipped = len(plan["items"]) - len(pending)
    summary = _native.batch_finish(spec, len(pending), skipped)
    summary["seconds"] = time.monotonic() - start
    return summary


def _map_on_dask(
    spec: str,
    pending: list,
    workers: int,
    threads_per_worker: Optional[int],
    scheduler: Optional[str],
    progress: Optional[Callable[[int, int, Dict[str, Any]], None]],
) -> None:
    """Runs the pending items on a local cluster or the scheduler's, as they finish."""
    from dask.distributed import Client, LocalCluster, as_completed

    cluster = None
    if scheduler is None:
        cores = os.cpu_count() or 1
        threads = threads_per_worker or max(1, cores // max(1, workers))
        cluster = LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            env={"RAYON_NUM_THREADS": str(threads)},
        )
        client = Client(cluster)
    else:
        client = Client(scheduler)
        if threads_per_worker:
            client.run(_set_threads, threads_per_worker)
    try:
        futures = client.map(_run_item, [spec] * len(pending), pending, pure=False)
        for done, future in enumerate(as_completed(futures), start=1):
            row = future.result()
            if progress is not None:
                progress(done, len(pending), row)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def main(argv: Optional[list] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m iblkit.batch",
        description="Run an iblkit batch spec on Dask (a local cluster, or --scheduler).",
        epilog="Examples:\n"
        "  python -m iblkit.batch assets/batch/bundled.toml\n"
        "  python -m iblkit.batch spec.toml --workers 8 --json\n"
        "  python -m iblkit.batch spec.toml --scheduler tcp://10.0.0.1:8786\n"
        "Exit status: 0 every probe ok, 1 internal failure, 2 bad spec or a failed probe.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("spec", help="the batch spec (TOML, docs/BATCH.md)")
    parser.add_argument("--workers", type=int, default=2, help="local worker processes")
    parser.add_argument("--threads-per-worker", type=int, default=None)
    parser.add_argument("--scheduler", default=None, help="address of a running scheduler")
    parser.add_argument("--retry-failed", action="store_true", help="run failed probes again")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    args = parser.parse_args(argv)
    if args.workers < 1:
        parser.error("--workers must be at least 1")

    def report(done: int, total: int, row: Dict[str, Any]) -> None:
        status = row.get("status")
        line = f"[{done}/{total}] {row.get('id')}: {status} ({row.get('seconds', 0):.2f} s)"
        if status != "ok":
            line += f": {row.get('error')}"
        print(line, file=sys.stderr, flush=True)

    try:
        summary = run(
            args.spec,
            workers=args.workers,
            threads_per_worker=args.threads_per_worker,
            scheduler=args.scheduler,
            retry_failed=args.retry_failed,
            progress=report,
        )
    except _native.BadInputError as e:
        print(f"iblkit.batch: {e}", file=sys.stderr)
        return 2
    except _native.InternalError as e:
        print(f"iblkit.batch: {e}", file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(
            f"{summary['items']} probes: {summary['ran']} run now, {summary['skipped']} done "
            f"before; {summary['ok']} ok, {len(summary['failed'])} failed, "
            f"in {summary['seconds']:.1f} s\nrows: {summary['rows']}"
        )
        for item_id, message in summary["failed"]:
            print(f"  failed {item_id}: {message}")
    return 2 if summary["failed"] else 0


if __name__ == "__main__":
    # Run as `python -m iblkit.batch`: call the copy imported as `iblkit.batch`, so the functions
    # Dask ships to the workers are pickled by reference to that module, not from `__main__`.
    from iblkit.batch import main as _main

    sys.exit(_main())
