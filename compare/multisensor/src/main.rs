//! smc-lmb next to multisensor-lmb-filters-rs 0.3.2 on that library's own bouncing-object
//! scenarios (`tests/fixtures/scenario_n*_s*.json` of its crate source, with ground truth).
//!
//! ```text
//! cargo run --release -- [--scenarios n20_s4,n50_s8] [--filters peer-ic,ours-pu-static]
//!                        [--timeout 60] [--threads 1] [--out results.jsonl]
//! ```
//!
//! Every (scenario, filter) pair runs in a child process of this binary (`--one`), so that a
//! run over the time limit (or the memory limit) is stopped and reported as such; the child
//! prints one JSON line per step (wall time of the filter's step, OSPA with c = 5 m, p = 2 and
//! with c = 100 m, p = 1, number of estimates) and the parent averages them. The OSPA of both
//! filters is smc-lmb's own `metrics::ospa` on the estimated (x, y).

mod ours;
mod peer;

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// One scenario file of the peer: truth and every sensor's points, per step.
pub struct Scenario {
    pub name: String,
    pub path: PathBuf,
    pub objects: usize,
    pub sensors: usize,
    pub dt: f64,
    pub process_noise_std: f64,
    pub measurement_noise_std: f64,
    pub detection_probability: f64,
    pub survival_probability: f64,
    pub clutter_rate: f64,
    /// Area of the scene (m²): the clutter's volume.
    pub area: f64,
    /// Birth locations `[x, y, vx, vy]` (the peer's layout).
    pub birth_locations: Vec<[f64; 4]>,
    /// `truth[k]`: true positions at step k.
    pub truth: Vec<Vec<[f64; 2]>>,
    /// `readings[k][s]`: sensor s's points at step k.
    pub readings: Vec<Vec<Vec<[f64; 2]>>>,
}

fn err<E: std::fmt::Display>(context: &str) -> impl FnOnce(E) -> String + '_ {
    move |e| format!("{context}: {e}")
}

fn points(v: &serde_json::Value, what: &str) -> Result<Vec<[f64; 2]>, String> {
    if v.is_null() {
        return Ok(Vec::new());
    }
    serde_json::from_value(v.clone()).map_err(err(what))
}

impl Scenario {
    pub fn load(path: &Path) -> Result<Scenario, String> {
        let ctx = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(err(&ctx))?;
        let v: serde_json::Value = serde_json::from_str(&text).map_err(err(&ctx))?;
        let num = |key: &str| -> Result<f64, String> {
            v["model"][key]
                .as_f64()
                .ok_or_else(|| format!("{ctx}: model.{key} missing"))
        };
        let sensors = v["num_sensors"]
            .as_u64()
            .ok_or_else(|| format!("{ctx}: num_sensors missing"))? as usize;
        let objects = v["num_objects"]
            .as_u64()
            .ok_or_else(|| format!("{ctx}: num_objects missing"))? as usize;
        let b: [f64; 4] =
            serde_json::from_value(v["bounds"].clone()).map_err(err(&format!("{ctx}: bounds")))?;
        let birth_locations: Vec<[f64; 4]> =
            serde_json::from_value(v["model"]["birth_locations"].clone())
                .map_err(err(&format!("{ctx}: model.birth_locations")))?;
        let steps = v["steps"]
            .as_array()
            .ok_or_else(|| format!("{ctx}: steps missing"))?;
        let mut truth = Vec::with_capacity(steps.len());
        let mut readings = Vec::with_capacity(steps.len());
        for (k, s) in steps.iter().enumerate() {
            truth.push(points(
                &s["ground_truth"],
                &format!("{ctx}: steps[{k}].ground_truth"),
            )?);
            let r = &s["sensor_readings"];
            let per_sensor: Vec<Vec<[f64; 2]>> = if r.is_null() {
                vec![Vec::new(); sensors]
            } else {
                let arr = r
                    .as_array()
                    .ok_or_else(|| format!("{ctx}: steps[{k}].sensor_readings not a list"))?;
                if arr.len() != sensors {
                    return Err(format!(
                        "{ctx}: steps[{k}] has readings of {} sensors, num_sensors is {sensors}",
                        arr.len()
                    ));
                }
                arr.iter()
                    .enumerate()
                    .map(|(i, z)| points(z, &format!("{ctx}: steps[{k}].sensor_readings[{i}]")))
                    .collect::<Result<_, _>>()?
            };
            readings.push(per_sensor);
        }
        Ok(Scenario {
            name: path
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("?")
                .trim_start_matches("scenario_")
                .to_string(),
            path: path.to_path_buf(),
            objects,
            sensors,
            dt: num("dt")?,
            process_noise_std: num("process_noise_std")?,
            measurement_noise_std: num("measurement_noise_std")?,
            detection_probability: num("detection_probability")?,
            survival_probability: num("survival_probability")?,
            clutter_rate: num("clutter_rate")?,
            area: (b[1] - b[0]) * (b[3] - b[2]),
            birth_locations,
            truth,
            readings,
        })
    }
}

