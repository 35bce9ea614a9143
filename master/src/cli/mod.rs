pub mod campaign;
pub mod isolate;
pub mod replay;
pub mod stats;
