"""autumn play: an Autumn program or task in the browser, served from this machine.

``python3 -m autumnc.play PROGRAM|TASK`` (``autumn play`` runs it) starts a small
web server on 127.0.0.1 (a free port unless --port says otherwise) and prints
the page's URL, which carries a random token. The design, in short:

* One process, one session. The server holds a single episode (an
  ``autumnc.Env``) behind a lock; the page (play_page.html, beside this file,
  with its script and style inline and nothing fetched from elsewhere) only
  ever sends actions and JSON documents, never a file path. Every file the
  server reads was named on its command line; the only files it writes are
  recorded traces and answers, under --out-dir, with names it makes itself.
* Security: the server binds to 127.0.0.1 only. Every request must carry the
  token (``?token=`` on the page's URL, the ``X-Autumn-Token`` header on API
  calls), and a Host or Origin header that is not the server's own is refused
  with 403, so other pages in the browser (and DNS-rebinding tricks) cannot
  drive it.
* Engines: --engine compiled (the default) asks for the program's compiled
  module; while it compiles the interpreter serves, and once it is ready the
  episode moves over by replaying its actions (both engines are exact, so the
  frames do not change). Every answer says which engine served it.
* Frames travel as rows of colour names, the golden-trace format
  (../shared/conformance), so what the page shows, what ``autumn run --json``
  prints and what a recording holds are compared as they are. A recording is
  a trace file ``autumn check PROGRAM TRACE`` replays frame for frame.
* Replay: the page uploads the *content* of a trace file, of ``autumn solve
  TASK --json`` output (a planning task's plan) or of a task's answers file
  (its reference_plan); the server runs the actions on a fresh episode of the
  same program and sends every frame back, with where the run stopped, where a
  recorded frame differed, and (for a planning task) which frames reach the
  goal, for the page's timeline.
* Tasks: a task file (its "type" one of the benchmark's three) plays its
  program (a change-detection task its changed program, as a participant meets
  it), shows a planning task's goal over the grid, and, after the interaction
  phase, asks the task's question; the answer is saved as JSON (--out-dir).
* A program that does not load (a parse or start-up error) still gets its
  page, which shows the error with its location; "reload" reads the file
  again, so the program can be fixed while the server runs.
"""
import argparse
import hmac
import http.server
import json
import os
import secrets
import sys
import threading
import time
import urllib.parse

from . import _core

PAGE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "play_page.html")
MAX_BODY = 32 << 20           # bytes of one uploaded JSON document
MAX_REPLAY_ACTIONS = 5000     # a replay's frames all travel to the page at once
MAX_EPISODE_ACTIONS = 100000  # a live episode's log (it is replayed when the engine changes)
MOVES = ["noop", "left", "right", "up", "down"]
TASK_TYPES = {"masked_frame_prediction": "mfp", "change_detection": "cd", "planning": "planning"}


class UsageError(Exception):
    """A bad command line or file: one line, exit status 2."""


# --- actions ------------------------------------------------------------------

def parse_action(text, grid):
    """(action id for autumnc.Env, canonical text) of "noop", "left", ..., "click X Y"."""
    if isinstance(text, dict):  # a task file's {"type": "click", "x": X, "y": Y}
        kind = text.get("type")
        text = f"click {text.get('x')} {text.get('y')}" if kind == "click" else str(kind)
    if not isinstance(text, str):
        raise ValueError(f"an action must be a string such as \"left\" or \"click 3 4\", got {text!r}")
    words = text.split()
    if len(words) == 1 and words[0] in MOVES:
        return MOVES.index(words[0]), words[0]
    if len(words) == 3 and words[0] == "click":
        try:
            x, y = int(words[1]), int(words[2])
        except ValueError:
            raise ValueError(f"bad click {text!r}: x and y must be integers") from None
        if not (0 <= x < grid and 0 <= y < grid):
            raise ValueError(f"click {x} {y} is outside the {grid}x{grid} grid")
        return 5 + y * grid + x, f"click {x} {y}"
    raise ValueError(f"unknown action {text!r} (noop, left, right, up, down or click X Y)")


# --- what was named on the command line: a program or a task ---------------------

