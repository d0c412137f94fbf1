"""Your own models on a KITTI drive, from Python (the twin of examples/own_vehicle_model.rs).

1. A vehicle model of your own — a car that keeps its speed and heading — goes where the
   extended constant-turn (ECT) model of Gostar et al. (2019) goes: the paper's Monte-Carlo
   plane prediction (Algorithm 1) of every frame's walls into the next frame. The two models'
   error distributions are printed side by side.
2. A road-user motion model of your own — a velocity that decays towards rest — tracks the
   drive's clusters instead of constant velocity.

    python python/examples/own_vehicle_model.py [DRIVE_DIR]
"""

import sys
from pathlib import Path

import numpy as np

import smc_lmb

DRIVE = Path(__file__).resolve().parents[2].parent / "shared/data/kitti_raw/2011_09_26/2011_09_26_drive_0005_sync"


def straight_ahead(kinematics, dt, n, rng, sigma_speed=0.5, sigma_heading=0.01):
    """n draws of the next pose (X, Y, heading) of a car that keeps its speed and heading;
    `kinematics` is the measured [X, Ẋ, Y, Ẏ, φ, φ̇] at k."""
    x, vx, y, vy, phi, _ = kinematics
    v = np.hypot(vx, vy) + sigma_speed * np.sqrt(dt) * rng.standard_normal(n)
    heading = phi + sigma_heading * np.sqrt(dt) * rng.standard_normal(n)
    return np.column_stack([x + v * dt * np.cos(heading), y + v * dt * np.sin(heading), heading])


def damped_velocity(particles, dt, rng, tau=2.0, sigma=3.0):
    """Road users [x, ẋ, y, ẏ, z, ż] whose velocity decays towards rest (Ornstein–Uhlenbeck)."""
    decay = np.exp(-dt / tau)
    kick = sigma * np.sqrt(1.0 - decay * decay)
    out = particles.copy()
    for axis in (0, 2, 4):
        out[:, axis + 1] = decay * out[:, axis + 1] + kick * rng.standard_normal(len(out))
        out[:, axis] += dt * out[:, axis + 1]
    return out


def compare(drive, frames=(0, 49), runs=10):
    ect = smc_lmb.predict_plane_pairs("raw", drive, frames=frames, runs=runs, seed=1)["summary"]
    own = smc_lmb.predict_plane_pairs(
        "raw", drive, frames=frames, runs=runs, seed=1, vehicle_model=straight_ahead
    )["summary"]
    return ect, own


def main():
    drive = Path(sys.argv[1]) if len(sys.argv) > 1 else DRIVE
    ect, own = compare(drive)
    print("plane prediction k → k+1, frames 0–49, 10 Monte-Carlo runs each:")
    print(f"{'':<28} {'ECT':>14} {'straight_ahead':>14}")
    for key in ["pairs", "median_normal_angle_deg", "p90_normal_angle_deg",
                "median_vertex_distance_m", "p90_vertex_distance_m"]:
        print(f"{key:<28} {ect[key]:>14.3f} {own[key]:>14.3f}")
    for name, f in [("constant velocity", None), ("damped_velocity", damped_velocity)]:
        s = smc_lmb.track(drive, particles=300, transition=f)
        print(f"tracked with {name}: {s['clusters_per_frame']:.2f} clusters a frame over {s['frames']} frames")


if __name__ == "__main__":
    main()
