#!/usr/bin/env python3
"""writes the seed corpora of fuzz/corpus/ (docs/fuzzing.md): valid inputs of each parser and
known-bad inputs. standard library only; run from anywhere:

    python3 fuzz/make_corpus.py

the run log seeds follow docs/run-log.md "Byte layout" (bodies stored as is, codec 0; one seed
carries a hand-made zstd frame). the world seeds are copies of small bundled worlds plus YAML
oddities; existing files of the same names are replaced, others are left alone (the fuzzers'
own finds may be added by hand)."""

import json
import os
import shutil
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
CORPUS = os.path.join(HERE, "corpus")


def write(target, name, data):
    os.makedirs(os.path.join(CORPUS, target), exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(CORPUS, target, name), "wb") as f:
        f.write(data)


# ---- run logs --------------------------------------------------------------------------------
MAGIC = b"\x89PLOG\r\n\x1a"
KIND = {"header": 1, "steps": 2, "events": 3, "sensors": 4, "end": 5}


def crc(b):
    return zlib.crc32(b) & 0xFFFFFFFF


def chunk_header(kind, index, count, codec, first, last, raw, stored):
    h = b"PCHK" + struct.pack("<IQIIqqQQI", KIND[kind], index, count, codec, first, last, raw,
                              stored, 0)
    return h + struct.pack("<I", crc(h))


def chunk(kind, index, count, body, first=0, last=0, codec=0, raw=None, stored=None):
    raw = len(body) if raw is None else raw
    stored = len(body) if stored is None else stored
    return (chunk_header(kind, index, count, codec, first, last, raw, stored) + body +
            struct.pack("<I", crc(body)))


LAYOUT = {"nq": 2, "nv": 2, "na": 0, "nu": 1, "nmocap": 0, "nuserdata": 0, "nbody": 2,
          "num_controllers": 1,
          "joints": [{"name": "a", "type": "hinge", "qpos_adr": 0, "qpos_width": 1,
                      "qvel_adr": 0, "qvel_width": 1},
                     {"name": "b", "type": "slide", "qpos_adr": 1, "qpos_width": 1,
                      "qvel_adr": 1, "qvel_width": 1}],
          "actuator_names": ["m"], "mocap_body_names": [], "body_names": ["world", "b"],
          "controller_names": ["joint_servo"]}


def header_json(layout=None):
    return json.dumps({
        "format_version": 1, "penumbra_version": "0.1.0", "mujoco_version": "2.2.2",
        "world_file": "", "world_text": "", "model_file": "/m.xml",
        "model_text": "<mujoco/>", "composed_mjcf": "<mujoco/>", "assets": [], "seed": 3,
        "command_line": "penumbra run m.xml --record x.plog", "timestep_sec": 0.002,
        "layout": LAYOUT if layout is None else layout, "has_sensor_records": True,
        "adversity": ""}).encode()


def field(enc, words, is_int=False):
    if enc == 0:
        return struct.pack("<BI", 0, len(words))
    fmt = "<%d%s" % (len(words), "q" if is_int else "d")
    return struct.pack("<BI", enc, len(words)) + struct.pack(fmt, *words)


def step(n, enc=2, prev_xor=False):
    # step, time, then qpos qvel act ctrl qacc_warmstart qfrc_applied xfrc_applied mocap_pos
    # mocap_quat userdata controller_next_update (sizes of LAYOUT)
    e = 1 if prev_xor else enc
    return (struct.pack("<qd", n, n * 0.002) + field(e, [0.1 * n, 0.5]) + field(e, [1.0, -1.0]) +
            field(0, []) + field(e, [0.25]) + field(0, [0, 0]) + field(0, [0, 0]) +
            field(0, [0] * 12) + field(0, []) + field(0, []) + field(0, []) +
            field(2, [n + 10], is_int=True))


