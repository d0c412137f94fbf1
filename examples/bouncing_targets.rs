//! The bouncing-target scenarios of the Gaussian-mixture LMB library multisensor-lmb-filters-rs
//! (its `scripts/generate/generate_scenarios.py`): N objects spawned uniformly in
//! [−90, 90]² with velocities N(0, 3²) m/s, moving at constant velocity for 100 steps of 1 s
//! and bouncing off the walls of [−100, 100]²; each is detected with p_D = 0.98 with 1 m
//! position noise, plus 0–2 uniform clutter points per step. Our generator draws from our own
//! random stream (the same distributions, not the same numbers as the Python script).
//!
//! The filter gets the peer's model written as a [`RunConfig`]: constant velocity (σ_a = 0.5),
//! p_S = 0.99, p_D = 0.98, σ = 1 m, clutter rate 1 over 200 m × 200 m, and either its 16 static
//! birth terms (a 4 × 4 grid at ±25, ±75 m; position std 50 m, velocity std 10 m/s;
//! r_B = 0.01) — sampled with the measurement-guided proposal (`static`) or plainly
//! (`static-plain`) — or adaptive birth (λ_B = 1, r_B,max = 0.1, position std 1 m = the
//! measurement noise, velocity std 10 m/s = the static terms' velocity spread).
//!
//! ```text
//! cargo run --release --example bouncing_targets -- --objects 10,20,50 --runs 5 \
//!     --birth static,static-plain,adaptive --particles 1000
//! cargo run --release --example bouncing_targets -- --objects 10 --seed 1 \
//!     --write-json /tmp/bouncing_n10.json   # the scenario in the peer's JSON layout
//! ```
//!
//! Reports mean OSPA (c = 100 m, p = 1) over the 100 steps and the mean and median wall time of
//! `LmbFilter::step`, averaged over the runs (seeds `seed`, `seed + 1`, …).

use anyhow::{Context, Result};
use clap::Parser;
use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};
use smc_lmb::config::{
    BirthConfig, ClutterConfig, DetectionConfig, MeasurementConfig, RunConfig, TransitionConfig,
};
use smc_lmb::filter::{BirthTerm, Frame, LmbConfig, Measurements};
use smc_lmb::metrics::ospa;
use smc_lmb::rng::{seeded, FilterRng};
use std::time::Instant;

const HALF_WIDTH: f64 = 100.0;
const SPAWN_MARGIN: f64 = 10.0;
const INIT_VELOCITY_STD: f64 = 3.0;
const DETECTION: f64 = 0.98;
const NOISE_STD: f64 = 1.0;
const CLUTTER_MAX: u32 = 2;
const STEPS: usize = 100;

#[derive(Parser, Debug)]
#[command(about = "Bouncing-target scenarios through the particle LMB filter")]
struct Args {
    /// Object counts, comma-separated.
    #[arg(long, default_value = "10,20,50", value_delimiter = ',')]
    objects: Vec<usize>,
    /// Births to compare, comma-separated: `static`, `static-plain`, `adaptive`.
    #[arg(
        long,
        default_value = "static,static-plain,adaptive",
        value_delimiter = ','
    )]
    birth: Vec<String>,
    /// Monte-Carlo runs per object count.
    #[arg(long, default_value_t = 1)]
    runs: usize,
    /// Seed of the first run (run i uses seed + i, for the scenario and the filter).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Particles per track and per birth track.
    #[arg(long, default_value_t = 1000)]
    particles: usize,
    /// Write the first object count's scenario (seed `seed`) in the peer's JSON layout and
    /// stop.
    #[arg(long)]
    write_json: Option<std::path::PathBuf>,
    /// Print one JSON object per (objects, birth) instead of a table.
    #[arg(long)]
    json: bool,
}

/// One simulated run: per step the true positions and the measurements.
struct Scenario {
    truth: Vec<Vec<[f64; 2]>>,
    measurements: Vec<Vec<[f64; 2]>>,
}

/// Reflects a coordinate and its velocity off the walls at ±[`HALF_WIDTH`].
fn bounce(p: &mut f64, v: &mut f64) {
    if *p < -HALF_WIDTH {
        *p = -2.0 * HALF_WIDTH - *p;
        *v = -*v;
    } else if *p > HALF_WIDTH {
        *p = 2.0 * HALF_WIDTH - *p;
        *v = -*v;
    }
}

