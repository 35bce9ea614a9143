pub mod campaign;
pub mod isolate;
pub mod loop_cmd;
pub mod replay;
pub mod stats;