def read_colour_table(task_file):
    """Task colour ids -> names: color_dict.yaml in the task's folder or the one above
    (the benchmark's layout), else the built-in AutumnBench table (autumnc ids 0..39)."""
    folder = os.path.dirname(os.path.abspath(task_file))
    for d in (folder, os.path.dirname(folder)):
        yaml = os.path.join(d, "color_dict.yaml")
        if os.path.isfile(yaml):
            table = {}
            with open(yaml, encoding="utf-8") as f:
                for line in f:
                    line = line.split("#", 1)[0].strip()
                    if not line or ":" not in line:
                        continue
                    key, name = line.split(":", 1)
                    try:
                        table[int(key)] = name.strip().strip("\"'")
                    except ValueError:
                        continue
            return table
    return {i: n for i, n in enumerate(_core.colour_names()[:40])}


def resolve_program(programs_dir, name):
    """NAME.sexp or NAME.au (NAME_wrong also as NAME_change_detection_wrong_program)."""
    names = [name]
    if name.endswith("_wrong"):
        names.append(name[: -len("_wrong")] + "_change_detection_wrong_program")
    for n in names:
        for ext in (".sexp", ".au", ""):
            p = os.path.join(programs_dir, n + ext)
            if os.path.isfile(p):
                return p
    raise UsageError(f"no program {name!r} in {programs_dir} (looked for {name}.sexp and {name}.au)")


class Target:
    """The program to play, and the task it belongs to when a task file was given."""

    def __init__(self, path, programs_dir=None):
        if not os.path.exists(path):
            raise UsageError(f"no such file: {path}")
        if os.path.isdir(path):
            raise UsageError(f"{path} is a folder: give a program (.au, .sexp) or a task file (.json)")
        self.path = os.path.abspath(path)
        self.task = None
        self.program_path = self.path
        if path.endswith(".json"):
            try:
                with open(path, encoding="utf-8") as f:
                    task = json.load(f)
            except (OSError, ValueError) as e:
                raise UsageError(f"{path}: not a task file ({e})") from None
            if not isinstance(task, dict) or task.get("type") not in TASK_TYPES:
                raise UsageError(f"{path}: not a task file (its \"type\" must be one of "
                                 f"{', '.join(TASK_TYPES)}); give a program or a task")
            kind = TASK_TYPES[task["type"]]
            folder = programs_dir or os.path.join(os.path.dirname(os.path.dirname(self.path)), "programs")
            name = task.get("wrong_program") if kind == "cd" else task.get("program")
            if not isinstance(name, str):
                raise UsageError(f"{path}: the task names no program")
            self.program_path = resolve_program(folder, name)
            self.task = task
            self.kind = kind
            self.colours = read_colour_table(self.path)
        # the program actually played (a change-detection task's changed one), as traces name it
        self.name = os.path.splitext(os.path.basename(self.program_path))[0]

    def grid_names(self, grid, masked_as=None):
        """A task grid (colour ids) as rows of names; id 0 (masked) becomes masked_as."""
        return [[masked_as if c == 0 else self.colours.get(c, f"?{c}") for c in row] for row in grid]

    def goal(self):
        """A planning task's goal: rows of colour names, null where the mask leaves a cell free."""
        if self.task is None or self.kind != "planning":
            return None
        goal, mask = self.task.get("goal"), self.task.get("mask")
        if not isinstance(goal, list) or not isinstance(mask, list) or len(goal) != len(mask):
            raise UsageError(f"{self.path}: a planning task needs \"goal\" and \"mask\" grids of one size")
        return [[self.colours.get(g, f"?{g}") if m else None for g, m in zip(grow, mrow)]
                for grow, mrow in zip(goal, mask)]

    def question(self):
        """What the page asks after the interaction phase (None for a plain program)."""
        if self.task is None:
            return None
        q = {"kind": self.kind, "task": os.path.basename(self.path)}
        if self.kind == "mfp":
            obs = self.task.get("observations") or []
            q["observations"] = [{"action": o.get("action"), "grid": self.grid_names(o.get("masked_grid") or [])}
                                 for o in obs]
            q["choices"] = [self.grid_names(c) for c in self.task.get("choices") or []]
        elif self.kind == "planning":
            q["goal"] = self.goal()
        return q


def at_goal(rows, goal):
    """True when a frame (rows of space-separated names) equals the goal on every masked cell."""
    if goal is None or len(rows) != len(goal):
        return False
    for row, want in zip(rows, goal):
        cells = row.split(" ")
        if len(cells) != len(want):
            return False
        if any(w is not None and c != w for c, w in zip(cells, want)):
            return False
    return True


