//! The fixed-step master: initialization, Jacobi and Gauss-Seidel stepping, multi-rate, events,
//! recording, clean termination on every path.
//!
//! Calling sequence per instance (FMI 2.0 section 4.2.4): fmi2Instantiate -> fmi2SetXXX
//! (variables settable in "Instantiated") -> fmi2SetupExperiment -> fmi2EnterInitializationMode
//! -> fmi2SetXXX (settable in "InitializationMode") -> exchange of connected values, repeated
//! once per instance so initial values propagate along chains (as libcosim does) ->
//! fmi2ExitInitializationMode -> { set inputs; fmi2DoStep(t_k, m*h); get outputs }* ->
//! fmi2Terminate -> fmi2FreeInstance.
//!
//! Time grid: communication points are computed from the integer step index k, never
//! accumulated. When t0 and h are whole numbers of nanoseconds (the usual case) t_k is the double
//! nearest to t0 + k*h taken exactly in nanoseconds, (t0_ns + k*h_ns)/1e9, which is how libcosim
//! keeps its clock (integer ns; `to_double_time_point`), otherwise t0 + k*h. Instance i steps at
//! every k divisible by its step multiple m_i, from t_k with size t_(k+m_i) - t_k, so that
//! t + h is exactly the next communication point (libcosim's `to_double_duration` rule). With
//! both rules shipsim hands every FMU bit-for-bit the times and step sizes libcosim does.
//!
//! Jacobi: every instance that steps at k takes its inputs from the outputs published at the
//! last communication point; an instance's outputs are published when its own step ends
//! (k + m_i), so slow instances do not leak future values into fast ones (same rule as
//! libcosim's fixed_step_algorithm with decimation factors).
//! Gauss-Seidel: instances step one after another in connection order, each reading the newest
//! outputs (already at t_{k+1} for those stepped earlier in the same macro step).
//!
//! The step loop allocates nothing: all connections are resolved before the first step into
//! per-instance arrays of value references, source indices, gains and offsets; each exchange is
//! one batched fmi2GetReal and one fmi2SetReal per instance (plus Integer/Boolean when present).

use crate::error::{Error, Result};
use crate::fmu::{Fmu, VR};
use crate::instance::{
    stderr_sink, Instance, Instantiated, LogSink, Readable, StepOutcome, Stepping,
};
use crate::model_description::VarType;
use crate::system::{Algorithm, Plan, System, TypedValue};
use std::collections::HashMap;
use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How to run.
#[derive(Clone, Default)]
pub struct RunOptions {
    /// FMU log messages below fmi2Warning are shown too, and loggingOn is passed to the FMUs.
    pub verbose: bool,
    /// Show a progress bar (the CLI enables it only when stderr is a terminal).
    pub progress: bool,
    /// Set to true (e.g. by Ctrl-C) to stop the run cleanly.
    pub interrupt: Option<Arc<AtomicBool>>,
    pub log_sink: Option<LogSink>,
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct Summary {
    pub macro_steps: u64,
    /// Sum over instances of fmi2DoStep calls.
    pub fmu_steps: u64,
    pub start_time: f64,
    pub end_time: f64,
    /// Wall time of the step loop only (after initialization).
    pub wall_time: Duration,
    /// Wall time including loading, instantiation and initialization.
    pub total_wall_time: Duration,
    pub rows: u64,
    /// Set when an FMU ended the simulation early (fmi2Discard + fmi2Terminated).
    pub terminated_by: Option<String>,
    pub output_file: Option<PathBuf>,
}

impl Summary {
    pub fn real_time_factor(&self) -> f64 {
        (self.end_time - self.start_time) / self.wall_time.as_secs_f64().max(1e-12)
    }
}

impl std::fmt::Display for Summary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let w = self.wall_time.as_secs_f64();
        writeln!(
            f,
            "simulated {} s .. {} s: {} macro steps, {} FMU steps",
            self.start_time, self.end_time, self.macro_steps, self.fmu_steps
        )?;
        write!(
            f,
            "wall time {:.3} s (step loop), {:.3} s total; real-time factor {:.1}; {:.3} us per macro step, {:.3} us per FMU step",
            w,
            self.total_wall_time.as_secs_f64(),
            self.real_time_factor(),
            w * 1e6 / self.macro_steps.max(1) as f64,
            w * 1e6 / self.fmu_steps.max(1) as f64
        )?;
        if let Some(t) = &self.terminated_by {
            write!(f, "\n{t}")?;
        }
        if let Some(p) = &self.output_file {
            write!(f, "\n{} rows written to {}", self.rows, p.display())?;
        }
        Ok(())
    }
}

