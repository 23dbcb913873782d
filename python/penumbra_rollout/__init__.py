"""Batched MuJoCo rollouts for Python: N copies of a model stepped in C++ on a thread pool.

- :class:`BatchStepper` (the pybind11 module ``_penumbra_rollout``, built by CMake into
  ``build/python`` when Debian's pybind11-dev is installed): raw N-copy stepping.
- :class:`QuadrupedVelocityEnv`: a vector environment with Gymnasium's ``VectorEnv``
  signatures (``reset(seed=, options=)``, ``step(actions)`` giving
  ``(obs, rewards, terminations, truncations, infos)``, ``num_envs``,
  ``single_observation_space``, ...) over the bundled Go1-class quadruped, with the
  observation, action and reward conventions of legged_gym (train/README.md).

Put ``build/python`` and ``python`` on ``PYTHONPATH``.
"""

from _penumbra_rollout import BatchStepper  # noqa: F401

from .quadruped_env import (DEFAULT_JOINT_POS, POLICY_JOINT_ORDER, QuadrupedEnvConfig,  # noqa: F401
                            QuadrupedVelocityEnv)