# --- the episode -------------------------------------------------------------------

class Session:
    """One episode of the program, driven by the page. All methods take the lock."""

    def __init__(self, target, engine="compiled", seed=0, out_dir=".", fps=None):
        self.target = target
        self.requested = engine
        self.seed = seed
        self.out_dir = out_dir
        self.fps_flag = fps
        self.lock = threading.Lock()
        self.records = 0
        self.load()

    # loading and engines

    def load(self):
        """(Re)reads the program file and starts an episode; a bad program is kept as the error."""
        self.env = self.probe = None
        self.text = ""
        self.load_error = None
        self.grid = 0
        self.background = "black"
        self.frame_rate = self.fps_flag or 4
        self.goal = None
        try:
            self.goal = self.target.goal()
            with open(self.target.program_path, encoding="utf-8") as f:
                self.text = f.read()
        except (OSError, UnicodeDecodeError, UsageError) as e:
            self.load_error = str(e)
            self._clear()
            return
        self._start(self.seed)

    def _env(self, seed):
        # "auto": the interpreter serves while the module compiles (we move over ourselves).
        mode = "interp" if self.requested == "interp" else "auto"
        return _core._Env(self.text, self.target.program_path, seed, mode, None, 0)

    def _start(self, seed):
        self.seed = seed
        self._clear()
        try:
            self.env = self._env(seed)
            self.obs, _ = self.env.reset(seed=seed)
            self.grid = self.env.grid_size
            self.load_error = None
        except Exception as e:  # ParseError, AutumnRuntimeError at start-up, ...
            self.env = None
            self.load_error = one_line(e)
            return
        self._host_facts(seed)
        # A module built into the package (or cached) is found in a few milliseconds, by
        # a thread: wait that long for it, so such programs start on the compiled engine.
        deadline = time.monotonic() + 0.3
        while self.requested == "compiled" and self.env.engine != "compiled" and time.monotonic() < deadline:
            time.sleep(0.02)
            self.obs, _ = self.env.reset(seed=seed)  # moves to the module when it is ready
        self.frames = [self.rows(self.obs)]

    def _clear(self):
        self.actions, self.frames, self.engines = [], [], []
        self.error = None
        self.obs = None

    def _host_facts(self, seed):
        """FRAME_RATE and background, as a host reads them (from a throwaway interpreter)."""
        try:
            interp = _core.Interpreter("interp")
            interp.run_script(self.text, "", "", seed)
            if not self.fps_flag:
                rate = float(interp.get_frame_rate())
                self.frame_rate = rate if 0 < rate <= 60 else 4
            self.background = interp.get_background() or "black"
        except Exception:
            pass

    def _maybe_move_to_compiled(self):
        """While the interpreter serves a compiled request, see whether the module is
        ready (a probe episode's reset moves to it when it is) and replay onto it."""
        if self.env is None or self.requested != "compiled" or self.env.engine == "compiled":
            return
        try:
            if self.probe is None:
                self.probe = self._env(self.seed)
            self.probe.reset(seed=self.seed)
            if self.probe.engine != "compiled":
                return
            self.probe = None
            env = self._env(self.seed)
            obs, _ = env.reset(seed=self.seed)
            if env.engine != "compiled":
                return
            for text in self.actions:
                obs, _, terminated, _, info = env.step(parse_action(text, self.grid)[0])
                if terminated:  # cannot happen on exact engines; keep the interpreter's episode
                    return
            self.env, self.obs = env, obs
        except Exception:
            self.probe = None

    def refresh_engine(self):
        """The page asks now and then while a module compiles: move over once it is ready."""
        try:
            self._maybe_move_to_compiled()
        except Exception:
            pass

    # colour ids -> names

    def rows(self, obs):
        names = _core.colour_names()
        if int(obs.max(initial=0)) >= len(names):
            names = _core.colour_names()
        return [" ".join(names[c] for c in row) for row in obs.tolist()]

    # what the page asks for

    def state(self, full=False):
        """What the page shows; full adds the task's question (sent once, with GET /api/state)."""
        t = self.target
        s = {
            "program": t.name,
            "program_file": os.path.basename(t.program_path),
            "grid": self.grid,
            "seed": self.seed,
            "step": len(self.actions),
            "frame": self.frames[-1] if self.frames else None,
            "engine": self.env.engine if self.env is not None else None,
            "requested_engine": self.requested,
            "error": self.error,
            "load_error": self.load_error,
            "frame_rate": self.frame_rate,
            "background": self.background,
            "last_action": self.actions[-1] if self.actions else None,
            "goal": self.goal,
            "at_goal": bool(self.frames) and at_goal(self.frames[-1], self.goal),
            "task": t.question() if full else None,
            "actions": len(self.actions),
        }
        return s

    def step(self, action):
        if self.env is None:
            raise ValueError(self.load_error or "no program loaded")
        if self.error is not None:
            raise ValueError("the episode ended with a runtime error: reset to start again")
        if len(self.actions) >= MAX_EPISODE_ACTIONS:
            raise ValueError(f"the episode has {MAX_EPISODE_ACTIONS} steps, this page's limit: reset")
        aid, text = parse_action(action, self.grid)
        obs, _, terminated, _, info = self.env.step(aid)
        if terminated:
            self.error = info.get("error", "runtime error")
            return
        self.actions.append(text)
        self.engines.append(self.env.engine)
        self.obs = obs
        self.frames.append(self.rows(obs))
        self._maybe_move_to_compiled()

    def reset(self, seed=None, engine=None):
        changed = engine is not None and engine != self.requested
        if engine is not None and engine not in ("compiled", "interp"):
            raise ValueError(f"unknown engine {engine!r} (compiled or interp)")
        if changed:
            self.requested = engine
        if seed is None:
            seed = self.seed
        if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0 or seed >= 2**63:
            raise ValueError(f"a seed must be a non-negative integer, got {seed!r}")
        if self.env is None or changed:
            self.load_error = None
            self._start(seed)
        else:
            self.seed = seed
            self._clear()
            try:
                self.obs, _ = self.env.reset(seed=seed)
            except Exception as e:  # a start-up error with this seed: shown like a load error
                self.env, self.load_error = None, one_line(e)
                return
            self.frames = [self.rows(self.obs)]
        self._maybe_move_to_compiled()

    def trace(self):
        """The episode so far in the golden-trace format."""
        if not self.frames:
            raise ValueError(self.load_error or "nothing to record")
        out = {"program": self.target.name, "grid_size": self.grid, "background": self.background,
               "traces": [{"seed": self.seed, "actions": list(self.actions), "frames": list(self.frames)}]}
        if self.error:
            out["error"] = self.error
        return out

    def save(self, doc, kind):
        """Writes doc under --out-dir with a name made here; returns its path."""
        os.makedirs(self.out_dir, exist_ok=True)
        self.records += 1
        stamp = time.strftime("%Y%m%d-%H%M%S")
        path = os.path.join(self.out_dir, f"{self.target.name}-{kind}-{stamp}-{os.getpid()}-{self.records}.json")
        with open(path, "w", encoding="utf-8") as f:
            json.dump(doc, f)
            f.write("\n")
        return os.path.abspath(path)

    def record(self):
        trace = self.trace()
        return {"path": self.save(trace, "trace"), "trace": trace}

    def replay(self, doc, index=0):
        """Runs the actions of an uploaded trace / solve output / answers file; every frame."""
        if self.load_error or not self.text:
            raise ValueError(self.load_error or "no program loaded")
        seed, actions, expected, source, notes = plan_of(doc, index, self.target)
        if len(actions) > MAX_REPLAY_ACTIONS:
            raise ValueError(f"{len(actions)} actions: a replay here takes at most {MAX_REPLAY_ACTIONS}")
        try:
            env = self._env(seed)
            obs, _ = env.reset(seed=seed)
        except Exception as e:
            raise ValueError(f"the replay cannot start (seed {seed}): {one_line(e)}") from None
        frames = [self.rows(obs)]
        texts, error, error_step, mismatch = [], None, None, None
        for i, a in enumerate(actions):
            try:
                aid, text = parse_action(a, self.grid)
            except ValueError as e:
                error, error_step = f"action {i + 1}: {e}", i + 1
                break
            obs, _, terminated, _, info = env.step(aid)
            if terminated:
                error, error_step = info.get("error", "runtime error"), i + 1
                break
            texts.append(text)
            frames.append(self.rows(obs))
        if expected:
            for i, (want, got) in enumerate(zip(expected, frames)):
                if list(want) != got:
                    mismatch = i
                    break
        goal_flags = [at_goal(f, self.goal) for f in frames] if self.goal else None
        return {"source": source, "seed": seed, "actions": texts, "frames": frames, "engine": env.engine,
                "error": error, "error_step": error_step, "mismatch": mismatch, "notes": notes,
                "at_goal": goal_flags,
                "reaches_goal": (goal_flags.index(True) if goal_flags and True in goal_flags else None)}

    def answer(self, body):
        """A participant's answer to the task's question, saved as JSON beside recordings."""
        t = self.target
        if t.task is None:
            raise ValueError("this is a program, not a task: there is no question to answer")
        result = {}
        if t.kind == "mfp":
            n = len(t.task.get("choices") or [])
            choice = body.get("choice")
            if not isinstance(choice, int) or isinstance(choice, bool) or not 0 <= choice < n:
                raise ValueError(f"the answer must be a choice from 0 to {n - 1}")
            result = {"choice": choice}
        elif t.kind == "cd":
            step = body.get("detected")
            if step is not None and (not isinstance(step, int) or isinstance(step, bool) or step < 0):
                raise ValueError("the answer must be the step the change was noticed at (or null: none seen)")
            result = {"detected": step, "steps": len(self.actions), "actions": list(self.actions)}
        else:
            result = {"found": bool(self.actions), "plan": list(self.actions), "length": len(self.actions),
                      "env_seed": self.seed, "reached_goal": any(at_goal(f, self.goal) for f in self.frames)}
        doc = {"task": os.path.basename(t.path), "type": t.task["type"], "program": t.task.get("program"),
               "answered_by": "participant (autumn play)", "result": result,
               "interaction": {"seed": self.seed, "actions": list(self.actions)}}
        return {"path": self.save(doc, "answer"), "answer": doc}


