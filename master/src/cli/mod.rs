pub mod campaign;
pub mod stats;
