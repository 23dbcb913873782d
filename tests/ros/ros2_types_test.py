#!/usr/bin/env python3
"""ROS 2 types (ros/ros2/ros2_types.h) checked by implementations nobody here wrote.

usage: ros2_types_test.py ROS_TESTS_BINARY WORK_DIR

runs ROS_TESTS_BINARY's Ros2Types.WritesSamplesForTheIndependentCheck, which writes one CDR
sample of every Ros2Type (SerializeCdr, i.e. Cyclone DDS's serializer) with the values it was
made from and the type table (DDS name, RIHS01 hash, ros2msg definition) to WORK_DIR, then checks
with the project venv's PyPI packages:
  - every RIHS01 hash against rosbags' Typestore.hash_rihs01 and against published values
    (std_msgs/msg/String's in the ROS 2 design docs; std_srvs/srv/Trigger_Request and
    _Response and the message types below as ROS 2 Jazzy's generated code and `ros2 topic info
    -v` have them, quoted by public projects; all table types but ParticipantEntitiesInfo), where a type is not in the table (String, Time, Header)
    as scripts/ros2_idl.py's implementation computes it;
  - every definition parsed by rosbags (get_types_from_msg) against rosbags' own Jazzy types;
  - every sample decoded by rosbags' deserialize_cdr and by mcap_ros2's decoder built from our
    definition text, field by field against the values it was made from; the request header of
    the Trigger samples (16 bytes: u64 client_guid, i64 sequence_number) by struct.
exit 77 (ctest's SKIP_RETURN_CODE) with the reason when the build has no ROS 2 or the venv is
missing.
"""

from __future__ import annotations

import importlib.util
import json
import os
import struct
import subprocess
import sys
from pathlib import Path

SKIP = 77

# RIHS01 hashes as ROS 2 Jazzy publishes them (rosidl_generator_type_description's output)
PUBLISHED = {
    # REP-2011's example value, ROS 2 design docs
    "std_msgs/msg/String": "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18",
    "std_srvs/srv/Trigger_Request": "RIHS01_d010825374ce8918e72bfd826c82603e60f45419e932ea976f807b74a863a199",
    "std_srvs/srv/Trigger_Response": "RIHS01_2d946c21e2fc3f1e9ca6986a8191d85fcc70097a8bb7771a053564bc47009cdf",
    "builtin_interfaces/msg/Time": "RIHS01_b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197",
    "std_msgs/msg/Header": "RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01",
    "geometry_msgs/msg/Twist": "RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a",
    "geometry_msgs/msg/PoseStamped": "RIHS01_10f3786d7d40fd2b54367835614bff85d4ad3b5dab62bf8bca0cc232d73b4cd8",
    "sensor_msgs/msg/Imu": "RIHS01_7d9a00ff131080897a5ec7e26e315954b8eae3353c3f995c55faf71574000b5b",
    "nav_msgs/msg/Odometry": "RIHS01_3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0",
    "rosgraph_msgs/msg/Clock": "RIHS01_692f7a66e93a3c83e71765d033b60349ba68023a8c689a79e48078bcb5c58564",
    # as `ros2 topic info -v` prints them on Jazzy
    "sensor_msgs/msg/Image": "RIHS01_d31d41a9a4c4bc8eae9be757b0beed306564f7526c88ea6a4588fb9582527d47",
    "sensor_msgs/msg/CameraInfo": "RIHS01_b3dfd68ff46c9d56c80fd3bd4ed22c7a4ddce8c8348f2f59c299e73118e7e275",
    "sensor_msgs/msg/PointCloud2": "RIHS01_9198cabf7da3796ae6fe19c4cb3bdd3525492988c70522628af5daa124bae2b5",
    "sensor_msgs/msg/JointState": "RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e",
    "tf2_msgs/msg/TFMessage": "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087",
}

TRIGGER_HEADER = struct.Struct("<Qq")  # rmw_cyclonedds's request header, after the 4-byte CDR header


def skip(reason: str) -> None:
    print(f"skipped: {reason}")
    sys.exit(SKIP)


try:
    import numpy as np
    from mcap_ros2._dynamic import generate_dynamic
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore
except ImportError as e:
    skip(f"{e} (run with the project venv's python: scripts/install-deps.sh makes .venv)")

failures: list[str] = []


def check(ok: bool, what: str) -> None:
    if not ok:
        failures.append(what)
        print("FAIL", what)


def plain(v):
    """a decoded value as JSON-like python (numpy arrays as lists)."""
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, (bytes, bytearray)):
        return list(v)
    return v


