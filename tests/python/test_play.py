"""autumn play (autumnc/play.py) driven as a person drives it: in a real headless browser.

One server per target (a random 16x16 program, a planning task, a program that
does not load) runs as `python3 -m autumnc.play` in a subprocess, and one
headless Chromium (selenium + chromedriver, Debian's packages, which
scripts/bootstrap.sh installs) is shared by every test of the module. The page
is driven only through what a person uses: arrow keys, clicks on the canvas,
its buttons and its file input; what it shows is read back from
window.autumnPlay (the frame as rows of colour names, the trace format) and
compared with the `autumn` CLI's own answers: `autumn run --json` for the same
seed and actions, `autumn check` (both engines) for the recorded trace,
`autumn solve --json` for the plan replayed, and the task file's goal and mask
for the frame the timeline reaches (and, played live as a participant would, for
the answer the page saves). Without Chromium the tests fail with a
message saying what to install: they never pass by skipping.
"""
import json
import os
import shutil
import subprocess
import sys
import time
import urllib.error
import urllib.parse
import urllib.request

import pytest

import autumnc
from conftest import BUILD, PROGRAMS, REPO

AUTUMN = os.environ.get("AUTUMN_CLI") or os.path.join(BUILD, "autumn")
PROGRAM = os.path.join(PROGRAMS, "flood_defense.au")  # 16x16, random, clicks and arrows both matter
TASK = os.path.join(REPO, "tasks", "generated", "prompts", "sokoban_planning.json")
WAIT = 20  # seconds for anything the page does


# --- the servers ----------------------------------------------------------------------

class Server:
    def __init__(self, target, out_dir, *flags):
        self.log = os.path.join(str(out_dir), os.path.basename(target) + ".log")
        with open(self.log, "w") as err:
            self.proc = subprocess.Popen(
                [sys.executable, "-m", "autumnc.play", target, "--out-dir", str(out_dir), *flags],
                stdout=subprocess.PIPE, stderr=err, text=True)
        line = self.proc.stdout.readline().strip()
        if not line.startswith("http://127.0.0.1:"):
            self.proc.kill()
            with open(self.log) as f:
                raise AssertionError(f"autumn play printed {line!r}, not its URL; stderr: {f.read()}")
        self.url = line
        parts = urllib.parse.urlsplit(line)
        self.base = f"{parts.scheme}://{parts.netloc}"
        self.token = urllib.parse.parse_qs(parts.query)["token"][0]

    def stop(self):
        self.proc.terminate()
        try:
            self.proc.wait(5)
        except subprocess.TimeoutExpired:
            self.proc.kill()


@pytest.fixture(scope="module")
def out_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("play")


@pytest.fixture(scope="module")
def servers(out_dir):
    started = {}
    try:
        started["program"] = Server(PROGRAM, out_dir)
        # the interpreter: no module compile for the task's copy of sokoban (the program above
        # runs on the compiled engine, its module built into the package)
        started["task"] = Server(TASK, out_dir, "--engine", "interp")
        bad = out_dir / "broken.au"
        bad.write_text("(program\n  (= GRID_SIZE 8)\n  (object Dot (Cell 0 0 \"red\"))\n  (= dot (initnext (Dot (Position 1 1)) (prev dot))\n")
        started["broken"] = Server(str(bad), out_dir, "--engine", "interp")
        yield started
    finally:
        for s in started.values():
            s.stop()


# --- the browser ----------------------------------------------------------------------

def find_browser():
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver") or ("/usr/bin/chromedriver" if os.path.exists("/usr/bin/chromedriver") else None)
    try:
        import selenium  # noqa: F401
    except ImportError:
        return None, None, "python3-selenium is not installed"
    if not chromium or not driver:
        return None, None, "chromium or chromedriver is not installed"
    return chromium, driver, None


