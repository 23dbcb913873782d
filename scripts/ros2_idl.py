#!/usr/bin/env python3
"""ROS 2 message types for the ROS 2 bridge (src/penumbra/ros/ros2/), generated at build time.

Reads the ROS 2 Jazzy message definitions shipped inside the `rosbags` package
(rosbags.typesys, Stores.ROS2_JAZZY) and writes:

  --idl FILE   one IDL file with the types below and their dependencies, named as
               rmw_cyclonedds names them (module pkg { module msg { module dds_ { struct T_ }}}),
               for Cyclone DDS's idlc;
  --inc FILE   a C++ fragment: one PENUMBRA_ROS2_TYPE(enumerator, ros name, DDS type name,
               RIHS01 type hash, ros2msg definition, descriptor) row per type of Ros2Type.

The RIHS01 hash (REP-2011) is computed here, as rosidl_generator_type_description does: the
type description (the type's fields and, sorted by name, every type it references) as JSON
with ", " and ": " separators and no default values, hashed with SHA-256. The definition text
is the complete message definition in rosbag2's "ros2msg" layout (the type's .msg text, then for
each dependency, depth first, a line of 80 '=' and "MSG: pkg/Type" and its text), without the
comments of the original .msg files.

std_srvs/srv/Trigger is not in rosbags: its request and response are defined below from
std_srvs's Trigger.srv. On the wire (rmw_cyclonedds) a request or reply sample starts with the
request header {uint64 guid, int64 sequence number}, which the IDL structs of the service carry
as their first two members; the hash is that of the ROS type without it.

usage: ros2_idl.py --idl OUT.idl --inc OUT.inc [--check]
  --check   print every type's hash next to rosbags' Typestore.hash_rihs01 and fail on a
            difference (the tests do the same against the built table).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import sys
from dataclasses import dataclass, field

# the types the bridge publishes, subscribes to or serves: Ros2Type's enumerators, in order
ENUM_TYPES = [
    ("kImage", "sensor_msgs/msg/Image"),
    ("kCameraInfo", "sensor_msgs/msg/CameraInfo"),
    ("kPointCloud2", "sensor_msgs/msg/PointCloud2"),
    ("kImu", "sensor_msgs/msg/Imu"),
    ("kJointState", "sensor_msgs/msg/JointState"),
    ("kOdometry", "nav_msgs/msg/Odometry"),
    ("kTfMessage", "tf2_msgs/msg/TFMessage"),
    ("kClock", "rosgraph_msgs/msg/Clock"),
    ("kTwist", "geometry_msgs/msg/Twist"),
    ("kPoseStamped", "geometry_msgs/msg/PoseStamped"),
    ("kTriggerRequest", "std_srvs/srv/Trigger_Request"),
    ("kTriggerResponse", "std_srvs/srv/Trigger_Response"),
    ("kParticipantEntitiesInfo", "rmw_dds_common/msg/ParticipantEntitiesInfo"),
]

# rmw_cyclonedds's request header, the first members of a service's request and reply samples
SERVICE_TYPES = {"std_srvs/srv/Trigger_Request", "std_srvs/srv/Trigger_Response"}
REQUEST_HEADER = [("client_guid", "uint64"), ("sequence_number", "int64")]

# type ids of type_description_interfaces/msg/FieldType (ROS 2 Iron and later)
FIELD_TYPE_IDS = {
    "nested": 1,
    "int8": 2,
    "uint8": 3,
    "int16": 4,
    "uint16": 5,
    "int32": 6,
    "uint32": 7,
    "int64": 8,
    "uint64": 9,
    "float32": 10,
    "float64": 11,
    "float128": 12,
    "char": 13,
    "wchar": 14,
    "bool": 15,
    "byte": 16,
    "string": 17,
    "wstring": 18,
    "bounded_string": 21,
    "bounded_wstring": 22,
}
ARRAY_OFFSET = 48  # T[N]
BOUNDED_SEQUENCE_OFFSET = 96  # T[<=N]
UNBOUNDED_SEQUENCE_OFFSET = 144  # T[]

# .msg primitive type -> IDL type (the wire types are the same size and alignment)
IDL_TYPES = {
    "bool": "boolean",
    "byte": "octet",
    "char": "uint8",
    "int8": "int8",
    "uint8": "uint8",
    "int16": "int16",
    "uint16": "uint16",
    "int32": "int32",
    "uint32": "uint32",
    "int64": "int64",
    "uint64": "uint64",
    "float32": "float",
    "float64": "double",
    "string": "string",
}


@dataclass
class Field:
    name: str
    base: str  # a primitive ("float64", "string") or a type name ("std_msgs/msg/Header")
    kind: str = "single"  # single, array (T[N]), bounded (T[<=N]), sequence (T[])
    size: int = 0  # N of an array or bounded sequence
    string_bound: int = 0  # N of string<=N

    @property
    def nested(self) -> bool:
        return "/" in self.base


@dataclass
class Message:
    name: str  # pkg/msg/Type or pkg/srv/Type_Request
    fields: list[Field]
    constants: list[tuple[str, str, str]] = field(default_factory=list)  # (type, name, value)


def from_rosbags(store, name: str) -> Message:
    """One message of the rosbags type store, in this script's own model."""
    from rosbags.interfaces import Nodetype

    consts, fielddefs = store.fielddefs[name]

    def element(desc, f: Field):
        if desc[0] == Nodetype.NAME:
            f.base = desc[1]
        elif desc[0] == Nodetype.BASE:
            f.base, f.string_bound = desc[1][0], desc[1][1] or 0
        else:
            raise SystemExit(f"ros2_idl: {name}.{f.name}: nested arrays are not supported")

    fields = []
    for fname, desc in fielddefs:
        f = Field(fname, "")
        if desc[0] in (Nodetype.ARRAY, Nodetype.SEQUENCE):
            sub, count = desc[1]
            element(sub, f)
            if desc[0] == Nodetype.ARRAY:
                f.kind, f.size = "array", count
            elif count:
                f.kind, f.size = "bounded", count
            else:
                f.kind = "sequence"
        else:
            element(desc, f)
        fields.append(f)
    return Message(name, fields, [(t, n, str(v)) for n, t, v in consts])


