"""autumnc.Env and autumnc.VecEnv: Gymnasium-shaped faces of the C++ core.

Actions are integers: 0 noop, 1 left, 2 right, 3 up, 4 down, and 5 + y*W + x a
click on cell (x, y). Observations are uint8 arrays [H, W] of colour ids
(``autumnc.colour_names()[id]`` is the colour; ids 0..39 are AutumnBench's
color_dict.yaml). Autumn programs have no reward: it is 1.0 on steps where the
program's trigger condition (``trigger=``) held, else 0.0. A runtime error of
the program terminates the episode (``info["error"]``, or ``info["errors"]``
by environment index for VecEnv). ``max_episode_steps`` truncates episodes.
"""
import os

from . import _core
from .spaces import Box, Discrete


def _program_text(program):
    """(text, name) of a path, an ``autumnc.Program``, program text, or a (text, name) pair."""
    if isinstance(program, tuple) and len(program) == 2 and all(isinstance(p, str) for p in program):
        return program
    path = getattr(program, "path", program)
    if isinstance(path, (str, os.PathLike)) and os.path.isfile(path):
        with open(path, "r", encoding="utf-8") as f:
            return f.read(), os.fspath(path)
    if isinstance(program, str) and program.lstrip().startswith("("):
        return program, "<program>"
    raise FileNotFoundError(f"no Autumn program at {program!r} (give a path, the program text, or a (text, name) pair)")


def _spaces(grid):
    return Discrete(5 + grid * grid), Box(0, 255, (grid, grid))


class Env(_core._Env):
    """One Autumn episode, shaped like a Gymnasium environment.

    ``Env(program, seed=0, engine="auto", trigger=None, max_episode_steps=None)``

    * program: a path to an Autumn program (.au or .sexp), an
      ``autumnc.Program``, or the program's text.
    * seed: the random seed of the first episode (``reset(seed=...)`` changes it).
    * engine: "auto" (compiled when the program's module is ready; the
      interpreter serves while it compiles and a later ``reset()`` moves over),
      "compiled" (waits for the module; RuntimeError if it cannot be built) or
      "interp". Results are the same on every engine.
    * trigger: an Autumn expression (a trigger condition); the reward is 1.0
      on steps after which it held, else 0.0 (Autumn programs have no reward).
    * max_episode_steps: episodes are truncated after this many steps.

    ``reset(seed=None, options=None) -> (obs, info)``;
    ``step(action) -> (obs, reward, terminated, truncated, info)``.

    Actions are integer ids, ``action_space = Discrete(5 + W*H)``: 0 noop,
    1 left, 2 right, 3 up, 4 down, and ``5 + y*W + x`` a click on cell (x, y)
    (x the column, y the row, from the top left). Anything else raises
    ValueError.

    Observations are uint8 arrays ``[H, W]`` indexed ``obs[y, x]``, one colour
    id per cell (``observation_space = Box(0, 255, (H, W))``), as the
    benchmark harness renders: the grid painted with the program's background
    colour, then every rendered cell in render order (the last one drawn in a
    cell shows; cells outside the grid are dropped). Ids 0..39 are
    AutumnBench's color_dict.yaml; other colours get 40, 41, ... in order of
    first appearance, the same ids process-wide (``autumnc.colour_names()[id]``).

    A runtime error of the program terminates the episode (``info["error"]``
    holds the message). ``clone()`` copies the environment, ``state_hash()``
    digests its state, ``grid_size`` is W (= H), ``engine`` the engine serving.
    """

    metadata: dict[str, list[str]] = {"render_modes": []}

    def __init__(self, program, seed=0, engine="auto", trigger=None, max_episode_steps=None):
        """Loads the program (a path, an autumnc.Program or its text) and starts the first
        episode with ``seed``; the class docstring explains every argument."""
        text, name = _program_text(program)
        super().__init__(text, name, seed, engine, trigger, max_episode_steps or 0)
        self.action_space, self.observation_space = _spaces(self.grid_size)

    def clone(self):
        """An independent copy of this environment at the same point of the same episode, of this
        class and with the same spaces: stepping either with the same actions gives the same
        observations."""
        copy = type(self).__new__(type(self))
        _core._Env.__init__(copy, self)
        copy.__dict__.update(self.__dict__)
        return copy

    def close(self):
        """Gymnasium's close(): there is nothing to release (the memory goes with the object)."""

    def __repr__(self):
        return f"autumnc.Env(grid={self.grid_size}, engine={self.engine!r})"


class VecEnv(_core._VecEnv):
    """``num_envs`` episodes stepped together in C++ worker threads.

    ``VecEnv(program, num_envs, num_threads=0, seed=0, engine="auto",
    trigger=None, max_episode_steps=None)``: the arguments of ``autumnc.Env``,
    plus N = num_envs and the worker threads (0: one per core). Actions and
    observations are Env's (``single_action_space``,
    ``single_observation_space``), batched along a first axis of N.

    ``step(actions)`` takes N integers and returns ``(obs [N,H,W] uint8,
    rewards [N] float32, terminated [N] bool, truncated [N] bool, info)``; the
    arrays are the same objects on every call, overwritten in place (copy what
    you keep). An episode that ended is reset by the next step, which ignores
    its action. Episode k of environment i uses seed ``seed + i + k*N``.
    ``clone(ids)`` / ``restore(ids, states)`` copy environments out and back
    (``autumnc.EnvState``, which pickles and has a bytes form);
    ``state_hash()`` digests each one. Results do not depend on num_threads
    (0: one per core). engine "auto" waits for the compiled module and falls
    back to the interpreter if it cannot be built. A VecEnv takes one call at a
    time: a call from another thread while one runs raises RuntimeError. A
    num_envs that cannot fit in memory raises MemoryError before allocating.
    """

    def __init__(self, program, num_envs, num_threads=0, seed=0, engine="auto", trigger=None,
                 max_episode_steps=None):
        """Loads the program (as for Env) and starts ``num_envs`` episodes, environment i
        with seed ``seed + i``; the class docstring explains every argument."""
        text, name = _program_text(program)
        super().__init__(text, name, num_envs, num_threads, seed, engine, trigger, max_episode_steps or 0)
        self.single_action_space, self.single_observation_space = _spaces(self.grid_size)

    def close(self):
        """Gymnasium's close(): there is nothing to release (the memory goes with the object)."""

    def __repr__(self):
        return f"autumnc.VecEnv(num_envs={self.num_envs}, grid={self.grid_size}, threads={self.num_threads})"