@pytest.fixture(scope="module")
def browser():
    chromium, driver_path, why = find_browser()
    if why:
        pytest.fail(f"test_play needs a real browser: {why} "
                    "(apt-get install -y chromium chromium-driver python3-selenium; scripts/bootstrap.sh does)",
                    pytrace=False)
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    opts = webdriver.ChromeOptions()
    opts.binary_location = chromium
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
              "--window-size=1200,900", "--disable-extensions", "--no-first-run"):
        opts.add_argument(a)
    driver = webdriver.Chrome(service=Service(driver_path), options=opts)
    driver.set_script_timeout(WAIT)
    try:
        yield driver
    finally:
        driver.quit()


def js(driver, expr):
    return driver.execute_script("return " + expr)


def wait_for(driver, expr, what, timeout=WAIT):
    end = time.time() + timeout
    while time.time() < end:
        v = js(driver, expr)
        if v:
            return v
        time.sleep(0.02)
    said = js(driver, "document.getElementById('status').textContent")
    raise AssertionError(f"timed out waiting for {what} ({expr}); the page says: {said!r}")


def open_page(driver, server):
    driver.get(server.url)
    wait_for(driver, "window.autumnPlay && window.autumnPlay.ready", "the page to load")


def settle(driver, step):
    wait_for(driver, f"autumnPlay.idle() && autumnPlay.step === {step}", f"step {step}")


def cli(*args, timeout=120):
    if not os.path.exists(AUTUMN):
        pytest.fail(f"no autumn binary at {AUTUMN} (build the tree, or set AUTUMN_CLI)", pytrace=False)
    return subprocess.run([AUTUMN, *args], capture_output=True, text=True, timeout=timeout)


# --- the tests ------------------------------------------------------------------------

SEED = 3
# (what a person does, the action it is)
INPUTS = [("key", "ARROW_LEFT", "left"), ("click", (5, 4), "click 5 4"), ("key", "ARROW_UP", "up"),
          ("button", "step-btn", "noop"), ("click", (2, 3), "click 2 3"), ("key", "ARROW_RIGHT", "right"),
          ("key", "ARROW_DOWN", "down"), ("click", (5, 4), "click 5 4"), ("key", "ARROW_RIGHT", "right")]


def test_keys_and_clicks_give_the_cli_frames(browser, servers):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys
    d = browser
    open_page(d, servers["program"])
    # its module is built into the package: the compiled engine serves (at once, or after the
    # page's next look while the module loads)
    wait_for(d, "autumnPlay.engine === 'compiled'", "the compiled engine")
    seed = d.find_element(By.ID, "seed")
    seed.clear()
    seed.send_keys(str(SEED))
    d.find_element(By.ID, "reset-btn").click()
    wait_for(d, f"autumnPlay.idle() && autumnPlay.seed === {SEED} && autumnPlay.step === 0", "the reset")
    canvas = d.find_element(By.ID, "grid")
    grid = js(d, "autumnPlay.frame.length")
    assert grid == 16
    for i, (how, what, _) in enumerate(INPUTS):
        if how == "key":
            ActionChains(d).send_keys(getattr(Keys, what)).perform()
        elif how == "button":
            d.find_element(By.ID, what).click()
        else:
            size = canvas.size["width"]
            cell = size / grid
            x, y = what
            # offsets from the element's centre (selenium 4)
            ActionChains(d).move_to_element_with_offset(canvas, int((x + 0.5) * cell - size / 2),
                                                        int((y + 0.5) * cell - size / 2)).click().perform()
        settle(d, i + 1)
    actions = [a for _, _, a in INPUTS]
    assert js(d, "autumnPlay.actions") == actions
    shown = js(d, "autumnPlay.frames")
    run = cli("run", PROGRAM, "--seed", str(SEED), "--actions", ",".join(actions), "--json", "--engine", "interp")
    assert run.returncode == 0, run.stderr
    want = json.loads(run.stdout)["traces"][0]["frames"]
    assert len(shown) == len(want) == len(actions) + 1
    for i, (a, b) in enumerate(zip(shown, want)):
        assert a == b, f"frame {i} differs from autumn run's"
    assert js(d, "autumnPlay.frame") == want[-1]
    assert want[0] != want[-1]  # the inputs did something
    # play steps with noop on its own until paused
    play = d.find_element(By.ID, "play-btn")
    play.click()
    wait_for(d, f"autumnPlay.step >= {len(actions) + 3}", "three played steps")
    play.click()
    wait_for(d, "autumnPlay.idle() && !autumnPlay.playing", "the pause")
    played = js(d, "autumnPlay.actions")[len(actions):]
    assert played and set(played) == {"noop"}
    assert len(js(d, "autumnPlay.frames")) == js(d, "autumnPlay.step") + 1


