//! The standard RFS benchmark scenarios (linear: constant velocity with position measurements;
//! nonlinear: coordinated turn with range-bearing measurements) run through the particle LMB
//! filter over Monte-Carlo runs, reporting OSPA, GOSPA, cardinality error and time per step.
//!
//! ```text
//! cargo run --release --example rfs_benchmark -- --scenario nonlinear --runs 20 --seed 1 \
//!     --associator lbp --particles 1000 [--json] [--smooth-lag 5]
//! ```
//!
//! `--smooth-lag L` also scores the fixed-lag smoothed estimates (each step's reported tracks
//! with their states refined by the next L measurements, `filter::FixedLagSmoother`), reported
//! separately from the filter's own.

use anyhow::{Context, Result};
use clap::Parser;
use smc_lmb::filter::association::{AssociationProblem, Marginals};
use smc_lmb::filter::{
    AssociationMethod, Associator, Estimate, FixedLagSmoother, Frame, Jitter, LmbConfig,
    Measurements,
};
use smc_lmb::metrics::{cardinality_error, gospa, ospa};
use smc_lmb::rng::seeded;
use smc_lmb::sim::{DynamicsSpec, Scenario};
use smc_lmb::FilterRng;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

#[derive(Parser, Debug)]
#[command(about = "Standard RFS benchmarks through the particle LMB filter")]
struct Args {
    /// `linear` or `nonlinear`.
    #[arg(long, default_value = "nonlinear")]
    scenario: String,
    /// Monte-Carlo runs.
    #[arg(long, default_value_t = 1)]
    runs: usize,
    /// Seed of the first run (run i uses seed + i).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// `murty`, `gibbs` or `lbp` (optionally with `:N`, e.g. `murty:500`).
    #[arg(long, default_value = "lbp")]
    associator: String,
    /// Particles per track.
    #[arg(long, default_value_t = 1000)]
    particles: usize,
    /// Scale each track's particles with its existence, keeping at least this many
    /// (`LmbConfig::min_particles`; default: every track keeps `--particles`).
    #[arg(long)]
    min_particles: Option<usize>,
    /// Diversity after resampling: `none`, `roughening:K` or `regularised:SCALE`.
    #[arg(long, default_value = "regularised:0.2")]
    jitter: String,
    /// Resample when the effective sample size falls below this fraction of the particles.
    #[arg(long, default_value_t = 0.5)]
    resample_threshold: f64,
    /// Acceleration noise of the filter's motion model (m/s²); default: the scenario's
    /// reference value (5). The truth is generated without noise either way.
    #[arg(long)]
    sigma_accel: Option<f64>,
    /// Print one JSON object instead of tables.
    #[arg(long)]
    json: bool,
    /// Also print where the OSPA comes from: its localisation and cardinality parts, missed
    /// and false objects, the r ≥ 0.5 estimator's OSPA, and how late objects are found.
    #[arg(long)]
    breakdown: bool,
    /// Also score the fixed-lag smoothed estimates with this lag (steps); 0: off.
    #[arg(long, default_value_t = 0)]
    smooth_lag: usize,
    /// Merge duplicate tracks within this squared scaled distance
    /// (`LmbConfig::merge_threshold`); default: no merging.
    #[arg(long)]
    merge: Option<f64>,
}

struct RunResult {
    ospa: Vec<f64>,
    gospa: Vec<f64>,
    card: Vec<f64>,
    ms: Vec<f64>,
    /// Per step: time spent in the associator (summed over its calls, whichever thread), and
    /// the tracks and particles the filter holds after the step.
    association_ms: Vec<f64>,
    tracks: Vec<f64>,
    particles: Vec<f64>,
    /// Where the OSPA comes from (`--breakdown`).
    parts: Breakdown,
    /// Per step: OSPA of the fixed-lag smoothed estimates, its localisation and cardinality
    /// parts (`--smooth-lag`; empty otherwise).
    smoothed: Vec<(f64, f64, f64)>,
}

/// The MAP estimate's OSPA split into its localisation and cardinality parts, GOSPA's missed
/// and false objects, the OSPA of the other common estimator (every track with r ≥ 0.5), and
/// how late objects are first found; summed over steps and objects.
#[derive(Default)]
struct Breakdown {
    ospa_localisation: f64,
    ospa_cardinality: f64,
    missed: f64,
    false_tracks: f64,
    ospa_threshold_estimator: f64,
    steps: usize,
    /// Per truth object: steps from its first appearance until an estimate lies within c/2.
    first_found_delay: Vec<f64>,
    /// Objects never found.
    never_found: usize,
    /// OSPA summed over the steps in which some object is in its first 5 steps.
    ospa_young: f64,
    young_steps: usize,
}