def compare(decoded, expected, path: str, signed_char: bool = False) -> None:
    """signed_char: the decoder reads .msg `char` (ROS 2: uint8) as int8 (mcap_ros2 0.6 does)."""
    if isinstance(expected, dict):
        for k, v in expected.items():
            if not hasattr(decoded, k):
                check(False, f"{path}.{k}: missing in the decoded message")
                continue
            compare(getattr(decoded, k), v, f"{path}.{k}", signed_char)
    elif isinstance(expected, list):
        got = plain(decoded)
        if not isinstance(got, (list, tuple)) or len(got) != len(expected):
            check(False, f"{path}: {got!r} != {expected!r}")
            return
        for i, (g, e) in enumerate(zip(got, expected)):
            compare(g, e, f"{path}[{i}]", signed_char)
    else:
        got = plain(decoded)
        if isinstance(expected, bool) or isinstance(got, bool):
            check(bool(got) == bool(expected) and int(got) == int(expected),
                  f"{path}: {got!r} != {expected!r}")
        elif signed_char and isinstance(got, int) and got < 0 and ".data[" in path:
            check(got + 256 == expected, f"{path}: {got!r} (as uint8 {got + 256}) != {expected!r}")
        else:
            check(got == expected, f"{path}: {got!r} != {expected!r}")


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    binary, work = sys.argv[1], Path(sys.argv[2])
    work.mkdir(parents=True, exist_ok=True)
    for old in work.glob("*"):
        old.unlink()
    run = subprocess.run(
        [binary, "--gtest_filter=Ros2Types.WritesSamplesForTheIndependentCheck"],
        env={**os.environ, "PENUMBRA_ROS2_CDR_DIR": str(work)},
        capture_output=True, text=True, timeout=120, check=False,
    )
    if "skipped: this build has no ROS 2" in run.stdout:
        skip("this build has no ROS 2 (configure with -DPENUMBRA_WITH_ROS2=AUTO or ON after "
             "scripts/install-deps.sh)")
    if run.returncode != 0 or not (work / "types.json").exists():
        print(run.stdout, run.stderr)
        print("FAIL: the sample writer failed")
        return 1
    table = json.loads((work / "types.json").read_text())
    store = get_typestore(Stores.ROS2_JAZZY)

    # our hash implementation (scripts/ros2_idl.py) on a type outside the table
    spec = importlib.util.spec_from_file_location(
        "ros2_idl", Path(__file__).resolve().parents[2] / "scripts" / "ros2_idl.py")
    ros2_idl = importlib.util.module_from_spec(spec)
    sys.modules["ros2_idl"] = ros2_idl
    spec.loader.exec_module(ros2_idl)
    msgs, _ = ros2_idl.load()
    msgs["std_msgs/msg/String"] = ros2_idl.from_rosbags(store, "std_msgs/msg/String")
    for name, published in PUBLISHED.items():
        ours = table[name]["type_hash"] if name in table else ros2_idl.rihs01(msgs, name)
        check(ours == published, f"{name}: hash {ours} != published {published}")

    # the Trigger types (not in rosbags), without the request header, for rosbags' reader
    trigger_store = get_typestore(Stores.EMPTY)
    trigger_store.register(get_types_from_msg("bool success\nstring message",
                                              "std_srvs/msg/Trigger_Response"))
    trigger_store.register(get_types_from_msg("", "std_srvs/msg/Trigger_Request"))

    for name, t in sorted(table.items()):
        h = t["type_hash"]
        if name in store.fielddefs:
            check(h == store.hash_rihs01(name), f"{name}: hash {h} != rosbags' {store.hash_rihs01(name)}")
        pkg, ns, typ = name.split("/")
        check(t["dds_name"] == f"{pkg}::{ns}::dds_::{typ}_", f"{name}: DDS name {t['dds_name']}")

        # the definition, parsed by rosbags, is the Jazzy type with its dependencies
        definition = t["definition"]
        if name in store.fielddefs:
            parsed = get_types_from_msg(definition, name)
            for dep, (consts, fields) in parsed.items():
                want = store.fielddefs.get(dep)
                check(want is not None and list(fields) == list(want[1]),
                      f"{name}: definition of {dep} parses as {fields}, Jazzy has {want}")
            deps = set()
            todo = [name]
            while todo:
                for _, desc in store.fielddefs[todo.pop()][1]:
                    sub = desc[1][0] if desc[0] in (3, 4) else desc
                    if sub[0] == 2 and sub[1] not in deps:
                        deps.add(sub[1])
                        todo.append(sub[1])
            check(set(parsed) == deps | {name},
                  f"{name}: the definition holds {sorted(parsed)}, expected {sorted(deps | {name})}")

        data = (work / t["file"]).read_bytes()
        check(data[:2] == b"\x00\x01" and data[2] == 0 and data[3] < 4 and len(data) % 4 == 0,
              f"{name}: CDR header {data[:4].hex()} for {len(data)} bytes")
        expected = dict(t["expected"])
        body = data
        mcap_name = name
        if name.startswith("std_srvs/srv/Trigger_"):
            guid, seq = TRIGGER_HEADER.unpack_from(data, 4)
            check(guid == expected.pop("client_guid"), f"{name}: client_guid {guid:#x}")
            check(seq == expected.pop("sequence_number"), f"{name}: sequence_number {seq}")
            body = data[:4] + data[4 + TRIGGER_HEADER.size:]  # 16 keeps the 8-byte alignment
            rb_name = name.replace("/srv/", "/msg/")
            if name.endswith("Request"):
                expected.pop("structure_needs_at_least_one_member")
                check(body[4] == 0, f"{name}: placeholder byte {body[4]}")
            decoded = trigger_store.deserialize_cdr(body, rb_name)
        else:
            decoded = store.deserialize_cdr(body, name)
        compare(decoded, expected, f"{name} (rosbags)")

        # mcap_ros2 builds its decoder from our definition text alone
        decoders = generate_dynamic(mcap_name, definition)
        compare(decoders[mcap_name](body), expected, f"{name} (mcap_ros2)",
                signed_char=name.startswith("rmw_dds_common/"))
        print(f"ok {name} {h} ({len(data)} bytes)")

    if failures:
        print(f"{len(failures)} failures")
        return 1
    print(f"all {len(table)} types: hashes, definitions and CDR agree with rosbags and mcap_ros2")
    return 0


if __name__ == "__main__":
    sys.exit(main())
