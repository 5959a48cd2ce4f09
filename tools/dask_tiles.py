#!/usr/bin/env python3
"""Build a terrain pyramid in shards on a Dask distributed cluster, then merge it.

Each of the N shards is one Dask task that runs, as a subprocess on a worker,

    tinsmith tiles INPUT -o DEST --shard I/N --threads T [EXTRA...]

and the driver then runs `tinsmith tiles merge DEST` locally, which writes layer.json
last. DEST must be one directory every worker and the driver see at the same path (a
shared file system), and INPUT must be readable at the same path from every worker; both
are made absolute here before they are sent.

The cluster is either an existing scheduler (--scheduler tcp://host:8786, its workers
started with `dask worker tcp://host:8786 --nthreads 1`) or, by default, a
`distributed.LocalCluster` of --workers worker processes with one thread each, talking
to the scheduler over TCP on 127.0.0.1. Dask does all the scheduling: the driver submits
N tasks and waits for them.

Shards are idempotent: a shard writes each tile atomically and records each finished
block after its tiles, and a re-run keeps the tiles it finds recorded with the same
fingerprint. So when a worker is lost mid-shard, Dask runs the task again on another worker
(up to the scheduler's `distributed.scheduler.allowed-failures`, 3 by default) and the
result is the same pyramid; the child `tinsmith` of a lost worker is killed with it
(Linux: PR_SET_PDEATHSIG), so two runs of one shard do not overlap. A shard whose
`tinsmith` exits non-zero is not retried (a bad input fails the same way every time):
the driver names every failed shard with the tail of its stderr, runs no merge, and exits
1. Run the driver again once the cause is fixed: finished tiles are kept.

Each task measures its own child, not its worker: wall time, CPU time (user + system)
and peak RSS of the `tinsmith` process alone, through GNU time (/usr/bin/time; see
run_measured for why not os.wait4 alone). The JSON summary on stdout (and in
--summary FILE) lists, per shard and for the merge: exit code, wall_s, cpu_s, user_s,
sys_s, max_rss_mb, the pid and host of the process that ran it (a worker's, for the
shards) and, from the shard's own report, its blocks and weight; then the totals. Logs
go to stderr.

Usage (from a checkout, after `make deps`):
    .venv/bin/python tools/dask_tiles.py INPUT -o DEST --shards 8 [--workers 2]
        [--scheduler tcp://host:8786] [--tinsmith target/release/tinsmith]
        [--shard-threads 1] [--merge-threads 0] [--summary FILE] [-- EXTRA tinsmith options]
e.g.
    .venv/bin/python tools/dask_tiles.py dem.tif -o terrain/ --shards 8 -- --normals --max-zoom 12

Exit codes: 0 the pyramid is complete (layer.json written), 1 a shard or the merge
failed, 2 bad usage.
"""

import argparse
import json
import os
import shutil
import socket
import sys
import time

# The last characters of a failed run's stderr kept in the summary and the message.
STDERR_TAIL = 4000


# GNU time measures its child alone; setpriv gives that child the parent-death signal.
GNU_TIME = "/usr/bin/time"
SETPRIV = "/usr/bin/setpriv"


# Variables a Dask nanny sets for its own Python worker (distributed.yaml,
# `nanny.pre-spawn-environ`) that are not meant for the programs a task runs: glibc's
# MALLOC_TRIM_THRESHOLD_ also turns off malloc's adaptive mmap threshold, so every large
# buffer of a child is mapped, faulted in and unmapped again (a shard of the ETOPO5
# pyramid: 0.06 -> 0.35 s of system time, `MALLOC_TRIM_THRESHOLD_=65536 tinsmith tiles
# ... --shard 0/4`).
NOT_FOR_CHILDREN = ("MALLOC_TRIM_THRESHOLD_",)


def child_environment():
    """This process's environment without the variables in NOT_FOR_CHILDREN."""
    return {k: v for k, v in os.environ.items() if k not in NOT_FOR_CHILDREN}