/// An associator that adds the time of every call to a shared counter (nanoseconds).
struct Timed {
    inner: AssociationMethod,
    nanos: Arc<AtomicU64>,
}

impl Associator for Timed {
    fn marginals(&self, problem: &AssociationProblem, rng: &mut FilterRng) -> Marginals {
        let t0 = Instant::now();
        let m = self.inner.marginals(problem, rng);
        let dt = t0.elapsed().as_nanos() as u64;
        self.nanos.fetch_add(dt, Ordering::Relaxed);
        m
    }
}

fn run_once(
    scenario: &Scenario,
    associator: &AssociationMethod,
    config: &LmbConfig,
    seed: u64,
) -> Result<RunResult> {
    let sim = scenario.generate(seed)?;
    let nanos = Arc::new(AtomicU64::new(0));
    let timed = Timed {
        inner: *associator,
        nanos: Arc::clone(&nanos),
    };
    let mut filter = scenario.filter(config.clone(), timed)?;
    let mut rng = seeded(seed ^ 0x5EED);
    let (c, p) = (scenario.ospa_cutoff, scenario.ospa_order);
    let mut out = RunResult {
        ospa: vec![],
        gospa: vec![],
        card: vec![],
        ms: vec![],
        association_ms: vec![],
        tracks: vec![],
        particles: vec![],
        parts: Breakdown::default(),
        smoothed: vec![],
    };
    let lag = config.smoothing_lag;
    let mut smoother = FixedLagSmoother::new(lag);
    let position = |e: &[Estimate]| -> Vec<Vec<f64>> {
        e.iter().map(|e| vec![e.state[0], e.state[2]]).collect()
    };
    let truth_at = |k: usize| -> Vec<Vec<f64>> {
        sim.truth[k].iter().map(|(_, s)| vec![s[0], s[2]]).collect()
    };
    let mut first_seen: std::collections::BTreeMap<u64, (usize, Option<usize>)> =
        Default::default();
    for (k, z) in sim.measurements.iter().enumerate() {
        let frame = Frame::new(k as f64 * scenario.period, Measurements::from_rows(2, z)?);
        let t0 = Instant::now();
        let est = filter.step(&frame, &mut rng)?;
        out.ms.push(t0.elapsed().as_secs_f64() * 1e3);
        out.association_ms
            .push(nanos.swap(0, Ordering::Relaxed) as f64 * 1e-6);
        out.tracks.push(filter.tracks().len() as f64);
        out.particles.push(
            filter
                .tracks()
                .iter()
                .map(|t| t.particles.len() as f64)
                .sum(),
        );
        if lag > 0 {
            if let Some(late) = smoother.push(&filter, est.clone())? {
                let o = ospa(&truth_at(k - lag), &position(&late), c, p)?;
                out.smoothed
                    .push((o.distance, o.localisation, o.cardinality));
            }
        }
        let x = position(&est);
        let truth = truth_at(k);
        let o = ospa(&truth, &x, c, p)?;
        let g = gospa(&truth, &x, c, p)?;
        out.ospa.push(o.distance);
        out.gospa.push(g.distance);
        let b = &mut out.parts;
        b.ospa_localisation += o.localisation;
        b.ospa_cardinality += o.cardinality;
        b.missed += g.n_missed as f64;
        b.false_tracks += g.n_false as f64;
        b.steps += 1;
        let confident: Vec<Vec<f64>> = filter
            .tracks()
            .iter()
            .filter(|t| t.existence >= 0.5)
            .map(|t| {
                let m = t.particles.mean();
                vec![m[0], m[2]]
            })
            .collect();
        b.ospa_threshold_estimator += ospa(&truth, &confident, c, p)?.distance;
        let mut young = false;
        for (id, state) in &sim.truth[k] {
            let entry = first_seen.entry(*id).or_insert((k, None));
            if k < entry.0 + 5 {
                young = true;
            }
            let near = x
                .iter()
                .any(|e| (e[0] - state[0]).hypot(e[1] - state[2]) < c / 2.0);
            if near && entry.1.is_none() {
                entry.1 = Some(k);
            }
        }
        if young {
            b.ospa_young += o.distance;
            b.young_steps += 1;
        }
        out.card
            .push(cardinality_error([(truth.len(), x.len())]).mean);
    }
    if lag > 0 {
        let first = out.smoothed.len();
        for (i, late) in smoother.finish(&filter).iter().enumerate() {
            let o = ospa(&truth_at(first + i), &position(late), c, p)?;
            out.smoothed
                .push((o.distance, o.localisation, o.cardinality));
        }
    }
    for (born, found) in first_seen.values() {
        match found {
            Some(f) => out.parts.first_found_delay.push((f - born) as f64),
            None => out.parts.never_found += 1,
        }
    }
    Ok(out)
}

