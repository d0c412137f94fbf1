"""Shared helpers of the Python tests: the real recordings beside the checkout and a small
filter configuration."""

import os
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def shared_data(relative):
    """A path under ``../shared/data`` (beside the checkout). Missing: under ``CI=true`` the
    test fails naming it; elsewhere it is skipped with a line on stderr."""
    path = REPO.parent / "shared" / "data" / relative
    if path.exists():
        return path
    if os.environ.get("CI") == "true":
        pytest.fail(f"CI=true but the shared data {path} is missing: the tests on real recordings must run")
    print(f"SKIPPED: {path} is absent, a test on real data did not run", file=sys.stderr)
    pytest.skip(f"{path} is absent")


def planar_config(seed=0, particles=400, clutter_rate=2.0, detection=0.95):
    """A planar constant-velocity filter with position measurements and adaptive birth."""
    return {
        "seed": seed,
        "filter": {"particles": particles},
        "transition": {"model": "constant_velocity", "dims": 2, "sigma_accel": 0.5},
        "measurement": {"model": "position", "sigma": 0.5},
        "detection": {"model": "constant", "probability": detection},
        "clutter": {"rate": clutter_rate, "volume": 200.0 * 200.0},
        "birth": {
            "model": "adaptive",
            "expected_births": 0.1,
            "max_existence": 0.1,
            "particles": particles,
            "position_std": 0.5,
            "velocity_std": 2.0,
        },
    }