def test_record_is_a_trace_autumn_check_replays(browser, servers):
    from selenium.webdriver.common.by import By
    d = browser
    if (js(d, "window.autumnPlay && autumnPlay.step") or 0) < len(INPUTS):  # run alone: take a few steps first
        open_page(d, servers["program"])
        start = js(d, "autumnPlay.step")
        for _ in range(3):
            d.find_element(By.ID, "step-btn").click()
        settle(d, start + 3)
    steps = js(d, "autumnPlay.step")
    d.find_element(By.ID, "record-btn").click()
    rec = wait_for(d, "autumnPlay.lastRecord", "the recording")
    path = rec["path"]
    assert os.path.isfile(path)
    with open(path) as f:
        trace = json.load(f)
    assert trace["traces"][0]["frames"] == js(d, "autumnPlay.frames")
    assert len(trace["traces"][0]["actions"]) == steps
    for engine in ("interp", "compiled"):
        r = cli("check", PROGRAM, path, "--engine", engine)
        assert r.returncode == 0, f"autumn check --engine {engine}: {r.stdout}{r.stderr}"
        assert f"matched {steps + 1}/{steps + 1} frames" in r.stdout


def goal_cells(task_file):
    """The task's goal as {(x, y): colour name} over its mask, with the task's colour table."""
    with open(task_file) as f:
        task = json.load(f)
    names = {}
    with open(os.path.join(os.path.dirname(os.path.dirname(task_file)), "color_dict.yaml")) as f:
        for line in f:
            if ":" in line and not line.lstrip().startswith("#"):
                k, v = line.split(":", 1)
                names[int(k)] = v.strip()
    return {(x, y): names[g] for y, (grow, mrow) in enumerate(zip(task["goal"], task["mask"]))
            for x, (g, m) in enumerate(zip(grow, mrow)) if m}


def test_replay_a_solve_plan_reaches_the_goal(browser, servers, out_dir):
    from selenium.webdriver.common.by import By
    d = browser
    solved = cli("solve", TASK, "--json", "--time-limit", "30")
    assert solved.returncode == 0, solved.stderr
    plan_file = out_dir / "solve.json"
    plan_file.write_text(solved.stdout)
    plan = json.loads(solved.stdout)["result"]["plan"]
    assert plan
    open_page(d, servers["task"])
    assert js(d, "autumnPlay.goal") is not None
    goal = goal_cells(TASK)

    def reached():
        rows = [r.split(" ") for r in js(d, "autumnPlay.frame")]
        return all(rows[y][x] == c for (x, y), c in goal.items())

    assert not reached()
    d.find_element(By.ID, "replay-file").send_keys(str(plan_file))
    wait_for(d, "autumnPlay.mode === 'replay' && autumnPlay.replay", "the replay")
    assert js(d, "autumnPlay.replay.actions") == plan
    # forward through the timeline until the page shows the goal
    forward = d.find_element(By.ID, "tl-forward")
    at = None
    for i in range(1, len(plan) + 1):
        forward.click()
        wait_for(d, f"autumnPlay.replayPos === {i}", f"timeline position {i}")
        if reached():
            at = i
            break
    assert at is not None, "the plan's frames never show the goal"
    assert js(d, "autumnPlay.atGoal") is True
    assert d.find_element(By.ID, "goal-badge").is_displayed()
    # back one and jump back: the timeline moves both ways
    d.find_element(By.ID, "tl-back").click()
    wait_for(d, f"autumnPlay.replayPos === {at - 1}", "back")
    assert not reached()
    jump = d.find_element(By.ID, "tl-jump")
    jump.clear()
    jump.send_keys(str(at))
    d.find_element(By.ID, "tl-go").click()
    wait_for(d, f"autumnPlay.replayPos === {at}", "the jump")
    assert reached()


