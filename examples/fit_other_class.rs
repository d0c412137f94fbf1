//! Fits the density of the `Other` class (`smc_lmb::cloud::other_class`) on the KITTI object
//! benchmark's training scans and writes the model the library embeds:
//!
//! ```text
//! cargo run --release --example fit_other_class -- \
//!     --object ../shared/data/kitti_object/training --out src/cloud/other_class.json
//! ```
//!
//! Every scan goes through the tracker's detection (`detect_objects` with
//! `TrackingConfig::default()`, seed 1 per frame). A cluster is an `Other` example when none
//! of its points lies in a labelled box (any type but DontCare) grown by [`MARGIN`], all its
//! points are in front of camera 2 within the image's columns (KITTI labels only what the
//! camera sees), and none of them projects into a DontCare region (unlabelled objects there
//! may be road users). A cluster with at least half of its points in one road user's box is
//! an example of that class (reported, not fitted); the rest are left out.
//!
//! The mixture is fitted by expectation–maximisation from a deterministic start (the examples
//! sorted by height, cut into equal groups), for 1 to [`MAX_K`] components, and the count of
//! least BIC is kept. A small ridge ([`RIDGE`]) on the covariances' diagonals keeps them away
//! from singular on few examples.

use anyhow::{bail, Context, Result};
use clap::Parser;
use nalgebra::{Matrix4, Point3, Vector4};
use smc_lmb::cloud::classes::{default_prior, ClassFeatures, ClassModel, ObjectClass};
use smc_lmb::cloud::other_class::{
    other_features, ComponentFile, OtherDensity, OtherModelFile, OTHER_FEATURE_NAMES,
};
use smc_lmb::kitti::labels::ObjectType;
use smc_lmb::kitti::object::{object_class, ObjectFrames};
use smc_lmb::kitti::tracking::IMAGE_SIZE;
use smc_lmb::pipeline::drive_tracking::{detect_objects, TrackingConfig};
use std::f64::consts::PI;
use std::path::PathBuf;

/// Growth of the label boxes (m) for "in no labelled box": labels are drawn tight and a
/// cluster may take in a few points of the ground or a neighbour beside an object.
const MARGIN: f64 = 0.3;
/// Most mixture components tried.
const MAX_K: usize = 5;
/// Added to the covariances' diagonals (feature units²: ln-sides, m, ln-density).
const RIDGE: f64 = 1e-3;

#[derive(Parser)]
struct Args {
    /// The object benchmark's `training` folder.
    #[arg(long, default_value = "../shared/data/kitti_object/training")]
    object: PathBuf,
    /// Where to write the model (JSON).
    #[arg(long)]
    out: Option<PathBuf>,
}

struct Example {
    features: ClassFeatures,
    z: [f64; 4],
}

