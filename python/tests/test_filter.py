"""LmbFilter from Python: a linear-Gaussian scenario it must track, the configuration as a
dict or TOML text, a Python motion model, reproducibility, errors and the GIL."""

import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import smc_lmb
from conftest import planar_config

TOML = """
seed = 0
[filter]
particles = 400
[transition]
model = "constant_velocity"
dims = 2
sigma_accel = 0.5
[measurement]
model = "position"
sigma = 0.5
[detection]
model = "constant"
probability = 0.95
[clutter]
rate = 2.0
volume = 40000.0
[birth]
model = "adaptive"
expected_births = 0.1
max_existence = 0.1
particles = 400
position_std = 0.5
velocity_std = 2.0
"""


def scenario(seed=11, steps=30):
    """Two constant-velocity targets on [−100, 100]², position noise 0.5 m, p_D 0.95 and
    Poisson(2) uniform clutter, simulated here with NumPy."""
    rng = np.random.default_rng(seed)
    x0 = np.array([[-20.0, 1.0, -10.0, 0.5], [15.0, -0.8, 20.0, -1.0]])
    truth, frames = [], []
    for k in range(steps):
        pos = x0[:, [0, 2]] + k * x0[:, [1, 3]]
        truth.append(pos)
        seen = pos[rng.uniform(size=2) < 0.95]
        z = seen + rng.normal(0, 0.5, seen.shape)
        clutter = rng.uniform(-100, 100, (rng.poisson(2.0), 2))
        frames.append(np.vstack([z, clutter]))
    return truth, frames


def positions(estimates):
    return np.array([[e.state[0], e.state[2]] for e in estimates]).reshape(-1, 2)


def track(filter_, frames):
    return [filter_.step(float(k), z) for k, z in enumerate(frames)]


def assert_finds_the_targets(history, truth):
    # After a settling period of 10 steps: over the 20 target-steps × 2 that follow, at most
    # 2 misses (no estimate within 2 m, four times the measurement noise) and at most 3 false
    # estimates (more than 5 m from both targets); mean OSPA (c = 10 m) below 1.2 m, where a
    # filter that tracked nothing would score 10 m.
    missed = false = 0
    for est, x in list(zip(history, truth))[10:]:
        p = positions(est)
        d = np.linalg.norm(p[:, None, :] - x[None, :, :], axis=2) if len(p) else np.full((1, 2), np.inf)
        missed += int((d.min(axis=0) > 2.0).sum())
        false += int((d.min(axis=1) > 5.0).sum())
    assert missed <= 2 and false <= 3, (missed, false)
    ospa = [smc_lmb.ospa(x, positions(e), c=10.0)["distance"] for e, x in zip(history, truth)]
    assert np.mean(ospa[10:]) < 1.2, ospa


def test_filter_finds_two_targets_in_clutter():
    truth, frames = scenario()
    f = smc_lmb.LmbFilter(planar_config())
    history = track(f, frames)
    assert_finds_the_targets(history, truth)
    # The two targets keep their labels once confirmed: the estimate nearest each target
    # carries the same label from step 10 on.
    for j in range(2):
        nearest = {
            min(est, key=lambda e: np.hypot(e.state[0] - x[j, 0], e.state[2] - x[j, 1])).label
            for est, x in list(zip(history, truth))[10:]
        }
        assert len(nearest) == 1, nearest
    assert f.steps == len(frames)
    tracks = f.tracks()
    assert len(tracks) >= 2
    for t in tracks:
        assert t.particles.shape == (len(t.weights), 4)
        assert t.weights.sum() == pytest.approx(1.0)
    # The most probable tracks' particle means are the estimates.
    for e in history[-1]:
        t = next(t for t in tracks if t.label == e.label)
        np.testing.assert_allclose(t.weights @ t.particles, e.state, rtol=1e-9, atol=1e-9)
    assert len(f.step_times_ms()) == len(frames)


def test_toml_text_and_dict_give_the_same_run():
    _, frames = scenario(steps=12)
    a = track(smc_lmb.LmbFilter(planar_config()), frames)
    b = track(smc_lmb.LmbFilter(TOML), frames)
    assert [[(e.label, e.existence) for e in s] for s in a] == [[(e.label, e.existence) for e in s] for s in b]
    for sa, sb in zip(a, b):
        for ea, eb in zip(sa, sb):
            np.testing.assert_array_equal(ea.state, eb.state)


def test_run_equals_steps_and_reset_repeats():
    _, frames = scenario(steps=12)
    f = smc_lmb.LmbFilter(planar_config())
    stepped = track(f, frames)
    f.reset()
    ran = f.run([float(k) for k in range(len(frames))], frames)
    for sa, sb in zip(stepped, ran):
        assert [e.label for e in sa] == [e.label for e in sb]
        for ea, eb in zip(sa, sb):
            np.testing.assert_array_equal(ea.state, eb.state)