/// Loads each distinct FMU once (instances of the same file share one loaded library).
pub fn load_fmus(system: &System) -> Result<Vec<Arc<Fmu>>> {
    let mut cache: HashMap<PathBuf, Arc<Fmu>> = HashMap::new();
    let mut out = Vec::new();
    for inst in &system.instances {
        let key = inst.fmu.canonicalize().unwrap_or_else(|_| inst.fmu.clone());
        let fmu = match cache.get(&key) {
            Some(f) => {
                if f.co_simulation().can_be_instantiated_only_once_per_process {
                    return Err(Error::fmu(
                        &inst.fmu,
                        format!(
                            "instance '{}': the FMU declares canBeInstantiatedOnlyOncePerProcess=\"true\" and is already used by another instance",
                            inst.name
                        ),
                    ));
                }
                f.clone()
            }
            None => {
                if !inst.fmu.exists() {
                    return Err(Error::system(
                        &system.source,
                        inst.line,
                        format!(
                            "instance '{}': FMU file '{}' not found",
                            inst.name,
                            inst.fmu.display()
                        ),
                    ));
                }
                let f = Arc::new(Fmu::load(&inst.fmu).map_err(|e| match e {
                    Error::Fmu { path, message } => Error::Fmu {
                        path,
                        message: format!("(instance '{}') {message}", inst.name),
                    },
                    e => e,
                })?);
                cache.insert(key, f.clone());
                f
            }
        };
        out.push(fmu);
    }
    Ok(out)
}

/// Resolved per-instance exchange arrays.
#[derive(Default)]
struct Ports {
    // inputs: vr, index into the shared value vector, gain, offset, scratch buffer
    in_r_vr: Vec<VR>,
    in_r_src: Vec<usize>,
    in_r_gain: Vec<f64>,
    in_r_off: Vec<f64>,
    in_r_buf: Vec<f64>,
    in_i_vr: Vec<VR>,
    in_i_src: Vec<usize>,
    in_i_buf: Vec<i32>,
    in_b_vr: Vec<VR>,
    in_b_src: Vec<usize>,
    in_b_buf: Vec<i32>,
    // observed variables (connection sources and recorded): contiguous ranges of the shared vectors
    out_r_vr: Vec<VR>,
    out_r_at: usize,
    out_i_vr: Vec<VR>,
    out_i_at: usize,
    out_b_vr: Vec<VR>,
    out_b_at: usize,
}

struct Values {
    r: Vec<f64>,
    i: Vec<i32>,
    b: Vec<i32>,
}

impl Ports {
    #[inline]
    fn set_inputs<S>(&mut self, inst: &mut Instance<S>, v: &Values) -> Result<()> {
        if !self.in_r_vr.is_empty() {
            for j in 0..self.in_r_vr.len() {
                self.in_r_buf[j] = self.in_r_gain[j] * v.r[self.in_r_src[j]] + self.in_r_off[j];
            }
            inst.set_real(&self.in_r_vr, &self.in_r_buf)?;
        }
        if !self.in_i_vr.is_empty() {
            for j in 0..self.in_i_vr.len() {
                self.in_i_buf[j] = v.i[self.in_i_src[j]];
            }
            inst.set_integer(&self.in_i_vr, &self.in_i_buf)?;
        }
        if !self.in_b_vr.is_empty() {
            for j in 0..self.in_b_vr.len() {
                self.in_b_buf[j] = v.b[self.in_b_src[j]];
            }
            inst.set_boolean(&self.in_b_vr, &self.in_b_buf)?;
        }
        Ok(())
    }

