pub mod campaign;
pub mod isolate;
pub mod loop_cmd;
pub mod realtime;
pub mod replay;
pub mod stats;
