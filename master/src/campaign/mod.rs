//! Campaigns: many runs of one system over factors, seeds and arms, one KPI row per run.
//!
//! - [`table`]: the run table (typed columns) and its files (CSV, Parquet).

pub mod plot;
pub mod table;