/// The fixture folder of the peer crate's unpacked source, from `cargo metadata` (the package's
/// `manifest_path`).
fn peer_fixtures() -> Result<PathBuf, String> {
    let manifest = concat!(env!("CARGO_MANIFEST_DIR"), "/Cargo.toml");
    let out = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .args([
            "metadata",
            "--format-version",
            "1",
            "--manifest-path",
            manifest,
        ])
        .stderr(Stdio::inherit())
        .output()
        .map_err(err("cargo metadata"))?;
    if !out.status.success() {
        return Err("cargo metadata failed".into());
    }
    let v: serde_json::Value =
        serde_json::from_slice(&out.stdout).map_err(err("cargo metadata"))?;
    let pkg = v["packages"]
        .as_array()
        .and_then(|ps| {
            ps.iter().find(|p| {
                p["name"] == "multisensor-lmb-filters-rs" && p["version"] == peer::VERSION
            })
        })
        .ok_or("cargo metadata: no package multisensor-lmb-filters-rs")?;
    let path = pkg["manifest_path"]
        .as_str()
        .ok_or("cargo metadata: no manifest_path")?;
    Ok(Path::new(path)
        .parent()
        .ok_or("manifest_path has no parent")?
        .join("tests/fixtures"))
}

/// Scenario files `scenario_n{objects}_s{sensors}.json`, by sensors then objects.
fn scenario_files(dir: &Path) -> Result<Vec<(usize, usize, String, PathBuf)>, String> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).map_err(err(&dir.display().to_string()))? {
        let p = e.map_err(err("read_dir"))?.path();
        let Some(stem) = p.file_stem().and_then(|s| s.to_str()) else {
            continue;
        };
        let Some(rest) = stem.strip_prefix("scenario_n") else {
            continue;
        };
        let Some((n, s)) = rest.split_once("_s") else {
            continue;
        };
        if let (Ok(n), Ok(s)) = (n.parse::<usize>(), s.parse::<usize>()) {
            out.push((s, n, format!("n{n}_s{s}"), p));
        }
    }
    out.sort();
    Ok(out)
}

/// A filter to run: the peer's (by its `bench_utils::create_filter` name) or ours.
#[derive(Clone, Debug, PartialEq)]
pub enum Spec {
    Peer(&'static str),
    Ours {
        rule: ours::Rule,
        birth: ours::Birth,
    },
}

impl Spec {
    fn parse(name: &str) -> Result<Spec, String> {
        let parts: Vec<&str> = name.split('-').collect();
        match parts.as_slice() {
            ["peer", r] => Ok(Spec::Peer(match *r {
                "lmb" => "LMB-LBP",
                "ic" => "IC-LMB-LBP",
                "pu" => "PU-LMB-LBP",
                "ga" => "GA-LMB-LBP",
                "aa" => "AA-LMB-LBP",
                _ => return Err(format!("unknown peer filter `{name}`")),
            })),
            ["ours", r, b @ ..] => Ok(Spec::Ours {
                rule: ours::Rule::parse(r).ok_or_else(|| format!("unknown rule in `{name}`"))?,
                birth: ours::Birth::parse(&b.join("-"))
                    .ok_or_else(|| format!("unknown birth in `{name}`"))?,
            }),
            _ => Err(format!(
                "unknown filter `{name}` (peer-{{lmb,ic,pu,ga,aa}} or \
                 ours-{{single,ic,pu,ga,aa}}-{{static,static-plain,adaptive}})"
            )),
        }
    }