def plan_of(doc, index, target):
    """(seed, actions, expected frames or None, source, notes) of an uploaded document."""
    if not isinstance(doc, dict):
        raise ValueError("expected a JSON object: a trace file, `autumn solve --json` output or an answers file")
    notes = []
    prog = doc.get("program")
    if isinstance(prog, str) and prog not in (target.name, os.path.splitext(os.path.basename(target.program_path))[0]):
        notes.append(f"this file is for program {prog!r}; it is replayed on {target.name!r}")
    if isinstance(doc.get("traces"), list):
        traces = doc["traces"]
        if not traces:
            raise ValueError("the trace file's \"traces\" array is empty")
        if not isinstance(index, int) or not 0 <= index < len(traces):
            raise ValueError(f"trace {index} does not exist (the file has {len(traces)})")
        tr = traces[index]
        if not isinstance(tr, dict) or not isinstance(tr.get("actions"), list):
            raise ValueError(f"trace {index} has no \"actions\" list")
        seed = tr.get("seed", 0)
        frames = tr.get("frames") if isinstance(tr.get("frames"), list) else None
        if len(traces) > 1:
            notes.append(f"trace {index} of {len(traces)}")
        return check_seed(seed), tr["actions"], frames, "trace", notes
    result = doc.get("result")
    if isinstance(result, dict) and "plan" in result:
        if result.get("plan") is None:
            raise ValueError("this solve output has no plan (the solver found none)")
        if not isinstance(result["plan"], list):
            raise ValueError("the solve output's \"plan\" is not a list of actions")
        return check_seed(result.get("env_seed", 0)), result["plan"], None, "solve", notes
    if isinstance(doc.get("reference_plan"), list):
        return check_seed(doc.get("seed", 0)), doc["reference_plan"], None, "answers", notes
    interaction = doc.get("interaction")
    if isinstance(interaction, dict) and isinstance(interaction.get("actions"), list):
        return check_seed(interaction.get("seed", 0)), interaction["actions"], None, "answer", notes
    if isinstance(doc.get("actions"), list):
        return check_seed(doc.get("seed", 0)), doc["actions"], None, "actions", notes
    raise ValueError("nothing to replay: expected a trace file (\"traces\"), `autumn solve --json` output "
                     "(\"result\".\"plan\") or an answers file (\"reference_plan\")")


