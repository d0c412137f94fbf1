"""Plane segmentation and plane prediction on clouds built here with NumPy (a road and a
building facade, with known planes and a known ego motion), and on the real drive."""

import numpy as np
import pytest

import smc_lmb
from conftest import shared_data


def street(seed=0):
    """A sensor 1.7 m above a flat road (z = −1.7 over [−20, 20]²) beside a facade at x = 10
    (y ∈ [−10, 10], z from the road to 6 m), 1 cm Gaussian noise across each surface."""
    rng = np.random.default_rng(seed)
    g = rng.uniform(-20, 20, (20000, 2))
    ground = np.column_stack([g, np.full(len(g), -1.7) + rng.normal(0, 0.01, len(g))])
    w = rng.uniform([-10, -1.7], [10, 6.0], (8000, 2))
    wall = np.column_stack([np.full(len(w), 10.0) + rng.normal(0, 0.01, len(w)), w])
    pts = np.vstack([ground, wall])
    return np.column_stack([pts, np.zeros(len(pts))])


def test_ground_and_facade_are_found_where_they_were_built():
    seg = smc_lmb.extract_planes(street(), seed=1)
    g = seg["ground"]
    assert g is not None
    # n·p + d = 0 with d ≥ 0: the road z = −1.7 is n = (0, 0, 1), d = 1.7.
    np.testing.assert_allclose(g["normal"], [0, 0, 1], atol=2e-3)
    assert g["offset"] == pytest.approx(1.7, abs=0.01)
    assert len(seg["walls"]) == 1
    w = seg["walls"][0]
    # The facade x = 10 is n = (−1, 0, 0), d = 10.
    np.testing.assert_allclose(w["normal"], [-1, 0, 0], atol=2e-3)
    assert w["offset"] == pytest.approx(10.0, abs=0.01)
    # Wall inliers are taken from 0.3 m above the road up (ground_clearance): they hold about
    # 7.4 / 7.7 of the facade's 8000 points, and the patch, lowered to the road, spans
    # 20 m × 7.7 m.
    assert w["area"] == pytest.approx(20 * 7.7, rel=0.02)
    assert w["rms"] == pytest.approx(0.01, rel=0.2)
    assert np.all(w["inliers"] >= 20000)
    assert len(w["inliers"]) == pytest.approx(8000 * 7.4 / 7.7, rel=0.02)
    assert seg["skipped"] == 0
    # Without lowering, the patch ends at the lowest inlier, 0.3 m above the road.
    high = smc_lmb.extract_planes(street(), seed=1, walls_to_ground=False)["walls"][0]
    assert high["area"] == pytest.approx(20 * 7.4, rel=0.02)
    assert min(v[2] for v in high["vertices"]) == pytest.approx(-1.4, abs=0.05)
    assert min(v[2] for v in w["vertices"]) == pytest.approx(-1.7, abs=0.02)


def test_segmentation_repeats_for_a_seed_and_options_apply():
    pts = street()
    a = smc_lmb.extract_planes(pts, seed=4)
    b = smc_lmb.extract_planes(pts, seed=4)
    np.testing.assert_array_equal(a["walls"][0]["inliers"], b["walls"][0]["inliers"])
    # A minimum wall area above the facade's 154 m² leaves no wall.
    assert smc_lmb.extract_planes(pts, seed=4, min_wall_area=200.0)["walls"] == []
    with pytest.raises(ValueError, match="unknown plane option `min_wal_area`"):
        smc_lmb.extract_planes(pts, min_wal_area=1.0)
    with pytest.raises(ValueError, match="min_points"):
        smc_lmb.extract_planes(pts, min_points=0)


