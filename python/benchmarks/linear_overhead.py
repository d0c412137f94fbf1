"""Per-step cost of calling the filter from Python on the linear RFS benchmark (constant
velocity, 12 targets, 30 clutter points a scan, 100 scans), against the filter's own time.

For each run the same simulated scenario goes through the same filter (the configuration
`linear_scenario` returns, which is the filter `examples/rfs_benchmark.rs` builds) three ways:
`step` called from a Python loop (wall time around each call), the time the library itself
spent inside those steps (`step_times_ms`, measured in Rust with the GIL released), and
`run`, which passes all frames in one call. The difference between the first two is the
Python overhead per step: argument conversion, building the estimate objects, GIL hand-off.
With `--python-model` the filter's motion model is a NumPy function (the same constant
velocity model), called once per track and step from the filter's worker threads.

    python python/benchmarks/linear_overhead.py --runs 5 --particles 1000 [--python-model]
"""

import argparse
import statistics
import time

import numpy as np

import smc_lmb


def constant_velocity(sigma):
    """The built-in planar constant-velocity model in NumPy: white acceleration noise."""

    def move(particles, dt, rng):
        out = particles.copy()
        accel = rng.normal(0.0, sigma, (len(particles), 2))
        out[:, [0, 2]] += dt * particles[:, [1, 3]] + 0.5 * dt * dt * accel
        out[:, [1, 3]] += dt * accel
        return out

    return move


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--particles", type=int, default=1000)
    ap.add_argument("--python-model", action="store_true")
    args = ap.parse_args()
    model = constant_velocity(5.0) if args.python_model else None

    loop_ms, inside_ms, run_ms, ospa = [], [], [], []
    for r in range(args.runs):
        sc = smc_lmb.linear_scenario(seed=args.seed + r, particles=args.particles)
        times, frames = list(sc["times"]), sc["measurements"]

        f = smc_lmb.LmbFilter(sc["config"], transition=model)
        for t, z, x in zip(times, frames, sc["truth"]):
            t0 = time.perf_counter()
            est = f.step(t, z)
            loop_ms.append((time.perf_counter() - t0) * 1e3)
            pos = np.array([[e.state[0], e.state[2]] for e in est]).reshape(-1, 2)
            ospa.append(smc_lmb.ospa(x[:, [0, 2]], pos, c=sc["ospa_cutoff"])["distance"])
        inside_ms.extend(f.step_times_ms())

        g = smc_lmb.LmbFilter(sc["config"], transition=model)
        t0 = time.perf_counter()
        g.run(times, frames)
        run_ms.append((time.perf_counter() - t0) * 1e3 / len(frames))

    overhead = [a - b for a, b in zip(loop_ms, inside_ms)]
    med, mean = statistics.median, statistics.fmean
    print(f"linear benchmark, {args.runs} runs × 100 steps, {args.particles} particles a track, "
          f"{'NumPy' if model else 'built-in'} motion model, mean OSPA {mean(ospa):.2f} m")
    print(f"{'ms/step':<34}{'median':>9}{'mean':>9}")
    print(f"{'step() from Python (wall)':<34}{med(loop_ms):>9.3f}{mean(loop_ms):>9.3f}")
    print(f"{'  of which inside the library':<34}{med(inside_ms):>9.3f}{mean(inside_ms):>9.3f}")
    print(f"{'  Python overhead':<34}{med(overhead):>9.3f}{mean(overhead):>9.3f}")
    print(f"{'run() of all frames, per step':<34}{med(run_ms):>9.3f}{mean(run_ms):>9.3f}")


if __name__ == "__main__":
    main()