def check_seed(seed):
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0 or seed >= 2**63:
        raise ValueError(f"a seed must be a non-negative integer, got {seed!r}")
    return seed


def one_line(e):
    return " ".join(str(e).split("\n")).strip() or type(e).__name__


# --- HTTP ----------------------------------------------------------------------------

class Handler(http.server.BaseHTTPRequestHandler):
    server_version = "autumn-play"
    sys_version = ""

    # set on the class made per server (make_server)
    session = None
    token = ""
    allowed_hosts = ()
    quiet = True

    def log_message(self, fmt, *args):
        if not self.quiet:
            sys.stderr.write("autumn play: %s\n" % (fmt % args))

    def _send(self, code, body, ctype="application/json; charset=utf-8"):
        data = body if isinstance(body, bytes) else json.dumps(body).encode("utf-8")
        self.send_response(code)
        self.send_header("Content-Type", ctype)
        self.send_header("Content-Length", str(len(data)))
        self.send_header("Cache-Control", "no-store")
        self.send_header("Referrer-Policy", "no-referrer")
        self.send_header("X-Content-Type-Options", "nosniff")
        self.send_header("X-Frame-Options", "DENY")
        self.send_header("Content-Security-Policy",
                         "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; "
                         "img-src data: blob:; connect-src 'self'; frame-ancestors 'none'; base-uri 'none'; "
                         "form-action 'none'")
        self.end_headers()
        if self.command != "HEAD":
            self.wfile.write(data)

    def _refuse(self, why):
        self._send(403, {"error": "forbidden: " + why})

    def _allowed(self, query):
        """Host, Origin and token checks; sends the 403 itself when they fail."""
        host = self.headers.get("Host", "")
        if host not in self.allowed_hosts:
            self._refuse("unexpected Host header")
            return False
        origin = self.headers.get("Origin")
        if origin is not None and origin not in {"http://" + h for h in self.allowed_hosts}:
            self._refuse("cross-origin request")
            return False
        given = self.headers.get("X-Autumn-Token") or (query.get("token") or [""])[0]
        if not hmac.compare_digest(given.encode("utf-8", "replace"), self.token.encode("utf-8")):
            self._refuse("missing or wrong token")
            return False
        return True

    def _route(self):
        url = urllib.parse.urlsplit(self.path)
        query = urllib.parse.parse_qs(url.query)
        if not self._allowed(query):
            return None, None
        return url.path, query

    def do_HEAD(self):
        self.do_GET()

    def do_GET(self):
        path, query = self._route()
        if path is None:
            return
        if path in ("/", "/index.html"):
            with open(PAGE, "rb") as f:
                self._send(200, f.read(), "text/html; charset=utf-8")
        elif path == "/api/state":
            with self.session.lock:
                self.session.refresh_engine()
                self._send(200, self.session.state(full=True))
        else:
            self._send(404, {"error": f"no such page: {path}"})

    def do_POST(self):
        path, query = self._route()
        if path is None:
            return
        try:
            length = int(self.headers.get("Content-Length") or 0)
        except ValueError:
            length = -1
        if length < 0 or length > MAX_BODY:
            self._send(413, {"error": f"the request body must be at most {MAX_BODY} bytes"})
            return
        raw = self.rfile.read(length) if length else b"{}"
        try:
            body = json.loads(raw.decode("utf-8")) if raw.strip() else {}
        except (UnicodeDecodeError, ValueError) as e:
            self._send(400, {"error": f"the request is not JSON ({e})"})
            return
        if not isinstance(body, dict):
            self._send(400, {"error": "the request must be a JSON object"})
            return
        s = self.session
        try:
            with s.lock:
                if path == "/api/step":
                    s.step(body.get("action", "noop"))
                    out = s.state()
                elif path == "/api/reset":
                    s.reset(body.get("seed"), body.get("engine"))
                    out = s.state()
                elif path == "/api/reload":
                    s.load()
                    out = s.state()
                elif path == "/api/record":
                    out = s.record()
                elif path == "/api/replay":
                    doc = body.get("document")
                    if isinstance(doc, str):
                        try:
                            doc = json.loads(doc)
                        except ValueError as e:
                            raise ValueError(f"the file is not JSON ({e})") from None
                    out = s.replay(doc, body.get("trace", 0))
                    out["goal"] = s.goal
                elif path == "/api/answer":
                    out = s.answer(body)
                else:
                    self._send(404, {"error": f"no such endpoint: {path}"})
                    return
        except (ValueError, OSError) as e:
            self._send(400, {"error": one_line(e)})
            return
        except Exception as e:  # an engine error we did not foresee: say it, keep serving
            self._send(500, {"error": f"{type(e).__name__}: {one_line(e)}"})
            return
        self._send(200, out)