def run_measured(cmd, tail=STDERR_TAIL):
    """Runs `cmd` (a list) to completion; returns its exit code, the last `tail`
    characters of its stderr and what it cost: wall, user and system CPU seconds and peak
    RSS of that process alone.

    The costs come from GNU time (/usr/bin/time, Debian's `time`), which forks the command
    from its own small process: os.wait4 on a child forked from this Python process would
    count this process's memory in the child's peak RSS (Linux keeps the high-water mark
    of the memory image an exec replaces), and a Dask worker holds tens of MB or more.
    Without GNU time, wait4 is used and `rss_includes_parent` says so. The command is
    killed if the thread that started it dies (a lost worker): PR_SET_PDEATHSIG, through
    setpriv for the command under GNU time."""
    import ctypes
    import signal
    import subprocess
    import tempfile

    def die_with_parent():
        # PR_SET_PDEATHSIG = 1: SIGKILL this process when the thread that forked it exits.
        try:
            ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)
        except (OSError, AttributeError):
            pass

    timed = os.access(GNU_TIME, os.X_OK)
    with tempfile.TemporaryFile() as err, tempfile.NamedTemporaryFile("r") as costs:
        run = list(cmd)
        if timed:
            if os.access(SETPRIV, os.X_OK):
                run = [SETPRIV, "--pdeathsig", "KILL", *run]
            run = [GNU_TIME, "-o", costs.name, "-f", "%e %U %S %M", *run]
        start = time.monotonic()
        child = subprocess.Popen(
            run,
            stdin=subprocess.DEVNULL,
            stdout=err,
            stderr=err,
            preexec_fn=die_with_parent,
            env=child_environment(),
        )
        _, status, usage = os.wait4(child.pid, 0)
        wall = time.monotonic() - start
        child.returncode = os.waitstatus_to_exitcode(status)
        err.seek(0)
        text = err.read().decode("utf-8", "replace")
        lines = costs.read().split("\n") if timed else []
    # GNU time's last line is the format; a line before it may say how the command ended.
    fields = [line for line in lines if line.strip()][-1:]
    if timed and fields and len(fields[0].split()) == 4:
        _, user, system, rss_kib = fields[0].split()
        user, system, rss_kib = float(user), float(system), int(rss_kib)
    else:
        timed = False
        user, system, rss_kib = usage.ru_utime, usage.ru_stime, usage.ru_maxrss
    return {
        "exit": child.returncode,
        "wall_s": round(wall, 3),
        "cpu_s": round(user + system, 3),
        "user_s": round(user, 3),
        "sys_s": round(system, 3),
        # KiB, from GNU time and from Linux's ru_maxrss alike.
        "max_rss_mb": round(rss_kib / 1024, 1),
        "rss_includes_parent": not timed,
        "pid": os.getpid(),
        "host": socket.gethostname(),
        "stderr_tail": text[-tail:],
    }


def run_shard(tinsmith, input_path, dest, index, count, threads, extra):
    """One Dask task: shard `index` of `count` into `dest`, measured (see run_measured),
    with the blocks and weight of the shard's own --report when it succeeded."""
    import tempfile

    with tempfile.TemporaryDirectory(prefix="tinsmith-shard-") as tmp:
        report = os.path.join(tmp, "report.json")
        cmd = [tinsmith, "tiles", input_path, "-o", dest, "--shard", f"{index}/{count}",
               "--threads", str(threads), "--report", report, *extra]
        result = run_measured(cmd)
        result["shard"] = f"{index}/{count}"
        if result["exit"] == 0:
            del result["stderr_tail"]  # progress lines only; kept for failures
            with open(report) as f:
                built = json.load(f)
            for key in ("blocks", "tiles_kept", "weight", "total_weight", "tiles"):
                result[key] = built[key]
    try:
        from distributed import get_worker

        result["worker"] = get_worker().address
    except (ImportError, ValueError):
        result["worker"] = None
    return result


def parse_args(argv):
    extra = []
    if "--" in argv:
        cut = argv.index("--")
        argv, extra = argv[:cut], argv[cut + 1:]
    p = argparse.ArgumentParser(
        description="Run the N shards of `tinsmith tiles` on a Dask cluster, then merge.",
        epilog="Options after `--` go to every `tinsmith tiles` shard (e.g. -- --normals "
               "--max-zoom 12); they must be the same for every shard, and are.",
    )
    p.add_argument("input", help="the raster (same path on every worker)")
    p.add_argument("-o", "--output", required=True,
                   help="the pyramid directory, shared by every worker and the driver")
    p.add_argument("--shards", type=int, required=True, help="N, the number of shards")
    p.add_argument("--scheduler", help="address of a running scheduler (tcp://host:8786); "
                   "default: a LocalCluster of --workers processes")
    p.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                   help="LocalCluster worker processes, one thread each (default: cores)")
    p.add_argument("--tinsmith", default="tinsmith",
                   help="the tinsmith binary, as the workers find it (default: on PATH)")
    p.add_argument("--shard-threads", type=int, default=1,
                   help="--threads of each shard (default 1: a worker slot per core)")
    p.add_argument("--merge-threads", type=int, default=0,
                   help="--threads of the merge (default 0: all cores)")
    p.add_argument("--summary", help="also write the JSON summary to this file")
    args = p.parse_args(argv)
    if min(args.shards, args.workers, args.shard_threads) < 1 or args.merge_threads < 0:
        p.error("--shards, --workers and --shard-threads must be at least 1, "
                "--merge-threads at least 0")
    args.extra = extra
    return args