fn main() -> Result<()> {
    let args = Args::parse();
    let frames = ObjectFrames::open(&args.object)
        .with_context(|| format!("opening {}", args.object.display()))?;
    let config = TrackingConfig::default();
    let model = ClassModel::default();
    let mut others: Vec<Example> = Vec::new();
    let mut road: Vec<(ObjectClass, ClassFeatures)> = Vec::new();
    let (mut skipped_view, mut skipped_dontcare, mut skipped_partial) = (0, 0, 0);
    let mut total = 0;
    for k in frames.frames()? {
        let cloud = frames.velodyne(k)?;
        let labels = frames.labels(k)?;
        let calib = frames.calib(k)?;
        let rect = calib.rect_from_velo();
        let boxes: Vec<_> = labels
            .iter()
            .filter(|l| l.object_type != ObjectType::DontCare)
            .map(|l| (object_class(l.object_type), l.to_velodyne(&rect).to_box3()))
            .collect();
        let dontcare: Vec<[f64; 4]> = labels
            .iter()
            .filter(|l| l.object_type == ObjectType::DontCare)
            .map(|l| l.bbox)
            .collect();
        let mut rng = smc_lmb::rng::seeded(1);
        let det = detect_objects(&cloud, &config, &mut rng)?;
        let (xs, ys, zs) = (cloud.xs(), cloud.ys(), cloud.zs());
        for c in &det.clusters {
            let Some(shape) = &c.shape else { continue };
            total += 1;
            let mut in_box = vec![0usize; boxes.len()];
            let mut any_in_box = false;
            let mut out_of_view = false;
            let mut in_dontcare = false;
            for &i in &c.indices {
                let i = i as usize;
                let p = Point3::new(xs[i] as f64, ys[i] as f64, zs[i] as f64);
                for (b, (_, bx)) in boxes.iter().enumerate() {
                    if bx.contains(&p, 0.0) {
                        in_box[b] += 1;
                    }
                    any_in_box |= bx.contains(&p, MARGIN);
                }
                match calib.project_to_image2(&p) {
                    Some([u, v]) if (0.0..IMAGE_SIZE[0]).contains(&u) => {
                        in_dontcare |= dontcare
                            .iter()
                            .any(|d| (d[0]..=d[2]).contains(&u) && (d[1]..=d[3]).contains(&v));
                    }
                    _ => out_of_view = true,
                }
            }
            let n = c.indices.len();
            let best = (0..boxes.len()).max_by_key(|&b| in_box[b]);
            if let Some(b) = best.filter(|&b| 2 * in_box[b] >= n) {
                if boxes[b].0.is_road_user() {
                    road.push((boxes[b].0, shape.features));
                } else {
                    skipped_partial += 1;
                }
                continue;
            }
            if any_in_box {
                skipped_partial += 1;
            } else if out_of_view {
                skipped_view += 1;
            } else if in_dontcare {
                skipped_dontcare += 1;
            } else {
                let f = shape.features;
                let unit = model.expected_points([1.0; 3], f.range).ln();
                let z = other_features(f.length, f.width, f.height, (f.points as f64).ln(), unit);
                others.push(Example { features: f, z });
            }
        }
    }
    println!(
        "{total} clusters: {} Other examples, {} in road users' boxes; left out: {skipped_view} \
         out of the camera's view, {skipped_dontcare} in DontCare regions, {skipped_partial} \
         partly in a label box (or in a Misc/Person_sitting/Tram box)",
        others.len(),
        road.len()
    );
    if others.len() < 20 {
        bail!("only {} Other examples", others.len());
    }
    let data: Vec<Vector4<f64>> = others.iter().map(|e| Vector4::from(e.z)).collect();
    for (j, name) in OTHER_FEATURE_NAMES.iter().enumerate() {
        let mut v: Vec<f64> = data.iter().map(|z| z[j]).collect();
        v.sort_by(f64::total_cmp);
        let q = |p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
        println!(
            "{name:>10}: 5% {:7.3}  25% {:7.3}  50% {:7.3}  75% {:7.3}  95% {:7.3}",
            q(0.05),
            q(0.25),
            q(0.5),
            q(0.75),
            q(0.95)
        );
    }

    let mut best: Option<(f64, Vec<ComponentFile>)> = None;
    for k in 1..=MAX_K.min(data.len() / 20) {
        let (comps, ll) = em(&data, k);
        // Free parameters: k−1 weights, 4k means, 10k covariance entries.
        let params = (k - 1 + 14 * k) as f64;
        let bic = params * (data.len() as f64).ln() - 2.0 * ll;
        println!("k = {k}: ln-likelihood {ll:.1}, BIC {bic:.1}");
        if best.as_ref().is_none_or(|(b, _)| bic < *b) {
            best = Some((bic, comps));
        }
    }
    let (_, components) = best.context("no mixture fitted")?;
    println!("kept {} components", components.len());
    for c in &components {
        println!(
            "  weight {:.3} mean [{}] sd [{}]",
            c.weight,
            c.mean.map(|v| format!("{v:.3}")).join(", "),
            (0..4)
                .map(|i| format!("{:.3}", c.covariance[i][i].sqrt()))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let file = OtherModelFile {
        source: format!(
            "KITTI object training scans {} (detect_objects, TrackingConfig::default(), seed 1): \
             clusters in no label box grown by {MARGIN} m, in camera 2's columns, outside \
             DontCare regions",
            args.object.display()
        ),
        examples: data.len(),
        features: OTHER_FEATURE_NAMES.map(String::from).to_vec(),
        components,
    };
    let density = OtherDensity::from_file(&file)?;

    // The per-frame decisions with the uniform and with the fitted Other model, on the
    // fitting scans (in-sample for Other: a check of the fit, not a score).
    let prior = default_prior();
    let decide = |f: &ClassFeatures, learned: Option<&OtherDensity>| -> Result<ObjectClass> {
        let mut ll = model.log_likelihoods(f)?;
        if let Some(d) = learned {
            let unit = model.expected_points([1.0; 3], f.range).ln();
            ll[ObjectClass::Other.index()] =
                d.ln_density(f.length, f.width, f.height, (f.points as f64).ln(), unit);
        }
        let mut b = smc_lmb::cloud::classes::ClassBelief::new(prior)?;
        b.update(&ll, 0.0)?;
        Ok(b.most_likely())
    };
    for (what, learned) in [("uniform Other", None), ("fitted Other", Some(&density))] {
        let mut table = [[0usize; 6]; 6];
        for e in &others {
            table[ObjectClass::Other.index()][decide(&e.features, learned)?.index()] += 1;
        }
        for (c, f) in &road {
            table[c.index()][decide(f, learned)?.index()] += 1;
        }
        println!("{what}: rows label, columns per-frame class (Car Van Truck Ped Cyc Other)");
        for (k, row) in table.iter().enumerate() {
            if row.iter().sum::<usize>() > 0 {
                println!("  {:>10} {:?}", ObjectClass::ALL[k].name(), row);
            }
        }
    }
    for (c, f) in &road {
        println!(
            "  road user {:<10} {:.2} × {:.2} × {:.2} m, {} points at {:.1} m",
            c.name(),
            f.length,
            f.width,
            f.height,
            f.points,
            f.range
        );
    }
    if let Some(out) = &args.out {
        std::fs::write(out, serde_json::to_string_pretty(&file)? + "\n")
            .with_context(|| format!("writing {}", out.display()))?;
        println!("wrote {}", out.display());
    }
    Ok(())
}

fn ln_gauss(z: &Vector4<f64>, mean: &Vector4<f64>, cov: &Matrix4<f64>) -> f64 {
    let Some(ch) = cov.cholesky() else {
        return f64::NEG_INFINITY;
    };
    let d = z - mean;
    let y = ch.solve(&d);
    let ln_det: f64 = 2.0 * ch.l().diagonal().iter().map(|v| v.ln()).sum::<f64>();
    -0.5 * (d.dot(&y) + ln_det + 4.0 * (2.0 * PI).ln())
}

/// EM for a `k`-component full-covariance mixture; the components and the data's
/// ln-likelihood.
fn em(data: &[Vector4<f64>], k: usize) -> (Vec<ComponentFile>, f64) {
    let n = data.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| data[a][2].total_cmp(&data[b][2]).then(a.cmp(&b)));
    let mut resp = vec![vec![0.0; k]; n];
    for (rank, &i) in order.iter().enumerate() {
        resp[i][rank * k / n] = 1.0;
    }
    let mut weights = vec![0.0; k];
    let mut means = vec![Vector4::zeros(); k];
    let mut covs = vec![Matrix4::identity(); k];
    let mut last = f64::NEG_INFINITY;
    let mut ll = last;
    for _ in 0..500 {
        // M step.
        for j in 0..k {
            let nj: f64 = resp.iter().map(|r| r[j]).sum::<f64>().max(1e-9);
            let mean = data
                .iter()
                .zip(&resp)
                .fold(Vector4::zeros(), |m, (z, r)| m + z * r[j])
                / nj;
            let mut cov = data.iter().zip(&resp).fold(Matrix4::zeros(), |c, (z, r)| {
                let d = z - mean;
                c + d * d.transpose() * r[j]
            }) / nj;
            cov += Matrix4::identity() * RIDGE;
            weights[j] = nj / n as f64;
            means[j] = mean;
            covs[j] = cov;
        }
        // E step.
        ll = 0.0;
        for (z, r) in data.iter().zip(resp.iter_mut()) {
            let t: Vec<f64> = (0..k)
                .map(|j| weights[j].ln() + ln_gauss(z, &means[j], &covs[j]))
                .collect();
            let top = t.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            let s: f64 = t.iter().map(|v| (v - top).exp()).sum();
            ll += top + s.ln();
            for j in 0..k {
                r[j] = (t[j] - top).exp() / s;
            }
        }
        if (ll - last).abs() < 1e-8 * ll.abs().max(1.0) {
            break;
        }
        last = ll;
    }
    let comps = (0..k)
        .map(|j| ComponentFile {
            weight: weights[j],
            mean: means[j].into(),
            covariance: std::array::from_fn(|a| std::array::from_fn(|b| covs[j][(a, b)])),
        })
        .collect();
    (comps, ll)
}