def log(steps_chunk=None, extra=b"", end=True, layout=None):
    body_steps = step(0) + step(1, prev_xor=True) + step(2, prev_xor=True)
    events = (struct.pack("<qd", 1, 0.002) + struct.pack("<I", 4) + b"note" +
              struct.pack("<Q", 8) + b'{"i": 1}')
    sensors = (struct.pack("<qd", 2, 0.004) + struct.pack("<I", 3) + b"cam" +
               struct.pack("<I", 7) + b"rgb.png" + struct.pack("<Q", 4) + b"\x89PNG")
    out = MAGIC + struct.pack("<II", 1, 0)
    out += chunk("header", 0, 1, header_json(layout))
    out += steps_chunk if steps_chunk is not None else chunk("steps", 1, 3, body_steps, 0, 2)
    out += chunk("events", 2, 1, events, 1, 1)
    out += chunk("sensors", 3, 1, sensors, 2, 2)
    out += extra
    if end:
        out += chunk("end", 4, 0, b'{"steps": 3, "events": 1, "sensor_records": 1, '
                                  b'"first_step": 0, "last_step": 2}')
    return out


def runlog_seeds():
    write("runlog", "valid_plain.plog", log())
    write("runlog", "no_end_chunk.plog", log(end=False))
    full = log()
    write("runlog", "cut_mid_chunk.plog", full[:len(full) - 30])
    body = step(0) + step(1, prev_xor=True) + step(2, prev_xor=True)
    # a steps chunk whose stored size is 2^64 - 4 (header CRC recomputed)
    bad = chunk_header("steps", 1, 3, 0, 0, 2, len(body), 2**64 - 4) + body + \
        struct.pack("<I", crc(body))
    write("runlog", "stored_size_2pow64_minus4.plog", log(steps_chunk=bad))
    # 3.2 GB declared by a 14-byte zstd frame (single segment, 8-byte content size, one RLE
    # block of one byte)
    frame = b"\x28\xb5\x2f\xfd\xe0" + struct.pack("<Q", 3_200_000_000) + b"\x0b\x00\x00\x00"
    write("runlog", "zstd_declares_3200000000.plog",
          log(steps_chunk=chunk("steps", 1, 3, frame, 0, 2, codec=1, raw=3_200_000_000)))
    # a zstd frame that decodes: single segment, 2-byte content size (size - 256), one last
    # raw block holding the steps body
    assert 256 <= len(body) < 65536 + 256
    small = b"\x28\xb5\x2f\xfd\x60" + struct.pack("<H", len(body) - 256) + \
        struct.pack("<I", (len(body) << 3) | 1)[:3] + body
    write("runlog", "zstd_raw_block.plog",
          log(steps_chunk=chunk("steps", 1, 3, small, 0, 2, codec=1, raw=len(body))))
    # 2^32 - 1 records declared for a body of three
    write("runlog", "record_count_4294967295.plog",
          log(steps_chunk=chunk("steps", 1, 2**32 - 1, body, 0, 2)))
    # a qpos of 2^32 - 1 zero entries in 5 bytes
    zero = struct.pack("<qd", 0, 0.0) + struct.pack("<BI", 0, 2**32 - 1) + \
        b"".join(struct.pack("<BI", 0, 0) for _ in range(10))
    write("runlog", "zero_field_4294967295.plog", log(steps_chunk=chunk("steps", 1, 1, zero)))
    # a layout with a negative count and a joint outside qpos
    lay = dict(LAYOUT, nq=-3)
    write("runlog", "layout_negative_nq.plog", log(layout=lay))
    lay = json.loads(json.dumps(LAYOUT))
    lay["joints"][1]["qpos_adr"] = 5
    write("runlog", "layout_joint_outside_qpos.plog", log(layout=lay))
    # a second end chunk's worth of bytes after the end, and a wrong chunk index
    write("runlog", "bytes_after_end.plog", log() + b"trailing")
    write("runlog", "wrong_index.plog",
          log(steps_chunk=chunk("steps", 7, 3, body, 0, 2)))
    write("runlog", "not_a_log.plog", b"seed: 3\nduration_sec: 1\n")


