//! What the WLS scenarios (S11, S13) share: the statistics of a run and the checks of a table
//! of fits against the seeds.

use super::{within_seeds, Spread};
use crate::study::{col, max_abs, Check};
use models::hull::tokyo_maru::L;
use shipsim::results::ResultsTable;

const P_NAMES: [&str; 8] = ["f22", "f23", "f25", "f32", "f33", "f35", "N′", "Y′"];

/// The fits and cycle offsets of one WLS run (S11, S13).
#[derive(Clone, Debug, Default)]
pub(super) struct WlsStats {
    /// Per fit: p̂ (N′, Y′ ×10²), evaluations, Σ|e|² ×10², [Parsons1980, Table 10] code, row.
    pub fits: Vec<([f64; 8], f64, f64, f64, usize)>,
    /// Max |η′| and η′ at the end of each cycle of `lu`.
    pub max_offset: Vec<f64>,
    pub end_offset: Vec<f64>,
    /// Max |δ_c|.
    pub max_command: f64,
}

/// The fits of a run and its offsets per cycle of `lu`, η measured from the track at
/// `eta_offset` [m].
pub(super) fn wls_stats(t: &ResultsTable, eta_offset: f64, lu: f64) -> Result<WlsStats, String> {
    let tp = col(t, "ship.time_prime")?;
    let eta = col(t, "ship.cross_track")?;
    let upd = col(t, "est.updates")?;
    let names = [
        "f22_estimate",
        "f23_estimate",
        "f25_estimate",
        "f32_estimate",
        "f33_estimate",
        "f35_estimate",
        "yaw_moment_prime_estimate",
        "sway_force_prime_estimate",
    ];
    let p: Vec<&[f64]> = names
        .iter()
        .map(|n| col(t, &format!("est.{n}")))
        .collect::<Result<_, _>>()?;
    let (ev, ss, va) = (
        col(t, "est.evaluations")?,
        col(t, "est.residual_sum_of_squares")?,
        col(t, "est.validity")?,
    );
    let mut s = WlsStats {
        max_command: max_abs(col(t, "ctl.rudder_command")?),
        ..Default::default()
    };
    for k in 1..tp.len() {
        if upd[k] > upd[k - 1] {
            let mut v: [f64; 8] = std::array::from_fn(|i| p[i][k]);
            v[6] *= 100.0;
            v[7] *= 100.0;
            s.fits.push((v, ev[k], ss[k] * 100.0, va[k], k));
        }
    }
    let n_cycles = (tp[tp.len() - 1] / lu + 1e-6).floor() as usize;
    for c in 0..n_cycles {
        let (a, b) = (c as f64 * lu - 1e-6, (c + 1) as f64 * lu + 1e-6);
        let mut m = 0.0f64;
        let mut end = 0.0;
        for k in 0..tp.len() {
            if tp[k] >= a && tp[k] <= b {
                let e = (eta[k] + eta_offset) / L;
                if e.abs() > m.abs() {
                    m = e;
                }
                end = e;
            }
        }
        s.max_offset.push(m);
        s.end_offset.push(end);
    }
    Ok(s)
}

/// The overrides of noise seed N: one set of instruments (sensors.seed = est_sensors.seed = N).
pub(super) fn wls_seed(seed: u64) -> Vec<String> {
    vec![
        format!("sensors.seed={seed}"),
        format!("est_sensors.seed={seed}"),
    ]
}

/// One check per parameter: the printed values of the updates `updates` (a row of `printed`
/// per parameter, "" = not compared) within the seeds' ranges; N′, Y′ in the printed scale
/// `ny` = (label, factor from ×10²).
pub(super) fn wls_table_checks(
    c: &mut Vec<Check>,
    id: &str,
    table: &str,
    runs: &[WlsStats],
    printed: &[[&str; 3]; 8],
    updates: &[usize],
    ny: (&str, f64),
) -> Result<(), String> {
    let (ny_label, ny_scale) = ny;
    let n_fits: Vec<usize> = runs.iter().map(|r| r.fits.len()).collect();
    let need = updates.iter().max().map_or(0, |m| m + 1);
    c.push(Check::holds(
        &format!("{id}: fits in every seed (at least one per update compared)"),
        &format!(">= {need} fit(s)"),
        format!(
            "{}..{}",
            n_fits.iter().min().unwrap_or(&0),
            n_fits.iter().max().unwrap_or(&0)
        ),
        n_fits.iter().all(|&n| n >= need),
    ));
    if n_fits.iter().any(|&n| n < need) {
        return Err(format!("{id}: a run without {need} fits"));
    }
    for (i, name) in P_NAMES.iter().enumerate() {
        let (scale, name) = if i >= 6 {
            (ny_scale, format!("{name}{ny_label}"))
        } else {
            (1.0, name.to_string())
        };
        let mut ps = Vec::new();
        let mut ss = Vec::new();
        for &u in updates {
            if printed[i][u].is_empty() {
                continue;
            }
            ps.push(printed[i][u]);
            ss.push(Spread::over(runs, |r| r.fits[u].0[i] * scale));
        }
        let label = if updates.len() > 1 {
            format!(
                "{table} {name}: updates {}",
                updates
                    .iter()
                    .map(|u| (u + 1).to_string())
                    .collect::<Vec<_>>()
                    .join(" / ")
            )
        } else {
            format!("{table} {name}: update {}", updates[0] + 1)
        };
        c.push(within_seeds(&label, &ps, &ss, ""));
    }
    Ok(())
}