def make_server(session, port=0, quiet=True, token=None):
    """A ThreadingHTTPServer on 127.0.0.1:port (0: a free one) serving session; (server, url)."""
    token = token or secrets.token_urlsafe(24)
    server = http.server.ThreadingHTTPServer(("127.0.0.1", port), None)
    server.daemon_threads = True
    real_port = server.server_address[1]
    handler = type("PlayHandler", (Handler,), {
        "session": session, "token": token, "quiet": quiet,
        "allowed_hosts": (f"127.0.0.1:{real_port}", f"localhost:{real_port}"),
    })
    server.RequestHandlerClass = handler
    return server, f"http://127.0.0.1:{real_port}/?token={token}"


# --- command line ----------------------------------------------------------------------

def parser():
    p = argparse.ArgumentParser(
        prog=os.environ.get("AUTUMN_PLAY_PROG", "python3 -m autumnc.play"),
        description="Play an Autumn program or an AutumnBench task in the browser: a local web server "
                    "(127.0.0.1 only) with a page that draws the grid, takes arrow keys and clicks, "
                    "records traces and replays traces and plans.")
    p.add_argument("target", metavar="PROGRAM|TASK", help="an Autumn program (.au, .sexp) or a task file (.json)")
    p.add_argument("--engine", choices=["compiled", "interp"], default="compiled",
                   help="compiled (default; the interpreter serves while the module compiles) or interp")
    p.add_argument("--seed", type=int, default=0, help="the first episode's seed (default 0, the benchmark's)")
    p.add_argument("--port", type=int, default=0, help="port on 127.0.0.1 (default: a free one)")
    p.add_argument("--out-dir", default=".", help="where recorded traces and answers are written (default: .)")
    p.add_argument("--programs", default=None, help="task files: the folder their programs are in "
                   "(default: the task's ../programs)")
    p.add_argument("--fps", type=float, default=None, help="play speed in frames per second "
                   "(default: the program's FRAME_RATE, else 4)")
    p.add_argument("--open", action="store_true", help="open the page in the default browser")
    p.add_argument("--verbose", action="store_true", help="log every request on stderr")
    return p


