# SPDX-License-Identifier: Apache-2.0
"""glintbake on a real Slurm cluster: starts munged, slurmctld and slurmd on localhost (config,
state and logs in a temporary folder, loopback ports only), bakes a manifest of several maps, a
sharded ndfgen map and a sharded tensorpack map with `glintbake bake --emit slurm`, kills one task's tool to show that its retry gives
the same bytes, and checks every output is byte-identical to the local bake. The daemons are
stopped and the folder removed whatever happens."""

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import unittest

import clitest
from clitest import ToolTestCase

DAEMONS = ["munged", "slurmctld", "slurmd", "sbatch", "squeue", "scontrol", "sinfo"]
SKIP = 77
SMALL = {"ndf-res": 16, "stride": 4, "sigma0": 2, "region": 2}
PACK = {"block": 8, "rank": 4}


def find(program):
    return shutil.which(program) or shutil.which(program, path="/usr/sbin:/usr/bin:/sbin")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Cluster:
    """munged + slurmctld + slurmd in `root`, stopped by stop()."""

    def __init__(self, root):
        self.root = root
        self.procs = []
        self.env = dict(os.environ, SLURM_CONF=os.path.join(root, "slurm.conf"))

    def start(self):
        r = self.root
        for d in ("state", "spool", "log"):
            os.makedirs(os.path.join(r, d))
        key = os.path.join(r, "munge.key")
        with open(key, "wb") as f:
            f.write(os.urandom(1024))
        os.chmod(key, 0o400)
        sock = os.path.join(r, "munge.socket")
        conf = f"""ClusterName=glintbaketest
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort={free_port()}
SlurmdPort={free_port()}
AuthType=auth/munge
AuthInfo=socket={sock}
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation={r}/state
SlurmdSpoolDir={r}/spool
SlurmctldPidFile={r}/slurmctld.pid
SlurmdPidFile={r}/slurmd.pid
SlurmctldLogFile={r}/log/slurmctld.log
SlurmdLogFile={r}/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/builtin
MpiDefault=none
ReturnToService=2
SlurmdParameters=config_overrides
MinJobAge=600
NodeName=localhost NodeAddr=127.0.0.1 CPUs={os.cpu_count() or 1} State=UNKNOWN
PartitionName=test Nodes=localhost Default=YES MaxTime=INFINITE State=UP
"""
        with open(self.env["SLURM_CONF"], "w") as f:
            f.write(conf)
        self.spawn([find("munged"), "-F", "--force", f"--key-file={key}", f"--socket={sock}",
                    f"--pid-file={r}/munged.pid", f"--log-file={r}/log/munged.log", f"--seed-file={r}/munge.seed"])
        self.wait_for(lambda: os.path.exists(sock), "munged socket")
        self.spawn([find("slurmctld"), "-D", "-i", "-f", self.env["SLURM_CONF"]])
        self.spawn([find("slurmd"), "-D", "-N", "localhost", "-f", self.env["SLURM_CONF"]])
        self.wait_for(self.node_idle, "the node to be idle")

    def spawn(self, argv):
        with open(os.path.join(self.root, "log", os.path.basename(argv[0]) + ".out"), "w") as log:
            self.procs.append(subprocess.Popen(argv, stdout=log, stderr=subprocess.STDOUT, env=self.env,
                                               start_new_session=True))

    def node_idle(self):
        out = subprocess.run([find("sinfo"), "-h", "-o", "%t"], env=self.env, capture_output=True, text=True)
        return out.returncode == 0 and out.stdout.strip() in ("idle", "mix")

    def wait_for(self, ready, what, timeout=60):
        end = time.time() + timeout
        while time.time() < end:
            for p in self.procs:
                if p.poll() is not None:
                    raise RuntimeError(f"{p.args[0]} exited ({p.returncode}) while waiting for {what}: "
                                       + self.logs())
            if ready():
                return
            time.sleep(0.2)
        raise RuntimeError(f"timed out waiting for {what}: " + self.logs())

    def job_state(self, job):
        out = subprocess.run([find("scontrol"), "show", "job", str(job)], env=self.env, capture_output=True, text=True)
        return [w.split("=", 1)[1] for w in out.stdout.split() if w.startswith("JobState=")]

    def logs(self):
        text = []
        for name in ("slurmctld.log", "slurmd.log"):
            p = os.path.join(self.root, "log", name)
            if os.path.exists(p):
                with open(p) as f:
                    text.append(name + ": " + " | ".join(f.read().splitlines()[-5:]))
        return "; ".join(text)

    def stop(self):
        for p in reversed(self.procs):
            if p.poll() is None:
                try:
                    os.killpg(p.pid, signal.SIGTERM)
                except ProcessLookupError:
                    pass
        for p in reversed(self.procs):
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()


