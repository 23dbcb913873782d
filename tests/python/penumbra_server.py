"""Starts a real `penumbra run WORLD --zmq` on free loopback ports for the Python client's tests.

The binary comes from $PENUMBRA_BINARY (ctest sets it), else build/penumbra under the source
tree. Use as a context manager:

    with PenumbraServer("worlds/quadruped_target.yaml", lockstep=True) as server:
        client = Client(server.endpoint)
"""

import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(REPO, "python"))


def penumbra_binary():
    path = os.environ.get("PENUMBRA_BINARY", os.path.join(REPO, "build", "penumbra"))
    if not os.access(path, os.X_OK):
        raise RuntimeError(f"penumbra binary not found at {path} (set PENUMBRA_BINARY)")
    return path


def free_ports(n):
    """n distinct TCP ports that are free on 127.0.0.1 now (the OS picks them)."""
    socks = []
    try:
        for _ in range(n):
            s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            s.bind(("127.0.0.1", 0))
            socks.append(s)
        return [s.getsockname()[1] for s in socks]
    finally:
        for s in socks:
            s.close()


class PenumbraServer:
    """A `penumbra run` child process with the ZeroMQ bridge on two free loopback ports.

    :param world: world file, relative to the repository root or absolute.
    :param lockstep: pass --lockstep (the run advances only on `step`).
    :param extra: further command-line arguments.
    :ivar endpoint: the command endpoint (tcp://127.0.0.1:PORT).
    :ivar pub_endpoint: the publish endpoint.
    :ivar out_dir: the run's output folder (a temporary folder, removed on exit).
    """

    def __init__(self, world, lockstep=True, extra=(), startup_timeout_sec=120):
        self.world = world if os.path.isabs(world) else os.path.join(REPO, world)
        self.lockstep = lockstep
        self.extra = list(extra)
        self.startup_timeout_sec = startup_timeout_sec
        self.proc = None
        self.returncode = None

    def __enter__(self):
        cmd_port, pub_port = free_ports(2)
        self.endpoint = f"tcp://127.0.0.1:{cmd_port}"
        self.pub_endpoint = f"tcp://127.0.0.1:{pub_port}"
        self.tmp = tempfile.mkdtemp(prefix="penumbra_pyclient_")
        self.out_dir = os.path.join(self.tmp, "out")
        self.log_path = os.path.join(self.tmp, "server.log")
        args = [penumbra_binary(), "run", self.world, "--out", self.out_dir, "--quiet",
                "--zmq", self.endpoint, "--zmq-pub", self.pub_endpoint]
        if self.lockstep:
            args.append("--lockstep")
        args += self.extra
        self.log = open(self.log_path, "wb")
        self.proc = subprocess.Popen(args, cwd=self.tmp, stdout=self.log, stderr=subprocess.STDOUT)
        return self

    def check_alive(self):
        """Raises with the server's log when the process has exited."""
        if self.proc.poll() is not None:
            raise RuntimeError(f"penumbra exited with {self.proc.returncode}:\n{self.output()}")

    def output(self):
        self.log.flush()
        with open(self.log_path, "rb") as f:
            return f.read().decode("utf-8", "replace")

    def connect(self, timeout_sec=60.0, name="test"):
        """A Client on the command endpoint once the server answered `hello` (retried every
        2 s while the run loads its world; late replies are skipped by id)."""
        from penumbra_client import Client, PenumbraTimeoutError
        client = Client(self.endpoint, timeout_sec=2.0, name=name, handshake=False)
        deadline = time.monotonic() + self.startup_timeout_sec
        while True:
            self.check_alive()
            try:
                client.hello()
                break
            except PenumbraTimeoutError:
                if time.monotonic() > deadline:
                    client.close()
                    raise
        client.timeout_sec = timeout_sec
        return client

    def wait(self, timeout_sec=60):
        """Waits for the process to exit by itself (e.g. after a `stop` request); returns the
        exit code. Raises subprocess.TimeoutExpired when it does not."""
        self.returncode = self.proc.wait(timeout_sec)
        return self.returncode

    def stop(self, timeout_sec=60):
        """SIGINT (as Ctrl-C) and wait; returns the exit code."""
        if self.proc is not None and self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout_sec)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.returncode = self.proc.returncode if self.proc else None
        return self.returncode

    def __exit__(self, *exc):
        self.stop()
        self.log.close()
        shutil.rmtree(self.tmp, ignore_errors=True)