fn parse_jitter(s: &str) -> Result<Jitter> {
    let (kind, value) = s.split_once(':').unwrap_or((s, ""));
    let num = || {
        value
            .parse::<f64>()
            .with_context(|| format!("--jitter {s}: `{value}` is not a number"))
    };
    Ok(match kind {
        "none" => Jitter::None,
        "roughening" => Jitter::Roughening { k: num()? },
        "regularised" => Jitter::Regularised { scale: num()? },
        _ => anyhow::bail!("--jitter {s}: expected none, roughening:K or regularised:SCALE"),
    })
}

fn print_breakdown(runs: &[RunResult], cutoff: f64) {
    let sum = |f: fn(&Breakdown) -> f64| runs.iter().map(|r| f(&r.parts)).sum::<f64>();
    let steps = sum(|b| b.steps as f64);
    let delays: Vec<f64> = runs
        .iter()
        .flat_map(|r| r.parts.first_found_delay.iter().copied())
        .collect();
    let never: usize = runs.iter().map(|r| r.parts.never_found).sum();
    let young_steps = sum(|b| b.young_steps as f64);
    println!("where the OSPA comes from (MAP estimate, means over steps):");
    println!(
        "  localisation part {:.2} m, cardinality part {:.2} m",
        sum(|b| b.ospa_localisation) / steps,
        sum(|b| b.ospa_cardinality) / steps
    );
    println!(
        "  missed objects {:.3}, false tracks {:.3} per step",
        sum(|b| b.missed) / steps,
        sum(|b| b.false_tracks) / steps
    );
    println!(
        "  estimator r ≥ 0.5 instead of MAP: OSPA {:.2} m",
        sum(|b| b.ospa_threshold_estimator) / steps
    );
    println!(
        "  steps with an object in its first 5 steps: {:.0} % of steps, OSPA {:.2} m there, {:.2} m elsewhere",
        100.0 * young_steps / steps,
        sum(|b| b.ospa_young) / young_steps.max(1.0),
        (runs.iter().flat_map(|r| &r.ospa).sum::<f64>() - sum(|b| b.ospa_young))
            / (steps - young_steps).max(1.0)
    );
    println!(
        "  objects first found within c/2 = {:.0} m after {:.2} steps on average (median {:.1}); never found: {never}",
        cutoff / 2.0,
        mean(&delays),
        median(&delays)
    );
}

