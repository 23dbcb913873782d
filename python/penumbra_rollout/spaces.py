"""The Box space of python/penumbra_client/spaces.py, loaded by file so that the rollout
package needs neither the client's ZeroMQ dependencies nor gymnasium."""

import importlib.util
import os

_path = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                     "penumbra_client", "spaces.py")
_spec = importlib.util.spec_from_file_location("_penumbra_client_spaces", _path)
_mod = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_mod)
Box = _mod.Box
