//! `kitti-tools eval --tracking ROOT --sequence NNNN --results DIR`: scores a KITTI tracking
//! results file (`DIR/NNNN.txt`, the `label_02` format with an optional score) against the
//! sequence's `label_02` truth with KITTI's rules, per class: HOTA, CLEAR MOT and IDF1 (see
//! `smc_lmb::pipeline::kitti_tracking_eval` and `docs/tracking_scores.md`).

use anyhow::{Context, Result};
use smc_lmb::kitti::labels::label_frame_count;
use smc_lmb::kitti::{read_tracking_labels, TrackingSequence};
use smc_lmb::pipeline::kitti_tracking_eval::{
    evaluate_kitti_tracking, KittiEvalConfig, KittiTrackingEvaluation,
};
use std::path::{Path, PathBuf};

/// How boxes are compared.
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Mode {
    /// Bird's-eye centre distance (camera x–z), a match within 2 m; similarity 1 − d/2.
    Bev,
    /// 3-D IoU of the oriented boxes ≥ 0.25 (camera y vertical).
    Iou3d,
    /// Image-box IoU ≥ 0.5 with KITTI's 2-D rules (TrackEval's `Kitti2DBox`).
    Iou2d,
}

/// What `eval --results` needs.
pub struct Request<'a> {
    /// The split folder (`.../training`).
    pub root: &'a Path,
    /// The sequence number.
    pub sequence: u32,
    /// The folder holding `NNNN.txt`.
    pub results: &'a Path,
    /// Similarity mode.
    pub mode: Mode,
    /// Only objects within this distance of the camera count (m).
    pub within: Option<f64>,
    /// Only what camera 2 sees counts.
    pub camera_view: bool,
    /// Print JSON.
    pub json: bool,
}

/// The results file of a sequence: `DIR/NNNN.txt`.
pub fn results_path(dir: &Path, sequence: u32) -> PathBuf {
    dir.join(format!("{sequence:04}.txt"))
}

