#!/usr/bin/env python3
"""a ROS 2 participant (Cyclone DDS's Python binding) that tries to reach `penumbra run --ros2`
from wherever it runs (tests/ros/ros2_remote_test.py starts it in a network namespace: another
host). For SECONDS it reads /clock and calls /penumbra/pause (std_srvs/srv/Trigger, with
rmw_cyclonedds's request header) every 0.5 s, then prints one JSON line:
{"clock_samples": N, "last_clock_sec": T, "replies": R}.

usage: ros2_remote_peer.py DOMAIN OWN_ADDRESS PEER_ADDRESS SECONDS
"""
import json
import sys
import time
from dataclasses import dataclass

import cyclonedds.idl as idl
import cyclonedds.idl.annotations as annotate
import cyclonedds.idl.types as T
from cyclonedds.core import Policy, Qos
from cyclonedds.domain import Domain, DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic


@dataclass
@annotate.final
class Time(idl.IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: T.int32
    nanosec: T.uint32


@dataclass
@annotate.final
class Clock(idl.IdlStruct, typename="rosgraph_msgs::msg::dds_::Clock_"):
    clock: Time


# rmw_cyclonedds's service samples: {client guid, sequence number} before the request / response
@dataclass
@annotate.final
class TriggerRequest(idl.IdlStruct, typename="std_srvs::srv::dds_::Trigger_Request_"):
    client_guid: T.uint64
    sequence_number: T.int64
    structure_needs_at_least_one_member: T.byte


@dataclass
@annotate.final
class TriggerResponse(idl.IdlStruct, typename="std_srvs::srv::dds_::Trigger_Response_"):
    client_guid: T.uint64
    sequence_number: T.int64
    success: bool
    message: str


def main():
    domain, own, peer, seconds = int(sys.argv[1]), sys.argv[2], sys.argv[3], float(sys.argv[4])
    # discovery both ways a ROS 2 node may use: multicast on its interface (Cyclone's default;
    # loopback has none) and unicast to the participant ports of PEER_ADDRESS
    multicast = "" if own.startswith("127.") else "<AllowMulticast>true</AllowMulticast>"
    config = ("<CycloneDDS><Domain id=\"%d\"><General><Interfaces>"
              "<NetworkInterface address=\"%s\"/></Interfaces>%s</General>"
              "<Discovery><ParticipantIndex>auto</ParticipantIndex>"
              "<MaxAutoParticipantIndex>32</MaxAutoParticipantIndex>"
              "<Peers><Peer address=\"%s\"/></Peers></Discovery></Domain></CycloneDDS>"
              % (domain, own, multicast or "<AllowMulticast>false</AllowMulticast>", peer))
    _domain = Domain(domain, config)
    dp = DomainParticipant(domain)
    reliable = Qos(Policy.Reliability.Reliable(max_blocking_time=100_000_000),
                   Policy.History.KeepLast(10), Policy.Durability.Volatile,
                   Policy.DataRepresentation(use_cdrv0_representation=True))
    clock = DataReader(dp, Topic(dp, "rt/clock", Clock), reliable)
    replies = DataReader(dp, Topic(dp, "rr/penumbra/pauseReply", TriggerResponse), reliable)
    requests = DataWriter(dp, Topic(dp, "rq/penumbra/pauseRequest", TriggerRequest), reliable)
    guid = 0x5045_4E55_4D42_5241
    n_clock, last, n_replies, seq = 0, None, 0, 0
    end = time.time() + seconds
    next_call = time.time() + 1.0
    while time.time() < end:
        for s in clock.take(100):
            if isinstance(s, Clock):
                n_clock += 1
                last = s.clock.sec + s.clock.nanosec * 1e-9
        for s in replies.take(10):
            if isinstance(s, TriggerResponse) and s.client_guid == guid:
                n_replies += 1
        if time.time() >= next_call:
            seq += 1
            requests.write(TriggerRequest(guid, seq, 0))
            next_call += 0.5
        time.sleep(0.02)
    print(json.dumps({"clock_samples": n_clock, "last_clock_sec": last, "replies": n_replies}),
          flush=True)


if __name__ == "__main__":
    main()