def test_walls_predicted_with_the_true_motion_land_on_the_next_scan():
    pts_k = street(seed=0)
    # The sensor moves 1 m along x and turns 2° left between the scans: every point is seen
    # at p' = M p with M = T_{k+1}⁻¹ T_k, T_k = I.
    a = np.deg2rad(2.0)
    pose_k1 = np.eye(4)
    pose_k1[:3, :3] = [[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]]
    pose_k1[:3, 3] = [1.0, 0.0, 0.0]
    m = np.linalg.inv(pose_k1)
    pts_k1 = pts_k.copy()
    pts_k1[:, :3] = pts_k[:, :3] @ m[:3, :3].T + m[:3, 3]
    r = smc_lmb.predict_planes_between(pts_k, pts_k1, np.eye(4), pose_k1, runs=3, seed=2)
    assert (r["predicted"], r["segmented"]) == (1, 1)
    pairs = r["pairs"]
    assert len(pairs["normal_angle_deg"]) == 1
    assert pairs["normal_angle_deg"][0] < 0.05
    assert pairs["vertex_distances"].max() < 0.05
    assert len(r["prediction_ms"]) == 3
    # Claiming the sensor stood still leaves the facade where it was in scan k: turned by 2°
    # and each corner v off by |M v − v| from its place in scan k + 1.
    still = smc_lmb.predict_planes_between(pts_k, pts_k1, np.eye(4), np.eye(4), seed=2)
    assert still["pairs"]["normal_angle_deg"][0] == pytest.approx(2.0, abs=0.05)
    v = smc_lmb.extract_planes(pts_k, seed=2)["walls"][0]["vertices"]
    moved = np.linalg.norm(v @ m[:3, :3].T + m[:3, 3] - v, axis=1)
    np.testing.assert_allclose(np.sort(still["pairs"]["vertex_distances"][0]), np.sort(moved), atol=0.05)
    with pytest.raises(ValueError, match="pose_k1.*rigid"):
        smc_lmb.predict_planes_between(pts_k, pts_k1, np.eye(4), 2 * np.eye(4))


def test_plane_prediction_over_the_real_drive():
    root = shared_data("kitti_raw/2011_09_26/2011_09_26_drive_0005_sync")
    r = smc_lmb.predict_plane_pairs("raw", root, frames=(10, 12), runs=3, seed=1)
    assert [f["frame"] for f in r["frames"]] == [11, 12]
    s = r["summary"]
    assert s["pairs"] == sum(len(f["pairs"]["normal_angle_deg"]) for f in r["frames"]) > 0
    # Consecutive scans 0.1 s apart: a predicted facade is within a few degrees of its match.
    assert s["median_normal_angle_deg"] < 3.0
    with pytest.raises(ValueError, match="sequence"):
        smc_lmb.predict_plane_pairs("tracking", root)


def test_plane_prediction_over_a_folder_of_scans(tmp_path):
    root = shared_data("kitti_raw/2011_09_26/2011_09_26_drive_0005_sync")
    scans = tmp_path / "scans"
    scans.mkdir()
    for k in range(10, 13):
        (scans / f"{k}.bin").write_bytes((root / "velodyne_points" / "data" / f"{k:010d}.bin").read_bytes())
    with pytest.raises(ValueError, match="no pose file"):
        smc_lmb.predict_plane_pairs("scans", scans, runs=2)
    # poses.txt beside the scans: a sensor standing still (the folder has no vehicle states,
    # so the measured motion is used)
    (scans / "poses.txt").write_text("1 0 0 0 0 1 0 0 0 0 1 0\n" * 3)
    r = smc_lmb.predict_plane_pairs("scans", scans, runs=2, seed=1)
    assert [f["frame"] for f in r["frames"]] == [1, 2]
    assert r["summary"]["pairs"] > 0
    # the same folder tracked, with its poses and its times
    (scans / "times.txt").write_text("0.0\n0.1\n0.2\n")
    t = smc_lmb.track(scans, layout="scans", config={"filter": {"particles": 150}})
    assert (t["name"], t["frames"], t["ego"]) == ("scans", 3, "poses")
    assert t["walls_per_frame"] > 0
    with pytest.raises(ValueError, match="scans"):
        smc_lmb.track(scans, layout="folder")


DRIVE = "kitti_raw/2011_09_26/2011_09_26_drive_0005_sync"


