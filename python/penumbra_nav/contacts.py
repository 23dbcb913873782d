"""A log of the contacts the robot's bodies take part in, from the ``contacts`` topic.

The navigator records contacts; it does not judge them (which are collisions is the
benchmark harness's call: a foot or wheel on the floor is a contact too). Contact points and
forces are as published (docs/zmq-protocol.md): ``p_W`` in the world frame, m; ``force_N``
(normal, tangent 1, tangent 2), N.
"""


class ContactLog:
    """Aggregates contacts between a robot's bodies and anything else, per body pair.

    :param body_names: body names by id (``model_info().bodies``; id 0 = world).
    :param robot_prefix: the robot's body-name prefix, e.g. ``"quadruped/"``.
    """

    def __init__(self, body_names, robot_prefix):
        self.body_names = dict(body_names)
        self.robot_prefix = robot_prefix
        self._pairs = {}
        #: messages read.
        self.messages = 0

    def _is_robot(self, body):
        return self.body_names.get(body, "").startswith(self.robot_prefix)

    def add(self, header):
        """Adds one ``contacts`` message's header (``stamp``, ``contacts``). Returns the
        number of robot contacts in it."""
        self.messages += 1
        n = 0
        for c in header.get("contacts", []):
            b1, b2 = c["body1"], c["body2"]
            r1, r2 = self._is_robot(b1), self._is_robot(b2)
            if r1 == r2:
                continue
            robot_body, other = (b1, b2) if r1 else (b2, b1)
            key = (self.body_names.get(robot_body, str(robot_body)),
                   self.body_names.get(other, str(other)))
            normal = abs(float(c.get("force_N", [0.0])[0]))
            entry = self._pairs.get(key)
            if entry is None:
                entry = {"robot_body": key[0], "other_body": key[1],
                         "first_time_sec": header["stamp"], "last_time_sec": header["stamp"],
                         "samples": 0, "max_normal_force_N": 0.0}
                self._pairs[key] = entry
            entry["last_time_sec"] = header["stamp"]
            entry["samples"] += 1
            entry["max_normal_force_N"] = max(entry["max_normal_force_N"], normal)
            n += 1
        return n

    def summary(self):
        """One dict per (robot body, other body) pair, sorted by names: ``robot_body``,
        ``other_body``, ``first_time_sec``, ``last_time_sec`` (sim time, s), ``samples``
        (contact points over all messages), ``max_normal_force_N``."""
        return [dict(v) for _, v in sorted(self._pairs.items())]
