#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Scale figures of a sharded bake on a one-node Slurm cluster (README, "Studio scale", "Figures").

Starts munged, slurmctld and slurmd on the loopback in a temporary folder (tests/slurm/cluster.py;
the daemons run as root), writes a normal map with mapgen, bakes it locally under /usr/bin/time -v,
then for every shard count N writes a manifest with "shards": N, runs
`glintbake bake --emit slurm`, submits the job array and its merge job with sbatch and waits for
them. It reports, per N: each task's wall time, CPU time (user + sys) and peak resident memory,
the merge job's, the total wall time from submission to the merge's end, and whether the merged
asset is byte-identical to the local bake; as a markdown table on stdout and as JSON (--json).
It also fits the mean shard CPU time to T(N) = F + W / N and projects it to a --project-size map.

How times are collected: the cluster runs without accounting (no slurmdbd, so no sacct), so every
tool command in the emitted tasks.txt and merge.sbatch is wrapped in `/usr/bin/time -v -o FILE`
before submission (one file per task and attempt); Slurm's own start and end times of every task
(scontrol show job, 1 s resolution) are recorded beside them.

Defaults are reduced options that fit a shared two-core machine: tensorpack on a 4096^2
`mapgen scratches --seed 9` map with --ndf-res 16 --block 8 --rank 8 --levels 2 --sigma0 4
(--tool-options replaces them). The node advertises --cpus CPUs (default 2), so that many
one-core tasks run at once. The daemons are stopped and the folder removed at the end, on an
error and on Ctrl-C (--keep leaves the folder).

Example:
  sudo scripts/slurm-scale.py --shards 4 16 --json scale.json
  scripts/slurm-scale.py --size 512 --shards 2 4   # a quick check of the pipeline
"""

import argparse
import hashlib
import json
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "slurm"))
from cluster import DAEMONS, Cluster, find  # noqa: E402

DEFAULT_OPTIONS = "--ndf-res 16 --block 8 --rank 8 --levels 2 --sigma0 4"
TIME = "/usr/bin/time"


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                epilog=__doc__.split("\n\n", 1)[1],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bin-dir", default=os.path.join(ROOT, "build", "bin"),
                   help="folder of the built tools (default: build/bin of this checkout)")
    p.add_argument("--shards", type=int, nargs="+", default=[4, 8, 16], help="shard counts (default: 4 8 16)")
    p.add_argument("--tool", default="tensorpack", choices=["tensorpack", "ndfgen"], help="the baking tool")
    p.add_argument("--tool-options", default=DEFAULT_OPTIONS,
                   help=f"options of the tool, one string (default: '{DEFAULT_OPTIONS}')")
    p.add_argument("--kind", default="scratches", help="mapgen kind (default: scratches)")
    p.add_argument("--size", type=int, default=4096, help="map size in texels (default: 4096)")
    p.add_argument("--seed", type=int, default=9, help="mapgen seed (default: 9)")
    p.add_argument("--cpus", type=int, default=2, help="CPUs the Slurm node advertises (default: 2)")
    p.add_argument("--local-threads", type=int, default=1,
                   help="-j of the local bake (default: 1, one core like every shard)")
    p.add_argument("--project-size", type=int, default=16384, help="map size of the projection (default: 16384)")
    p.add_argument("--project-machines", type=int, nargs="+", default=[16, 64, 256],
                   help="machine counts of the projection (default: 16 64 256)")
    p.add_argument("--timeout", type=float, default=3600, help="seconds to wait for one shard count's jobs")
    p.add_argument("--json", help="write the figures to this JSON file")
    p.add_argument("--keep", action="store_true", help="keep the temporary folder (map, bakes, logs)")
    return p.parse_args()


def options_dict(text):
    """'--a 1 --b x --flag' -> {"a": 1, "b": "x", "flag": true}: the manifest's option form."""
    words, out, i = shlex.split(text), {}, 0
    while i < len(words):
        w = words[i]
        if not w.startswith("--"):
            raise SystemExit(f"slurm-scale: expected an option, got '{w}' in --tool-options")
        name, eq, value = w[2:].partition("=")
        if not eq:
            if i + 1 < len(words) and not words[i + 1].startswith("--"):
                value, i = words[i + 1], i + 1
            else:
                value = True
        if isinstance(value, str) and re.fullmatch(r"-?\d+", value):
            value = int(value)
        elif isinstance(value, str) and re.fullmatch(r"-?\d*\.\d+(e-?\d+)?", value):
            value = float(value)
        out[name] = value
        i += 1
    return out


