//! `analysis` CLI: computes the data of the analysis report (open-loop modes, closed-loop
//! poles, Table 5.1, nonlinear robustness and gust sweeps) into an output folder
//! (`report.json` and CSV files); Python renders the report and its plots.
//!
//! ```text
//! cargo run --release -p analysis -- all --out out/analysis
//! PYTHONPATH=python .venv/bin/python -m tailsim.analysis_report out/analysis
//! ```

use std::path::PathBuf;

use analysis::closed::Condition;
use analysis::controllers::Kind;
use analysis::sweep::{run, Config};
use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "analysis",
    about = "Tail-sitter controller analysis (thesis §3.4.2, §4.4.1, ch. 5 and beyond)"
)]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(clap::Args, Clone)]
struct Common {
    /// Output folder (report.json, CSV, summary.json, cache/).
    #[arg(long, default_value = "out/analysis")]
    out: PathBuf,
    /// N of the geometric sweep (5.1.1), at least 2; the thesis uses 50.
    #[arg(long, default_value_t = 50, value_parser = parse_n, allow_negative_numbers = true)]
    n: usize,
    /// Only these parameter ids (CLa, CLq, CLde, CYb, …, m, Ix, Iy, Iz); default all 25.
    #[arg(long, value_delimiter = ',', value_parser = parse_param_id)]
    params: Vec<String>,
    /// Largest gust amplitude (m/s), at least 1; the sweep is 1, 2, … this.
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..), allow_negative_numbers = true)]
    max_gust: u32,
    /// The wider nonlinear sweep covers τ^this (0 = no wider sweep); finite, ≥ 0.
    #[arg(long, default_value_t = 3.0, value_parser = parse_tau_power, allow_negative_numbers = true)]
    wide_tau_power: f64,
    /// Threads (default: all cores); at least 1.
    #[arg(long, value_parser = parse_threads, allow_negative_numbers = true)]
    threads: Option<usize>,
    /// No progress bars.
    #[arg(long)]
    quiet: bool,
    /// Sensitivity study in level flight only (the thesis's condition).
    #[arg(long)]
    level_only: bool,
}

#[derive(Subcommand)]
enum Cmd {
    /// Everything: modes, poles, Table 5.1, nonlinear robustness, gusts.
    All(Common),
    /// Modes, closed-loop poles and Table 5.1 only (no nonlinear mission sweeps).
    Linear(Common),
    /// Modes, poles, and the nonlinear robustness and gust sweeps (Table 5.1 included).
    Nonlinear(Common),
    /// Only the thesis-vs-global aerodynamic model comparison (aero_models.json), which
    /// `all` and `nonlinear` also write.
    Aero(Common),
    /// The Monte-Carlo campaign's jobs flown natively (`python -m tailsim.campaign_native`
    /// writes them): one JSON job per line in, one JSON row per line out, in job order.
    CampaignJobs(CampaignJobs),
    /// Wind envelope over whole missions (wind_envelope.json, wind_envelope.csv): every
    /// controller, steady wind stepping in and turbulent from the start, every speed and
    /// bearing; perfect state or avionics, Gauss-Seidel or Jacobi, tuned or thesis
    /// configurations (`analysis::wind_envelope`; `--all` the whole grid).
    WindEnvelope(analysis::wind_envelope::Args),
    /// One native flight of the default mission through the atmosphere, as CSV (for the
    /// comparison with the FMU master: tests/test_master_atmosphere.py).
    WindTrace(WindTraceArgs),
    /// The thesis reproduction (reproduction.json): Table 5.1 etc. with configuration 1.
    Reproduction(Common),
}

#[derive(clap::Args, Clone)]
struct WindTraceArgs {
    /// "lqr", "tsd" or "px4".
    #[arg(long, default_value = "tsd")]
    controller: String,
    /// "gauss-seidel" or "jacobi".
    #[arg(long, default_value = "gauss-seidel")]
    ordering: String,
    /// Steady wind speed at the reference height (m/s) and the bearing it comes from (deg).
    #[arg(long, default_value_t = 0.0)]
    speed: f64,
    #[arg(long, default_value_t = 0.0)]
    from_deg: f64,
    /// `wind_profile`, `turbulence_intensity`, `seed`, `origin_height` of the atmosphere.
    #[arg(long, default_value_t = 1)]
    profile: i32,
    #[arg(long, default_value_t = 0)]
    intensity: i32,
    #[arg(long, default_value_t = 1)]
    seed: i32,
    #[arg(long, default_value_t = 0.0)]
    origin_height: f64,
    /// Stop time (s).
    #[arg(long, default_value_t = 5.0)]
    stop: f64,
    /// CSV file.
    #[arg(long)]
    out: PathBuf,
}

