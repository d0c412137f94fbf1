"""The Ray batch example, in local mode, on two small simulated drives and a broken one:
what it writes, that it resumes, and that a failure is reported, not raised."""

import importlib.util
import json
from pathlib import Path

import numpy as np

import smc_lmb

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "ray_batch.py"


def load_example():
    spec = importlib.util.spec_from_file_location("ray_batch", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_track_and_summary_agree_and_bad_layouts_are_named(tmp_path):
    drive = Path(smc_lmb.synth_street(tmp_path, frames=3, seed=2, drive=7))
    assert drive.name == "2020_01_01_drive_0007_sync"
    out = tmp_path / "t.json"
    s = smc_lmb.track(drive, out=out, particles=200)
    assert s["frames"] == 3 and s["ego"] == "oxts" and s["walls_per_frame"] > 0
    back = smc_lmb.tracks_summary(out)
    # Every number, times included, survives the JSON text to the last bit.
    assert back == s
    frames = json.loads(out.read_text())["frames"]
    assert [f["frame"] for f in frames] == [0, 1, 2]
    # The same seed gives the same tracks.
    again = smc_lmb.track(drive, particles=200)
    assert {k: v for k, v in again.items() if "ms" not in k} == {k: v for k, v in s.items() if "ms" not in k}
    for kwargs, needle in [({"layout": "tracking"}, "needs a sequence"), ({"layout": "lidar"}, "expected")]:
        try:
            smc_lmb.track(drive, **kwargs)
        except ValueError as e:
            assert needle in str(e), e
        else:
            raise AssertionError(f"{kwargs} was accepted")


def test_ray_batch_tracks_resumes_and_reports_failures(tmp_path):
    data = tmp_path / "data"
    for k, seed in [(1, 2), (2, 5)]:
        smc_lmb.synth_street(data, frames=3, seed=seed, drive=k)
    bad = data / "2020_01_01" / "2020_01_01_drive_0099_sync" / "velodyne_points" / "data"
    bad.mkdir(parents=True)
    (bad / "0000000000.bin").write_bytes(np.zeros(25, np.float32).tobytes())  # 100 bytes
    out = tmp_path / "out"
    config = 'filter = { particles = 200 }\n'
    (tmp_path / "tracking.toml").write_text(config)
    argv = ["--drives", str(data / "2020_01_01"), "--out", str(out), "--config", str(tmp_path / "tracking.toml")]
    batch = load_example()

    assert batch.main(argv) == 1  # the broken drive fails the batch
    rows = {r["recording"]: r for r in json.loads((out / "summary.json").read_text())}
    assert set(rows) == {f"2020_01_01_drive_{n:04}_sync" for n in (1, 2, 99)}
    for n in (1, 2):
        r = rows[f"2020_01_01_drive_{n:04}_sync"]
        assert r["status"] == "tracked" and r["frames"] == 3, r
        assert (out / r["recording"] / "tracks.json").is_file()
    failed = rows["2020_01_01_drive_0099_sync"]
    assert failed["status"] == "failed" and "0000000000.bin" in failed["error"], failed
    assert not (out / "2020_01_01_drive_0099_sync" / "tracks.json").exists()
    # Each drive's run is the library's own with that configuration.
    direct = smc_lmb.track(data / "2020_01_01" / "2020_01_01_drive_0001_sync", config=config)
    first = rows["2020_01_01_drive_0001_sync"]
    assert direct["clusters_per_frame"] == first["clusters_per_frame"]

    # Again: the finished drives are skipped and their files untouched.
    written = (out / "2020_01_01_drive_0001_sync" / "tracks.json").read_bytes()
    assert batch.main(argv) == 1
    rows = {r["recording"]: r for r in json.loads((out / "summary.json").read_text())}
    assert rows["2020_01_01_drive_0001_sync"]["status"] == "skipped"
    assert rows["2020_01_01_drive_0002_sync"]["status"] == "skipped"
    assert (out / "2020_01_01_drive_0001_sync" / "tracks.json").read_bytes() == written