def parse_time(path):
    """The figures of a /usr/bin/time -v report: wall and CPU seconds, peak RSS in MB, exit status."""
    with open(path) as f:
        text = f.read()

    def field(label):
        m = re.search(re.escape(label) + r":\s*(.+)", text)
        return m.group(1).strip() if m else None

    wall = 0.0
    for part in field("Elapsed (wall clock) time (h:mm:ss or m:ss)").split(":"):
        wall = wall * 60 + float(part)
    return {"wall_s": round(wall, 2),
            "cpu_s": round(float(field("User time (seconds)")) + float(field("System time (seconds)")), 2),
            "peak_mb": round(int(field("Maximum resident set size (kbytes)")) / 1024, 1),
            "exit": int(field("Exit status") or 0)}


def file_hash(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def loadavg():
    with open("/proc/loadavg") as f:
        return [float(x) for x in f.read().split()[:3]]


def run(argv, **kw):
    out = subprocess.run(argv, capture_output=True, text=True, **kw)
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(argv)} exited {out.returncode}: {out.stderr.strip()}")
    return out.stdout


def wrap_with_time(jobs):
    """Puts /usr/bin/time -v -o logs/time-*.txt in front of every tool command of the emitted jobs."""
    logs = os.path.join(jobs, "logs")
    tasks = os.path.join(jobs, "tasks.txt")
    with open(tasks) as f:
        lines = f.read().splitlines()
    wrapped = []
    for k, line in enumerate(lines):
        head, sep, cmd = line.rpartition(" && ")  # "mkdir -p PARTS && TOOL ..." for a shard
        timed = f"{TIME} -v -a -o {shlex.quote(os.path.join(logs, f'time-task-{k}.txt'))} {cmd}"
        wrapped.append(head + sep + timed)
    with open(tasks, "w") as f:
        f.write("\n".join(wrapped) + "\n")
    merge = os.path.join(jobs, "merge.sbatch")
    with open(merge) as f:
        lines = f.read().splitlines()
    timed_merge = f"{TIME} -v -a -o {shlex.quote(os.path.join(logs, 'time-merge.txt'))} "
    # The merge lines are "GLINTINFO merge PARTS... -o OUT --quiet && rm -rf PARTS".
    lines = [timed_merge + line if " merge " in line and not line.startswith("#") else line for line in lines]
    with open(merge, "w") as f:
        f.write("\n".join(lines) + "\n")


def last_attempt(path):
    """The last report of an appended /usr/bin/time file (a retried task has one per attempt)."""
    with open(path) as f:
        text = f.read()
    parts = text.split("\tCommand being timed:")
    attempts = len(parts) - 1
    tmp = path + ".last"
    with open(tmp, "w") as f:
        f.write("\tCommand being timed:" + parts[-1])
    figures = parse_time(tmp)
    os.remove(tmp)
    figures["attempts"] = attempts
    return figures


def slurm_times(cluster, job):
    """{array task id or None: (start, end) epoch seconds} from scontrol show job."""
    out = subprocess.run([find("scontrol"), "show", "job", "-o", str(job)], env=cluster.env,
                         capture_output=True, text=True).stdout
    times = {}
    for rec in out.splitlines():
        f = dict(w.split("=", 1) for w in rec.split() if "=" in w)
        if "StartTime" not in f or "EndTime" not in f:
            continue
        try:
            s = time.mktime(time.strptime(f["StartTime"], "%Y-%m-%dT%H:%M:%S"))
            e = time.mktime(time.strptime(f["EndTime"], "%Y-%m-%dT%H:%M:%S"))
        except ValueError:
            continue
        task = f.get("ArrayTaskId")
        times[int(task) if task and task.isdigit() else None] = (s, e, f.get("JobState"))
    return times


def wait_done(cluster, job, timeout):
    end = time.time() + timeout
    while time.time() < end:
        states = cluster.job_state(job)
        if states and states[0] in ("COMPLETED", "FAILED", "CANCELLED", "TIMEOUT", "NODE_FAIL", "OUT_OF_MEMORY"):
            return states[0]
        time.sleep(1)
    raise RuntimeError(f"job {job} did not finish within {timeout} s: " + cluster.logs())


def sacct_probe(cluster, job):
    out = subprocess.run([find("sacct") or "sacct", "-n", "-j", str(job)], env=cluster.env,
                         capture_output=True, text=True)
    return "works" if out.returncode == 0 and out.stdout.strip() else (out.stderr.strip() or "no records")


def fit(points):
    """Least squares of y = F + W x with x = 1 / N over [(N, y)]."""
    xs = [1.0 / n for n, _ in points]
    ys = [y for _, y in points]
    k = len(xs)
    mx, my = sum(xs) / k, sum(ys) / k
    sxx = sum((x - mx) ** 2 for x in xs)
    w = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else 0.0
    return my - w * mx, w