/// Mean over every run and step of one part of the smoothed OSPA.
fn smoothed_mean(runs: &[RunResult], part: fn(&(f64, f64, f64)) -> f64) -> f64 {
    let all: Vec<f64> = runs
        .iter()
        .flat_map(|r| r.smoothed.iter().map(part))
        .collect();
    mean(&all)
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    if s.is_empty() {
        return f64::NAN;
    }
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

fn main() -> Result<()> {
    let args = Args::parse();
    let mut scenario = match args.scenario.as_str() {
        "linear" => Scenario::linear(),
        "nonlinear" => Scenario::nonlinear(),
        other => anyhow::bail!("unknown scenario `{other}` (expected linear or nonlinear)"),
    };
    if let Some(s) = args.sigma_accel {
        match &mut scenario.dynamics {
            DynamicsSpec::ConstantVelocity { sigma_accel } => *sigma_accel = s,
            DynamicsSpec::CoordinatedTurn { sigma_vel, .. } => *sigma_vel = s,
        }
    }
    let associator: AssociationMethod = args
        .associator
        .parse()
        .map_err(|e| anyhow::anyhow!("{e}"))
        .context("--associator")?;
    anyhow::ensure!(args.runs > 0, "--runs must be at least 1");
    let config = LmbConfig {
        particles: args.particles,
        min_particles: args.min_particles,
        resample_threshold: args.resample_threshold,
        jitter: parse_jitter(&args.jitter)?,
        prune_threshold: 1e-3,
        max_tracks: 100,
        smoothing_lag: args.smooth_lag,
        merge_threshold: args.merge,
    };
    let mut runs = Vec::with_capacity(args.runs);
    for r in 0..args.runs {
        let res = run_once(&scenario, &associator, &config, args.seed + r as u64)
            .with_context(|| format!("run {r}"))?;
        if !args.json {
            eprintln!(
                "run {r}: mean OSPA {:.2} m, {:.2} ms/step",
                mean(&res.ospa),
                mean(&res.ms)
            );
        }
        runs.push(res);
    }
    let steps = scenario.steps;
    let per_step = |f: fn(&RunResult) -> &Vec<f64>| -> Vec<f64> {
        (0..steps)
            .map(|k| mean(&runs.iter().map(|r| f(r)[k]).collect::<Vec<_>>()))
            .collect()
    };
    let ospa_k = per_step(|r| &r.ospa);
    let gospa_k = per_step(|r| &r.gospa);
    let card_k = per_step(|r| &r.card);
    let all = |f: fn(&RunResult) -> &Vec<f64>| -> Vec<f64> {
        runs.iter().flat_map(|r| f(r).iter().copied()).collect()
    };
    let all_ms = all(|r| &r.ms);
    let assoc_ms = all(|r| &r.association_ms);
    let tracks = all(|r| &r.tracks);
    let particles = all(|r| &r.particles);
    let summary = serde_json::json!({
        "scenario": args.scenario,
        "runs": args.runs,
        "seed": args.seed,
        "associator": args.associator,
        "particles": args.particles,
        "sigma_accel": match scenario.dynamics {
            DynamicsSpec::ConstantVelocity { sigma_accel } => sigma_accel,
            DynamicsSpec::CoordinatedTurn { sigma_vel, .. } => sigma_vel,
        },
        "threads": rayon::current_num_threads(),
        "mean_ospa": mean(&ospa_k),
        "mean_gospa": mean(&gospa_k),
        "mean_card_error": mean(&card_k),
        "ms_per_step_median": median(&all_ms),
        "ms_per_step_mean": mean(&all_ms),
        "association_ms_per_step_median": median(&assoc_ms),
        "association_ms_per_step_mean": mean(&assoc_ms),
        "tracks_per_step": mean(&tracks),
        "particles_per_step": mean(&particles),
        "ospa_per_run": runs.iter().map(|r| mean(&r.ospa)).collect::<Vec<_>>(),
        "smoothing_lag": args.smooth_lag,
        "smoothed_mean_ospa": (args.smooth_lag > 0).then(|| smoothed_mean(&runs, |s| s.0)),
        "smoothed_localisation": (args.smooth_lag > 0).then(|| smoothed_mean(&runs, |s| s.1)),
        "smoothed_cardinality": (args.smooth_lag > 0).then(|| smoothed_mean(&runs, |s| s.2)),
        "ospa_per_step": ospa_k,
    });
    if args.json {
        println!("{summary}");
        return Ok(());
    }
    if args.breakdown {
        print_breakdown(&runs, scenario.ospa_cutoff);
    }
    println!("step  OSPA(m)  GOSPA(m)  |card err|");
    for k in 0..steps {
        println!(
            "{:>4}  {:>7.2}  {:>8.2}  {:>10.2}",
            k + 1,
            ospa_k[k],
            gospa_k[k],
            card_k[k]
        );
    }
    println!(
        "\n{} scenario, {} run(s), {} association, {} particles per track, {} thread(s)",
        args.scenario,
        args.runs,
        args.associator,
        args.particles,
        rayon::current_num_threads()
    );
    println!(
        "mean OSPA (c = {}, p = {}): {:.2} m",
        scenario.ospa_cutoff,
        scenario.ospa_order,
        mean(&ospa_k)
    );
    if args.smooth_lag > 0 {
        println!(
            "fixed-lag smoothed (lag {}): mean OSPA {:.2} m (localisation {:.2} m, cardinality {:.2} m)",
            args.smooth_lag,
            smoothed_mean(&runs, |s| s.0),
            smoothed_mean(&runs, |s| s.1),
            smoothed_mean(&runs, |s| s.2)
        );
    }
    println!("mean GOSPA: {:.2} m", mean(&gospa_k));
    println!("mean |cardinality error|: {:.3}", mean(&card_k));
    println!(
        "time per step: median {:.3} ms, mean {:.3} ms",
        median(&all_ms),
        mean(&all_ms)
    );
    println!(
        "association per step: median {:.3} ms, mean {:.3} ms; {:.1} tracks and {:.0} particles after a step",
        median(&assoc_ms),
        mean(&assoc_ms),
        mean(&tracks),
        mean(&particles)
    );
    Ok(())
}
