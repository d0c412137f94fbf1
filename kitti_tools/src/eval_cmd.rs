//! `kitti-tools eval`: scores the output of `track` against ground truth — OSPA and GOSPA of
//! the cluster tracks and their label switches against a simulated street's `truth.json`, a
//! KITTI drive's `tracklet_labels.xml` or a KITTI tracking sequence's `label_02` labels, the
//! wall tracks against the street's walls — and, on request, the recording's plane-prediction
//! statistics.

use anyhow::{bail, Context, Result};
use smc_lmb::kitti::{read_tracklets, RawDrive, TrackingSequence};
use smc_lmb::metrics::recall::{RecallBreakdown, Tally, RANGE_BINS};
use smc_lmb::metrics::PlanePredictionSummary;
use smc_lmb::pipeline::drive_evaluation::{
    evaluate_labels, ClusterEvaluation, ClusterEvaluationConfig, Evaluation, EvaluationOptions,
    FrameScore, WallEvaluation,
};
use smc_lmb::pipeline::{predict_pairs, DriveTracks, PlanePredictionConfig};
use smc_lmb::recording::{Recording, RecordingLabels};
use smc_lmb::sim::street::StreetTruth;
use std::path::PathBuf;

/// Flags of `eval`.
#[derive(clap::Args)]
pub struct Args {
    /// Output of `kitti-tools track`.
    #[arg(long, required_unless_present = "results")]
    tracks: Option<PathBuf>,
    /// With `--tracking`: score KITTI tracking results `DIR/NNNN.txt` (label_02 format, an
    /// optional score) instead of `--tracks`: HOTA, CLEAR MOT and IDF1 per class.
    #[arg(long, requires = "tracking", conflicts_with_all = ["tracks", "planes"])]
    results: Option<PathBuf>,
    /// With `--results`: bev (centre distance in the camera's x–z plane, match within 2 m),
    /// iou3d (oriented 3-D boxes, IoU ≥ 0.25) or iou2d (image boxes, IoU ≥ 0.5, TrackEval's
    /// KITTI 2-D rules).
    #[arg(long, value_enum, default_value = "bev")]
    mode: crate::tracking_eval_cmd::Mode,
    /// With `--results`: only objects within this distance of the camera count (m).
    #[arg(long, requires = "results")]
    within: Option<f64>,
    /// The drive folder; its `truth.json` (simulated) or `tracklet_labels.xml` (KITTI) is the
    /// truth unless `--truth` or `--tracklets` names one.
    #[arg(long, conflicts_with = "tracking")]
    drive: Option<PathBuf>,
    /// A KITTI tracking split folder (`.../training`); the sequence's `label_02/NNNN.txt`,
    /// moved to the Velodyne frame, is the truth. Needs `--sequence`.
    #[arg(long, requires = "sequence", conflicts_with_all = ["truth", "tracklets"])]
    tracking: Option<PathBuf>,
    /// Tracking sequence number.
    #[arg(long)]
    sequence: Option<u32>,
    /// With `--tracking`: score only what camera 2 sees — labelled objects and cluster tracks
    /// whose centre appears in its image — as KITTI labels only that view.
    #[arg(long, requires = "tracking")]
    camera_view: bool,
    /// A simulated street's `truth.json`.
    #[arg(long)]
    truth: Option<PathBuf>,
    /// A KITTI `tracklet_labels.xml` (needs `--drive` for the poses).
    #[arg(long)]
    tracklets: Option<PathBuf>,
    /// Simulated objects count in a frame only with at least this many lidar points.
    #[arg(long, default_value_t = 15)]
    min_points: usize,
    /// Simulated and labelled objects count only within this horizontal range of the sensor
    /// (m); the default is the tracker's default cluster range.
    #[arg(long, default_value_t = 40.0)]
    max_range: f64,
    /// OSPA/GOSPA cut-off c (m).
    #[arg(long, default_value_t = 3.0)]
    cutoff: f64,
    /// OSPA/GOSPA order p.
    #[arg(long, default_value_t = 1.0)]
    order: f64,
    /// Also predict every frame's walls to the next frame (ECT Monte Carlo, `--runs` runs) and
    /// report the plane-prediction statistics (needs `--drive` or `--tracking`).
    #[arg(long)]
    planes: bool,
    /// Monte-Carlo runs of `--planes`.
    #[arg(long, default_value_t = 10)]
    runs: usize,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

/// The tracking sequence of `--tracking` / `--sequence`, if given.
fn tracking_sequence(args: &Args) -> Result<Option<(TrackingSequence, String)>> {
    let (Some(root), Some(n)) = (&args.tracking, args.sequence) else {
        return Ok(None);
    };
    let what = format!("tracking sequence {n:04} of {}", root.display());
    let seq = TrackingSequence::open(root, n).with_context(|| format!("opening {what}"))?;
    Ok(Some((seq, what)))
}

/// The recording of `--tracking` / `--sequence` or `--drive`, if given.
fn open_recording(args: &Args) -> Result<Option<Box<dyn Recording>>> {
    if let Some((seq, _)) = tracking_sequence(args)? {
        return Ok(Some(Box::new(seq)));
    }
    match &args.drive {
        Some(dir) => {
            Ok(Some(Box::new(RawDrive::open(dir).with_context(|| {
                format!("opening drive {}", dir.display())
            })?)))
        }
        None => Ok(None),
    }
}

/// The labels to score against: `--truth` or `--tracklets` when given, else the recording's
/// own.
fn labels(args: &Args, recording: Option<&dyn Recording>) -> Result<RecordingLabels> {
    match (&args.truth, &args.tracklets, recording) {
        (Some(_), Some(_), _) => bail!("give --truth or --tracklets, not both"),
        (Some(p), None, _) => Ok(RecordingLabels::Street(Box::new(
            StreetTruth::read(p)
                .with_context(|| format!("reading street truth {}", p.display()))?,
        ))),
        (None, Some(p), _) => {
            if args.drive.is_none() {
                bail!("--tracklets needs --drive for the poses of the frames");
            }
            Ok(RecordingLabels::Tracklets(read_tracklets(p).with_context(
                || format!("reading tracklets {}", p.display()),
            )?))
        }
        (None, None, Some(rec)) => rec
            .labels()
            .with_context(|| format!("reading the labels of {}", rec.describe()))?
            .with_context(|| {
                format!(
                    "{} has no labels (a tracking sequence's label_02, a drive's truth.json or \
                     tracklet_labels.xml); name the truth with --truth or --tracklets",
                    rec.describe()
                )
            }),
        (None, None, None) => bail!("give --drive, --truth, --tracklets or --tracking"),
    }
}

fn plane_statistics(
    args: &Args,
    recording: Option<&dyn Recording>,
) -> Result<Option<PlanePredictionSummary>> {
    if !args.planes {
        return Ok(None);
    }
    let Some(rec) = recording else {
        bail!("--planes needs --drive or --tracking");
    };
    let mut rng = smc_lmb::rng::seeded(1);
    let results = predict_pairs(
        rec,
        None,
        &PlanePredictionConfig::default(),
        args.runs,
        &mut rng,
    )
    .with_context(|| format!("predicting planes of {}", rec.describe()))?;
    Ok(Some(crate::planes_cmd::pairs_and_summary(&results).1))
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    if let (Some(results), Some(root), Some(sequence)) =
        (&args.results, &args.tracking, args.sequence)
    {
        let request = crate::tracking_eval_cmd::Request {
            root,
            sequence,
            results,
            mode: args.mode,
            within: args.within,
            camera_view: args.camera_view,
            json: args.json,
        };
        return crate::tracking_eval_cmd::run(&request).map(|_| ());
    }
    let tracks_path = args
        .tracks
        .clone()
        .context("give --tracks (or --results)")?;
    let tracks = DriveTracks::read_json(&tracks_path)
        .with_context(|| format!("reading tracks {}", tracks_path.display()))?;
    let recording = open_recording(&args)?;
    let labels = labels(&args, recording.as_deref())?;
    let poses = match (labels.needs_poses(), &recording) {
        (false, _) | (_, None) => None,
        (true, Some(rec)) => Some(
            rec.poses()
                .with_context(|| format!("poses of {}", rec.describe()))?,
        ),
    };
    let options = EvaluationOptions {
        clusters: ClusterEvaluationConfig {
            cutoff: args.cutoff,
            order: args.order,
        },
        min_points: args.min_points,
        max_range: args.max_range,
        camera_view: args.camera_view,
    };
    let Evaluation {
        clusters,
        walls,
        car_van_recall,
    } = evaluate_labels(&tracks, &labels, poses.as_deref(), &options)
        .with_context(|| format!("scoring {}", tracks_path.display()))?;
    let planes = plane_statistics(&args, recording.as_deref())?;
    if args.json {
        let out = serde_json::json!({
            "tracks": tracks_path,
            "clusters": clusters,
            "walls": walls,
            "plane_prediction": planes,
            "car_van_recall": car_van_recall.as_ref().map(breakdown_json),
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    print_evaluation(&tracks.drive, &clusters, walls.as_ref());
    if let Some(r) = &car_van_recall {
        print_breakdown(
            &format!(
                "cars and vans within 40 m found by a track reported as a car or van (nearest, \
                 within c = {} m)",
                clusters.config.cutoff
            ),
            r,
        );
    }
    if let Some(s) = &planes {
        println!(
            "plane prediction ({} runs): {} pairs, normal angle median {:.3}° p90 {:.3}°, vertex \
             distance median {:.3} m p90 {:.3} m, prediction {:.4} ms",
            args.runs,
            s.pairs,
            s.median_normal_angle_deg,
            s.p90_normal_angle_deg,
            s.median_vertex_distance_m,
            s.p90_vertex_distance_m,
            s.mean_prediction_ms
        );
    }
    Ok(())
}

/// Prints the cluster and wall scores.
pub fn print_evaluation(run: &str, clusters: &ClusterEvaluation, walls: Option<&WallEvaluation>) {
    println!(
        "cluster tracks of {} ({} frames), c = {} m, p = {}:",
        run,
        clusters.frames.len(),
        clusters.config.cutoff,
        clusters.config.order
    );
    let mean = |f: &dyn Fn(&FrameScore) -> f64| {
        clusters.frames.iter().map(f).sum::<f64>() / clusters.frames.len() as f64
    };
    println!(
        "  mean OSPA {:.3} m, mean GOSPA {:.3} m; per frame {:.1} truth objects, {:.1} tracks, \
         {:.1} missed, {:.1} false",
        clusters.mean_ospa,
        clusters.mean_gospa,
        mean(&|f| f.truth as f64),
        mean(&|f| f.estimates as f64),
        mean(&|f| f.missed as f64),
        mean(&|f| f.false_tracks as f64)
    );
    println!(
        "  label switches {} over {} truth objects; every object kept one label: {}",
        clusters.labels.switches,
        clusters.labels.per_truth.len(),
        clusters.labels.all_kept
    );
    if let Some(w) = walls {
        println!(
            "wall tracks: {} reports, {} within 2° and 0.5 m of a truth wall ({} walls); normal \
             angle median {:.3}° p90 {:.3}°, offset median {:.3} m p90 {:.3} m",
            w.reports,
            w.matched,
            w.walls_matched,
            w.median_normal_angle_deg,
            w.p90_normal_angle_deg,
            w.median_offset_m,
            w.p90_offset_m
        );
    }
}

/// A tally as "0.75 (3/4)", or "– (0/0)".
pub fn ratio(t: &Tally) -> String {
    match t.ratio() {
        Some(r) => format!("{r:.2} ({}/{})", t.hits, t.total),
        None => "– (0/0)".to_string(),
    }
}

/// Prints a recall breakdown under `title`: in all, by occlusion level, by range.
pub fn print_breakdown(title: &str, r: &RecallBreakdown) {
    println!("{title}: {}", ratio(&r.recall));
    print_levels_and_ranges(&r.by_occlusion, &r.by_range);
}

/// Prints tallies by KITTI occlusion level (0–3) and by [`RANGE_BINS`], one a line.
pub fn print_levels_and_ranges(by_occlusion: &[Tally], by_range: &[Tally]) {
    let levels = [
        "fully visible",
        "partly occluded",
        "largely occluded",
        "unknown",
    ];
    for (name, t) in levels.iter().zip(by_occlusion) {
        println!("  {name:<17} {}", ratio(t));
    }
    for (w, t) in RANGE_BINS.windows(2).zip(by_range) {
        println!("  {:>2}–{:<2} m           {}", w[0], w[1], ratio(t));
    }
}

/// A recall breakdown as JSON: tallies with their ratios, and the range bins' edges.
pub fn breakdown_json(r: &RecallBreakdown) -> serde_json::Value {
    let tally =
        |t: &Tally| serde_json::json!({"hits": t.hits, "total": t.total, "ratio": t.ratio()});
    serde_json::json!({
        "recall": tally(&r.recall),
        "by_occlusion": r.by_occlusion.iter().map(tally).collect::<Vec<_>>(),
        "by_range": r.by_range.iter().map(tally).collect::<Vec<_>>(),
        "range_bins_m": RANGE_BINS,
    })
}
