//! How strong the moderate Dryden turbulence of the wind envelope is where the aircraft flies
//! (a development probe for the LQR's turbulent cells):
//! `lqrturb_gust_wind lqr|tsd default|tl|handover SPEEDS [BEARING_INDICES]`.
//!
//! Per turbulent cell: the wind met along the flown path (the trace's wind at the aircraft),
//! its RMS and largest horizontal magnitude, the largest 5 s vector mean of the horizontal
//! wind (what a slow controller sees as a steady wind), the phase and time of the largest
//! error, and whether the cell is held.
use analysis::controllers::Kind;
use analysis::wind_envelope::{fly_job, Job, MissionKind, WindForm, BEARINGS_DEG};
use rayon::prelude::*;

/// Window of the moving vector mean of the horizontal wind (s).
const MEAN_WINDOW: f64 = 5.0;

/// Wind statistics of one trace (CSV of `fly_job`): (RMS |w_h|, max |w_h|, max |5 s mean w_h|,
/// phase and time of the largest error).
fn stats(csv: &str) -> Option<(f64, f64, f64, i32, f64)> {
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next()?.split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name);
    let (it, ip, ie, iwn, iwe) = (col("t")?, col("phase")?, col("error")?, col("wind_n")?, col("wind_e")?);
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap_or(f64::NAN)).collect())
        .collect();
    if rows.len() < 2 {
        return None;
    }
    let dt = rows[1][it] - rows[0][it];
    let n = ((MEAN_WINDOW / dt).round() as usize).clamp(1, rows.len());
    let (mut sum_sq, mut max_h) = (0.0_f64, 0.0_f64);
    let (mut acc_n, mut acc_e, mut max_mean) = (0.0, 0.0, 0.0_f64);
    let (mut worst, mut worst_phase, mut worst_t) = (f64::NEG_INFINITY, 0, 0.0);
    for (i, r) in rows.iter().enumerate() {
        let h = r[iwn].hypot(r[iwe]);
        sum_sq += h * h;
        max_h = max_h.max(h);
        acc_n += r[iwn];
        acc_e += r[iwe];
        if i >= n {
            acc_n -= rows[i - n][iwn];
            acc_e -= rows[i - n][iwe];
        }
        if i + 1 >= n {
            max_mean = max_mean.max(acc_n.hypot(acc_e) / n as f64);
        }
        if r[ie] > worst {
            (worst, worst_phase, worst_t) = (r[ie], r[ip] as i32, r[it]);
        }
    }
    Some((
        (sum_sq / rows.len() as f64).sqrt(),
        max_h,
        max_mean,
        worst_phase,
        worst_t,
    ))
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 4 {
        eprintln!("usage: lqrturb_gust_wind lqr|tsd default|tl|handover SPEEDS [BEARING_INDICES]");
        std::process::exit(2);
    }
    let kind = if a[1] == "lqr" { Kind::Lqr } else { Kind::Tsd };
    let mission = match a[2].as_str() {
        "default" => MissionKind::Default,
        "tl" => MissionKind::TakeoffLanding,
        _ => MissionKind::Handover,
    };
    let speeds: Vec<f64> = a[3].split(',').map(|s| s.parse().expect("speed")).collect();
    let bearings: Vec<usize> = match a.get(4) {
        Some(b) if b != "all" => b.split(',').map(|s| s.parse().expect("bearing index")).collect(),
        _ => (0..BEARINGS_DEG.len()).collect(),
    };
    let jobs: Vec<(f64, usize)> = speeds
        .iter()
        .flat_map(|&s| bearings.iter().map(move |&b| (s, b)))
        .collect();
    let dir = std::env::temp_dir();
    let rows: Vec<String> = jobs
        .par_iter()
        .map(|&(s, b)| {
            let path = dir.join(format!("lqrturb_gust_wind_{}_{s}_{b}.csv", std::process::id()));
            let path = path.to_string_lossy().into_owned();
            let (cell, _) = fly_job(&Job::new(kind, mission, WindForm::Turbulent, s, b), Some(&path));
            let text = std::fs::read_to_string(&path).unwrap_or_default();
            let _ = std::fs::remove_file(&path);
            match stats(&text) {
                Some((rms, max_h, mean5, phase, t)) => format!(
                    "{s:>4} m/s {:>5}°  wind rms {rms:4.1}  max {max_h:4.1}  max 5-s mean {mean5:4.1} m/s  \
                     held {:5}  max error {:6.2} m in phase {phase} at {t:6.2} s",
                    BEARINGS_DEG[b], cell.held, cell.max_error
                ),
                None => format!("{s:>4} m/s {:>5}°  no trace", BEARINGS_DEG[b]),
            }
        })
        .collect();
    for r in rows {
        println!("{r}");
    }
}