def constant_velocity(sigma):
    def move(particles, dt, rng):
        out = particles.copy()
        accel = rng.normal(0.0, sigma, (len(particles), 2))
        out[:, [0, 2]] += dt * particles[:, [1, 3]] + 0.5 * dt * dt * accel
        out[:, [1, 3]] += dt * accel
        return out

    return move


def test_python_motion_model_tracks_the_targets():
    truth, frames = scenario()
    calls = []

    def model(particles, dt, rng):
        assert isinstance(rng, np.random.Generator)
        calls.append(particles.shape)
        return constant_velocity(0.5)(particles, dt, rng)

    f = smc_lmb.LmbFilter(planar_config(), transition=model)
    history = track(f, frames)
    assert_finds_the_targets(history, truth)
    assert calls and all(s[1] == 4 for s in calls)
    # Called once per track per step, with the whole particle set.
    assert len(calls) < 100 * len(frames)


RUN_TWICE = """
import json, sys
import numpy as np
import smc_lmb
sys.path.insert(0, sys.argv[1])
from conftest import planar_config
from test_filter import scenario, constant_velocity
_, frames = scenario(steps=15)
f = smc_lmb.LmbFilter(planar_config(seed=5), transition=constant_velocity(0.5))
out = [[(e.label, e.existence, e.state.tolist()) for e in f.step(float(k), z)] for k, z in enumerate(frames)]
print(json.dumps(out))
"""


def test_python_model_runs_repeat_whatever_the_thread_count():
    here = os.path.dirname(os.path.abspath(__file__))
    outputs = []
    for threads in ["1", "2", "1"]:
        env = dict(os.environ, RAYON_NUM_THREADS=threads)
        r = subprocess.run([sys.executable, "-c", RUN_TWICE, here], env=env, capture_output=True, text=True, cwd=here)
        assert r.returncode == 0, r.stderr
        outputs.append(r.stdout)
    assert outputs[0] == outputs[1] == outputs[2]
    assert "[[" in outputs[0]  # some estimates were made
    # A different seed gives a different run.
    f = smc_lmb.LmbFilter(planar_config(seed=6), transition=constant_velocity(0.5))
    _, frames = scenario(steps=15)
    other = [[(e.label, e.existence, e.state.tolist()) for e in f.step(float(k), z)] for k, z in enumerate(frames)]
    import json

    assert json.loads(outputs[0]) != json.loads(json.dumps(other))


def test_exceptions_of_the_motion_model_reach_the_caller():
    def broken(particles, dt, rng):
        raise KeyError("no such manoeuvre")

    f = smc_lmb.LmbFilter(planar_config(), transition=broken)
    f.step(0.0, np.array([[1.0, 2.0]]))  # no prediction at the first step
    with pytest.raises(KeyError, match="no such manoeuvre"):
        for k in range(1, 4):
            f.step(float(k), np.array([[1.0, 2.0]]))

    f = smc_lmb.LmbFilter(planar_config(), transition=lambda p, dt, rng: p[:, :2])
    f.step(0.0, np.array([[1.0, 2.0]]))
    with pytest.raises(ValueError, match=r"shape \(400, 2\), expected \(400, 4\)"):
        for k in range(1, 4):
            f.step(float(k), np.array([[1.0, 2.0]]))


def test_bad_configurations_and_frames_are_value_errors():
    cfg = planar_config()
    cfg["clutter"]["volume"] = -1.0
    with pytest.raises(ValueError, match="clutter"):
        smc_lmb.LmbFilter(cfg)
    cfg = planar_config()
    cfg["transition"]["model"] = "warp_drive"
    with pytest.raises(ValueError, match="warp_drive"):
        smc_lmb.LmbFilter(cfg)
    with pytest.raises(ValueError, match="TOML"):
        smc_lmb.LmbFilter("this is = not toml [")
    # toml places an unknown key at its table's header: `[measurement]`, line 9 of the text
    # (which starts with a newline).
    with pytest.raises(ValueError, match=r"line 9: unknown field `sigmaa`"):
        smc_lmb.LmbFilter(TOML.replace("sigma = 0.5", "sigmaa = 0.5"))
    f = smc_lmb.LmbFilter(planar_config())
    with pytest.raises(ValueError, match="dimension 3"):
        f.step(0.0, np.zeros((2, 3)))
    with pytest.raises(ValueError, match="not finite|finite"):
        f.step(0.0, np.array([[np.nan, 1.0]]))
    f.step(1.0, np.empty((0, 2)))
    with pytest.raises(ValueError, match="backwards"):
        f.step(0.5, np.empty((0, 2)))