fn generate(objects: usize, seed: u64) -> Scenario {
    let mut rng: FilterRng = seeded(seed);
    let spawn = HALF_WIDTH - SPAWN_MARGIN;
    let mut state: Vec<[f64; 4]> = (0..objects)
        .map(|_| {
            let x = rng.random_range(-spawn..spawn);
            let y = rng.random_range(-spawn..spawn);
            let vx: f64 = StandardNormal.sample(&mut rng);
            let vy: f64 = StandardNormal.sample(&mut rng);
            [x, y, INIT_VELOCITY_STD * vx, INIT_VELOCITY_STD * vy]
        })
        .collect();
    let mut out = Scenario {
        truth: Vec::with_capacity(STEPS),
        measurements: Vec::with_capacity(STEPS),
    };
    for _ in 0..STEPS {
        for s in &mut state {
            s[0] += s[2];
            s[1] += s[3];
            let [x, y, vx, vy] = s;
            bounce(x, vx);
            bounce(y, vy);
        }
        out.truth.push(state.iter().map(|s| [s[0], s[1]]).collect());
        let mut z = Vec::new();
        for s in &state {
            if rng.random::<f64>() < DETECTION {
                let ex: f64 = StandardNormal.sample(&mut rng);
                let ey: f64 = StandardNormal.sample(&mut rng);
                z.push([s[0] + NOISE_STD * ex, s[1] + NOISE_STD * ey]);
            }
        }
        for _ in 0..rng.random_range(0..=CLUTTER_MAX) {
            z.push([
                rng.random_range(-HALF_WIDTH..HALF_WIDTH),
                rng.random_range(-HALF_WIDTH..HALF_WIDTH),
            ]);
        }
        out.measurements.push(z);
    }
    out
}

/// The peer's 16 birth terms: a 4 × 4 grid, position std 50 m, velocity std 10 m/s.
fn static_terms() -> Vec<BirthTerm> {
    let grid = [-75.0, -25.0, 25.0, 75.0];
    grid.iter()
        .flat_map(|&x| {
            grid.iter().map(move |&y| BirthTerm {
                existence: 0.01,
                mean: vec![x, 0.0, y, 0.0],
                std: vec![50.0, 10.0, 50.0, 10.0],
            })
        })
        .collect()
}

fn config(birth: &str, particles: usize, seed: u64) -> Result<RunConfig> {
    let birth = match birth {
        "static" | "static-plain" => BirthConfig::Static {
            terms: static_terms(),
            particles,
            measurement_proposal: birth == "static",
        },
        "adaptive" => BirthConfig::Adaptive {
            expected_births: 1.0,
            max_existence: 0.1,
            particles,
            position_std: NOISE_STD,
            velocity_std: 10.0,
            turn_rate_std: 0.1,
        },
        other => anyhow::bail!("unknown birth `{other}` (static, static-plain or adaptive)"),
    };
    Ok(RunConfig {
        seed,
        survival: 0.99,
        filter: LmbConfig {
            particles,
            ..LmbConfig::default()
        },
        transition: TransitionConfig::ConstantVelocity {
            dims: 2,
            sigma_accel: 0.5,
        },
        measurement: Some(MeasurementConfig::Position { sigma: NOISE_STD }),
        detection: Some(DetectionConfig::Constant {
            probability: DETECTION,
        }),
        clutter: Some(ClutterConfig {
            rate: f64::from(CLUTTER_MAX) / 2.0,
            volume: (2.0 * HALF_WIDTH).powi(2),
        }),
        sensors: Vec::new(),
        fusion: None,
        birth,
        association: Default::default(),
    })
}

/// Mean OSPA over the steps, every step's wall time (ms) and the mean number of tracks kept.
fn run(scenario: &Scenario, cfg: &RunConfig) -> Result<(f64, Vec<f64>, f64)> {
    let mut filter = cfg.build()?;
    let mut rng = seeded(cfg.seed);
    let mut total = 0.0;
    let mut ms = Vec::with_capacity(STEPS);
    let mut tracks = 0;
    for (k, z) in scenario.measurements.iter().enumerate() {
        let frame = Frame::new(k as f64, Measurements::from_rows(2, z)?);
        let t0 = Instant::now();
        let est = filter.step(&frame, &mut rng)?;
        ms.push(t0.elapsed().as_secs_f64() * 1e3);
        tracks += filter.tracks().len();
        let x: Vec<[f64; 2]> = est.iter().map(|e| [e.state[0], e.state[2]]).collect();
        total += ospa(&scenario.truth[k], &x, 100.0, 1.0)?.distance;
    }
    Ok((total / STEPS as f64, ms, tracks as f64 / STEPS as f64))
}