fn wind_trace(a: &WindTraceArgs) -> Result<(), String> {
    use closed_loop::Ordering;
    let kind = Kind::ALL
        .into_iter()
        .find(|k| k.name().eq_ignore_ascii_case(&a.controller))
        .ok_or_else(|| format!("controller '{}': lqr, tsd or px4", a.controller))?;
    let ordering = match a.ordering.as_str() {
        "gauss-seidel" => Ordering::GaussSeidel,
        "jacobi" => Ordering::Jacobi,
        other => return Err(format!("ordering '{other}': gauss-seidel or jacobi")),
    };
    let params = atmosphere::Params {
        wind_speed: a.speed,
        wind_from: a.from_deg.to_radians(),
        wind_profile: a.profile,
        turbulence_intensity: a.intensity,
        seed: a.seed,
        origin_height: a.origin_height,
        ..atmosphere::Params::default()
    };
    let csv = analysis::wind_envelope::trace_csv(kind, ordering, params, a.stop)?;
    std::fs::write(&a.out, csv).map_err(|e| format!("{}: {e}", a.out.display()))
}

#[derive(clap::Args, Clone)]
struct CampaignJobs {
    /// JSON-lines file of jobs (`analysis::native_campaign::Job`).
    #[arg(long)]
    jobs: PathBuf,
    /// JSON-lines file of rows (`analysis::native_campaign::Row`).
    #[arg(long)]
    out: PathBuf,
    /// Threads (default: all cores; 1 for the per-run timing of one core); at least 1.
    #[arg(long, value_parser = parse_threads, allow_negative_numbers = true)]
    threads: Option<usize>,
}

/// Smallest N of the geometric sweep (5.1.1): the factors τ^-1 and τ^0 = 1.
const N_MIN: usize = 2;

fn parse_n(s: &str) -> Result<usize, String> {
    let n: usize = s.parse().map_err(|_| format!("expected a whole number ≥ {N_MIN}"))?;
    if n < N_MIN {
        return Err(format!("expected a whole number ≥ {N_MIN}"));
    }
    Ok(n)
}

/// A Table 5.1 parameter id of [`analysis::sensitivity::params`].
fn parse_param_id(s: &str) -> Result<String, String> {
    let ids: Vec<&str> = analysis::sensitivity::params().iter().map(|p| p.id).collect();
    if ids.contains(&s) {
        Ok(s.to_string())
    } else {
        Err(format!("unknown parameter id; known ids: {}", ids.join(", ")))
    }
}

fn parse_tau_power(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        _ => Err("expected a finite number ≥ 0".to_string()),
    }
}

fn parse_threads(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err("expected a whole number ≥ 1".to_string()),
    }
}