    #[inline]
    fn get_outputs<S: Readable>(&self, inst: &mut Instance<S>, v: &mut Values) -> Result<()> {
        let n = self.out_r_vr.len();
        if n > 0 {
            inst.get_real(&self.out_r_vr, &mut v.r[self.out_r_at..self.out_r_at + n])?;
        }
        let n = self.out_i_vr.len();
        if n > 0 {
            inst.get_integer(&self.out_i_vr, &mut v.i[self.out_i_at..self.out_i_at + n])?;
        }
        let n = self.out_b_vr.len();
        if n > 0 {
            inst.get_boolean(&self.out_b_vr, &mut v.b[self.out_b_at..self.out_b_at + n])?;
        }
        Ok(())
    }
}

fn set_value<S>(inst: &mut Instance<S>, vr: VR, v: &TypedValue) -> Result<()> {
    match v {
        TypedValue::Real(x) => inst.set_real(&[vr], &[*x]),
        TypedValue::Integer(x) => inst.set_integer(&[vr], &[*x]),
        TypedValue::Boolean(x) => inst.set_boolean(&[vr], &[*x as i32]),
        TypedValue::String(s) => inst.set_string(&[vr], &[s.as_str()]),
    }
}

/// A column of the recorder: which shared vector and where.
#[derive(Clone, Copy)]
enum Col {
    R(usize),
    I(usize),
    B(usize),
}

/// CSV recorder: header `time,instance.variable,...`, one row per `decimation` base steps.
/// Numbers are written in Rust's shortest round-trip form, so values survive the file exactly.
struct Recorder {
    out: Box<dyn Write>,
    cols: Vec<Col>,
    rows: u64,
}

impl Recorder {
    #[inline]
    fn row(&mut self, t: f64, v: &Values) -> std::io::Result<()> {
        write!(self.out, "{t}")?;
        for c in &self.cols {
            match *c {
                Col::R(j) => write!(self.out, ",{}", v.r[j])?,
                Col::I(j) => write!(self.out, ",{}", v.i[j])?,
                Col::B(j) => write!(self.out, ",{}", v.b[j])?,
            }
        }
        self.out.write_all(b"\n")?;
        self.rows += 1;
        Ok(())
    }
}

/// Where rows go.
pub enum Output {
    None,
    File(PathBuf),
    Writer(Box<dyn Write>),
}

struct Slot {
    inst: Instance<Stepping>,
    ports: Ports,
    m: u64,
    var_step: bool,
}

