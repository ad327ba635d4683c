"""A `compensator sweep` on a Dask cluster: one shard per task, merged in
shard order into what the single run writes (docs/sweep.md).

    python cli/scale-out/dask_sweep.py --scheduler tcp://host:8786 --shards 64 \\
        --out-dir /shared/run1 --output sweep.csv -- \\
        sweep --params my.toml --vary plunger.diameter=1% --samples 1000000

Each task runs ``compensator ARGS --shard K/N -o OUT_DIR/shard-K-of-N.csv``
on a worker (the binary and the parameter file must be reachable there,
OUT_DIR on storage the workers and this script share) and returns the
file's name; the script concatenates the files in K order. Without
``--scheduler`` a ``LocalCluster`` of ``--workers`` processes runs them
here. ``--check`` also runs the sweep once, unsharded, and fails unless the
merged output equals it byte for byte (what ``cargo xtask test`` runs).

Exit status: 0, 1 when some rows could not be computed (their error cells
say why), 2 for bad arguments or a shard that failed, 3 when ``--check``
finds a difference.
"""

import argparse
import os
import subprocess
import sys
import tempfile


def run_shard(binary, args, k, n, out_dir, threads):
    """Runs shard k of n; returns (k, path, exit status, standard error)."""
    path = os.path.join(out_dir, f"shard-{k}-of-{n}.csv")
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    done = subprocess.run(
        [binary, *args, "--shard", f"{k}/{n}", "-o", path],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    return k, path, done.returncode, done.stderr


def sweep(client, binary, args, shards, out_dir, threads=1):
    """Maps the shards over the cluster of `client`; returns the shards'
    results in shard order (`run_shard`'s tuples)."""
    futures = client.map(
        run_shard,
        [binary] * shards,
        [list(args)] * shards,
        range(1, shards + 1),
        [shards] * shards,
        [out_dir] * shards,
        [threads] * shards,
        pure=False,
    )
    return sorted(client.gather(futures))


def merge(results, output):
    """Concatenates the shards' files in order into the binary file `output`."""
    with open(output, "wb") as out:
        for _, path, _, _ in results:
            with open(path, "rb") as f:
                while chunk := f.read(1 << 20):
                    out.write(chunk)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--binary", default="compensator", help="the compensator binary (on the workers)")
    p.add_argument("--shards", type=int, required=True, help="number of shards (tasks)")
    p.add_argument("--scheduler", help="address of a running Dask scheduler (default: a LocalCluster)")
    p.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (default 2)")
    p.add_argument("--threads", type=int, default=1, help="threads per shard (RAYON_NUM_THREADS, default 1)")
    p.add_argument("--out-dir", help="where the shards are written (default: a temporary folder)")
    p.add_argument("--output", help="the merged CSV (default: standard output)")
    p.add_argument("--check", action="store_true", help="compare the merged output with the unsharded run")
    p.add_argument("args", nargs=argparse.REMAINDER, help="-- sweep ARGS...")
    a = p.parse_args(argv)
    args = a.args[1:] if a.args[:1] == ["--"] else a.args
    if not args or args[0] != "sweep" or a.shards < 1:
        p.error("give --shards N >= 1 and the command after --: -- sweep --params ...")
    from dask.distributed import Client, LocalCluster

    with tempfile.TemporaryDirectory() as tmp:
        out_dir = a.out_dir or tmp
        os.makedirs(out_dir, exist_ok=True)
        if a.scheduler:
            client, cluster = Client(a.scheduler), None
        else:
            cluster = LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True, dashboard_address=None)
            client = Client(cluster)
        try:
            results = sweep(client, a.binary, args, a.shards, out_dir, a.threads)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
        failed = [(k, code, err) for k, _, code, err in results if code not in (0, 1)]
        for k, code, err in failed:
            sys.stderr.write(f"dask_sweep: shard {k}/{a.shards} exited with {code}: {err}")
        if failed:
            return 2
        output = a.output or os.path.join(tmp, "merged.csv")
        merge(results, output)
        status = max(code for _, _, code, _ in results)
        if a.check:
            single = subprocess.run([a.binary, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
            with open(output, "rb") as f:
                merged = f.read()
            if single.returncode not in (0, 1) or merged != single.stdout:
                sys.stderr.write(
                    f"dask_sweep: the {a.shards} merged shards ({len(merged)} bytes) differ from the single run "
                    f"({len(single.stdout)} bytes, exit {single.returncode})\n"
                )
                return 3
            rows = merged.count(b"\n") - 1
            print(f"dask_sweep: {a.shards} shards on {a.workers} Dask workers merged equal the single run: "
                  f"{rows} rows, {len(merged)} bytes")
        if not a.output and not a.check:
            with open(output, "rb") as f:
                sys.stdout.buffer.write(f.read())
        return status


if __name__ == "__main__":
    sys.exit(main())