# ---- TUM trajectories ------------------------------------------------------------------------
def tum_seeds():
    ok = "# timestamp tx ty tz qx qy qz qw\n" + "".join(
        "%g %g %g 0 0 0 %g %g\n" % (1 + 0.1 * i, 0.1 * i, 0.02 * i * i, 0.0998 if i % 2 else 0,
                                    0.995 if i % 2 else 1) for i in range(12))
    write("tum", "valid.txt", ok)
    write("tum", "commas_tabs.txt", "1,0,0,0,0,0,0,1\n2\t1\t0\t0\t0\t0\t0\t1\r\n3 2 0 0 0 0 0 1\n")
    shifted = "".join("%g %g 0.5 0 0 0 0 1\n" % (1.05 + 0.1 * i, 0.1 * i + 0.01)
                      for i in range(12))
    write("tum", "two_files.txt", ok + "\n===\n" + shifted)
    write("tum", "coordinate_1e308.txt", "1 0 0 0 0 0 0 1\n2 1e308 0 0 0 0 0 1\n3 0 0 0 0 0 0 1\n")
    write("tum", "timestamp_1e300.txt", "1 0 0 0 0 0 0 1\n1e300 0 0 0 0 0 0 1\n")
    write("tum", "nan_inf.txt", "1 nan 0 0 0 0 0 1\n2 inf 0 0 0 0 0 1\n")
    write("tum", "nuls.txt", b"1 0 0 0 0 0 0 1\n" + b"\0" * 64)
    write("tum", "long_line.txt", "1 0 0 0 0 0 0 1\n" + "7" * 5000 + "\n")
    write("tum", "decreasing.txt", "2 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n")
    write("tum", "bad_quaternion.txt", "1 0 0 0 0 0 0 2\n")
    write("tum", "identical_positions.txt",
          "".join("%d 1 1 1 0 0 0 1\n" % i for i in range(1, 6)) + "===\n" +
          "".join("%d 5 5 5 0 0 0 1\n" % i for i in range(1, 6)))
    write("tum", "empty.txt", "# nothing\n\n")


# ---- world files -----------------------------------------------------------------------------
def world_seeds():
    for name in ["arm.yaml", "rover.yaml", "quadrotor.yaml", "sensors.yaml",
                 "metrics_example.yaml", "materials.yaml"]:
        src = os.path.join(ROOT, "worlds", name)
        if os.path.exists(src) and os.path.getsize(src) < 16384:
            shutil.copyfile(src, os.path.join(CORPUS, "world", name))
    write("world", "minimal.yaml", "seed: 1\nduration_sec: 1\n")
    write("world", "yaml_tag.yaml", "seed: !!str 3\nduration_sec: !custom 1\n")
    write("world", "anchors.yaml",
          "defaults: &d {width: 32, height: 24}\ncameras:\n  - {name: a, <<: *d}\n"
          "  - {name: b, <<: *d}\n")
    write("world", "deep.yaml", "a: " + "[" * 200 + "]" * 200 + "\n")
    write("world", "huge_numbers.yaml",
          "seed: 1e400\nduration_sec: 1e308\ncameras:\n  - {name: c, fovy_deg: 1e-300, "
          "width: 99999999999, height: -1}\n")
    write("world", "binary.yaml", b"seed: \x00\x01\xff\n")
    write("world", "long_name.yaml", "cameras:\n  - {name: " + "x" * 5000 + "}\n")


# ---- msgpack / JSON requests -----------------------------------------------------------------
def mp(v):
    """a minimal msgpack encoder (maps, arrays, str, int, float, bool, nil, bytes)."""
    if v is None:
        return b"\xc0"
    if v is True:
        return b"\xc3"
    if v is False:
        return b"\xc2"
    if isinstance(v, int):
        if 0 <= v < 128:
            return bytes([v])
        if -32 <= v < 0:
            return struct.pack("b", v)
        return b"\xd3" + struct.pack(">q", v)
    if isinstance(v, float):
        return b"\xcb" + struct.pack(">d", v)
    if isinstance(v, bytes):
        return b"\xc4" + bytes([len(v)]) + v
    if isinstance(v, str):
        b = v.encode()
        return (bytes([0xA0 | len(b)]) if len(b) < 32 else b"\xd9" + bytes([len(b)])) + b
    if isinstance(v, list):
        return bytes([0x90 | len(v)]) + b"".join(mp(x) for x in v)
    if isinstance(v, dict):
        return bytes([0x80 | len(v)]) + b"".join(mp(k) + mp(x) for k, x in v.items())
    raise TypeError(v)


