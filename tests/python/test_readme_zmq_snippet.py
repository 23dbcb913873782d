"""README.md's ZeroMQ snippet ("Live runs: ZeroMQ"), run as written against the real server:
the block after the `<!-- test: zmq-snippet` marker is read from README.md, so the
test fails when the README drifts. Its first line starts the server in the background (`&`),
the rest is one `python3 -c` command; both are split as a POSIX shell would (shlex, no shell
runs) and run from the repository root, with `./build/penumbra` replaced by $PENUMBRA_BINARY
and the interpreter exactly as written (the `python3` first on PATH may lack msgpack: the
README names Debian's /usr/bin/python3). Checks: the snippet exits 0, prints the server's
topics and a `published` map with what the step published (not `{}`), and `stop` ends the
server (exit 130, as Ctrl-C).

It uses the README's fixed port 5555 and --out /tmp/live (ctest RESOURCE_LOCK readme_zmq)."""

import ast
import os
import re
import shlex
import subprocess
import sys
import tempfile
import time
import unittest

sys.path.insert(0, os.path.dirname(__file__))
from penumbra_server import REPO, penumbra_binary  # noqa: E402

MARKER = "<!-- test: zmq-snippet"


def readme_snippet():
    """(server argv, client argv) of the README's marked block."""
    with open(os.path.join(REPO, "README.md")) as f:
        text = f.read()
    at = text.find(MARKER)
    if at < 0:
        raise AssertionError(f"README.md has no {MARKER!r} block")
    m = re.search(r"```[a-z]*\n(.*?)```", text[at:], re.S)
    if not m:
        raise AssertionError("no code block after the marker")
    first, _, rest = m.group(1).partition("\n")
    server = shlex.split(first, comments=True)
    if not server or server[-1] != "&":
        raise AssertionError(f"the block's first line starts no background server: {first!r}")
    return server[:-1], shlex.split(rest, comments=True)


class ReadmeZmqSnippetTest(unittest.TestCase):
    def test_snippet_as_written(self):
        server_argv, client_argv = readme_snippet()
        self.assertEqual(server_argv[0], "./build/penumbra")
        server_argv[0] = penumbra_binary()
        # the server's log goes to a file: a pipe nobody reads while the client runs could fill
        # and stall the server
        with tempfile.TemporaryFile("w+") as log:
            server = subprocess.Popen(server_argv, cwd=REPO, stdout=log, stderr=subprocess.STDOUT)
            client = subprocess.Popen(client_argv, cwd=REPO, stdout=subprocess.PIPE,
                                      stderr=subprocess.PIPE, text=True)
            try:
                # the snippet's REQ socket waits for ever for a server that died: watch both
                end, server_gone = time.monotonic() + 300, None
                while client.poll() is None and time.monotonic() < end:
                    if server.poll() is not None:
                        server_gone = server_gone or time.monotonic()
                        if time.monotonic() - server_gone > 10:
                            break
                    time.sleep(0.1)
                if client.poll() is None:
                    client.kill()
                client_out, client_err = client.communicate()
                server.wait(timeout=120)
            finally:
                if server.poll() is None:
                    server.kill()
                    server.wait()
                log.seek(0)
                out = log.read()
        print(client_out, client_err, out[-3000:], sep="\n", file=sys.stderr)
        self.assertEqual(client.returncode, 0,
                         f"{client_argv[0]} -c ... exited {client.returncode}: {client_err}")
        lines = client_out.strip().splitlines()
        topics = ast.literal_eval(lines[0])
        self.assertIn("camera/front/rgb", topics)
        published = ast.literal_eval(lines[1])
        # 500 steps, and the first request of a lockstep run also covers step 0
        self.assertEqual(published.get("ground_truth/poses"), 501, published)
        # the front camera at 10 Hz over 1 s: frames captured at t = 0, 0.1, ..., 1.0. it is a
        # real camera (profile realsense_d435_rgb), so a frame is published once its exposure
        # and readout have ended (docs/zmq-protocol.md): the one captured at the last step, 1.0 s,
        # is still exposing when the step's reply is sent
        self.assertEqual(published.get("camera/front/rgb"), 10, published)
        self.assertEqual(server.returncode, 0, "the snippet's `stop` ends the server")


if __name__ == "__main__":
    unittest.main()