/// Runs a validated plan with loaded FMUs (`fmus[i]` for `plan.instances[i]`).
pub fn run(plan: &Plan, fmus: &[Arc<Fmu>], output: Output, opts: &RunOptions) -> Result<Summary> {
    let t_begin = Instant::now();
    let n = plan.instances.len();
    let sink = opts
        .log_sink
        .clone()
        .unwrap_or_else(|| stderr_sink(opts.verbose));

    // ---- resolve exchange arrays
    let mut ports: Vec<Ports> = (0..n).map(|_| Ports::default()).collect();
    let mut observed: HashMap<(usize, VarType, VR), usize> = HashMap::new();
    let mut observe = |i: usize, t: VarType, vr: VR, ports: &mut Vec<Ports>| {
        let key = (i, t, vr);
        if !observed.contains_key(&key) {
            let p = &mut ports[i];
            let local = match t {
                VarType::Real => {
                    p.out_r_vr.push(vr);
                    p.out_r_vr.len() - 1
                }
                VarType::Boolean => {
                    p.out_b_vr.push(vr);
                    p.out_b_vr.len() - 1
                }
                _ => {
                    p.out_i_vr.push(vr);
                    p.out_i_vr.len() - 1
                }
            };
            observed.insert(key, local);
        }
    };
    for c in &plan.connections {
        observe(c.from_instance, c.var_type, c.from_vr, &mut ports);
    }
    for o in &plan.outputs {
        observe(o.instance, o.var_type, o.vr, &mut ports);
    }
    let (mut nr, mut ni, mut nb) = (0, 0, 0);
    for p in ports.iter_mut() {
        p.out_r_at = nr;
        nr += p.out_r_vr.len();
        p.out_i_at = ni;
        ni += p.out_i_vr.len();
        p.out_b_at = nb;
        nb += p.out_b_vr.len();
    }
    let global = |ports: &Vec<Ports>, i: usize, t: VarType, vr: VR| -> usize {
        let local = observed[&(i, t, vr)];
        match t {
            VarType::Real => ports[i].out_r_at + local,
            VarType::Boolean => ports[i].out_b_at + local,
            _ => ports[i].out_i_at + local,
        }
    };
    for c in &plan.connections {
        let g = global(&ports, c.from_instance, c.var_type, c.from_vr);
        let p = &mut ports[c.to_instance];
        match c.var_type {
            VarType::Real => {
                p.in_r_vr.push(c.to_vr);
                p.in_r_src.push(g);
                p.in_r_gain.push(c.gain);
                p.in_r_off.push(c.offset);
                p.in_r_buf.push(0.0);
            }
            VarType::Boolean => {
                p.in_b_vr.push(c.to_vr);
                p.in_b_src.push(g);
                p.in_b_buf.push(0);
            }
            _ => {
                p.in_i_vr.push(c.to_vr);
                p.in_i_src.push(g);
                p.in_i_buf.push(0);
            }
        }
    }
    let cols: Vec<Col> = plan
        .outputs
        .iter()
        .map(|o| {
            let g = global(&ports, o.instance, o.var_type, o.vr);
            match o.var_type {
                VarType::Real => Col::R(g),
                VarType::Boolean => Col::B(g),
                _ => Col::I(g),
            }
        })
        .collect();
    let mut vals = Values {
        r: vec![0.0; nr],
        i: vec![0; ni],
        b: vec![0; nb],
    };

    // ---- recorder
    let (out, out_path): (Option<Box<dyn Write>>, Option<PathBuf>) = match output {
        Output::None => (None, None),
        Output::File(p) => {
            if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(dir).map_err(|e| {
                    Error::io(format!("cannot create output folder {}", dir.display()), e)
                })?;
            }
            let f = std::fs::File::create(&p)
                .map_err(|e| Error::io(format!("cannot create output file {}", p.display()), e))?;
            (
                Some(Box::new(std::io::BufWriter::with_capacity(1 << 16, f))),
                Some(p),
            )
        }
        Output::Writer(w) => (Some(w), None),
    };
    let mut rec = match out {
        None => None,
        Some(mut w) => {
            let mut header = String::from("time");
            for o in &plan.outputs {
                header.push(',');
                header.push_str(&o.header);
            }
            header.push('\n');
            w.write_all(header.as_bytes())
                .map_err(|e| Error::io("writing the output header", e))?;
            Some(Recorder {
                out: w,
                cols,
                rows: 0,
            })
        }
    };
    let io_err = |e: std::io::Error| Error::io("writing the output file", e);

    // ---- instantiate and initialize
    let t0 = plan.start_time;
    let h = plan.step_size;
    let mut instantiated: Vec<Instance<Instantiated>> = Vec::with_capacity(n);
    for (i, pi) in plan.instances.iter().enumerate() {
        let mut inst = fmus[i].instantiate(&pi.name, opts.verbose, sink.clone())?;
        for sv in pi.start_values.iter().filter(|s| s.before_init) {
            set_value(&mut inst, sv.vr, &sv.value)
                .map_err(|e| ctx_err(e, &pi.name, &sv.variable))?;
        }
        instantiated.push(inst);
    }
    let mut initializing = Vec::with_capacity(n);
    for (i, inst) in instantiated.into_iter().enumerate() {
        let mut inst = inst.enter_initialization_mode(None, t0, Some(plan.stop_time))?;
        for sv in plan.instances[i]
            .start_values
            .iter()
            .filter(|s| !s.before_init)
        {
            set_value(&mut inst, sv.vr, &sv.value)
                .map_err(|e| ctx_err(e, &plan.instances[i].name, &sv.variable))?;
        }
        initializing.push(inst);
    }
    // Propagate initial values along connections (one round per instance covers any chain).
    if !plan.connections.is_empty() {
        for _ in 0..n {
            match plan.algorithm {
                Algorithm::Jacobi => {
                    for i in 0..n {
                        ports[i].get_outputs(&mut initializing[i], &mut vals)?;
                    }
                    for i in 0..n {
                        ports[i].set_inputs(&mut initializing[i], &vals)?;
                    }
                }
                Algorithm::GaussSeidel => {
                    for &i in &plan.order {
                        ports[i].set_inputs(&mut initializing[i], &vals)?;
                        ports[i].get_outputs(&mut initializing[i], &mut vals)?;
                    }
                }
            }
        }
    }
    let mut slots: Vec<Slot> = Vec::with_capacity(n);
    for (i, (inst, p)) in initializing.into_iter().zip(ports).enumerate() {
        let inst = inst.exit_initialization_mode()?;
        slots.push(Slot {
            inst,
            ports: p,
            m: plan.instances[i].step_multiple as u64,
            var_step: fmus[i]
                .co_simulation()
                .can_handle_variable_communication_step_size,
        });
    }
    for s in slots.iter_mut() {
        s.ports.get_outputs(&mut s.inst, &mut vals)?;
    }
    if let Some(r) = rec.as_mut() {
        r.row(t0, &vals).map_err(io_err)?;
    }

    // ---- step loop (no allocation below this line on the success path)
    let progress = if opts.progress {
        let pb = indicatif::ProgressBar::new(plan.n_steps);
        pb.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {percent:>3}% t={msg} s  elapsed {elapsed_precise} eta {eta}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        Some(pb)
    } else {
        None
    };
    let loop_start = Instant::now();
    let n_steps = plan.n_steps;
    let grid = TimeGrid::new(t0, h, n_steps);
    let dec = plan.decimation as u64;
    let events = &plan.events;
    let mut ev = 0usize;
    let mut fmu_steps = 0u64;
    let mut k = 0u64;
    let mut terminated_by = None;
    let order = &plan.order;
    let interrupt = opts.interrupt.clone();
    'outer: while k < n_steps {
        let t = grid.at(k);
        if let Some(flag) = &interrupt {
            if flag.load(Ordering::Relaxed) {
                if let Some(r) = rec.as_mut() {
                    r.out.flush().map_err(io_err)?;
                }
                if let Some(pb) = &progress {
                    pb.abandon();
                }
                return Err(Error::Interrupted { time: t });
            }
        }
        let ev_start = ev;
        while ev < events.len() && events[ev].step == k {
            ev += 1;
        }
        let evs = &events[ev_start..ev];
        match plan.algorithm {
            Algorithm::Jacobi => {
                for s in slots.iter_mut() {
                    if k % s.m == 0 {
                        s.ports.set_inputs(&mut s.inst, &vals)?;
                    }
                }
                for e in evs {
                    set_value(&mut slots[e.instance].inst, e.vr, &e.value)
                        .map_err(|err| at_time(err, t, &e.name))?;
                }
                for s in slots.iter_mut() {
                    if k % s.m == 0 {
                        let Some(hi) = grid.step_size(k, s.m, n_steps, s.var_step) else {
                            continue;
                        };
                        fmu_steps += 1;
                        if let StepOutcome::Terminated {
                            last_successful_time,
                        } = s.inst.do_step(t, hi)?
                        {
                            terminated_by = Some(format!(
                                "instance '{}' ended the simulation at t = {last_successful_time} s (fmi2Discard, fmi2Terminated)",
                                s.inst.name()
                            ));
                        }
                    }
                }
                for s in slots.iter_mut() {
                    if (k + 1) % s.m == 0 || k + 1 == n_steps {
                        s.ports.get_outputs(&mut s.inst, &mut vals)?;
                    }
                }
            }
            Algorithm::GaussSeidel => {
                for &i in order.iter() {
                    let s = &mut slots[i];
                    if k % s.m == 0 {
                        s.ports.set_inputs(&mut s.inst, &vals)?;
                    }
                    for e in evs.iter().filter(|e| e.instance == i) {
                        set_value(&mut s.inst, e.vr, &e.value)
                            .map_err(|err| at_time(err, t, &e.name))?;
                    }
                    if k % s.m == 0 {
                        if let Some(hi) = grid.step_size(k, s.m, n_steps, s.var_step) {
                            fmu_steps += 1;
                            if let StepOutcome::Terminated {
                                last_successful_time,
                            } = s.inst.do_step(t, hi)?
                            {
                                terminated_by = Some(format!(
                                    "instance '{}' ended the simulation at t = {last_successful_time} s (fmi2Discard, fmi2Terminated)",
                                    s.inst.name()
                                ));
                            }
                        }
                        s.ports.get_outputs(&mut s.inst, &mut vals)?;
                    }
                }
            }
        }
        k += 1;
        if let Some(r) = rec.as_mut() {
            if k % dec == 0 || k == n_steps || terminated_by.is_some() {
                r.row(grid.at(k), &vals).map_err(io_err)?;
            }
        }
        if let Some(pb) = &progress {
            if k & 0xfff == 0 {
                pb.set_position(k);
                pb.set_message(format!("{:.2}", grid.at(k)));
            }
        }
        if terminated_by.is_some() {
            break 'outer;
        }
    }
    let wall = loop_start.elapsed();
    if let Some(pb) = &progress {
        pb.finish_and_clear();
    }
    let rows = match rec.as_mut() {
        Some(r) => {
            r.out.flush().map_err(io_err)?;
            r.rows
        }
        None => 0,
    };
    drop(rec);
    // Terminate explicitly so that a failing fmi2Terminate is reported.
    for s in slots {
        s.inst.terminate()?;
    }
    Ok(Summary {
        macro_steps: k,
        fmu_steps,
        start_time: t0,
        end_time: grid.at(k),
        wall_time: wall,
        total_wall_time: t_begin.elapsed(),
        rows,
        terminated_by,
        output_file: out_path,
    })
}