class SlurmBake(ToolTestCase):
    def manifest(self, name, maps, out_dir, sharded):
        assets = [{"name": os.path.splitext(os.path.basename(m))[0], "tool": "ndfgen", "inputs": [m],
                   "output": os.path.join(out_dir, os.path.basename(m) + ".gbk")} for m in maps]
        assets.append({"name": "sharded", "tool": "ndfgen", "inputs": [sharded],
                       "output": os.path.join(out_dir, "sharded.gbk"), "shards": 3,
                       "options": {"ndf-res": 32}})
        # A sharded tensorpack bake: its merge replays the final assembly (formats/SPEC.md 10.9).
        assets.append({"name": "tsharded", "tool": "tensorpack", "inputs": [maps[1]],
                       "output": os.path.join(out_dir, "tsharded.gbk"), "shards": 2, "options": PACK})
        path = self.path(name)
        with open(path, "w") as f:
            json.dump({"schema": "glintbake.manifest/1", "defaults": {"options": SMALL}, "assets": assets}, f)
        return path

    def test_manifest_and_shards_on_slurm(self):
        maps = [self.mapgen(k, f"{k}.png", "--size", "32", "--seed", str(i))
                for i, k in enumerate(["beckmann", "scratches", "flakes"])]
        # Large enough that its shards are still running when one is killed.
        sharded = self.mapgen("scratches", "big.png", "--size", "160", "--seed", "9")
        os.makedirs(self.path("local"))
        os.makedirs(self.path("farm"))
        local = self.manifest("local.json", maps, self.path("local"), sharded)
        farm = self.manifest("farm.json", maps, self.path("farm"), sharded)
        self.run_ok("glintbake", "bake", local, "--quiet")

        doc = self.run_json("glintbake", "bake", farm, "--emit", "slurm", "--emit-dir", self.path("jobs"))
        self.assertEqual(doc["tasks"], 3 + 3 + 2)
        root = tempfile.mkdtemp(prefix="glintbake-slurm-")
        cluster = Cluster(root)
        try:
            cluster.start()
            out = subprocess.run([os.path.join(self.path("jobs"), "submit.sh")], env=cluster.env,
                                 capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            array, merge = out.stdout.split()
            killed = self.kill_one_shard(cluster, "--shard 1/3")
            end = time.time() + 150
            while time.time() < end and cluster.job_state(merge) not in (["COMPLETED"], ["FAILED"], ["CANCELLED"]):
                time.sleep(0.5)
            self.assertEqual(cluster.job_state(merge), ["COMPLETED"], cluster.logs())
            for name in os.listdir(self.path("local")):
                if name.endswith(".gbk"):
                    self.assertEqual(clitest.file_hash(os.path.join(self.path("farm"), name)),
                                     clitest.file_hash(os.path.join(self.path("local"), name)), name)
            self.assertFalse(os.path.exists(self.path("farm/sharded.gbk.shards")), "parts left behind")
            # The sharded tensorpack asset is the file tensorpack writes on one machine.
            one = self.path("tsharded.one.gbk")
            self.run_ok("tensorpack", maps[1], "-o", one, "--quiet", *[f"--{k}={v}" for k, v in SMALL.items()],
                        *[f"--{k}={v}" for k, v in PACK.items()])
            self.assertEqual(clitest.file_hash(self.path("farm/tsharded.gbk")), clitest.file_hash(one))
            if killed:
                logs = ""
                for name in os.listdir(os.path.join(self.path("jobs"), "logs")):
                    with open(os.path.join(self.path("jobs"), "logs", name)) as f:
                        logs += f.read()
                self.assertIn("attempt 1 failed (exit 137)", logs)
            else:
                self.fail("the shard finished before it could be killed")
        finally:
            cluster.stop()
            shutil.rmtree(root, ignore_errors=True)

    def kill_one_shard(self, cluster, marker, timeout=60):
        """Kills (SIGKILL) the first ndfgen process whose command line holds `marker`."""
        end = time.time() + timeout
        while time.time() < end:
            for pid in os.listdir("/proc"):
                if not pid.isdigit():
                    continue
                try:
                    with open(f"/proc/{pid}/cmdline", "rb") as f:
                        cmd = f.read().replace(b"\0", b" ").decode(errors="replace")
                except OSError:
                    continue
                if "ndfgen" in cmd and marker in cmd and self.tmp in cmd and "bash" not in cmd.split()[0]:
                    os.kill(int(pid), signal.SIGKILL)
                    return True
            time.sleep(0.01)
        return False


if __name__ == "__main__":
    missing = [d for d in DAEMONS if not find(d)]
    if missing:
        print("skipped: Slurm is not installed (missing " + ", ".join(missing) +
              "; scripts/install-deps.sh installs slurm-wlm and munge)")
        sys.exit(SKIP)
    if os.geteuid() != 0:
        print("skipped: the one-node Slurm cluster runs its daemons as root")
        sys.exit(SKIP)
    clitest.main()
