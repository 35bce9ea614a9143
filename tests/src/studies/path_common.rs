//! What the two path-control studies of the *Tokyo Maru* ([`super::path_control`] and
//! [`super::path_estimation`]) share: the report's time step and runs stopped at a prime time.

use crate::study::Env;
use shipsim::results::ResultsTable;

/// Δt′ of the report (one communication step).
pub const DT: f64 = 0.005;

/// [`Env::run`] stopped at t′ = `stop_prime` ship lengths (one base step is Δt′ = DT).
pub fn run_until(
    env: &Env,
    file: &str,
    sets: &[String],
    csv: &str,
    stop_prime: f64,
) -> Result<ResultsTable, String> {
    env.run_steps(file, sets, csv, Some((stop_prime / DT).round() as u64))
}
