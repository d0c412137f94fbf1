"""KITTI readers: scans written here with NumPy, label files written here, bad files that
must raise exceptions naming them, and the real recordings beside the checkout."""

import numpy as np
import pytest

import smc_lmb
from conftest import shared_data

DRIVE = "kitti_raw/2011_09_26/2011_09_26_drive_0005_sync"
# Frames of drive 0005 (= tracking sequence 0000) in the shared data.
FRAMES = 100


def test_a_bin_written_with_numpy_reads_back(tmp_path):
    rng = np.random.default_rng(3)
    points = rng.normal(0, 20, (257, 4)).astype(np.float32)
    path = tmp_path / "0000000000.bin"
    points.tofile(path)
    got = smc_lmb.read_kitti_bin(path)
    assert got.dtype == np.float32 and got.shape == (257, 4)
    np.testing.assert_array_equal(got, points)
    # A string path works as well as a pathlib one.
    np.testing.assert_array_equal(smc_lmb.read_kitti_bin(str(path)), points)


def test_a_truncated_bin_names_the_file(tmp_path):
    path = tmp_path / "truncated.bin"
    np.zeros(10, dtype=np.float32).tofile(path)  # 40 bytes: two and a half points
    with pytest.raises(ValueError, match="truncated.bin"):
        smc_lmb.read_kitti_bin(path)


def test_a_missing_file_is_file_not_found_naming_it(tmp_path):
    with pytest.raises(FileNotFoundError, match="nothing_here.bin"):
        smc_lmb.read_kitti_bin(tmp_path / "nothing_here.bin")
    with pytest.raises(OSError, match="no_drive"):
        smc_lmb.RawDrive(tmp_path / "no_drive")


LABELS = """\
0 -1 DontCare -1 -1 -10.000000 219.310000 188.490000 245.500000 218.560000 -1000.000000 -1000.000000 -1000.000000 -10.000000 -1.000000 -1.000000 -1.000000
0 0 Van 0 0 -1.793451 296.744956 161.752147 455.226042 292.372804 2.000000 1.823255 4.433886 -4.552284 1.858523 13.410495 -2.115488
1 2 Pedestrian 1 2 0.5 10 20 30 40 1.7 0.6 0.9 1.0 1.5 8.0 0.25
"""


def test_tracking_labels_written_here_read_back(tmp_path):
    path = tmp_path / "0000.txt"
    path.write_text(LABELS)
    lab = smc_lmb.read_tracking_labels(path)
    assert lab["type"] == ["DontCare", "Van", "Pedestrian"]
    np.testing.assert_array_equal(lab["frame"], [0, 0, 1])
    np.testing.assert_array_equal(lab["track_id"], [-1, 0, 2])
    np.testing.assert_array_equal(lab["occluded"], [-1, 0, 2])
    np.testing.assert_allclose(lab["bbox"][1], [296.744956, 161.752147, 455.226042, 292.372804])
    np.testing.assert_allclose(lab["dimensions"][2], [1.7, 0.6, 0.9])
    np.testing.assert_allclose(lab["location"][2], [1.0, 1.5, 8.0])
    np.testing.assert_allclose(lab["rotation_y"], [-1.0, -2.115488, 0.25])
    assert np.isnan(lab["score"]).all()


def test_a_bad_label_line_names_file_and_line(tmp_path):
    path = tmp_path / "0001.txt"
    path.write_text(LABELS + "2 3 Car 0 0 oops 1 2 3 4 1 1 1 0 0 0 0\n")
    with pytest.raises(ValueError, match=r"0001.txt:4"):
        smc_lmb.read_tracking_labels(path)


def test_real_raw_drive_scans_poses_and_times():
    root = shared_data(DRIVE)
    drive = smc_lmb.RawDrive(root)
    assert drive.frame_count == FRAMES
    assert all(drive.has_scan(k) for k in range(FRAMES)) and not drive.has_scan(FRAMES)
    scan = drive.velodyne(11)
    raw = np.fromfile(root / "velodyne_points/data/0000000011.bin", dtype=np.float32).reshape(-1, 4)
    np.testing.assert_array_equal(scan, raw)
    assert len(scan) == 123334  # seed 001's point count of frame 11
    poses = drive.poses()
    assert poses.shape == (FRAMES, 4, 4)
    np.testing.assert_allclose(poses[0], np.eye(4), atol=1e-12)
    for p in poses:
        np.testing.assert_allclose(p[:3, :3].T @ p[:3, :3], np.eye(3), atol=1e-9)
    # A slow bend at about 3.5 m/s: the first 49 frame steps of ~0.1 s cover 15 to 20 m.
    travelled = np.linalg.norm(np.diff(poses[:50, :3, 3], axis=0), axis=1).sum()
    assert 15.0 < travelled < 20.0, travelled
    times = drive.times()
    assert times[0] == 0.0 and np.all(np.diff(times) > 0.09) and np.all(np.diff(times) < 0.11)
    states = drive.vehicle_states()
    assert states.shape == (FRAMES, 6)
    speed = np.hypot(states[:, 1], states[:, 3])
    assert 2.5 < speed.mean() < 4.5


