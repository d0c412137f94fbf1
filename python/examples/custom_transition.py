"""A user's own motion model plugged into the filter from Python: velocity as an
Ornstein–Uhlenbeck process (manoeuvres decay with time constant tau),

    v_{k+1} = e^{-T/tau} v_k + sigma sqrt(1 - e^{-2T/tau}) eps,   x_{k+1} = x_k + T v_{k+1},

on the usual state layout [x, vx, y, vy], so the configured position measurement fits it.
The model is one function that moves the whole particle array at once (one call per track
and step, not per particle); its random numbers come from the generator the filter hands it,
so a run repeats exactly for the same seed. Three objects are simulated with the same
process and tracked. Mirrors examples/custom_transition.rs.

    python python/examples/custom_transition.py
"""

import numpy as np

import smc_lmb


def ornstein_uhlenbeck(tau, sigma):
    """f(particles[N, 4], dt, rng) -> particles[N, 4]: mean-reverting velocity."""

    def predict(particles, dt, rng):
        decay = np.exp(-dt / tau)
        kick = sigma * np.sqrt(1.0 - decay * decay)
        out = particles.copy()
        for axis in (0, 2):
            out[:, axis + 1] = decay * particles[:, axis + 1] + kick * rng.standard_normal(len(out))
            out[:, axis] = particles[:, axis] + dt * out[:, axis + 1]
        return out

    return predict


CONFIG = {
    "seed": 8,
    "filter": {"particles": 500},
    # The configured transition fixes the state layout [x, vx, y, vy]; the Python model
    # below replaces its motion.
    "transition": {"model": "constant_velocity", "dims": 2, "sigma_accel": 1.0},
    "measurement": {"model": "position", "sigma": 0.5},
    "detection": {"model": "constant", "probability": 0.9},
    "clutter": {"rate": 3.0, "volume": 120.0 * 120.0},
    "birth": {"model": "adaptive", "expected_births": 0.1, "max_existence": 0.1,
              "particles": 500, "position_std": 0.5, "velocity_std": 1.5},
}


def main():
    model = ornstein_uhlenbeck(tau=5.0, sigma=1.5)
    filt = smc_lmb.LmbFilter(CONFIG, transition=model)

    # Simulate three objects with the same model (one particle each) and noisy detections.
    sim = np.random.default_rng(7)
    truth = np.array([[-30.0, 1.0, 0.0, 0.5], [20.0, -1.0, 20.0, 0.0], [0.0, 0.0, -30.0, 1.0]])
    steps, total = 60, 0.0
    for k in range(steps):
        if k > 0:
            truth = model(truth, 1.0, sim)
        objects = truth[:, [0, 2]]
        seen = objects[sim.uniform(size=3) < 0.9]
        z = seen + 0.5 * sim.standard_normal(seen.shape)
        clutter = sim.uniform(-60.0, 60.0, (sim.integers(0, 6), 2))
        estimates = filt.step(float(k), np.vstack([z, clutter]))
        x = np.array([[e.state[0], e.state[2]] for e in estimates]).reshape(-1, 2)
        d = smc_lmb.ospa(objects, x, c=5.0)["distance"]
        total += d
        if k % 10 == 9:
            print(f"step {k + 1:>2}: {len(estimates)} tracks, OSPA(c = 5 m) {d:.2f} m")
    print(f"mean OSPA over {steps} steps: {total / steps:.2f} m")


if __name__ == "__main__":
    main()