def request_seeds():
    reqs = {
        "hello": {"cmd": "hello", "id": 1, "protocol": 1},
        "step": {"cmd": "step", "id": 2, "steps": 10, "ctrl": [0.1, -0.2, 0.3]},
        "set_pose": {"cmd": "set_pose", "body": "ball", "xyz": [0.0, 1.0, 2.5],
                     "quat": [1.0, 0.0, 0.0, 0.0]},
        "record": {"cmd": "start_recording", "path": "x.plog", "force": False},
        "sync": {"cmd": "sync", "token": "abc"},
        "subscribe": {"cmd": "subscribe", "topics": ["state", "camera/front/rgb"]},
        "odd": {"cmd": None, "id": {"nested": [1, 2, {"x": b"\x00\x01"}]}, "n": -5,
                "big": 2**62, "f": 1e308},
    }
    for name, r in reqs.items():
        write("request", "msgpack_" + name + ".bin", b"\x00" + mp(r))
        if name != "odd":
            write("request", "json_" + name + ".bin", b"\x01" + json.dumps(r).encode())
    # hostile msgpack: a map32 that declares 2^32 - 1 entries, deep arrays, trailing bytes,
    # a str32 of 4 GB, an ext value, a non-string key
    write("request", "msgpack_map32_huge.bin", b"\x00\xdf\xff\xff\xff\xff")
    write("request", "msgpack_deep.bin", b"\x00" + b"\x91" * 100 + b"\xc0")
    write("request", "msgpack_trailing.bin", b"\x00" + mp({"cmd": "hello"}) + b"\xc0")
    write("request", "msgpack_str32_huge.bin", b"\x00\xdb\xff\xff\xff\xff" + b"abc")
    write("request", "msgpack_ext.bin", b"\x00\x81\xa1x\xd4\x01\x02")
    write("request", "msgpack_int_key.bin", b"\x00\x81\x01\xc0")
    write("request", "json_deep.bin", b"\x01" + b"[" * 1000 + b"]" * 1000)
    write("request", "json_bad_utf8.bin", b'\x01{"cmd": "\xff\xfe"}')


# ---- viewer messages -------------------------------------------------------------------------
def frame(header, payload=b""):
    h = json.dumps(header).encode()
    return struct.pack("<I", len(h)) + h + payload


def viewer_seeds():
    write("viewer_messages", "frame_rgb.bin",
          frame({"type": "frame", "camera": "front", "kind": "rgb", "frame": 3,
                 "time_sec": 0.15}, b"\xff\xd8\xff\xe0JPEG"))
    write("viewer_messages", "frame_empty_payload.bin", frame({"type": "frame"}))
    write("viewer_messages", "frame_length_too_big.bin", b"\xff\xff\xff\xff{}")
    write("viewer_messages", "frame_header_not_json.bin", struct.pack("<I", 3) + b"{x}")
    write("viewer_messages", "frame_short.bin", b"\x01\x00")
    write("viewer_messages", "text_subscribe.txt",
          json.dumps({"cmd": "subscribe", "streams": ["camera/front/rgb"]}))
    write("viewer_messages", "text_pause.txt", json.dumps({"cmd": "pause", "id": 7}))
    write("viewer_messages", "text_record.txt",
          json.dumps({"cmd": "start_recording", "path": "../../etc/x.plog"}))
    write("viewer_messages", "text_array.txt", "[1, 2, 3]")


