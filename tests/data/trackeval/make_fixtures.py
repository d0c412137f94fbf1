"""Builds the TrackEval fixtures beside this script and writes TrackEval's scores of them.

Ground truth: `gt/label_02/0000.txt` is KITTI's real tracking label file of sequence 0000,
frames 0-49; `gt/label_02/0001.txt` is the same file with every `Van` renamed `Car` and every
`Cyclist` renamed `Pedestrian`, so that both evaluated classes have several objects (0000 has
no Car and one Pedestrian; its Vans exercise the distractor rule). Trackers are derived from the
truth deterministically (see TRACKERS below) and written to `trackers/NAME/data/NNNN.txt`.
Then TrackEval's `Kitti2DBox` evaluates every tracker on both sequences for `car` and
`pedestrian` with HOTA, CLEAR and Identity, and the per-sequence numbers go to
`expected.json`.

Run from anywhere:  python3 make_fixtures.py   (needs `pip install trackeval 'numpy<2' scipy`)
"""

import json
import math
import os
import random
import shutil
import sys
import tempfile

import numpy as np
import trackeval

HERE = os.path.dirname(os.path.abspath(__file__))
GT_DIR = os.path.join(HERE, "gt", "label_02")
TRACKERS_DIR = os.path.join(HERE, "trackers")
FRAMES = 50
SEQUENCES = ["0000", "0001"]


def read_lines(path):
    with open(path) as f:
        return [l.split() for l in f if l.strip()]


def write_lines(path, rows):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        for r in rows:
            f.write(" ".join(r) + "\n")


def fmt(v):
    return "%.6f" % v


def objects(rows):
    """Every labelled object (no DontCare), with a score of 1 appended."""
    return [r[:17] + ["1.000000"] for r in rows if r[2] != "DontCare"]


def shift(row, dx, dy, dz=0.0):
    """Moves the image box by (dx, dy) pixels and the 3-D location by (dx/100, 0, dz) m."""
    r = list(row)
    r[6], r[8] = fmt(float(r[6]) + dx), fmt(float(r[8]) + dx)
    r[7], r[9] = fmt(float(r[7]) + dy), fmt(float(r[9]) + dy)
    r[13] = fmt(float(r[13]) + dx / 100.0)
    r[15] = fmt(float(r[15]) + dz)
    return r


def perfect(rows, seq):
    return objects(rows)


def shifted(rows, seq):
    return [shift(r, 6.0, 3.0, 0.5) for r in objects(rows)]


def dropped(rows, seq):
    out = []
    for i, r in enumerate(objects(rows)):
        frame = int(r[0])
        if i % 4 == 1:
            continue
        if r[1] == "1" and 20 <= frame < 26:
            continue
        out.append(r)
    return out


def swapped(rows, seq):
    """Ids 1 and 2 exchanged from frame 25 on (in 0001 both are Pedestrians)."""
    out = []
    for r in objects(rows):
        r = list(r)
        if int(r[0]) >= 25 and r[1] in ("1", "2"):
            r[1] = "2" if r[1] == "1" else "1"
        out.append(r)
    return out