def test_a_broken_program_shows_its_error_and_the_server_goes_on(browser, servers):
    from selenium.webdriver.common.by import By
    d = browser
    open_page(d, servers["broken"])
    err = d.find_element(By.ID, "load-error")
    assert err.is_displayed()
    assert "broken.au:" in err.text and "error" in err.text
    # still serving
    d.find_element(By.ID, "step-btn").click()
    wait_for(d, "autumnPlay.idle() && autumnPlay.requestError", "the refused step")
    assert servers["broken"].proc.poll() is None


def request(server, path, token=True, headers=None, body=None):
    url = server.base + path + (("?token=" + server.token) if token else "")
    req = urllib.request.Request(url, data=None if body is None else json.dumps(body).encode(),
                                 headers=headers or {}, method="GET" if body is None else "POST")
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            return r.status
    except urllib.error.HTTPError as e:
        return e.code


def test_requests_without_the_token_or_from_elsewhere_are_refused(servers):
    s = servers["program"]
    assert request(s, "/api/state") == 200
    assert request(s, "/api/state", token=False) == 403
    assert request(s, "/", token=False) == 403
    assert request(s, "/api/step", token=False, body={"action": "left"}) == 403
    assert request(s, "/api/state", headers={"X-Autumn-Token": "wrong"}, token=False) == 403
    assert request(s, "/api/state", headers={"Host": "evil.example"}) == 403
    assert request(s, "/api/step", headers={"Origin": "http://evil.example"}, body={"action": "left"}) == 403
    assert request(s, "/api/replay", body={"document": {"traces": []}}) == 400


def test_a_participant_plays_the_plan_and_saves_the_answer(browser, servers):
    """The planning task as a participant meets it: play the plan live, reach the goal, answer."""
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys
    d = browser
    open_page(d, servers["task"])
    d.find_element(By.ID, "reset-btn").click()
    wait_for(d, "autumnPlay.idle() && autumnPlay.step === 0", "the reset")
    assert js(d, "autumnPlay.task.kind") == "planning"
    with open(TASK) as f:
        task = json.load(f)
    with open(os.path.join(os.path.dirname(os.path.dirname(TASK)), "answers", os.path.basename(TASK))) as f:
        plan = [a["type"] for a in json.load(f)["reference_plan"]]
    keys = {"up": Keys.ARROW_UP, "down": Keys.ARROW_DOWN, "left": Keys.ARROW_LEFT, "right": Keys.ARROW_RIGHT}
    assert task["type"] == "planning" and set(plan) <= set(keys) | {"noop"}
    for i, a in enumerate(plan):
        if a == "noop":
            d.find_element(By.ID, "step-btn").click()
        else:
            ActionChains(d).send_keys(keys[a]).perform()
        settle(d, i + 1)
    goal = goal_cells(TASK)
    assert any(all(r.split(" ")[x] == c for (x, y), c in goal.items() for r in [frame[y]])
               for frame in js(d, "autumnPlay.frames"))
    d.find_element(By.ID, "question-btn").click()
    d.find_element(By.ID, "submit-answer").click()
    saved = wait_for(d, "autumnPlay.lastAnswer", "the saved answer")
    with open(saved["path"]) as f:
        answer = json.load(f)
    assert answer["type"] == "planning" and answer["result"]["plan"] == plan
    assert answer["result"]["reached_goal"] is True
