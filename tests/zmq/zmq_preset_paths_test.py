#!/usr/bin/env python3
"""`set_adversity` preset files from a ZeroMQ client stay inside the world file's folder
(docs/zmq-protocol.md `set_adversity`, docs/security.md "Files named by clients"): an absolute
path, `..`, a symbolic link and a non-YAML file outside the folder are refused with `bad_field`,
and no reply quotes the content of the file it names; a preset file inside the folder works.
A real `penumbra run --zmq --lockstep` on loopback (the Server / Client of zmq_bridge_test.py).

usage: zmq_preset_paths_test.py --binary PATH/penumbra --source REPO_ROOT
"""
import argparse
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import zmq_bridge_test as zb  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", required=True)
    ap.add_argument("--source", required=True)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = os.path.join(tmp, "world")
        outside = os.path.join(tmp, "outside")
        os.makedirs(os.path.join(folder, "presets"))
        os.makedirs(outside)
        world = zb.write_world(folder, args.source, duration=30.0)
        secret = os.path.join(outside, "secret.yaml")
        with open(secret, "w") as f:
            f.write("api_token: SECRET-TOKEN\n")
        notes = os.path.join(outside, "notes.txt")
        with open(notes, "w") as f:
            f.write("one line of SECRET-TEXT\n")
        with open(os.path.join(folder, "bad.yaml"), "w") as f:
            f.write("presets:\n  p:\n    fog: {mor_m: SECRET-VALUE}\n")
        with open(os.path.join(folder, "presets", "smoky.yaml"), "w") as f:
            f.write("presets:\n  smoky:\n    fog: {mor_m: 4}\n    lights: {scale: 0.4}\n")
        os.symlink(secret, os.path.join(folder, "link.yaml"))
        os.symlink(notes, os.path.join(folder, "notes.yaml"))
        os.symlink("/etc/passwd", os.path.join(folder, "passwd.yaml"))
        os.symlink(outside, os.path.join(folder, "out"))
        server = zb.Server(args.binary, world, os.path.join(tmp, "run"), ["--lockstep"])
        try:
            c = zb.Client(server, topics=())
            refused = {
                secret: "is absolute",
                secret + "#p": "is absolute",
                "../outside/secret.yaml": "'..' component",
                "presets/../../outside/secret.yaml": "'..' component",
                "link.yaml": "is a symbolic link",
                "notes.yaml": "is a symbolic link",
                "passwd.yaml": "is a symbolic link",
                "out/secret.yaml": "'out' is a symbolic link",
                "bad.yaml": "line 3: not a valid adversity preset file",
            }
            passwd_first = open("/etc/passwd").readline().strip()
            for spec, words in refused.items():
                r = c.call("set_adversity", preset=spec)
                assert not r["ok"], f"{spec}: accepted: {r}"
                err = r["error"]
                assert err["code"] == "bad_field" and err["field"] == "preset", (spec, r)
                m = err["message"]
                assert words in m, (spec, m)
                for leaked in ("SECRET", "api_token", passwd_first, folder):
                    assert leaked not in m, f"{spec}: the reply quotes {leaked!r}: {m}"
            # a preset file inside the world file's folder, named relative to it
            r = c.ok("set_adversity", preset="presets/smoky.yaml#smoky")
            assert r["applies_from_step"] == r["step"] + 1, r
            c.ok("step", n=5)
            c.ok("stop")
            c.close()
            assert server.wait() == 0
            # the server's own log names the bad file's key and value for its user
            with open(server.log_path) as f:
                log = f.read()
            assert "SECRET-VALUE" in log and "presets.p.fog.mor_m" in log, log
        finally:
            server.kill()
    print("preset_paths: ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
