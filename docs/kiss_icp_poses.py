"""KISS-ICP (pip package `kiss-icp`) on a folder of KITTI .bin scans, for docs/odometry.md.

Writes one KITTI pose line per scan (3x4 row-major, scan k -> scan 0) and prints ms/scan
(reading included, as in `kitti-tools odometry`). Default configuration (max range 100 m,
voxel 1 m), no deskewing and no KITTI vertical-angle correction unless --kitti-deskew is given:
then scans get KISS-ICP's KITTI correction and per-point times from the azimuth, as its
`kitti_raw` loader does.

    python docs/kiss_icp_poses.py SCANS_DIR OUT.txt [--kitti-deskew]
"""

import argparse
import glob
import os
import time

import numpy as np
from kiss_icp.config import load_config
from kiss_icp.kiss_icp import KissICP


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scans")
    ap.add_argument("out")
    ap.add_argument("--kitti-deskew", action="store_true")
    args = ap.parse_args()
    files = sorted(glob.glob(os.path.join(args.scans, "*.bin")))
    if not files:
        raise SystemExit(f"no .bin scans in {args.scans}")
    config = load_config(None)  # max range 100 m, voxel 1 m
    config.data.deskew = args.kitti_deskew
    odometry = KissICP(config)
    if args.kitti_deskew:
        from kiss_icp.pybind import kiss_icp_pybind

    poses = []
    start = time.perf_counter()
    for f in files:
        points = np.fromfile(f, dtype=np.float32).reshape((-1, 4))[:, :3].astype(np.float64)
        stamps = np.array([])
        if args.kitti_deskew:
            points = np.asarray(
                kiss_icp_pybind._correct_kitti_scan(kiss_icp_pybind._Vector3dVector(points))
            )
            stamps = 0.5 * (-np.arctan2(points[:, 1], points[:, 0]) / np.pi + 1.0)
        odometry.register_frame(points, stamps)
        poses.append(odometry.last_pose.copy())
    elapsed = time.perf_counter() - start
    with open(args.out, "w") as out:
        for p in poses:
            out.write(" ".join(f"{v:.9e}" for v in p[:3, :].reshape(-1)) + "\n")
    print(f"{len(files)} scans, {1000.0 * elapsed / len(files):.1f} ms/scan")


if __name__ == "__main__":
    main()
