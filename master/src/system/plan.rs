//! The validated, resolved form of a [`System`](super::System): everything the master needs,
//! by instance index and value reference, produced by [`System::validate`](super::System::validate).

use super::{Algorithm, TypedValue};
use crate::fmu::VR;
use crate::model_description::VarType;
use std::path::PathBuf;

/// A start/parameter value to apply before or during initialization.
#[derive(Debug, Clone)]
pub struct StartValue {
    pub vr: VR,
    pub value: TypedValue,
    /// Settable in "Instantiated" (else in "InitializationMode"), FMI 2.0 section 4.2.4.
    pub before_init: bool,
    pub variable: String,
}

#[derive(Debug, Clone)]
pub struct PlanInstance {
    pub name: String,
    pub step_multiple: u32,
    pub start_values: Vec<StartValue>,
    /// Out of process whatever the run's option ([`InstanceSpec::isolate`](super::InstanceSpec::isolate)).
    pub isolate: bool,
}

/// A checked connection, by instance index and value reference.
#[derive(Debug, Clone)]
pub struct PlanConnection {
    pub from_instance: usize,
    pub from_vr: VR,
    pub to_instance: usize,
    pub to_vr: VR,
    pub var_type: VarType,
    pub gain: f64,
    pub offset: f64,
    pub name: String,
    /// A term of a summed input ([`ConnectionSpec::sum`](super::ConnectionSpec::sum)): the
    /// input gets the sum of its connections' terms, added in plan order.
    pub sum: bool,
    /// The value mapping of an Integer or Boolean connection (SSP mapping transformations).
    pub mapping: Option<super::ValueMapping>,
}

#[derive(Debug, Clone)]
pub struct PlanEvent {
    /// Applied before the step that starts at t_k = t0 + k*h.
    pub step: u64,
    pub instance: usize,
    pub vr: VR,
    pub value: TypedValue,
    pub name: String,
}

#[derive(Debug, Clone)]
pub struct PlanOutput {
    pub instance: usize,
    pub vr: VR,
    pub var_type: VarType,
    pub header: String,
}

/// Everything the master needs, resolved to indices and value references before the first step.
#[derive(Debug, Clone)]
pub struct Plan {
    pub start_time: f64,
    pub step_size: f64,
    /// Number of base steps: the run ends at t0 + n_steps*h.
    pub n_steps: u64,
    pub stop_time: f64,
    /// Set when the stop time asked for is off the base-step grid: the run then ends at the last
    /// grid point before it (`stop_time` is that point) or with a short last step to it
    /// (`stop_time` is the one asked for and step n_steps is the short one).
    pub off_grid: Option<super::OffGrid>,
    pub algorithm: Algorithm,
    pub instances: Vec<PlanInstance>,
    /// Stepping order (Gauss-Seidel: connection order; Jacobi: file order).
    pub order: Vec<usize>,
    pub connections: Vec<PlanConnection>,
    pub events: Vec<PlanEvent>,
    pub outputs: Vec<PlanOutput>,
    pub output_file: Option<PathBuf>,
    pub decimation: u32,
    pub warnings: Vec<String>,
}