def false_positives(rows, seq):
    """The truth plus, per frame: a Car far from everything, a Pedestrian inside the frame's
    first DontCare region (removed by the preprocessing), a short Pedestrian (height < 25 px,
    removed) and, every third frame, a Pedestrian overlapping the first object by half."""
    out = objects(rows)
    dontcare = {}
    first = {}
    for r in rows:
        f = int(r[0])
        if r[2] == "DontCare":
            dontcare.setdefault(f, r)
        else:
            first.setdefault(f, r)
    for f in range(FRAMES):
        out.append([str(f), "100", "Car", "0", "0", "0", fmt(20.0 + f), "200.0", fmt(120.0 + f),
                    "260.0", "1.5", "1.6", "4.0", "-20.0", "1.6", "30.0", "0.0", "0.800000"])
        if f in dontcare:
            d = [float(v) for v in dontcare[f][6:10]]
            cx, cy = (d[0] + d[2]) / 2, (d[1] + d[3]) / 2
            out.append([str(f), "101", "Pedestrian", "0", "0", "0", fmt(cx - 5), fmt(cy - 5),
                        fmt(cx + 5), fmt(cy + 5), "1.7", "0.6", "0.8", "-5.0", "1.6", "25.0",
                        "0.0", "0.700000"])
        out.append([str(f), "102", "Pedestrian", "0", "0", "0", "600.0", "100.0", "620.0",
                    "120.0", "1.7", "0.6", "0.8", "0.0", "1.6", "60.0", "0.0", "0.600000"])
        if f % 3 == 0 and f in first:
            b = [float(v) for v in first[f][6:10]]
            w = b[2] - b[0]
            out.append([str(f), str(200 + f // 10), "Pedestrian", "0", "0", "0",
                        fmt(b[0] + w / 3), fmt(b[1]), fmt(b[2] + w / 3), fmt(b[3]),
                        "1.7", "0.6", "0.8", "0.0", "1.6", "20.0", "0.0", "0.500000"])
    out.sort(key=lambda r: (int(r[0]), int(r[1])))
    return out


def mixed(rows, seq):
    """Jittered boxes (seeded), a drop pattern, swapped ids, the false positives, Vans reported
    as Cars (distractors in 0000) and a second track id for object 1 after frame 40."""
    rng = random.Random(20 + int(seq))
    out = []
    for i, r in enumerate(false_positives(rows, seq)):
        r = list(r)
        frame = int(r[0])
        if int(r[1]) < 100:
            if i % 7 == 3:
                continue
            r = shift(r, rng.uniform(-12, 12), rng.uniform(-8, 8), rng.uniform(-1, 1))
            if r[2] == "Van":
                r[2] = "Car"
            if frame >= 25 and r[1] in ("1", "2"):
                r[1] = "2" if r[1] == "1" else "1"
            if frame > 40 and r[1] == "1":
                r[1] = "7"
        out.append(r)
    return out


TRACKERS = {
    "perfect": perfect,
    "shifted": shifted,
    "dropped": dropped,
    "swapped": swapped,
    "false_positives": false_positives,
    "mixed": mixed,
}


def build_inputs():
    source = read_lines(os.path.join(GT_DIR, "0000.txt"))
    renamed = []
    for r in source:
        r = list(r)
        r[2] = {"Van": "Car", "Cyclist": "Pedestrian"}.get(r[2], r[2])
        renamed.append(r)
    write_lines(os.path.join(GT_DIR, "0001.txt"), renamed)
    with open(os.path.join(HERE, "gt", "evaluate_tracking.seqmap.training"), "w") as f:
        for seq in SEQUENCES:
            f.write("%s empty 000000 %06d\n" % (seq, FRAMES))
    truth = {"0000": source, "0001": renamed}
    if os.path.isdir(TRACKERS_DIR):
        shutil.rmtree(TRACKERS_DIR)
    for name, make in TRACKERS.items():
        for seq in SEQUENCES:
            write_lines(os.path.join(TRACKERS_DIR, name, "data", seq + ".txt"),
                        make(truth[seq], seq))


def plain(v):
    if isinstance(v, np.ndarray):
        return float(np.mean(v))
    return float(v)


def evaluate():
    out_dir = tempfile.mkdtemp()
    eval_config = trackeval.Evaluator.get_default_eval_config()
    eval_config.update({"USE_PARALLEL": False, "PRINT_RESULTS": False, "PRINT_CONFIG": False,
                        "TIME_PROGRESS": False, "OUTPUT_SUMMARY": False,
                        "OUTPUT_DETAILED": False, "PLOT_CURVES": False, "LOG_ON_ERROR": None})
    dataset_config = trackeval.datasets.Kitti2DBox.get_default_dataset_config()
    dataset_config.update({"GT_FOLDER": os.path.join(HERE, "gt"),
                           "TRACKERS_FOLDER": TRACKERS_DIR, "OUTPUT_FOLDER": out_dir,
                           "TRACKERS_TO_EVAL": sorted(TRACKERS), "CLASSES_TO_EVAL":
                           ["car", "pedestrian"], "SPLIT_TO_EVAL": "training",
                           "PRINT_CONFIG": False})
    evaluator = trackeval.Evaluator(eval_config)
    dataset = trackeval.datasets.Kitti2DBox(dataset_config)
    metrics = [trackeval.metrics.HOTA({"PRINT_CONFIG": False}),
               trackeval.metrics.CLEAR({"THRESHOLD": 0.5, "PRINT_CONFIG": False}),
               trackeval.metrics.Identity({"THRESHOLD": 0.5, "PRINT_CONFIG": False})]
    res, _ = evaluator.evaluate([dataset], metrics)
    shutil.rmtree(out_dir, ignore_errors=True)
    res = res["Kitti2DBox"]
    hota_fields = ["HOTA", "DetA", "AssA", "LocA", "DetRe", "DetPr", "AssRe", "AssPr",
                   "HOTA(0)", "LocA(0)"]
    clear_fields = ["MOTA", "MOTP", "IDSW", "Frag", "MT", "PT", "ML", "CLR_TP", "CLR_FN",
                    "CLR_FP"]
    id_fields = ["IDF1", "IDP", "IDR", "IDTP", "IDFN", "IDFP"]
    expected = {"trackeval_version": getattr(trackeval, "__version__", "unknown"),
                "frames": FRAMES, "trackers": {}}
    for tracker in sorted(TRACKERS):
        per_seq = {}
        for seq in SEQUENCES:
            per_class = {}
            for cls in ["car", "pedestrian"]:
                r = res[tracker][seq][cls]
                row = {}
                row.update({k: plain(r["HOTA"][k]) for k in hota_fields})
                row["HOTA_alpha"] = [float(v) for v in r["HOTA"]["HOTA"]]
                row.update({k: plain(r["CLEAR"][k]) for k in clear_fields})
                row.update({k: plain(r["Identity"][k]) for k in id_fields})
                per_class[cls] = row
            per_seq[seq] = per_class
        expected["trackers"][tracker] = per_seq
    with open(os.path.join(HERE, "expected.json"), "w") as f:
        json.dump(expected, f, indent=1, sort_keys=True)
        f.write("\n")


if __name__ == "__main__":
    build_inputs()
    evaluate()
    print("wrote", os.path.join(HERE, "expected.json"), file=sys.stderr)