/// The communication points t_k (module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeGrid {
    t0: f64,
    h: f64,
    /// (t0, h) in whole nanoseconds, when both are and t_n stays exact in an i64.
    ns: Option<(i64, i64)>,
}

impl TimeGrid {
    /// The grid from t0 with base step h over `n_steps` steps.
    pub fn new(t0: f64, h: f64, n_steps: u64) -> TimeGrid {
        let whole_ns = |x: f64| {
            let n = (x * 1e9).round();
            (n.abs() < 1e15 && n / 1e9 == x).then_some(n as i64)
        };
        let ns = match (whole_ns(t0), whole_ns(h)) {
            (Some(a), Some(b)) if b > 0 && (n_steps as f64) * (b as f64) < 4e18 => Some((a, b)),
            _ => None,
        };
        TimeGrid { t0, h, ns }
    }

    /// t_k.
    #[inline]
    pub fn at(&self, k: u64) -> f64 {
        match self.ns {
            Some((t0, h)) => (t0 + k as i64 * h) as f64 / 1e9,
            None => self.t0 + k as f64 * self.h,
        }
    }

    /// Step size of an instance stepping at k with step multiple m: t_(k+m) - t_k, shortened to
    /// t_n - t_k at the end of the run if the FMU can take a variable step, else None (the last
    /// partial step is dropped).
    #[inline]
    pub fn step_size(&self, k: u64, m: u64, n_steps: u64, var_step: bool) -> Option<f64> {
        if k + m <= n_steps {
            Some(self.at(k + m) - self.at(k))
        } else if var_step {
            Some(self.at(n_steps) - self.at(k))
        } else {
            None
        }
    }
}

fn ctx_err(e: Error, instance: &str, variable: &str) -> Error {
    match e {
        Error::Fmi {
            instance: _,
            function,
            status,
            time,
            log,
        } => Error::Other(format!(
            "{} (setting '{instance}.{variable}')",
            Error::Fmi {
                instance: instance.to_string(),
                function,
                status,
                time,
                log
            }
        )),
        e => e,
    }
}

fn at_time(e: Error, t: f64, name: &str) -> Error {
    Error::Other(format!("event at t = {t} setting '{name}': {e}"))
}

/// Validates a system, loads its FMUs and runs it.
pub fn run_system(system: &System, output: Output, opts: &RunOptions) -> Result<(Plan, Summary)> {
    let begin = Instant::now();
    let fmus = load_fmus(system)?;
    let mds: Vec<&crate::model_description::ModelDescription> =
        fmus.iter().map(|f| &f.model_description).collect();
    let plan = system.validate(&mds)?;
    for w in &plan.warnings {
        eprintln!("warning: {w}");
    }
    let mut summary = run(&plan, &fmus, output, opts)?;
    summary.total_wall_time = begin.elapsed();
    Ok((plan, summary))
}
