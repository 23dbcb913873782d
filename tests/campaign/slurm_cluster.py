"""A single-node Slurm cluster on localhost for tests: munged, slurmctld and slurmd (Debian's
slurm-wlm and munge) started as root with their own key, config, ports, sockets and state in a
scratch folder, and stopped again (by their process ids) on exit.

    with SlurmCluster(tmp) as cluster:      # raises SlurmUnavailable when it cannot start
        env = cluster.env()                 # SLURM_CONF for sbatch / squeue
"""

import os
import shutil
import socket
import subprocess
import time


class SlurmUnavailable(Exception):
    """Slurm or munge is missing or would not start on this machine."""


def _free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class SlurmCluster:
    def __init__(self, folder, cpus=2):
        self.dir = os.path.abspath(folder)
        self.cpus = cpus
        self.procs = []

    def env(self):
        e = dict(os.environ)
        e["SLURM_CONF"] = self.conf
        return e

    def _log(self, name):
        path = os.path.join(self.dir, name)
        return open(path).read() if os.path.exists(path) else ""

    def __enter__(self):
        for tool in ("munged", "slurmctld", "slurmd", "sbatch", "squeue", "sinfo"):
            if shutil.which(tool) is None and not os.path.exists("/usr/sbin/" + tool):
                raise SlurmUnavailable(tool + " not found (Debian packages slurm-wlm and munge)")
        if os.geteuid() != 0:
            raise SlurmUnavailable("slurmd must run as root here (it starts jobs as their user)")
        os.makedirs(self.dir, exist_ok=True)
        os.chmod(self.dir, 0o755)
        for sub in ("state", "spool", "munge"):
            os.makedirs(os.path.join(self.dir, sub), exist_ok=True)
        os.chmod(os.path.join(self.dir, "munge"), 0o700)
        key = os.path.join(self.dir, "munge", "munge.key")
        with open(key, "wb") as f:
            f.write(os.urandom(1024))
        os.chmod(key, 0o600)
        self.socket = os.path.join(self.dir, "munge", "munge.socket")
        self.procs.append(subprocess.Popen(
            ["/usr/sbin/munged", "-F", "--force", "--key-file=" + key, "--socket=" + self.socket,
             "--pid-file=" + os.path.join(self.dir, "munge", "munged.pid"),
             "--log-file=" + os.path.join(self.dir, "munge", "munged.log"),
             "--seed-file=" + os.path.join(self.dir, "munge", "munged.seed")],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        self._wait(lambda: os.path.exists(self.socket), 10, "munged did not create its socket")
        self.conf = os.path.join(self.dir, "slurm.conf")
        d = self.dir
        with open(self.conf, "w") as f:
            f.write(f"""ClusterName=penumbratest
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort={_free_port()}
SlurmdPort={_free_port()}
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket={self.socket}
StateSaveLocation={d}/state
SlurmdSpoolDir={d}/spool
SlurmctldPidFile={d}/slurmctld.pid
SlurmdPidFile={d}/slurmd.pid
SlurmctldLogFile={d}/slurmctld.log
SlurmdLogFile={d}/slurmd.log
ProctrackType=proctrack/pgid
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SwitchType=switch/none
ReturnToService=2
SchedulerType=sched/backfill
SlurmctldTimeout=30
SlurmdTimeout=30
InactiveLimit=0
MinJobAge=2
KillWait=2
NodeName=localhost NodeHostname=localhost NodeAddr=127.0.0.1 CPUs={self.cpus} State=UNKNOWN
PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP
""")
        env = self.env()
        self.procs.append(subprocess.Popen(["/usr/sbin/slurmctld", "-D", "-i", "-f", self.conf], env=env,
                                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        self.procs.append(subprocess.Popen(["/usr/sbin/slurmd", "-D", "-N", "localhost", "-f", self.conf], env=env,
                                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))

        def node_idle():
            for p in self.procs:
                if p.poll() is not None:
                    raise SlurmUnavailable("a Slurm daemon exited at start:\n" + self._log("slurmctld.log")[-2000:] +
                                           self._log("slurmd.log")[-2000:])
            r = subprocess.run(["sinfo", "-h", "-N", "-o", "%T"], env=env, capture_output=True, text=True)
            return r.returncode == 0 and r.stdout.strip() in ("idle", "mixed")
        try:
            self._wait(node_idle, 60, "the node did not become idle")
        except SlurmUnavailable:
            self.__exit__(None, None, None)
            raise
        return self

    def _wait(self, ok, timeout, message):
        end = time.time() + timeout
        while time.time() < end:
            if ok():
                return
            time.sleep(0.2)
        raise SlurmUnavailable(message + ":\n" + self._log("slurmctld.log")[-2000:] + self._log("slurmd.log")[-2000:])

    def __exit__(self, *exc):
        for p in reversed(self.procs):
            if p.poll() is None:
                p.terminate()
        for p in reversed(self.procs):
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        self.procs = []
        return False