    pub fn name(&self) -> String {
        match self {
            Spec::Peer(p) => format!(
                "peer-{}",
                match *p {
                    "LMB-LBP" => "lmb",
                    "IC-LMB-LBP" => "ic",
                    "PU-LMB-LBP" => "pu",
                    "GA-LMB-LBP" => "ga",
                    _ => "aa",
                }
            ),
            Spec::Ours { rule, birth } => format!("ours-{}-{}", rule.name(), birth.name()),
        }
    }

    /// The default set for a scenario with `sensors` sensors: the peer's four multi-sensor
    /// filters (and its single-sensor LMB with one sensor), ours with every rule and with
    /// static and adaptive birth (and the single-sensor filter with one sensor).
    fn defaults(sensors: usize) -> Vec<Spec> {
        let mut v = Vec::new();
        if sensors == 1 {
            v.push(Spec::Peer("LMB-LBP"));
        }
        for p in ["IC-LMB-LBP", "PU-LMB-LBP", "GA-LMB-LBP", "AA-LMB-LBP"] {
            v.push(Spec::Peer(p));
        }
        let mut rules = Vec::new();
        if sensors == 1 {
            rules.push(ours::Rule::Single);
        }
        rules.extend(
            ours::Rule::FUSED
                .iter()
                .copied()
                .filter(|_| ours::MULTI_SENSOR),
        );
        for birth in [ours::Birth::Static, ours::Birth::Adaptive] {
            for &rule in &rules {
                v.push(Spec::Ours { rule, birth });
            }
        }
        v
    }
}

/// CPU time of this process so far (all its threads), ms.
pub fn cpu_ms() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid timespec to write into; the clock id is a constant of the OS.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        return f64::NAN;
    }
    ts.tv_sec as f64 * 1e3 + ts.tv_nsec as f64 * 1e-6
}

/// Wall and CPU time (ms) of `f`.
pub fn timed<T>(f: impl FnOnce() -> T) -> (T, f64, f64) {
    let c0 = cpu_ms();
    let t0 = std::time::Instant::now();
    let out = f();
    let wall = t0.elapsed().as_secs_f64() * 1e3;
    (out, wall, cpu_ms() - c0)
}

/// What a child reports after each step.
pub struct StepOut {
    /// Wall time of the filter's step, ms.
    pub ms: f64,
    /// CPU time of the process (all threads) during the step, ms.
    pub cpu_ms: f64,
    pub estimates: Vec<[f64; 2]>,
}

/// A filter that steps through a scenario.
pub trait Runner {
    fn step(&mut self, k: usize) -> Result<StepOut, String>;
}

/// Child mode: run one filter on one scenario, one JSON line per step on stdout.
fn run_one(path: &Path, spec: &Spec, seed: u64, tuning: ours::Tuning) -> Result<(), String> {
    let scenario = Scenario::load(path)?;
    let mut runner: Box<dyn Runner + '_> = match spec {
        Spec::Peer(name) => Box::new(peer::PeerRunner::new(path, name)?),
        Spec::Ours { rule, birth } => Box::new(ours::OurRunner::new(
            &scenario, *rule, *birth, seed, tuning,
        )?),
    };
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    writeln!(
        out,
        "{}",
        serde_json::json!({"start": spec.name(), "threads": rayon::current_num_threads()})
    )
    .map_err(err("stdout"))?;
    for k in 0..scenario.truth.len() {
        let s = runner.step(k)?;
        let truth = &scenario.truth[k];
        let o5 = smc_lmb::metrics::ospa(truth, &s.estimates, 5.0, 2.0).map_err(err("ospa"))?;
        let o100 = smc_lmb::metrics::ospa(truth, &s.estimates, 100.0, 1.0).map_err(err("ospa"))?;
        writeln!(
            out,
            "{}",
            serde_json::json!({
                "k": k, "ms": s.ms, "cpu_ms": s.cpu_ms, "ospa_5_2": o5.distance, "ospa_100_1": o100.distance,
                "estimates": s.estimates.len(), "truth": truth.len(),
            })
        )
        .map_err(err("stdout"))?;
        out.flush().map_err(err("stdout"))?;
    }
    Ok(())
}