def spread(values, fmt="{:.1f}"):
    lo, hi = fmt.format(min(values)), fmt.format(max(values))
    return lo if lo == hi else lo + " - " + hi


def main():
    a = parse_args()
    missing = [d for d in DAEMONS if not find(d)]
    if missing:
        raise SystemExit("slurm-scale: Slurm is not installed (missing " + ", ".join(missing) +
                         "; scripts/install-deps.sh installs slurm-wlm and munge)")
    if os.geteuid() != 0:
        raise SystemExit("slurm-scale: the one-node Slurm cluster runs its daemons as root")
    if not os.access(TIME, os.X_OK):
        raise SystemExit(f"slurm-scale: {TIME} (GNU time) is needed")
    tool = lambda name: os.path.join(os.path.abspath(a.bin_dir), name)  # noqa: E731
    opts = options_dict(a.tool_options)
    tool_argv = shlex.split(a.tool_options)

    def interrupted(signum, frame):
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, interrupted)
    signal.signal(signal.SIGINT, interrupted)  # also when started in the background (SIGINT ignored)
    root = tempfile.mkdtemp(prefix="glintbake-scale-")
    cluster = Cluster(os.path.join(root, "cluster"), cpus=a.cpus)
    os.makedirs(cluster.root)
    submitted = []
    doc = {"tool": a.tool, "options": a.tool_options, "map": {"kind": a.kind, "size": a.size, "seed": a.seed},
           "cpus": a.cpus, "load_before": loadavg(), "timing": "/usr/bin/time -v around every tool command; "
           "Slurm start/end from scontrol", "runs": []}
    try:
        mp = os.path.join(root, "map.png")
        print(f"mapgen {a.kind} --size {a.size} ...", file=sys.stderr)
        run([tool("mapgen"), a.kind, "-o", mp, "--size", str(a.size), "--seed", str(a.seed), "--quiet"])
        local = os.path.join(root, "local.gbk")
        print(f"local bake ({a.tool} -j{a.local_threads}) ...", file=sys.stderr)
        run([TIME, "-v", "-o", os.path.join(root, "time-local.txt"), tool(a.tool), mp, "-o", local, "--quiet",
             "-j", str(a.local_threads), *tool_argv])
        doc["local"] = parse_time(os.path.join(root, "time-local.txt"))
        doc["local"]["threads"] = a.local_threads
        doc["local"]["bytes"] = os.path.getsize(local)
        local_hash = file_hash(local)
        print(f"local: {doc['local']}", file=sys.stderr)

        print("starting the cluster ...", file=sys.stderr)
        cluster.start()
        for n in a.shards:
            work = os.path.join(root, f"n{n}")
            os.makedirs(os.path.join(work, "out"))
            out = os.path.join(work, "out", "map.gbk")
            manifest = os.path.join(work, "manifest.json")
            with open(manifest, "w") as f:
                json.dump({"schema": "glintbake.manifest/1",
                           "assets": [{"name": "map", "tool": a.tool, "inputs": [mp], "output": out,
                                       "shards": n, "options": opts}]}, f)
            jobs = os.path.join(work, "jobs")
            run([tool("glintbake"), "bake", manifest, "--emit", "slurm", "--emit-dir", jobs, "--quiet"],
                env=dict(os.environ, PATH=os.path.abspath(a.bin_dir) + os.pathsep + os.environ["PATH"]))
            wrap_with_time(jobs)
            load0 = loadavg()
            t0 = time.time()
            print(f"{n} shards: submitting ...", file=sys.stderr)
            array, merge = run([os.path.join(jobs, "submit.sh")], env=cluster.env).split()
            submitted += [array, merge]
            state = wait_done(cluster, merge, a.timeout)
            total = time.time() - t0
            if state != "COMPLETED":
                raise RuntimeError(f"{n} shards: merge job {state}: " + cluster.logs())
            logs = os.path.join(jobs, "logs")
            tasks = [last_attempt(os.path.join(logs, f"time-task-{k}.txt")) for k in range(n)]
            st = slurm_times(cluster, array)
            for k, t in enumerate(tasks):
                if k in st:
                    t["slurm_wall_s"] = st[k][1] - st[k][0]
            mt = last_attempt(os.path.join(logs, "time-merge.txt"))
            ms = slurm_times(cluster, merge).get(None)
            if ms:
                mt["slurm_wall_s"] = ms[1] - ms[0]
            first = min((v[0] for v in st.values()), default=t0)
            identical = file_hash(out) == local_hash
            r = {"shards": n, "tasks": tasks, "merge": mt, "total_wall_s": round(total, 1),
                 "slurm_span_s": (ms[1] - first) if ms else None, "identical": identical,
                 "load_before": load0, "load_after": loadavg(), "sacct": sacct_probe(cluster, array)}
            doc["runs"].append(r)
            print(f"{n} shards: total {total:.0f} s, identical {identical}", file=sys.stderr)
            if not identical:
                raise RuntimeError(f"{n} shards: the merged asset differs from the local bake")
            os.remove(out)
        doc["load_after"] = loadavg()

        # T(N) = F + W / N on the mean shard CPU time; the local bake joins as N = 1 only when a
        # single shard count was measured.
        points = [(r["shards"], sum(t["cpu_s"] for t in r["tasks"]) / r["shards"]) for r in doc["runs"]]
        if len({n for n, _ in points}) < 2:
            points.append((1, doc["local"]["cpu_s"]))
        F, W = fit(points)
        scale = (a.project_size / a.size) ** 2
        doc["fit"] = {"F_s": round(F, 2), "W_s": round(W, 1), "local_predicted_s": round(F + W, 1),
                      "points": points}
        doc["projection"] = {"size": a.project_size, "area_ratio": scale,
                             "per_shard_s": {str(m): round(scale * (F + W / m), 1) for m in a.project_machines}}
        report(doc)
        if a.json:
            with open(a.json, "w") as f:
                json.dump(doc, f, indent=2)
                f.write("\n")
        return 0
    except KeyboardInterrupt:
        print("slurm-scale: interrupted, cleaning up", file=sys.stderr)
        return 130
    finally:
        if submitted and cluster.procs:
            # Cancel what is left and let the killed tasks go before the daemons and the folder.
            subprocess.run([find("scancel") or "scancel", *submitted], env=cluster.env, capture_output=True)
            end = time.time() + 30
            while time.time() < end:
                q = subprocess.run([find("squeue"), "-h"], env=cluster.env, capture_output=True, text=True)
                if q.returncode != 0 or not q.stdout.strip():
                    break
                time.sleep(0.5)
        cluster.stop()
        if a.keep:
            print(f"slurm-scale: kept {root}", file=sys.stderr)
        else:
            for _ in range(3):  # a task's last write may land while the tree is removed
                shutil.rmtree(root, ignore_errors=True)
                if not os.path.exists(root):
                    break
                time.sleep(1)