def stands_still(kinematics, dt, n, rng):
    """A car that never moves: n copies of its pose at k."""
    x, _, y, _, phi, _ = kinematics
    return np.tile([x, y, phi], (n, 1))


def test_a_python_vehicle_model_goes_through_algorithm_1():
    root = shared_data(DRIVE)
    kw = dict(frames=(0, 8), runs=3, seed=2)
    ect = smc_lmb.predict_plane_pairs("raw", root, **kw)["summary"]
    still = smc_lmb.predict_plane_pairs("raw", root, vehicle_model=stands_still, **kw)["summary"]
    bicycle = smc_lmb.predict_plane_pairs("raw", root, vehicle_model="bicycle", **kw)["summary"]
    assert ect["pairs"] >= 10
    # The car drives about 0.35 m a frame: a model that ignores it misplaces the vertices.
    assert still["median_vertex_distance_m"] > ect["median_vertex_distance_m"] + 0.1, (still, ect)
    assert bicycle["median_vertex_distance_m"] < still["median_vertex_distance_m"] - 0.1, (bicycle, still)


def test_a_python_vehicle_model_of_the_wrong_shape_or_nan_is_named():
    root = shared_data(DRIVE)
    kw = dict(frames=(0, 1), runs=2, seed=2)
    with pytest.raises(ValueError, match=r"shape \(1, 2\), expected \(1, 3\)"):
        smc_lmb.predict_plane_pairs("raw", root, vehicle_model=lambda k, dt, n, rng: np.zeros((n, 2)), **kw)
    with pytest.raises(ValueError, match="non-finite"):
        smc_lmb.predict_plane_pairs("raw", root, vehicle_model=lambda k, dt, n, rng: np.full((n, 3), np.nan), **kw)

    def boom(k, dt, n, rng):
        raise RuntimeError("my model broke")

    with pytest.raises(RuntimeError, match="my model broke"):
        smc_lmb.predict_plane_pairs("raw", root, vehicle_model=boom, **kw)
    with pytest.raises(ValueError, match="hovercraft"):
        smc_lmb.predict_plane_pairs("raw", root, vehicle_model="hovercraft", **kw)
    with pytest.raises(ValueError, match="callable"):
        smc_lmb.predict_plane_pairs("raw", root, vehicle_model=3, **kw)


def test_track_takes_a_python_road_user_model_and_vehicle_model():
    root = shared_data(DRIVE)
    calls = []

    def cv(particles, dt, rng):
        calls.append(particles.shape)
        out = particles.copy()
        for axis in (0, 2, 4):
            out[:, axis] += dt * out[:, axis + 1]
        return out

    cfg = {"filter": {"particles": 150}}
    a = smc_lmb.track(root, config=cfg, transition=cv, vehicle_model=stands_still)
    assert calls and all(shape[1] == 6 for shape in calls), calls[:3]
    assert a["ego"] == "oxts+PythonVehicleModel"
    b = smc_lmb.track(root, config=cfg, vehicle_model="ct")
    assert b["ego"] == "oxts+ct"
    with pytest.raises(ValueError, match=r"expected \(\d+, 6\)"):
        smc_lmb.track(root, config=cfg, transition=lambda p, dt, rng: p[:, :4])


def test_the_own_vehicle_model_example_compares_and_tracks():
    import importlib.util
    from conftest import REPO

    root = shared_data(DRIVE)
    spec = importlib.util.spec_from_file_location("own_vehicle_model", REPO / "python/examples/own_vehicle_model.py")
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    ect, own = example.compare(root, frames=(0, 6), runs=2)
    assert ect["pairs"] > 0 and own["pairs"] > 0
    # a straight-ahead car on a slow bend is near the ECT over one frame, not far off
    assert own["median_vertex_distance_m"] < 1.0, own
    s = smc_lmb.track(root, config={"filter": {"particles": 150}}, transition=example.damped_velocity)
    assert s["frames"] == 100 and s["cluster_labels"] > 0