def test_real_tracking_labels_match_the_text():
    root = shared_data("kitti_tracking/training")
    path = root / "label_02" / "0000.txt"
    lines = [l.split() for l in path.read_text().splitlines() if l.strip()]
    lab = smc_lmb.read_tracking_labels(path)
    assert len(lab["type"]) == len(lines)
    assert lab["type"] == [l[2] for l in lines]
    np.testing.assert_array_equal(lab["track_id"], [int(l[1]) for l in lines])
    np.testing.assert_allclose(lab["location"], [[float(v) for v in l[13:16]] for l in lines])


def write_odometry_layout(root, poses_cam, tr, scans):
    seq = root / "sequences" / "00"
    (seq / "velodyne").mkdir(parents=True)
    for k, s in enumerate(scans):
        s.astype(np.float32).tofile(seq / "velodyne" / f"{k:06d}.bin")
    proj = " ".join(["7.0e+02", "0", "6.0e+02", "0", "0", "7.0e+02", "1.8e+02", "0", "0", "0", "1", "0"])
    lines = [f"P{i}: {proj}" for i in range(4)]
    lines.append("Tr: " + " ".join(f"{v:.12e}" for v in tr[:3].ravel()))
    (seq / "calib.txt").write_text("\n".join(lines) + "\n")
    (seq / "times.txt").write_text("".join(f"{0.1 * k:.6e}\n" for k in range(len(scans))))
    (root / "poses").mkdir()
    (root / "poses" / "00.txt").write_text(
        "".join(" ".join(f"{v:.12e}" for v in p[:3].ravel()) + "\n" for p in poses_cam)
    )


def test_an_odometry_layout_written_here_reads_back(tmp_path):
    # Tr: Velodyne x → camera z, y → −x, z → −y, plus an offset (the KITTI mounting).
    tr = np.eye(4)
    tr[:3, :3] = [[0, -1, 0], [0, 0, -1], [1, 0, 0]]
    tr[:3, 3] = [0.05, -0.08, -0.27]
    # The camera drives forward (its z) 1 m a frame while turning about its y axis.
    poses_cam = []
    for k in range(3):
        a = 0.05 * k
        p = np.eye(4)
        p[:3, :3] = [[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]]
        p[:3, 3] = [0.0, 0.0, float(k)]
        poses_cam.append(p)
    rng = np.random.default_rng(1)
    scans = [rng.normal(0, 10, (50 + k, 4)) for k in range(3)]
    write_odometry_layout(tmp_path, poses_cam, tr, scans)

    seq = smc_lmb.OdometrySequence(tmp_path, 0)
    assert (seq.name, seq.frame_count) == ("00", 3)
    np.testing.assert_array_equal(seq.velodyne(2), scans[2].astype(np.float32))
    np.testing.assert_allclose(seq.times(), [0.0, 0.1, 0.2])
    # Velodyne poses V_k = Tr⁻¹ P_k Tr.
    expected = np.array([np.linalg.inv(tr) @ p @ tr for p in poses_cam])
    np.testing.assert_allclose(seq.poses(), expected, atol=1e-9)
    # Forward in the camera is +x for the Velodyne: frame 2 is about 2 m ahead.
    assert seq.poses()[2][0, 3] == pytest.approx(2.0, abs=0.1)


def test_a_bad_pose_line_names_the_file_and_line(tmp_path):
    write_odometry_layout(tmp_path, [np.eye(4)], np.eye(4), [np.zeros((1, 4))])
    (tmp_path / "poses" / "00.txt").write_text("1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 oops 0 1 0 0 0 0 1 0\n")
    with pytest.raises(ValueError, match=r"00.txt:2"):
        smc_lmb.OdometrySequence(tmp_path, 0).poses()


def test_real_tracking_sequence_poses_and_labels():
    root = shared_data("kitti_tracking/training")
    seq = smc_lmb.TrackingSequence(root, 0)
    assert seq.name == "0000" and seq.frame_count == FRAMES
    # The shared copy keeps no scans (they are raw drive 0005's): frames come from OXTS.
    assert not seq.has_scan(0)
    poses = seq.poses()
    assert poses.shape == (FRAMES, 4, 4)
    np.testing.assert_allclose(poses[0], np.eye(4), atol=1e-12)
    np.testing.assert_allclose(seq.times()[:3], [0.0, 0.1, 0.2])
    lab = seq.labels()
    direct = smc_lmb.read_tracking_labels(root / "label_02" / "0000.txt")
    assert lab["type"] == direct["type"]
    np.testing.assert_array_equal(lab["frame"], direct["frame"])