/// Scores the results; returns the evaluation after printing it.
pub fn run(req: &Request) -> Result<KittiTrackingEvaluation> {
    let seq = TrackingSequence::open(req.root, req.sequence).with_context(|| {
        format!(
            "opening tracking sequence {:04} of {}",
            req.sequence,
            req.root.display()
        )
    })?;
    let truth = seq
        .labels()
        .with_context(|| format!("reading the truth {}", seq.labels_path().display()))?;
    let path = results_path(req.results, req.sequence);
    let results = read_tracking_labels(&path)
        .with_context(|| format!("reading the results {}", path.display()))?;
    let calib = if req.camera_view {
        Some(
            seq.calib()
                .with_context(|| format!("reading {}", seq.calib_path().display()))?,
        )
    } else {
        None
    };
    let mut config = match req.mode {
        Mode::Bev => KittiEvalConfig::bev(2.0),
        Mode::Iou3d => KittiEvalConfig::iou_3d(),
        Mode::Iou2d => KittiEvalConfig::iou_2d(),
    };
    config.max_range = req.within;
    let frames = label_frame_count(&truth).max(seq.frame_count());
    let eval = evaluate_kitti_tracking(&truth, &results, frames, &config, calib.as_ref())
        .with_context(|| format!("scoring {}", path.display()))?;
    if req.json {
        let out = serde_json::json!({
            "truth": seq.labels_path(),
            "results": path,
            "evaluation": eval,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        print_table(&path, &eval);
    }
    Ok(eval)
}

/// Prints one line per class (scores in percent, as TrackEval prints them).
fn print_table(path: &Path, e: &KittiTrackingEvaluation) {
    println!(
        "{} against KITTI truth, frames 0..{}, {:?}, match threshold {}{}{}",
        path.display(),
        e.frames,
        e.config.similarity,
        e.config.match_threshold,
        e.config
            .max_range
            .map_or(String::new(), |r| format!(", within {r} m")),
        if e.camera_view { ", camera 2 view" } else { "" }
    );
    if e.results_outside_frames > 0 {
        println!(
            "  {} result lines lie beyond frame {} and were not scored",
            e.results_outside_frames,
            e.frames.saturating_sub(1)
        );
    }
    println!(
        "{:<11}{:>7}{:>7}{:>7}{:>7}{:>9}{:>7}{:>6}{:>6}{:>5}{:>5}{:>7}{:>7}{:>7}{:>7}{:>7}",
        "class",
        "HOTA",
        "DetA",
        "AssA",
        "LocA",
        "MOTA",
        "MOTP",
        "IDSW",
        "Frag",
        "MT",
        "ML",
        "IDF1",
        "prec",
        "recall",
        "truth",
        "tracks"
    );
    for c in &e.classes {
        let (h, cl, id) = (&c.scores.hota, &c.scores.clear, &c.scores.identity);
        let p = |v: f64| format!("{:.2}", 100.0 * v);
        let name = c.class.name();
        println!(
            "{:<11}{:>7}{:>7}{:>7}{:>7}{:>9}{:>7}{:>6}{:>6}{:>5}{:>5}{:>7}{:>7}{:>7}{:>7}{:>7}",
            name,
            p(h.hota),
            p(h.det_a),
            p(h.ass_a),
            p(h.loc_a),
            p(cl.mota),
            p(cl.motp),
            cl.idsw,
            cl.frag,
            cl.mt,
            cl.ml,
            p(id.idf1),
            p(cl.precision),
            p(cl.recall),
            c.truth_objects,
            c.tracker_objects
        );
    }
    for c in &e.classes {
        if let Some(r) = &c.recall_breakdown {
            crate::eval_cmd::print_breakdown(
                &format!(
                    "{} truth within 40 m found (CLEAR matches), by occlusion and range",
                    c.class.name()
                ),
                r,
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixture_root() -> PathBuf {
        // The vendored TrackEval fixtures hold KITTI's layout: gt/label_02/NNNN.txt.
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/trackeval")
    }

    fn request<'a>(root: &'a Path, results: &'a Path, mode: Mode) -> Request<'a> {
        Request {
            root,
            sequence: 1,
            results,
            mode,
            within: None,
            camera_view: false,
            json: false,
        }
    }

    #[test]
    fn perfect_results_score_one_in_both_modes() {
        let root = fixture_root().join("gt");
        let results = fixture_root().join("trackers/perfect/data");
        for mode in [Mode::Bev, Mode::Iou3d, Mode::Iou2d] {
            let e = run(&request(&root, &results, mode)).unwrap();
            for c in &e.classes {
                assert!((c.scores.hota.hota - 1.0).abs() < 1e-12, "{mode:?} {c:?}");
                assert!((c.scores.clear.mota - 1.0).abs() < 1e-12);
                assert!((c.scores.identity.idf1 - 1.0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn bad_results_lines_name_file_line_and_field() {
        let dir = tempfile::tempdir().unwrap();
        let root = fixture_root().join("gt");
        let good =
            std::fs::read_to_string(fixture_root().join("trackers/perfect/data/0001.txt")).unwrap();
        let mut lines: Vec<String> = good.lines().map(str::to_string).collect();
        for (what, line, expect) in [
            ("short", "3 1 Car 0 0 0 1 2 3", "9 values"),
            (
                "text",
                "3 1 Car 0 0 0 1 2 3 4 1.5 1.6 4.0 x 1.6 20 0",
                "x (value 14 of 17)",
            ),
        ] {
            lines[2] = line.to_string();
            std::fs::write(dir.path().join("0001.txt"), lines.join("\n")).unwrap();
            let err = run(&request(&root, dir.path(), Mode::Bev)).unwrap_err();
            let text = format!("{err:#}");
            assert!(text.contains("0001.txt:3"), "{what}: {text}");
            assert!(text.contains(expect), "{what}: {text}");
        }
    }

    #[test]
    fn results_for_other_frames_are_empty_frames_not_errors() {
        let dir = tempfile::tempdir().unwrap();
        let root = fixture_root().join("gt");
        std::fs::write(
            dir.path().join("0001.txt"),
            "70 1 Car 0 0 0 100 100 200 200 1.5 1.6 4.0 0 1.6 20 0 0.9\n",
        )
        .unwrap();
        let e = run(&request(&root, dir.path(), Mode::Bev)).unwrap();
        assert_eq!(e.results_outside_frames, 1);
        let car = &e.classes[0].scores.clear;
        assert_eq!((car.tp, car.fp), (0, 0));
        assert!(car.fn_count > 0);
    }
}