# ---- method command templates ----------------------------------------------------------------
def template_seeds():
    """fuzz/template_fuzz.cc's layout: the template, then NUL-separated placeholder values."""
    bundled = "{penumbra} slam opencv_rgbd {dataset} {output} --intrinsics {fx},{fy},{cx},{cy}"
    nav = ("/usr/bin/env PYTHONPATH={pythonpath} /usr/bin/python3 -m penumbra_nav --endpoint "
           "{endpoint} --goal {goal_x} {goal_y} --out {out_dir}/episode.json")
    hostile = "\0/tmp/o $(touch X) `touch Y`\0a b\tc\0{dataset}"
    for name, text in [
            ("bundled.txt", bundled + hostile),
            ("nav.txt", nav),
            ("sh_positional.txt", "sh -c 'slam \"$1\" > \"$2\"' sh {dataset} {output}" + hostile),
            ("python_argv.txt", "/usr/bin/python3 -c 'import sys; print(sys.argv[1])' {dataset}"),
            ("sh_c_dashdash.txt", "sh -c -- 'true {output}'"),
            ("timeit.txt", "python3 -m timeit -s 'os.system(\"cat {dataset} > {output}\")'"),
            ("env_nice_sh.txt", "/usr/bin/env A=1 nice -n 5 bash -ec 'x {seed}' bash"),
            ("perl_e.txt", "perl -lne 'print' {dataset}/x.txt"),
            ("quotes.txt", "/opt/x/run 'a b' \"{output}\" x{seed}y {{z}} --k={fx},{fy}"),
            ("merged.txt", "run {dataset}{output}"),
            ("operators.txt", "run {dataset}; touch X | y > z $(a) `b`"),
            ("ssh.txt", "ssh host slam {output}"),
            ("braces.txt", "run {dataset } }{ {{{seed}}}"),
    ]:
        write("template", name, text)


# ---- rollout arguments -----------------------------------------------------------------------
def rollout_seed(copies, threads, substeps, mode, per_copy=4096, cap=1 << 30, values=()):
    """fuzz/rollout_fuzz.cc's layout: three int64 counts, a mode byte (bit 0: counts raw, else
    folded to -1..4; bit 1: joint PD), bytes per copy and cap (uint64), float64 values."""
    return (struct.pack("<qqqB", copies, threads, substeps, mode) + struct.pack("<QQ", per_copy, cap)
            + b"".join(struct.pack("<d", v) for v in values))


def rollout_seeds():
    nan, inf = float("nan"), float("inf")
    small = [0.1, -0.2, 0.3, 0.0] * 8
    write("rollout", "direct_two_copies.bin", rollout_seed(3, 3, 3, 0, values=small))
    write("rollout", "joint_pd.bin", rollout_seed(2, 2, 4, 2, values=[20, 5, 0.5, 0.1] + small))
    write("rollout", "threads_100000.bin", rollout_seed(1, 100000, 1, 1))
    write("rollout", "copies_1e7.bin", rollout_seed(10 ** 7, 1, 1, 1, per_copy=1 << 20))
    write("rollout", "substeps_2_31.bin", rollout_seed(1, 1, 2 ** 31 - 1, 1))
    write("rollout", "negative_counts.bin", rollout_seed(-1, -(2 ** 63), -5, 1))
    write("rollout", "nan_inputs.bin", rollout_seed(3, 2, 2, 0, values=[nan, 0, inf, -inf] * 4))
    write("rollout", "nan_gains.bin", rollout_seed(2, 2, 2, 2, values=[nan, 1, inf, 1] + small))
    write("rollout", "huge_inputs.bin", rollout_seed(2, 2, 5, 2, values=[1e9, 1e9, 1e9, 1e9]
                                                     + [1e308, -1e308] * 8))
    write("rollout", "memory_overflow.bin", rollout_seed(2 ** 40, 1, 1, 1, per_copy=2 ** 63,
                                                         cap=2 ** 64 - 1))


# ---- ONNX policies and the policy's per-step checks --------------------------------------------
def onnx_seeds():
    """fuzz/onnx_fuzz.cc's layout: two bytes (observation and action sizes - 1, mod 64), then
    the file: the crafted models of tests/control/make_crafted_onnx.py and two fixtures."""
    import sys
    sys.path.insert(0, os.path.join(ROOT, "tests", "control"))
    from make_crafted_onnx import crafted
    for name, data in sorted(crafted().items()):
        write("onnx", name, b"\x03\x01" + data)
    for name, n_in, n_out in (("mlp_48x12.onnx", 48, 12), ("gemm_15x12.onnx", 15, 12)):
        with open(os.path.join(ROOT, "tests", "control", "fixtures", name), "rb") as f:
            write("onnx", name, bytes([n_in - 1, n_out - 1]) + f.read())