def trigger_messages() -> list[Message]:
    """std_srvs/srv/Trigger.srv: an empty request and {bool success, string message}."""
    return [
        Message("std_srvs/srv/Trigger_Request", []),
        Message(
            "std_srvs/srv/Trigger_Response",
            [Field("success", "bool"), Field("message", "string")],
        ),
    ]


def hash_fields(msg: Message) -> list[Field]:
    # an empty structure gets rosidl's placeholder member (IDL has no empty structs)
    return msg.fields or [Field("structure_needs_at_least_one_member", "uint8")]


def field_type_id(f: Field) -> int:
    if f.nested:
        tid = FIELD_TYPE_IDS["nested"]
    elif f.base == "string" and f.string_bound:
        tid = FIELD_TYPE_IDS["bounded_string"]
    else:
        tid = FIELD_TYPE_IDS[f.base]
    offset = {
        "single": 0,
        "array": ARRAY_OFFSET,
        "bounded": BOUNDED_SEQUENCE_OFFSET,
        "sequence": UNBOUNDED_SEQUENCE_OFFSET,
    }[f.kind]
    return tid + offset


def type_description(msg: Message) -> dict:
    return {
        "type_name": msg.name,
        "fields": [
            {
                "name": f.name,
                "type": {
                    "type_id": field_type_id(f),
                    "capacity": f.size,
                    "string_capacity": f.string_bound,
                    "nested_type_name": f.base if f.nested else "",
                },
            }
            for f in hash_fields(msg)
        ],
    }


def dependencies(msgs: dict[str, Message], name: str, seen: set[str] | None = None) -> set[str]:
    """Every type `name` references, directly or not."""
    seen = set() if seen is None else seen
    for f in msgs[name].fields:
        if f.nested and f.base not in seen:
            seen.add(f.base)
            dependencies(msgs, f.base, seen)
    return seen


def rihs01(msgs: dict[str, Message], name: str) -> str:
    """REP-2011's RIHS01 hash of `name`."""
    hashable = {
        "type_description": type_description(msgs[name]),
        "referenced_type_descriptions": [
            type_description(msgs[d]) for d in sorted(dependencies(msgs, name))
        ],
    }
    text = json.dumps(
        hashable, ensure_ascii=True, allow_nan=False, indent=None, separators=(", ", ": ")
    )
    return "RIHS01_" + hashlib.sha256(text.encode("utf-8")).hexdigest()


def short_name(name: str) -> str:
    """pkg/msg/Type -> pkg/Type, as .msg files write field types."""
    pkg, _, typ = name.split("/")
    return f"{pkg}/{typ}"


def msg_text(msg: Message) -> str:
    lines = [f"{t} {n}={v}" for t, n, v in msg.constants]
    for f in msg.fields:
        base = short_name(f.base) if f.nested else f.base
        if f.base == "string" and f.string_bound:
            base = f"string<={f.string_bound}"
        suffix = {"single": "", "array": f"[{f.size}]", "bounded": f"[<={f.size}]",
                  "sequence": "[]"}[f.kind]
        lines.append(f"{base}{suffix} {f.name}")
    return "".join(line + "\n" for line in lines)


def ros2msg_definition(msgs: dict[str, Message], name: str) -> str:
    """The complete definition as rosbag2 writes it (rosbag2_cpp LocalMessageDefinitionSource)."""
    seen: set[str] = set()

    def append(n: str) -> str:
        text = msg_text(msgs[n])
        for dep in sorted({short_name(f.base) for f in msgs[n].fields if f.nested}):
            full = next(f.base for f in msgs[n].fields if f.nested and short_name(f.base) == dep)
            if dep not in seen:
                seen.add(dep)
                text += "\n" + "=" * 80 + "\n" + f"MSG: {dep}\n" + append(full)
        return text

    return append(name)


