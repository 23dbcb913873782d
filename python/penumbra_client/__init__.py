"""Python client of Penumbra's ZeroMQ bridge (``penumbra run WORLD --zmq``).

Pure Python on Debian's python3-zmq, python3-msgpack and python3-numpy. The wire format is
docs/zmq-protocol.md (protocol version 1); this package's guide is docs/python-client.md.

- :class:`Client`: handshake, model info, lockstep ``step``, state, ctrl, controller commands
  (twist, joint targets, waypoints), mocap, adversity/effects, recording, subscriptions.
- :class:`PenumbraEnv`: a Gymnasium-style ``reset()`` / ``step()`` environment (gymnasium
  itself is optional).
- camera images arrive as numpy arrays: RGB uint8 (H, W, 3), depth float32 metres (H, W) or
  uint16 millimetres.
"""

from .client import DEFAULT_ENDPOINT, Client
from .env import PenumbraEnv
from .images import ENCODINGS, ImageFormatError, depth_mm_to_m, image_from_buffer
from .messages import LIDAR_POINT_DTYPE, Message, ModelInfo, State, StepResult, Subscription
from .protocol import (PROTOCOL_VERSION, BadFieldError, BadReplyError, CommandFailedError,
                       ConflictError, MalformedRequestError, MissingFieldError,
                       NotAvailableError, PenumbraError, PenumbraTimeoutError,
                       RequestTooLargeError, RunEndedError, StoppingError,
                       UnknownCommandError, UnknownFieldError, VersionMismatchError)
from .spaces import Box, Dict

__all__ = [
    "Client", "DEFAULT_ENDPOINT", "PenumbraEnv", "Message", "ModelInfo", "State", "StepResult",
    "Subscription", "LIDAR_POINT_DTYPE", "ENCODINGS", "ImageFormatError", "image_from_buffer",
    "depth_mm_to_m", "Box", "Dict", "PROTOCOL_VERSION", "PenumbraError", "PenumbraTimeoutError",
    "BadReplyError", "MalformedRequestError", "RequestTooLargeError", "UnknownCommandError",
    "MissingFieldError", "BadFieldError", "UnknownFieldError", "VersionMismatchError",
    "ConflictError", "NotAvailableError", "RunEndedError", "StoppingError", "CommandFailedError",
]
