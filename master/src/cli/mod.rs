pub mod campaign;
pub mod isolate;
pub mod stats;