def idl_struct_name(name: str) -> str:
    return name.split("/")[2] + "_"


def dds_type_name(name: str) -> str:
    pkg, ns, typ = name.split("/")
    return f"{pkg}::{ns}::dds_::{typ}_"


def c_descriptor(name: str) -> str:
    pkg, ns, typ = name.split("/")
    return f"{pkg}_{ns}_dds__{typ}__desc"


def idl_member(f: Field) -> str:
    if f.nested:
        base = dds_type_name(f.base)
    elif f.base == "string" and f.string_bound:
        base = f"string<{f.string_bound}>"
    else:
        base = IDL_TYPES[f.base]
    if f.kind == "single":
        return f"{base} {f.name};"
    if f.kind == "array":
        return f"{base} {f.name}[{f.size}];"
    if f.kind == "bounded":
        return f"sequence<{base}, {f.size}> {f.name};"
    return f"sequence<{base}> {f.name};"


def write_idl(msgs: dict[str, Message], order: list[str]) -> str:
    out = [
        "// generated by scripts/ros2_idl.py from ROS 2 Jazzy's message definitions; do not edit",
        "",
    ]
    for name in order:
        pkg, ns, _ = name.split("/")
        members = [f"{IDL_TYPES[t]} {n};" for n, t in REQUEST_HEADER] if name in SERVICE_TYPES else []
        members += [idl_member(f) for f in hash_fields(msgs[name])]
        body = "".join(f"        {m}\n" for m in members)
        out.append(
            f"module {pkg} {{ module {ns} {{ module dds_ {{\n"
            f"      struct {idl_struct_name(name)} {{\n{body}      }};\n"
            f"}}; }}; }};\n"
        )
    return "\n".join(out)


def topological(msgs: dict[str, Message], roots: list[str]) -> list[str]:
    order: list[str] = []

    def visit(n: str):
        if n in order:
            return
        for f in msgs[n].fields:
            if f.nested:
                visit(f.base)
        order.append(n)

    for r in roots:
        visit(r)
    return order


def cxx_string(text: str) -> str:
    assert ")ros2msg" not in text
    return f'R"ros2msg({text})ros2msg"'


def write_inc(msgs: dict[str, Message]) -> str:
    rows = [
        "// generated by scripts/ros2_idl.py from ROS 2 Jazzy's message definitions; do not edit",
        "// PENUMBRA_ROS2_TYPE(enumerator, ros name, DDS type name, RIHS01 hash, ros2msg definition,",
        "//                    descriptor of the generated C struct)",
    ]
    for enum, name in ENUM_TYPES:
        rows.append(
            f'PENUMBRA_ROS2_TYPE({enum}, "{name}", "{dds_type_name(name)}", "{rihs01(msgs, name)}",\n'
            f"                   {cxx_string(ros2msg_definition(msgs, name))},\n"
            f"                   {c_descriptor(name)})"
        )
    return "\n".join(rows) + "\n"


def load() -> tuple[dict[str, Message], object]:
    try:
        from rosbags.typesys import Stores, get_typestore
    except ImportError as e:
        raise SystemExit(
            f"ros2_idl: {e}: run with the project venv's python (scripts/install-deps.sh makes .venv)"
        )
    store = get_typestore(Stores.ROS2_JAZZY)
    msgs: dict[str, Message] = {m.name: m for m in trigger_messages()}
    todo = [n for _, n in ENUM_TYPES if n not in msgs]
    while todo:
        n = todo.pop()
        if n in msgs:
            continue
        if n not in store.fielddefs:
            raise SystemExit(f"ros2_idl: {n} is not in rosbags' ROS 2 Jazzy store")
        msgs[n] = from_rosbags(store, n)
        todo += [f.base for f in msgs[n].fields if f.nested]
    return msgs, store


def write_if_changed(path: str, text: str) -> None:
    try:
        with open(path, encoding="utf-8") as f:
            if f.read() == text:
                return
    except FileNotFoundError:
        pass
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, path)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--idl", help="the IDL file to write")
    ap.add_argument("--inc", help="the C++ type table fragment to write")
    ap.add_argument("--check", action="store_true", help="compare hashes with rosbags'")
    args = ap.parse_args()
    msgs, store = load()
    roots = [n for _, n in ENUM_TYPES]
    if args.idl:
        write_if_changed(args.idl, write_idl(msgs, topological(msgs, roots)))
    if args.inc:
        write_if_changed(args.inc, write_inc(msgs))
    if args.check:
        bad = 0
        for name in sorted(msgs):
            ours = rihs01(msgs, name)
            theirs = store.hash_rihs01(name) if name in store.fielddefs else "(not in rosbags)"
            ok = ours == theirs or name not in store.fielddefs
            bad += not ok
            print(f"{'ok ' if ok else 'BAD'} {name} {ours} {theirs}")
        return 1 if bad else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