def policy_seed(clip, step, terms, outputs):
    """fuzz/policy_fuzz.cc's layout: output count, clip choice, int64 step, term count, 3 bytes
    per term (kind, size, history - 1), float32 outputs."""
    return (struct.pack("<BBqB", len(outputs), clip, step, len(terms))
            + b"".join(bytes(t) for t in terms) + struct.pack("<%df" % len(outputs), *outputs))


def policy_seeds():
    nan, inf = float("nan"), float("inf")
    terms = [(0, 3, 0), (4, 12, 2), (6, 12, 0)]
    write("policy", "finite.bin", policy_seed(0, 4, terms, [0.1 * i for i in range(12)]))
    write("policy", "clip_100.bin", policy_seed(1, 8, terms, [250.0, -250.0, 1.0]))
    write("policy", "huge_3e38.bin", policy_seed(0, 12, terms, [0.0, 3e38, 0.0]))
    write("policy", "neg_inf.bin", policy_seed(2, 16, terms, [-inf, 0.0]))
    write("policy", "nan.bin", policy_seed(3, -1, [], [nan] * 4))
    write("policy", "max_step.bin", policy_seed(1, 2 ** 63 - 1, terms * 5, [1e6, -1e6]))


# ---- ROS 2 samples -----------------------------------------------------------------------------
# fuzz/ros2_sample_fuzz.cc's layout: one byte, the Ros2Type (ros/ros2/ros2_types.h's order), then
# the CDR as a DDS sample carries it: the encapsulation header (0, 1: little endian; 0, 0: big),
# two option bytes whose last is the count of padding bytes at the end, then XCDR1 data: each
# primitive aligned to its size from the first byte after the header, strings and sequences a
# uint32 length first (a string's counts its terminating NUL). written here by hand, not by the
# serializer under test.
ROS2_TYPE = {"Image": 0, "JointState": 4, "TFMessage": 6, "Clock": 7, "Twist": 8,
             "PoseStamped": 9, "TriggerRequest": 10, "TriggerResponse": 11}


class Cdr:
    def __init__(self, little=True):
        self.e = "<" if little else ">"
        self.b = bytearray()

    def put(self, fmt, *v):
        size = struct.calcsize(fmt)
        self.b += bytes(-len(self.b) % size)
        self.b += struct.pack(self.e + fmt * len(v), *v)
        return self

    def string(self, s, nul=True):
        s = s.encode() if isinstance(s, str) else s
        self.put("I", len(s) + (1 if nul else 0))
        self.b += s + (b"\0" if nul else b"")
        return self

    def doubles(self, v):
        self.put("I", len(v))
        if v:
            self.put("d", *v)
        return self

    def header(self, sec, nanosec, frame):
        return self.put("i", sec).put("I", nanosec).string(frame)

    def sample(self, type_name, pad=True):
        n = -len(self.b) % 4 if pad else 0
        head = (b"\x00\x01" if self.e == "<" else b"\x00\x00") + bytes([0, n])
        return bytes([ROS2_TYPE[type_name]]) + head + bytes(self.b) + bytes(n)


def joint_state(names, pos, vel=(), eff=(), frame="", little=True, sec=12, nanosec=5):
    c = Cdr(little).header(sec, nanosec, frame).put("I", len(names))
    for n in names:
        c.string(n)
    return c.doubles(list(pos)).doubles(list(vel)).doubles(list(eff)).sample("JointState")


