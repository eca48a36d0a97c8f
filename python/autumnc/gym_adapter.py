"""Registers autumnc with Gymnasium when Gymnasium happens to be installed.

``gymnasium.make("autumnc/Autumn-v0", program=PATH)`` then gives a
``gymnasium.Env`` wrapping ``autumnc.Env`` with real Gymnasium spaces. Without
Gymnasium this module does nothing (it is not a dependency).
"""
_registered = False


def _make_class(gym):
    import numpy as np

    from .envs import Env

    class GymnasiumEnv(gym.Env):
        metadata = {"render_modes": []}

        def __init__(self, program, **kwargs):
            self._env = Env(program, **kwargs)
            g = self._env.grid_size
            self.action_space = gym.spaces.Discrete(5 + g * g)
            self.observation_space = gym.spaces.Box(0, 255, (g, g), np.uint8)

        def reset(self, seed=None, options=None):
            super().reset(seed=seed)
            return self._env.reset(seed=seed, options=options)

        def step(self, action):
            return self._env.step(int(action))

    return GymnasiumEnv


def register():
    global _registered
    if _registered:
        return
    try:
        import gymnasium
    except ImportError:
        return
    cls = _make_class(gymnasium)
    globals()["GymnasiumEnv"] = cls
    gymnasium.register(id="autumnc/Autumn-v0", entry_point=cls)
    _registered = True