/// The averages of one (scenario, filter) run.
#[derive(Default, Clone)]
struct Summary {
    steps: usize,
    total_steps: usize,
    ospa5: f64,
    ospa100: f64,
    ms_mean: f64,
    ms_median: f64,
    cpu_mean: f64,
    card_err: f64,
    threads: usize,
    /// Wall time of the whole child process, s.
    elapsed: f64,
    /// `None` when it finished; otherwise why not.
    stopped: Option<String>,
    /// Our filter's settings where they differ from the defaults (e.g. `mode, continuous`);
    /// empty for the defaults and for the peer.
    variant: String,
}

fn summarise(lines: &[serde_json::Value], total_steps: usize) -> Summary {
    let steps: Vec<&serde_json::Value> = lines.iter().filter(|l| l.get("k").is_some()).collect();
    let n = steps.len().max(1) as f64;
    let f = |key: &str| -> Vec<f64> {
        steps
            .iter()
            .map(|l| l[key].as_f64().unwrap_or(f64::NAN))
            .collect()
    };
    let mut ms = f("ms");
    let ms_mean = ms.iter().sum::<f64>() / n;
    ms.sort_by(f64::total_cmp);
    let ms_median = match ms.len() {
        0 => f64::NAN,
        m if m % 2 == 1 => ms[m / 2],
        m => 0.5 * (ms[m / 2 - 1] + ms[m / 2]),
    };
    let card_err = steps
        .iter()
        .map(|l| {
            (l["estimates"].as_f64().unwrap_or(0.0) - l["truth"].as_f64().unwrap_or(0.0)).abs()
        })
        .sum::<f64>()
        / n;
    Summary {
        steps: steps.len(),
        total_steps,
        ospa5: f("ospa_5_2").iter().sum::<f64>() / n,
        ospa100: f("ospa_100_1").iter().sum::<f64>() / n,
        ms_mean,
        ms_median,
        cpu_mean: f("cpu_ms").iter().sum::<f64>() / n,
        card_err,
        threads: lines
            .iter()
            .find_map(|l| l.get("threads").and_then(|t| t.as_u64()))
            .unwrap_or(0) as usize,
        elapsed: f64::NAN,
        stopped: None,
        variant: String::new(),
    }
}

