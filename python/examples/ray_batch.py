"""Track many KITTI recordings in parallel with Ray: one task per recording, each writing
``OUT/NAME/tracks.json`` through ``smc_lmb.track``, and one summary table.

The same script runs on a laptop and on a cluster: without ``--address`` it starts a local
Ray instance (``ray.init()``); with ``--address auto`` (or ``RAY_ADDRESS`` set) it joins a
running cluster, whose workers need ``smc_lmb`` installed and the recordings at the same
paths (a shared file system). Like ``kitti-tools batch`` it is resumable: a recording whose
``tracks.json`` is already there is skipped (the library writes it atomically, so a stopped
task leaves none), and a recording that fails is a row of the table with its error.

    python python/examples/ray_batch.py --drives LIST_OR_FOLDER --out DIR [--config F.toml]

``LIST_OR_FOLDER`` is a text file with one raw drive folder per line (``#`` comments,
relative paths from the file's folder) or a folder whose raw drives are all taken.
"""

import argparse
import json
import pathlib
import sys

import ray

import smc_lmb


def recordings(spec):
    """The raw drive folders named by a list file or found in a folder, in order."""
    spec = pathlib.Path(spec)
    if spec.is_dir():
        return sorted(p for p in spec.iterdir() if (p / "velodyne_points").is_dir())
    drives = []
    for line in spec.read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            drives.append(spec.parent / line)
    return drives


@ray.remote
def track_one(drive, out, config, seed):
    """Tracks one raw drive into ``out/NAME/tracks.json`` unless it is there already."""
    name = pathlib.Path(drive).name
    dest = pathlib.Path(out) / name / "tracks.json"
    try:
        if dest.exists():
            return {"recording": name, "status": "skipped", **smc_lmb.tracks_summary(dest)}
        dest.parent.mkdir(parents=True, exist_ok=True)
        summary = smc_lmb.track(drive, out=dest, config=config, seed=seed)
        return {"recording": name, "status": "tracked", **summary}
    except Exception as e:  # one recording's failure is a row, not the end of the batch
        return {"recording": name, "status": "failed", "error": str(e)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--drives", required=True, help="list file or folder of raw drives")
    ap.add_argument("--out", required=True, help="output folder")
    ap.add_argument("--config", help="tracking configuration (TOML), the same for all")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--address", help="Ray cluster address (default: a local instance)")
    args = ap.parse_args(argv)

    drives = recordings(args.drives)
    if not drives:
        sys.exit(f"{args.drives} names no recording")
    config = pathlib.Path(args.config).read_text() if args.config else None
    ray.init(address=args.address, include_dashboard=False, log_to_driver=False)
    try:
        rows = ray.get([track_one.remote(str(d), args.out, config, args.seed) for d in drives])
    finally:
        ray.shutdown()

    columns = ["recording", "status", "frames", "walls_per_frame", "clusters_per_frame", "ms_per_frame"]
    print("\t".join(columns + ["error"]))
    for r in rows:
        cells = [r.get(c, "") for c in columns]
        cells = [f"{c:.2f}" if isinstance(c, float) else str(c) for c in cells]
        print("\t".join(cells + [r.get("error", "")]))
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "summary.json").write_text(json.dumps(rows, indent=1) + "\n")
    failed = sum(r["status"] == "failed" for r in rows)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