def report(doc):
    loc = doc["local"]
    print(f"{doc['tool']} {doc['options']} on a {doc['map']['size']}^2 `mapgen {doc['map']['kind']} --seed "
          f"{doc['map']['seed']}` map; node of {doc['cpus']} CPUs; load average {doc['load_before']} before, "
          f"{doc['load_after']} after.\n")
    print("| bake | wall per shard (min - max) | CPU per shard (min - max) | sum of CPU | peak memory per shard "
          "| merge: wall, CPU, memory | total wall | identical |")
    print("|---|---:|---:|---:|---:|---:|---:|:---:|")
    print(f"| local (-j{loc['threads']}) | {loc['wall_s']:.0f} s | {loc['cpu_s']:.1f} s | | {loc['peak_mb']:.0f} MB "
          f"| | {loc['wall_s']:.0f} s | |")
    for r in doc["runs"]:
        t, m = r["tasks"], r["merge"]
        print(f"| {r['shards']} shards | {spread([x['wall_s'] for x in t], '{:.0f}')} s "
              f"| {spread([x['cpu_s'] for x in t])} s | {sum(x['cpu_s'] for x in t):.0f} s "
              f"| {spread([x['peak_mb'] for x in t], '{:.0f}')} MB "
              f"| {m['wall_s']:.1f} s, {m['cpu_s']:.1f} s, {m['peak_mb']:.0f} MB | {r['total_wall_s']:.0f} s "
              f"| {'yes' if r['identical'] else 'NO'} |")
    f = doc["fit"]
    print(f"\nMean shard CPU time T(N) = {f['F_s']} s + {f['W_s']} s / N (local predicted {f['local_predicted_s']} s, "
          f"measured {loc['cpu_s']} s).")
    p = doc["projection"]
    print(f"Projection to {p['size']}^2 ({p['area_ratio']:.0f} times the texels): " +
          ", ".join(f"{m} machines {s / 60:.1f} min per shard" for m, s in p["per_shard_s"].items()) + ".")
    print(f"sacct: {doc['runs'][0]['sacct'] if doc['runs'] else 'not tried'}")


if __name__ == "__main__":
    sys.exit(main())