/// Runs one pair in a child process with a time and an address-space limit.
fn run_child(
    path: &Path,
    spec: &Spec,
    total_steps: usize,
    opts: &Opts,
) -> Result<(Summary, Vec<serde_json::Value>), String> {
    let exe = std::env::current_exe().map_err(err("current_exe"))?;
    let mut cmd = Command::new("sh");
    cmd.arg("-c")
        .arg(format!(
            "ulimit -v {} && exec \"$0\" \"$@\"",
            opts.mem_gb * 1024 * 1024
        ))
        .arg(&exe)
        .arg("--one")
        .arg(path)
        .arg(spec.name())
        .arg("--seed")
        .arg(opts.seed.to_string())
        .arg("--particles")
        .arg(opts.tuning.particles.to_string())
        .arg("--estimate")
        .arg(opts.tuning.estimator.name())
        .arg("--motion")
        .arg(opts.tuning.motion.name())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    if let Some(m) = opts.tuning.birth_particles {
        cmd.arg("--birth-particles").arg(m.to_string());
    }
    if let Some(m) = opts.tuning.min_particles {
        cmd.arg("--min-particles").arg(m.to_string());
    }
    if let Some(t) = opts.threads {
        cmd.env("RAYON_NUM_THREADS", t.to_string());
    }
    let mut child = cmd.spawn().map_err(err("spawn"))?;
    let stdout = child.stdout.take().expect("piped");
    let stderr = child.stderr.take().expect("piped");
    let reader = std::thread::spawn(move || {
        BufReader::new(stdout)
            .lines()
            .map_while(Result::ok)
            .filter_map(|l| serde_json::from_str::<serde_json::Value>(&l).ok())
            .collect::<Vec<_>>()
    });
    let err_reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = std::io::Read::read_to_string(&mut BufReader::new(stderr), &mut s);
        s
    });
    let t0 = Instant::now();
    let limit = Duration::from_secs_f64(opts.timeout);
    let mut timed_out = false;
    let status = loop {
        if let Some(st) = child.try_wait().map_err(err("wait"))? {
            break st;
        }
        if t0.elapsed() > limit {
            timed_out = true;
            let _ = child.kill();
            break child.wait().map_err(err("wait"))?;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let lines = reader.join().unwrap_or_default();
    let stderr_text = err_reader.join().unwrap_or_default();
    let mut s = summarise(&lines, total_steps);
    s.elapsed = t0.elapsed().as_secs_f64();
    if timed_out {
        s.stopped = Some(format!("timeout ({} s)", opts.timeout));
    } else if !status.success() || s.steps < total_steps {
        let last = stderr_text
            .lines()
            .rev()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("");
        let why = if stderr_text.contains("memory allocation")
            || stderr_text.contains("capacity overflow")
        {
            format!(
                "out of memory ({} GB limit, after {:.0} s)",
                opts.mem_gb,
                t0.elapsed().as_secs_f64()
            )
        } else {
            format!("failed: {}", last.trim())
        };
        s.stopped = Some(why);
    }
    Ok((s, lines))
}

struct Opts {
    scenarios: Option<Vec<String>>,
    filters: Option<Vec<String>>,
    timeout: f64,
    mem_gb: u64,
    threads: Option<usize>,
    seed: u64,
    tuning: ours::Tuning,
    out: Option<PathBuf>,
    fixtures: Option<PathBuf>,
    /// Results of earlier runs (`--out` files) to put in the table too.
    from: Vec<PathBuf>,
    /// Only print the table of the `--from` files.
    table_only: bool,
    /// Print one row per (scenario, filter) instead of one per (scenario, rule).
    rows: bool,
}

fn parse_args() -> Result<(Opts, Option<(PathBuf, String)>), String> {
    let mut o = Opts {
        scenarios: None,
        filters: None,
        timeout: 60.0,
        mem_gb: 8,
        threads: None,
        seed: 42,
        tuning: ours::Tuning {
            particles: ours::PARTICLES,
            min_particles: None,
            estimator: ours::Estimator::Mean,
            motion: ours::Motion::Discrete,
            birth_particles: None,
        },
        out: None,
        fixtures: None,
        from: Vec::new(),
        table_only: false,
        rows: false,
    };
    let mut one = None;
    let mut args = std::env::args().skip(1);
    let list = |s: String| {
        s.split(',')
            .map(str::to_string)
            .filter(|s| !s.is_empty())
            .collect()
    };
    while let Some(a) = args.next() {
        let mut val = || args.next().ok_or_else(|| format!("{a} needs a value"));
        match a.as_str() {
            "--scenarios" => o.scenarios = Some(list(val()?)),
            "--filters" => o.filters = Some(list(val()?)),
            "--timeout" => o.timeout = val()?.parse().map_err(err("--timeout"))?,
            "--mem-gb" => o.mem_gb = val()?.parse().map_err(err("--mem-gb"))?,
            "--threads" => o.threads = Some(val()?.parse().map_err(err("--threads"))?),
            "--seed" => o.seed = val()?.parse().map_err(err("--seed"))?,
            "--particles" => o.tuning.particles = val()?.parse().map_err(err("--particles"))?,
            "--min-particles" => {
                o.tuning.min_particles = Some(val()?.parse().map_err(err("--min-particles"))?)
            }
            "--estimate" => {
                let v = val()?;
                o.tuning.estimator = ours::Estimator::parse(&v)
                    .ok_or_else(|| format!("--estimate: `{v}` is not mean or mode"))?
            }
            "--motion" => {
                let v = val()?;
                o.tuning.motion = ours::Motion::parse(&v)
                    .ok_or_else(|| format!("--motion: `{v}` is not discrete or continuous"))?
            }
            "--birth-particles" => {
                o.tuning.birth_particles = Some(val()?.parse().map_err(err("--birth-particles"))?)
            }
            "--rows" => o.rows = true,
            "--out" => o.out = Some(val()?.into()),
            "--fixtures" => o.fixtures = Some(val()?.into()),
            "--from" => o.from.push(val()?.into()),
            "--table-only" => o.table_only = true,
            "--one" => {
                let p = val()?;
                let f = args.next().ok_or("--one needs a scenario and a filter")?;
                one = Some((PathBuf::from(p), f));
            }
            "-h" | "--help" => {
                println!(
                    "multisensor-compare [--scenarios n5_s2,...] [--filters peer-ic,ours-pu-static,...]\n\
                     \x20   [--timeout SECONDS (60)] [--mem-gb GB (8)] [--threads N (RAYON_NUM_THREADS of our filter)]\n\
                     \x20   [--seed 42] [--particles 1000] [--min-particles N] [--birth-particles N] [--estimate mean|mode] [--motion discrete|continuous]\n\
                     \x20   [--out results.jsonl] [--fixtures DIR] [--from earlier.jsonl ...] [--table-only] [--rows]\n\
                     filters: peer-{{lmb,ic,pu,ga,aa}}, ours-{{single,ic,pu,ga,aa}}-{{static,static-plain,adaptive}}"
                );
                std::process::exit(0);
            }
            other => return Err(format!("unknown argument `{other}`")),
        }
    }
    Ok((o, one))
}

fn cell(s: &Summary) -> (String, String, String) {
    match &s.stopped {
        None => (
            format!("{:.3}", s.ospa5),
            format!("{:.2}", s.ospa100),
            format!("{:.1} / {:.1}", s.ms_mean, s.cpu_mean),
        ),
        Some(why) => (
            why.clone(),
            format!("({}/{} steps)", s.steps, s.total_steps),
            if s.steps > 0 {
                format!("({:.0} / {:.0} over those)", s.ms_mean, s.cpu_mean)
            } else {
                "–".into()
            },
        ),
    }
}

fn main() {
    if let Err(e) = real_main() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn real_main() -> Result<(), String> {
    let (opts, one) = parse_args()?;
    if let Some((path, filter)) = one {
        return run_one(&path, &Spec::parse(&filter)?, opts.seed, opts.tuning);
    }
    let mut results: BTreeMap<(usize, usize), Vec<(Spec, Summary)>> = BTreeMap::new();
    for p in &opts.from {
        let text = std::fs::read_to_string(p).map_err(err(&p.display().to_string()))?;
        for line in text.lines().filter(|l| !l.trim().is_empty()) {
            let v: serde_json::Value =
                serde_json::from_str(line).map_err(err(&p.display().to_string()))?;
            let g = |k: &str| v[k].as_f64().unwrap_or(f64::NAN);
            let key = (
                v["sensors"].as_u64().unwrap_or(0) as usize,
                v["objects"].as_u64().unwrap_or(0) as usize,
            );
            let spec = Spec::parse(v["filter"].as_str().unwrap_or(""))?;
            let s = Summary {
                steps: g("steps") as usize,
                total_steps: g("total_steps") as usize,
                ospa5: g("ospa_5_2"),
                ospa100: g("ospa_100_1"),
                ms_mean: g("ms_per_step_mean"),
                ms_median: g("ms_per_step_median"),
                cpu_mean: g("cpu_ms_per_step_mean"),
                card_err: g("card_abs_err"),
                threads: g("threads") as usize,
                elapsed: g("elapsed_s"),
                stopped: v["stopped"].as_str().map(str::to_string),
                variant: match spec {
                    Spec::Peer(_) => String::new(),
                    Spec::Ours { .. } => variant_of(&v),
                },
            };
            let runs = results.entry(key).or_default();
            runs.retain(|(sp, r)| sp != &spec || r.variant != s.variant);
            runs.push((spec, s));
        }
    }
    if opts.table_only {
        print(&results, opts.rows);
        return Ok(());
    }
    let dir = match &opts.fixtures {
        Some(d) => d.clone(),
        None => peer_fixtures()?,
    };
    eprintln!("peer fixtures: {}", dir.display());
    let mut files = scenario_files(&dir)?;
    if let Some(want) = &opts.scenarios {
        for w in want {
            if !files.iter().any(|f| &f.2 == w) {
                return Err(format!("no scenario {w} in {}", dir.display()));
            }
        }
        files.retain(|f| want.contains(&f.2));
    }
    let wanted: Option<Vec<Spec>> = opts
        .filters
        .as_ref()
        .map(|fs| fs.iter().map(|f| Spec::parse(f)).collect::<Result<_, _>>())
        .transpose()?;
    let mut out_file = match &opts.out {
        Some(p) => Some(std::fs::File::create(p).map_err(err(&p.display().to_string()))?),
        None => None,
    };
    for (sensors, objects, name, path) in &files {
        let scenario = Scenario::load(path)?;
        let specs = wanted.clone().unwrap_or_else(|| Spec::defaults(*sensors));
        for spec in specs {
            let (mut s, _) = run_child(path, &spec, scenario.truth.len(), &opts)?;
            if let Spec::Ours { .. } = spec {
                s.variant = variant_of(&serde_json::json!({
                    "particles": opts.tuning.particles,
                    "min_particles": opts.tuning.min_particles,
                    "estimate": opts.tuning.estimator.name(),
                    "motion": opts.tuning.motion.name(),
                    "birth_particles": opts.tuning.birth_particles,
                }));
            }
            let (a, b, c) = cell(&s);
            eprintln!(
                "{name} {:<26} OSPA(5,2) {a}  OSPA(100,1) {b}  ms/step wall/CPU {c} (wall median {:.2})  |n̂−n| {:.2}  threads {}",
                spec.name(),
                s.ms_median,
                s.card_err,
                s.threads
            );
            if let Some(f) = out_file.as_mut() {
                writeln!(
                    f,
                    "{}",
                    serde_json::json!({
                        "scenario": name, "objects": objects, "sensors": sensors,
                        "filter": spec.name(), "steps": s.steps, "total_steps": s.total_steps,
                        "ospa_5_2": s.ospa5, "ospa_100_1": s.ospa100,
                        "ms_per_step_mean": s.ms_mean, "ms_per_step_median": s.ms_median,
                        "cpu_ms_per_step_mean": s.cpu_mean,
                        "card_abs_err": s.card_err, "threads": s.threads, "elapsed_s": s.elapsed,
                        "stopped": s.stopped, "seed": opts.seed,
                        "particles": opts.tuning.particles,
                        "min_particles": opts.tuning.min_particles,
                        "estimate": opts.tuning.estimator.name(),
                        "motion": opts.tuning.motion.name(),
                        "birth_particles": opts.tuning.birth_particles,
                    })
                )
                .map_err(err("--out"))?;
            }
            let runs = results.entry((*sensors, *objects)).or_default();
            runs.retain(|(sp, r)| sp != &spec || r.variant != s.variant);
            runs.push((spec, s));
        }
    }
    print(&results, opts.rows);
    Ok(())
}

/// Our settings of a result line (`--out` file) that differ from the defaults, for the name
/// of its row: `mode`, `continuous`, `N particles`, `min N`, `birth N`.
fn variant_of(v: &serde_json::Value) -> String {
    let mut parts = Vec::new();
    if let Some(e) = v["estimate"].as_str().filter(|e| *e != "mean") {
        parts.push(e.to_string());
    }
    if let Some(m) = v["motion"].as_str().filter(|m| *m != "discrete") {
        parts.push(m.to_string());
    }
    if let Some(p) = v["particles"]
        .as_u64()
        .filter(|&p| p != ours::PARTICLES as u64)
    {
        parts.push(format!("{p} particles"));
    }
    if let Some(m) = v["min_particles"].as_u64() {
        parts.push(format!("min {m}"));
    }
    if let Some(b) = v["birth_particles"].as_u64() {
        parts.push(format!("birth {b}"));
    }
    parts.join(", ")
}

fn print(results: &BTreeMap<(usize, usize), Vec<(Spec, Summary)>>, rows: bool) {
    if rows {
        print_rows(results)
    } else {
        print_table(results)
    }
}

/// The order of the rows of a scenario: the peer's filters, then ours by birth and rule.
fn row_order(s: &Spec) -> (usize, usize, usize) {
    use ours::{Birth, Rule};
    let rule = |r: Rule| match r {
        Rule::Single => 0,
        Rule::IteratedCorrector => 1,
        Rule::ParallelUpdate => 2,
        Rule::GeometricAverage => 3,
        Rule::ArithmeticAverage => 4,
    };
    match s {
        Spec::Peer(p) => (
            0,
            0,
            [
                "LMB-LBP",
                "IC-LMB-LBP",
                "PU-LMB-LBP",
                "GA-LMB-LBP",
                "AA-LMB-LBP",
            ]
            .iter()
            .position(|q| q == p)
            .unwrap_or(5),
        ),
        Spec::Ours { rule: r, birth } => (
            1,
            match birth {
                Birth::Static => 0,
                Birth::StaticPlain => 1,
                Birth::Adaptive => 2,
            },
            rule(*r),
        ),
    }
}

/// One row per (scenario, filter): mean OSPA (5 m, p 2), mean OSPA (100 m, p 1), mean
/// |cardinality error|, wall and CPU ms per step, status (a stopped run's means are over the
/// steps it finished).
fn print_rows(results: &BTreeMap<(usize, usize), Vec<(Spec, Summary)>>) {
    println!("| scenario | filter | OSPA (5 m, p 2) | OSPA (100 m, p 1) | mean abs. cardinality error | wall ms/step | CPU ms/step | status |");
    println!("|---|---|---|---|---|---|---|---|");
    for (&(sensors, objects), runs) in results {
        let mut runs: Vec<&(Spec, Summary)> = runs.iter().collect();
        runs.sort_by_key(|(s, r)| (row_order(s), r.variant.clone()));
        for (spec, s) in runs {
            let status = match &s.stopped {
                None => "done".to_string(),
                Some(why) => format!("{why}, {}/{} steps", s.steps, s.total_steps),
            };
            let name = if s.variant.is_empty() {
                spec.name()
            } else {
                format!("{} ({})", spec.name(), s.variant)
            };
            if s.steps == 0 {
                println!("| n{objects}_s{sensors} | {name} | – | – | – | – | – | {status} |");
                continue;
            }
            println!(
                "| n{objects}_s{sensors} | {name} | {:.3} | {:.2} | {:.2} | {:.1} | {:.1} | {status} |",
                s.ospa5,
                s.ospa100,
                s.card_err,
                s.ms_mean,
                s.cpu_mean
            );
        }
    }
}

/// One row per (scenario, rule): the peer's filter, ours with static birth, ours with adaptive
/// birth; each OSPA(5 m, 2), OSPA(100 m, 1) and ms per step.
fn print_table(results: &BTreeMap<(usize, usize), Vec<(Spec, Summary)>>) {
    use ours::{Birth, Rule};
    println!(
        "| objects | sensors | rule | peer OSPA₅,₂ | peer OSPA₁₀₀,₁ | peer ms wall / CPU | ours static OSPA₅,₂ | OSPA₁₀₀,₁ | ms wall / CPU | ours adaptive OSPA₅,₂ | OSPA₁₀₀,₁ | ms wall / CPU |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    let rules: [(&str, Option<&str>, Option<Rule>); 5] = [
        ("single", Some("LMB-LBP"), Some(Rule::Single)),
        ("IC", Some("IC-LMB-LBP"), Some(Rule::IteratedCorrector)),
        ("PU", Some("PU-LMB-LBP"), Some(Rule::ParallelUpdate)),
        ("GA", Some("GA-LMB-LBP"), Some(Rule::GeometricAverage)),
        ("AA", Some("AA-LMB-LBP"), Some(Rule::ArithmeticAverage)),
    ];
    for (&(sensors, objects), runs) in results {
        for (label, peer, rule) in rules {
            // The defaults' run when there is one, else the first of the variants.
            let find = |want: &Spec| {
                runs.iter()
                    .filter(|(s, _)| s == want)
                    .min_by_key(|(_, r)| !r.variant.is_empty())
                    .map(|(_, r)| cell(r))
            };
            let p = peer.and_then(|p| find(&Spec::Peer(p)));
            let st = rule.and_then(|rule| {
                find(&Spec::Ours {
                    rule,
                    birth: Birth::Static,
                })
            });
            let ad = rule.and_then(|rule| {
                find(&Spec::Ours {
                    rule,
                    birth: Birth::Adaptive,
                })
            });
            if p.is_none() && st.is_none() && ad.is_none() {
                continue;
            }
            let dash = || ("–".to_string(), "–".to_string(), "–".to_string());
            let (p, st, ad) = (
                p.unwrap_or_else(dash),
                st.unwrap_or_else(dash),
                ad.unwrap_or_else(dash),
            );
            println!(
                "| {objects} | {sensors} | {label} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                p.0, p.1, p.2, st.0, st.1, st.2, ad.0, ad.1, ad.2
            );
        }
    }
}
