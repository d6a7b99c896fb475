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
    /// N of the geometric sweep (5.1.1); the thesis uses 50.
    #[arg(long, default_value_t = 50)]
    n: usize,
    /// Only these parameter ids (CLa, CLq, CLde, CYb, …, m, Ix, Iy, Iz); default all 25.
    #[arg(long, value_delimiter = ',')]
    params: Vec<String>,
    /// Largest gust amplitude (m/s); the sweep is 1, 2, … this.
    #[arg(long, default_value_t = 20)]
    max_gust: u32,
    /// The wider nonlinear sweep covers τ^this (0 = no wider sweep).
    #[arg(long, default_value_t = 3.0)]
    wide_tau_power: f64,
    /// Threads (default: all cores).
    #[arg(long)]
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
    /// The thesis reproduction (reproduction.json): Table 5.1 etc. with configuration 1.
    Reproduction(Common),
}

#[derive(clap::Args, Clone)]
struct CampaignJobs {
    /// JSON-lines file of jobs (`analysis::native_campaign::Job`).
    #[arg(long)]
    jobs: PathBuf,
    /// JSON-lines file of rows (`analysis::native_campaign::Row`).
    #[arg(long)]
    out: PathBuf,
    /// Threads (default: all cores; 1 for the per-run timing of one core).
    #[arg(long)]
    threads: Option<usize>,
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
        Cmd::Reproduction(c) => {
            let cfg = analysis::reproduction::Config {
                n: c.n.max(2),
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
        let amplitudes: Vec<f64> = (1..=c.max_gust.max(1)).map(f64::from).collect();
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
    cfg.n = c.n.max(2);
    cfg.params = c.params;
    cfg.gust_amplitudes = (1..=c.max_gust.max(1)).map(f64::from).collect();
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