def log(message):
    print(f"dask_tiles: {message}", file=sys.stderr, flush=True)


def resolve_binary(name):
    """A path with a slash is made absolute (the workers' working directory may differ);
    a bare name is left for each worker's PATH, after checking the driver finds it."""
    if os.sep in name:
        return os.path.abspath(name)
    if shutil.which(name) is None:
        log(f"note: {name!r} is not on this machine's PATH; the workers must find it")
    return name


def describe_failure(shard, result=None, error=None):
    if error is not None:
        return (f"shard {shard} failed: its task raised {type(error).__name__}: {error} "
                "(a worker lost that many times: see the workers' logs)")
    tail = result["stderr_tail"].strip().splitlines()[-10:]
    where = result.get("worker") or result["host"]
    return (f"shard {shard} failed (tinsmith exit {result['exit']}) on {where}:\n    "
            + "\n    ".join(tail))


def main(argv):
    args = parse_args(argv)
    from distributed import Client, LocalCluster, as_completed

    input_path = os.path.abspath(args.input)
    dest = os.path.abspath(args.output)
    tinsmith = resolve_binary(args.tinsmith)
    n = args.shards
    start = time.monotonic()
    cluster = None
    if args.scheduler:
        client = Client(args.scheduler)
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                               protocol="tcp://", host="127.0.0.1", dashboard_address=None)
        client = Client(cluster)
    try:
        log(f"{n} shards of {input_path} into {dest} on {client.scheduler.address} "
            f"({len(client.scheduler_info()['workers'])} workers)")
        futures = {}
        for i in range(n):
            future = client.submit(run_shard, tinsmith, input_path, dest, i, n,
                                   args.shard_threads, args.extra, pure=False,
                                   key=f"tinsmith-shard-{i}-of-{n}-{os.getpid()}-{start}")
            futures[future] = f"{i}/{n}"
        results, failures = [], []
        for future in as_completed(futures):
            shard = futures[future]
            if future.status == "error":
                failures.append(describe_failure(shard, error=future.exception()))
                continue
            result = future.result()
            results.append(result)
            if result["exit"] != 0:
                failures.append(describe_failure(shard, result=result))
            else:
                log(f"shard {shard} done in {result['wall_s']:.1f} s "
                    f"({result['cpu_s']:.1f} s CPU, {result['max_rss_mb']:.0f} MB) "
                    f"on {result['worker']}")
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    results.sort(key=lambda r: int(r["shard"].split("/")[0]))
    summary = {"input": input_path, "output": dest, "shards": n, "driver_pid": os.getpid(),
               "results": results}
    if failures:
        for message in failures:
            log(message)
        log(f"{len(failures)} of {n} shards failed; no merge run, no layer.json written. "
            "Fix the cause and run again: finished tiles are kept.")
        emit(summary, args.summary)
        return 1
    merge = run_measured([tinsmith, "tiles", "merge", dest, "--threads",
                          str(args.merge_threads)])
    summary["merge"] = merge
    if merge["exit"] != 0:
        log("the merge failed (tinsmith exit {}):\n    {}".format(
            merge["exit"], "\n    ".join(merge["stderr_tail"].strip().splitlines()[-10:])))
        emit(summary, args.summary)
        return 1
    del merge["stderr_tail"]
    shards_cpu = sum(r["cpu_s"] for r in results)
    summary["totals"] = {
        "wall_s": round(time.monotonic() - start, 3),
        "shards_wall_s": round(sum(r["wall_s"] for r in results), 3),
        "shards_cpu_s": round(shards_cpu, 3),
        "merge_cpu_s": merge["cpu_s"],
        "cpu_s": round(shards_cpu + merge["cpu_s"], 3),
        "max_shard_rss_mb": max(r["max_rss_mb"] for r in results),
        "merge_rss_mb": merge["max_rss_mb"],
    }
    log(f"merged: {os.path.join(dest, 'layer.json')} written, "
        f"{summary['totals']['wall_s']:.1f} s wall, {summary['totals']['cpu_s']:.1f} s CPU")
    emit(summary, args.summary)
    return 0


def emit(summary, path):
    text = json.dumps(summary, indent=2)
    print(text)
    if path:
        with open(path, "w") as f:
            f.write(text + "\n")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