def main(argv=None):
    args = parser().parse_args(argv)
    prog = parser().prog
    try:
        if args.seed < 0 or args.seed >= 2**63:
            raise UsageError(f"--seed must be a non-negative integer, got {args.seed}")
        if not 0 <= args.port <= 65535:
            raise UsageError(f"--port must be from 0 to 65535, got {args.port}")
        if args.fps is not None and not 0 < args.fps <= 60:
            raise UsageError(f"--fps must be above 0 and at most 60, got {args.fps}")
        if os.path.exists(args.out_dir) and not os.path.isdir(args.out_dir):
            raise UsageError(f"--out-dir {args.out_dir} is a file, not a folder")
        if args.programs is not None and not os.path.isdir(args.programs):
            raise UsageError(f"--programs {args.programs} is not a folder")
        target = Target(args.target, args.programs)
    except UsageError as e:
        print(f"{prog}: {e}", file=sys.stderr)
        return 2
    session = Session(target, args.engine, args.seed, args.out_dir, args.fps)
    try:
        server, url = make_server(session, args.port, quiet=not args.verbose)
    except OSError as e:
        print(f"{prog}: cannot listen on 127.0.0.1:{args.port} ({e.strerror or e})", file=sys.stderr)
        return 1
    what = f"{target.kind} task {os.path.basename(target.path)}, " if target.task is not None else ""
    print(f"autumn play: {what}program {target.program_path}", file=sys.stderr)
    if session.load_error:
        print(f"autumn play: the program does not load (the page shows why): {session.load_error}",
              file=sys.stderr)
    print(url, flush=True)
    print("autumn play: serving on 127.0.0.1 until Ctrl-C", file=sys.stderr, flush=True)
    if args.open:
        import webbrowser
        webbrowser.open(url)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        print("autumn play: stopped", file=sys.stderr)
    finally:
        server.server_close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
