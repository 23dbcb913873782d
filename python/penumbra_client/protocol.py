"""Messages of Penumbra's ZeroMQ protocol (docs/zmq-protocol.md), version 1.

A request is one msgpack map ``{"cmd": NAME, "id": ID, ...fields}``; a reply is one msgpack map
``{"ok": true, "cmd": NAME, "id": ID, ...result}`` or an error reply whose ``error`` map holds
``code``, ``field`` and ``message``. :func:`encode_request` and :func:`decode_reply` convert
between these and Python values; :func:`error_from_reply` turns an error reply into the
exception class of its code (:class:`PenumbraError` subclasses).
"""

from __future__ import annotations

import msgpack
import numpy as np

#: the protocol version this client speaks (``protocol`` in ``hello``).
PROTOCOL_VERSION = 1


class PenumbraError(Exception):
    """An error reply from the server, or a failure to get one.

    :ivar code: the protocol's error code (``"bad_field"``, ...; ``"timeout"``,
        ``"bad_reply"`` for failures on the client side).
    :ivar field: the request field the error is about (e.g. ``"ctrl[3]"``), or None.
    :ivar cmd: the command of the request, or None.
    :ivar message: the server's human-readable text.
    :ivar reply: the whole reply map (None for client-side failures).
    """

    code = "error"

    def __init__(self, message, code=None, field=None, cmd=None, reply=None):
        self.message = message
        if code is not None:
            self.code = code
        self.field = field
        self.cmd = cmd
        self.reply = reply
        where = f" (field {field})" if field else ""
        super().__init__(f"{cmd or '?'}: {self.code}{where}: {message}")


class MalformedRequestError(PenumbraError):
    """``malformed``: the request was not one msgpack map with a string ``cmd``."""
    code = "malformed"


class RequestTooLargeError(PenumbraError):
    """``too_large``: the request exceeded the server's ``max_request_bytes``."""
    code = "too_large"


class UnknownCommandError(PenumbraError):
    """``unknown_command``: no command of that name (the message lists the valid ones)."""
    code = "unknown_command"


class MissingFieldError(PenumbraError):
    """``missing_field``: a required field was absent (``field`` names it)."""
    code = "missing_field"


class BadFieldError(PenumbraError):
    """``bad_field``: a field had the wrong type, size or range, or named something the model
    does not have (``field`` names it)."""
    code = "bad_field"


class UnknownFieldError(PenumbraError):
    """``unknown_field``: a key the command does not take (``field`` names it)."""
    code = "unknown_field"


class VersionMismatchError(PenumbraError):
    """``version_mismatch``: the server speaks another protocol version."""
    code = "version_mismatch"


class ConflictError(PenumbraError):
    """``conflict``: the command does not fit the run's state (e.g. ``step`` while running
    free)."""
    code = "conflict"


class NotAvailableError(PenumbraError):
    """``not_available``: not in this build or for this world (e.g. ``twist`` without a
    controller that takes twists)."""
    code = "not_available"


class RunEndedError(PenumbraError):
    """``run_ended``: the run has ended (end time, ``stop``, Ctrl-C or an error)."""
    code = "run_ended"


class StoppingError(RunEndedError):
    """``stopping``: the run is stopping or has stopped and the command was not carried out
    (queued when the run stopped, sent while the server shuts down, or ``start_recording``
    after a stop). A kind of :class:`RunEndedError`."""
    code = "stopping"


class CommandFailedError(PenumbraError):
    """``failed``: the command was valid but failed while being applied."""
    code = "failed"


class PenumbraTimeoutError(PenumbraError):
    """No reply (or not all messages a step announced) within the client's timeout."""
    code = "timeout"


class BadReplyError(PenumbraError):
    """The server's reply was not a msgpack map of the protocol."""
    code = "bad_reply"


ERROR_CLASSES = {cls.code: cls for cls in (
    MalformedRequestError, RequestTooLargeError, UnknownCommandError, MissingFieldError,
    BadFieldError, UnknownFieldError, VersionMismatchError, ConflictError, NotAvailableError,
    RunEndedError, StoppingError, CommandFailedError)}


def _to_msgpack(value):
    # numpy values become plain msgpack numbers and arrays (reals as float64)
    if isinstance(value, np.ndarray):
        if value.dtype.kind == "f":
            return value.astype(np.float64).tolist()
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, tuple):
        return list(value)
    raise TypeError(f"cannot encode {type(value).__name__} in a request: {value!r}")


def pack(value):
    """msgpack bytes of ``value`` (str as msgpack str, bytes as bin, numpy as numbers)."""
    return msgpack.packb(value, use_bin_type=True, default=_to_msgpack)


def unpack(body):
    """The Python value of one msgpack body (str keys, bin as bytes).

    :raises BadReplyError: the body is not exactly one msgpack value.
    """
    try:
        return msgpack.unpackb(body, raw=False, strict_map_key=False)
    except (ValueError, msgpack.UnpackException) as e:
        raise BadReplyError(f"not msgpack: {e}") from None


def encode_request(cmd, fields=None, request_id=None):
    """The body of a request: ``{"cmd": cmd, "id": request_id, **fields}`` as msgpack.

    Fields whose value is None are left out (the server's default applies). numpy arrays and
    scalars are sent as msgpack arrays and numbers (float64 for reals).

    :raises TypeError: a field value msgpack cannot hold.
    """
    if not isinstance(cmd, str) or not cmd:
        raise TypeError(f"cmd: {cmd!r}; expected a non-empty str")
    body = {"cmd": cmd}
    if request_id is not None:
        body["id"] = request_id
    for key, value in (fields or {}).items():
        if key in ("cmd", "id"):
            raise TypeError(f"field '{key}' is set by the client")
        if value is not None:
            body[key] = value
    return pack(body)


def decode_reply(body):
    """The reply map of a reply body; raises the error class of an error reply.

    :returns: the reply map (``ok`` is True).
    :raises PenumbraError: (a subclass by ``error.code``) for an error reply;
        :class:`BadReplyError` for a body that is not a reply map.
    """
    reply = unpack(body)
    if not isinstance(reply, dict) or not isinstance(reply.get("ok"), bool):
        raise BadReplyError(f"not a reply map with a bool 'ok': {reply!r:.200}")
    if not reply["ok"]:
        raise error_from_reply(reply)
    return reply


def error_from_reply(reply):
    """The exception for an error reply map (``ok`` false)."""
    err = reply.get("error") or {}
    code = err.get("code", "error")
    cls = ERROR_CLASSES.get(code, PenumbraError)
    return cls(err.get("message", ""), code=code, field=err.get("field"), cmd=reply.get("cmd"),
               reply=reply)