def test_the_gil_is_released_while_the_filter_runs():
    # 8000 particles a track: the run takes about 0.7 s on one core of a laptop-class machine.
    sc = smc_lmb.linear_scenario(seed=1, particles=8000)
    f = smc_lmb.LmbFilter(sc["config"])
    ticks = []
    stop = threading.Event()

    def ticker():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=ticker)
    t.start()
    try:
        t0 = time.perf_counter()
        f.run(list(sc["times"]), sc["measurements"])
        t1 = time.perf_counter()
    finally:
        stop.set()
        t.join()
    assert t1 - t0 > 0.2, "the run is too short to tell"
    inside = [x for x in ticks if t0 + 0.05 < x < t1 - 0.05]
    # With the GIL held throughout, the other thread could not tick at all in there.
    assert len(inside) > 10, (len(inside), t1 - t0)


def test_the_custom_transition_example_tracks_its_three_objects():
    example = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples", "custom_transition.py")
    r = subprocess.run([sys.executable, example], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    last = r.stdout.strip().splitlines()[-1]
    assert last.startswith("mean OSPA over 60 steps:"), r.stdout
    # Three objects, position noise 0.5 m, c = 5 m: losing one object for good would cost
    # about 5/3 m a step on its own.
    assert float(last.split()[-2]) < 1.2, r.stdout
    assert "step 60: 3 tracks" in r.stdout


def test_the_readme_example_runs_and_tracks_its_object(capsys):
    from conftest import REPO

    text = (REPO / "README.md").read_text()
    block = text[text.index("## Python") :].split("```python\n", 1)[1].split("```", 1)[0]
    cwd = os.getcwd()
    os.chdir(REPO)
    try:
        exec(compile(block, "README.md (Python section)", "exec"), {})
    finally:
        os.chdir(cwd)
    lines = capsys.readouterr().out.splitlines()
    # The object moves along y = 5 from x = −10 at 2 m a step; at step 9 it is at (8, 5).
    last = [l for l in lines if l.startswith("9 ")]
    assert last, lines
    x, y = (float(v) for v in last[-1].split("[")[1].rstrip("]").split())
    assert abs(x - 8.0) < 1.0 and abs(y - 5.0) < 1.0, last


def test_range_bearing_measurements_use_the_sensor_pose():
    cfg = planar_config(clutter_rate=0.5)
    cfg["measurement"] = {"model": "range_bearing", "sigma_range": 0.2, "sigma_bearing": 0.01}
    cfg["clutter"]["volume"] = 50.0 * np.pi  # range 0–50 m × bearing −π/2–π/2
    f = smc_lmb.LmbFilter(cfg)
    rng = np.random.default_rng(2)
    # A still object at (10, 5); the sensor drives along x at 1 m/s facing +x from (0, 0).
    for k in range(15):
        sx = float(k)
        dx, dy = 10.0 - sx, 5.0
        z = [[np.hypot(dx, dy) + rng.normal(0, 0.2), np.arctan2(dy, dx) + rng.normal(0, 0.01)]]
        est = f.step(float(k), np.array(z), sensor_pose=[sx, 0.0, 0.0])
    assert len(est) == 1
    assert np.hypot(est[0].state[0] - 10.0, est[0].state[2] - 5.0) < 0.5, est
    g = smc_lmb.LmbFilter(cfg)
    with pytest.raises(ValueError, match="sensor_pose"):
        g.step(0.0, np.array([[5.0, 0.1]]), sensor_pose=[1.0, 2.0])


def test_two_sensors_fused_from_a_dict_of_measurements():
    # The scenario seen twice: by a sensor at the origin and by one mounted 1 m ahead and
    # turned half a turn, which measures in its own frame (p_sensor = R(π)ᵀ(p − (1, 0))).
    truth, frames = scenario(seed=5)
    cfg = planar_config()
    sensor = {
        "measurement": cfg.pop("measurement"),
        "detection": cfg.pop("detection"),
        "clutter": cfg.pop("clutter"),
    }
    cfg["sensors"] = [
        {"name": "front", **sensor},
        {"name": "back", **sensor, "mounting": [1.0, 0.0, np.pi]},
    ]
    cfg["fusion"] = {"method": "pu"}
    f = smc_lmb.LmbFilter(cfg)
    history = []
    for k, z in enumerate(frames):
        local = np.column_stack([1.0 - z[:, 0], -z[:, 1]])
        # The back sensor reports every other frame only.
        by_sensor = {"front": z} if k % 2 else {"front": z, "back": local}
        history.append(f.step(float(k), by_sensor))
    assert_finds_the_targets(history, truth)
    with pytest.raises(ValueError, match=r'no sensor named "side".*"front", "back"'):
        f.step(float(len(frames)), {"side": frames[0]})
    cfg["fusion"] = {"method": "ga", "weights": [0.9, 0.9]}
    with pytest.raises(ValueError, match="sum"):
        smc_lmb.LmbFilter(cfg)
