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
import subprocess
import sys
import tempfile
import time

import clitest
from clitest import ToolTestCase

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cluster import DAEMONS, Cluster, find  # noqa: E402

SKIP = 77
SMALL = {"ndf-res": 16, "stride": 4, "sigma0": 2, "region": 2}
PACK = {"block": 8, "rank": 4}


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