def ros2_seeds():
    nan, inf = float("nan"), float("inf")
    t = "ros2_sample"
    write(t, "twist.bin", Cdr().put("d", 0.5, 0, 0, 0, 0, -0.25).sample("Twist"))
    write(t, "twist_big_endian.bin", Cdr(False).put("d", 0.5, 0, 0, 0, 0, 1).sample("Twist"))
    write(t, "twist_nan_inf.bin", Cdr().put("d", nan, inf, -inf, -0.0, 1e308, 5e-324)
          .sample("Twist"))
    write(t, "twist_short.bin", Cdr().put("d", 1, 2, 3, 4, 5).sample("Twist"))
    write(t, "pose_stamped.bin", Cdr().header(3, 250000000, "world").put(
        "d", 1, 2, 3, 0, 0, 0, 1).sample("PoseStamped"))
    write(t, "pose_stamped_negative_stamp.bin", Cdr().header(-2, 999999999, "map").put(
        "d", 0, 0, 0, 0, 0, 0, 1).sample("PoseStamped"))
    write(t, "pose_stamped_nanosec_1e9.bin", Cdr().header(0, 1000000000, "world").put(
        "d", 0, 0, 0, 0, 0, 0, 1).sample("PoseStamped"))
    write(t, "pose_stamped_frame_no_nul.bin", Cdr().put("i", 0).put("I", 0).string(
        "world", nul=False).put("d", 0, 0, 0, 0, 0, 0, 1).sample("PoseStamped"))
    write(t, "pose_stamped_frame_1025.bin", Cdr().header(0, 0, "f" * 1025).put(
        "d", 0, 0, 0, 0, 0, 0, 1).sample("PoseStamped"))
    write(t, "joint_state.bin", joint_state(["shoulder", "elbow"], [0.1, -0.2], [0, 0],
                                            frame="base_link"))
    write(t, "joint_state_big_endian.bin", joint_state(["a"], [1.0], little=False))
    write(t, "joint_state_unnamed.bin", joint_state([], [0.5, 0.25, 0.125]))
    write(t, "joint_state_count_mismatch.bin", joint_state(["a", "b"], [1.0]))
    write(t, "joint_state_1024.bin", joint_state(["j%d" % i for i in range(1024)], [0.0] * 1024))
    write(t, "joint_state_1025.bin", joint_state(["j%d" % i for i in range(1025)], []))
    write(t, "joint_state_1025_unnamed.bin", joint_state([], [0.0] * 1025))
    write(t, "joint_state_4g_names.bin",
          Cdr().header(0, 0, "").put("I", 0xFFFFFFFF).string("a").sample("JointState"))
    write(t, "joint_state_4g_positions.bin",
          Cdr().header(0, 0, "").put("I", 0).put("I", 0x20000000).put("d", 1.0)
          .sample("JointState"))
    write(t, "joint_state_name_4g.bin",
          Cdr().header(0, 0, "").put("I", 1).put("I", 0xFFFFFFFF).sample("JointState"))
    write(t, "trigger_request.bin",
          Cdr().put("Q", 0x0110f00dcafe0001).put("q", 7).put("B", 0).sample("TriggerRequest"))
    write(t, "trigger_request_short.bin", Cdr().put("Q", 1).sample("TriggerRequest"))
    write(t, "trigger_response.bin", Cdr().put("Q", 9).put("q", 3).put("B", 1)
          .string("step: step 1, t = 0.002 s").sample("TriggerResponse"))
    write(t, "trigger_response_bool_2.bin", Cdr().put("Q", 9).put("q", 3).put("B", 2)
          .string("").sample("TriggerResponse"))
    write(t, "clock.bin", Cdr().put("i", 100).put("I", 2000000).sample("Clock"))
    write(t, "clock_min.bin", Cdr().put("i", -2 ** 31).put("I", 999999999).sample("Clock"))
    image = Cdr().header(1, 2, "camera").put("I", 2, 2).string("rgb8").put("B", 0).put("I", 6)
    image.put("I", 12).b += bytes(range(12))
    write(t, "image.bin", image.sample("Image"))
    tf = Cdr().put("I", 1).header(0, 1, "world").string("base").put("d", 1, 2, 3, 0, 0, 0, 1)
    write(t, "tf_message.bin", tf.sample("TFMessage"))
    write(t, "bad_encapsulation.bin", b"\x08\x00\x07\x00\x00" + bytes(48))
    write(t, "header_only.bin", b"\x08\x00\x01\x00\x00")


if __name__ == "__main__":
    runlog_seeds()
    tum_seeds()
    world_seeds()
    request_seeds()
    viewer_seeds()
    rollout_seeds()
    template_seeds()
    onnx_seeds()
    policy_seeds()
    ros2_seeds()
    for t in sorted(os.listdir(CORPUS)):
        files = os.listdir(os.path.join(CORPUS, t))
        size = sum(os.path.getsize(os.path.join(CORPUS, t, f)) for f in files)
        print("%-16s %3d files, %6d bytes" % (t, len(files), size))