fn campaign_jobs(a: &CampaignJobs) -> Result<usize, String> {
    use analysis::native_campaign::{run, Job};
    use rayon::prelude::*;
    use std::io::Write;

    let text = std::fs::read_to_string(&a.jobs).map_err(|e| format!("{}: {e}", a.jobs.display()))?;
    let jobs: Vec<Job> = text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .enumerate()
        .map(|(i, l)| serde_json::from_str(l).map_err(|e| format!("{} line {}: {e}", a.jobs.display(), i + 1)))
        .collect::<Result<_, _>>()?;
    let rows: Vec<String> = jobs
        .par_iter()
        .map(|j| serde_json::to_string(&run(j)).map_err(|e| e.to_string()))
        .collect::<Result<_, _>>()?;
    let mut f =
        std::io::BufWriter::new(std::fs::File::create(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?);
    for r in &rows {
        writeln!(f, "{r}").map_err(|e| e.to_string())?;
    }
    f.flush().map_err(|e| e.to_string())?;
    Ok(rows.len())
}

fn main() {
    let cli = Cli::parse();
    let (c, robustness, gusts, aero_only) = match cli.command {
        Cmd::All(c) => (c, true, true, false),
        Cmd::Linear(c) => (c, false, false, false),
        Cmd::Nonlinear(c) => (c, true, true, false),
        Cmd::Aero(c) => (c, false, false, true),
        Cmd::WindEnvelope(a) => {
            if let Err(e) = analysis::wind_envelope::main(&a) {
                eprintln!("wind envelope failed: {e}");
                std::process::exit(1);
            }
            return;
        }
        Cmd::WindTrace(a) => {
            if let Err(e) = wind_trace(&a) {
                eprintln!("wind trace failed: {e}");
                std::process::exit(1);
            }
            return;
        }
        Cmd::Reproduction(c) => {
            let cfg = analysis::reproduction::Config {
                n: c.n,
                params: c.params,
                mission: Default::default(),
            };
            if let Some(t) = c.threads {
                let _ = rayon::ThreadPoolBuilder::new().num_threads(t).build_global();
            }
            if let Err(e) = analysis::reproduction::run(&c.out, &cfg, !c.quiet) {
                eprintln!("reproduction failed: {e}");
                std::process::exit(1);
            }
            return;
        }
        Cmd::CampaignJobs(a) => {
            if let Some(t) = a.threads {
                let _ = rayon::ThreadPoolBuilder::new().num_threads(t).build_global();
            }
            match campaign_jobs(&a) {
                Ok(n) => eprintln!("wrote {} rows to {}", n, a.out.display()),
                Err(e) => {
                    eprintln!("campaign-jobs failed: {e}");
                    std::process::exit(1);
                }
            }
            return;
        }
    };
    if let Some(t) = c.threads {
        let _ = rayon::ThreadPoolBuilder::new().num_threads(t).build_global();
    }
    if robustness || aero_only {
        // Thesis (aero_model 0) against global (1) aerodynamics: analysis::aero_models.
        let start = std::time::Instant::now();
        let amplitudes: Vec<f64> = (1..=c.max_gust).map(f64::from).collect();
        match analysis::aero_models::run(&c.out, &flight_mission::MissionParams::default(), &amplitudes) {
            Ok(rows) => eprintln!(
                "wrote {}/aero_models.json: {} flights in {:.1} s",
                c.out.display(),
                rows.len(),
                start.elapsed().as_secs_f64()
            ),
            Err(e) => {
                eprintln!("aerodynamic model comparison failed: {e}");
                std::process::exit(1);
            }
        }
        if aero_only {
            return;
        }
    }
    let mut cfg = Config::full(c.out);
    cfg.n = c.n;
    cfg.params = c.params;
    cfg.gust_amplitudes = (1..=c.max_gust).map(f64::from).collect();
    cfg.robustness = robustness;
    cfg.wide_tau_power = c.wide_tau_power;
    cfg.gusts = gusts;
    cfg.progress = !c.quiet;
    cfg.controllers = Kind::ALL.to_vec();
    if c.level_only {
        cfg.conditions = vec![Condition::Level];
    }
    match run(&cfg) {
        Ok(s) => {
            eprintln!(
                "wrote {}/report.json: {} jobs ({} from the cache) in {:.1} s",
                cfg.out.display(),
                s.jobs,
                s.cache_hits,
                s.wall_time_s
            );
        }
        Err(e) => {
            eprintln!("analysis failed: {e}");
            std::process::exit(1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::error::ErrorKind;

    fn parse(args: &[&str]) -> Result<Cli, clap::Error> {
        Cli::try_parse_from(["analysis"].iter().chain(args))
    }

    #[test]
    fn unknown_param_ids_are_refused_with_the_known_ids() {
        let e = parse(&["linear", "--params", "CLa,XYZ"]).err().expect("XYZ refused");
        assert_eq!(e.kind(), ErrorKind::ValueValidation);
        let msg = e.to_string();
        assert!(
            msg.contains("XYZ") && msg.contains("--params") && msg.contains("CLa, CLq"),
            "{msg}"
        );
        assert!(parse(&["linear", "--params", "CLa,Iz"]).is_ok());
    }

    #[test]
    fn numeric_options_are_ranged() {
        for args in [
            ["linear", "--n", "0"],
            ["linear", "--n", "1"],
            ["linear", "--n", "-1"],
            ["linear", "--max-gust", "0"],
            ["linear", "--wide-tau-power", "nan"],
            ["linear", "--wide-tau-power", "-1"],
            ["linear", "--threads", "0"],
        ] {
            let e = parse(&args).err().unwrap_or_else(|| panic!("{args:?} accepted"));
            assert_eq!(e.kind(), ErrorKind::ValueValidation, "{args:?}");
            assert_eq!(e.exit_code(), 2);
        }
        assert!(parse(&["linear", "--n", "2", "--max-gust", "1", "--wide-tau-power", "0"]).is_ok());
    }
}
