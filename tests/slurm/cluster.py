# SPDX-License-Identifier: Apache-2.0
"""A one-node Slurm cluster on the loopback for tests and measurements: munged, slurmctld and
slurmd run from a given folder (configuration, state, spool and logs in it, ports picked free on
127.0.0.1, no cgroups, no systemd, no accounting). The daemons run as root. Used by test_slurm.py
and scripts/slurm-scale.py."""

import os
import shutil
import signal
import socket
import subprocess
import time

# Programs a cluster needs (daemons and the client commands used on it).
DAEMONS = ["munged", "slurmctld", "slurmd", "sbatch", "squeue", "scontrol", "sinfo"]


def find(program):
    return shutil.which(program) or shutil.which(program, path="/usr/sbin:/usr/bin:/sbin")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Cluster:
    """munged + slurmctld + slurmd in `root`, stopped by stop()."""

    def __init__(self, root, cpus=None):
        self.root = root
        self.cpus = cpus or os.cpu_count() or 1  # CPUs the node advertises
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
NodeName=localhost NodeAddr=127.0.0.1 CPUs={self.cpus} State=UNKNOWN
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