/// The scenario in the layout of the peer's `generate_scenarios.py` (one sensor), with the
/// model it reads and the ground truth.
fn peer_json(s: &Scenario, objects: usize, seed: u64) -> serde_json::Value {
    let grid = [-75.0, -25.0, 25.0, 75.0];
    let births: Vec<[f64; 4]> = grid
        .iter()
        .flat_map(|&x| grid.iter().map(move |&y| [x, y, 0.0, 0.0]))
        .collect();
    let steps: Vec<serde_json::Value> = (0..STEPS)
        .map(|k| {
            serde_json::json!({
                "step": k,
                "object_ids": (0..objects).collect::<Vec<_>>(),
                "ground_truth": s.truth[k],
                "sensor_readings": [s.measurements[k]],
            })
        })
        .collect();
    serde_json::json!({
        "type": "bouncing",
        "measurement_format": "x_y",
        "seed": seed,
        "num_objects": objects,
        "num_sensors": 1,
        "num_steps": STEPS,
        "bounds": [-HALF_WIDTH, HALF_WIDTH, -HALF_WIDTH, HALF_WIDTH],
        "spawn_margin": SPAWN_MARGIN,
        "init_velocity_std": INIT_VELOCITY_STD,
        "model": {
            "dt": 1.0,
            "process_noise_std": 0.5,
            "measurement_noise_std": NOISE_STD,
            "detection_probability": DETECTION,
            "survival_probability": 0.99,
            "clutter_rate": f64::from(CLUTTER_MAX) / 2.0,
            "clutter_min": 0,
            "clutter_max": CLUTTER_MAX,
            "birth_locations": births,
        },
        "steps": steps,
    })
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    match s.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => s[n / 2],
        n => 0.5 * (s[n / 2 - 1] + s[n / 2]),
    }
}

fn main() -> Result<()> {
    let args = Args::parse();
    anyhow::ensure!(args.runs > 0, "--runs must be at least 1");
    anyhow::ensure!(!args.objects.is_empty(), "--objects needs a count");
    if let Some(path) = &args.write_json {
        let n = args.objects[0];
        let text = serde_json::to_string(&peer_json(&generate(n, args.seed), n, args.seed))?;
        std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))?;
        eprintln!("{n} objects, seed {}: {}", args.seed, path.display());
        return Ok(());
    }
    if !args.json {
        println!(
            "| objects | birth | mean OSPA (m) | ms/step mean | ms/step median | tracks kept |"
        );
        println!("|---|---|---|---|---|---|");
    }
    for &n in &args.objects {
        let scenarios: Vec<Scenario> = (0..args.runs)
            .map(|r| generate(n, args.seed + r as u64))
            .collect();
        for birth in &args.birth {
            let mut ospas = Vec::new();
            let mut ms = Vec::new();
            let mut tracks = Vec::new();
            for (r, s) in scenarios.iter().enumerate() {
                let cfg = config(birth, args.particles, args.seed + r as u64)?;
                let (o, t, k) = run(s, &cfg).with_context(|| format!("{n} objects, {birth}"))?;
                ospas.push(o);
                ms.extend(t);
                tracks.push(k);
            }
            if args.json {
                println!(
                    "{}",
                    serde_json::json!({
                        "objects": n, "birth": birth, "runs": args.runs, "seed": args.seed,
                        "particles": args.particles, "threads": rayon::current_num_threads(),
                        "mean_ospa": mean(&ospas), "ospa_per_run": ospas,
                        "ms_per_step_mean": mean(&ms), "ms_per_step_median": median(&ms),
                        "tracks_per_step": mean(&tracks),
                    })
                );
            } else {
                println!(
                    "| {n} | {birth} | {:.2} | {:.2} | {:.2} | {:.1} |",
                    mean(&ospas),
                    mean(&ms),
                    median(&ms),
                    mean(&tracks)
                );
            }
        }
    }
    Ok(())
}
