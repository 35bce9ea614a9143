//! The checkpoint file: a versioned little-endian binary layout, checked on reading.
//!
//! ```text
//! magic "SHIPCKPT", version u32 (2)
//! step u64, time f64
//! fingerprint: start_time f64, step_size f64, n_steps u64, algorithm u8 (0 Jacobi, 1 Gauss-Seidel)
//!   instances: u32 n, n x (name str, guid str, FMU SHA-256 hex str, step_multiple u32)
//!   order:     u32 n, n x u32
//!   observed:  u32 n, n x (instance u32, type u8, value reference u32, label str)
//!   couplings: u32 n, n x (to instance u32, to value reference u32, gain f64, offset f64,
//!              flags u8 (1 summed, 2 mapped, 4 Boolean mapping), [u32 m, m x (i32, i32)
//!              when mapped], label str)
//!   starts:    u32 n, n x (instance u32, value reference u32, value, label str)
//!   events:    u32 n, n x (step u64, instance u32, value reference u32, value, label str)
//!   value:     u8 type (0 Real f64, 1 Integer i32, 2 Boolean u8, 3 String str), the value
//! values: u32 n, n x f64 (Real); u32 n, n x i32 (Integer); u32 n, n x i32 (Boolean)
//! states: u32 n, n x (name str, u64 length, the FMU's bytes)
//! checksum u64: FNV-1a 64 of every byte before it
//! str: u32 length, UTF-8 bytes
//! ```
//!
//! Version 1 (before issue 38) had no FMU hashes, couplings, start values or events; such a
//! file is refused with the advice to take the checkpoint again.
//!
//! Reading never trusts a length: a count is checked against the bytes left in the file
//! before anything is allocated for it, so a truncated or hostile file is an error naming the
//! file and what was being read, never a panic or a huge allocation.

use super::{Checkpoint, Coupling, Fingerprint, InstanceId, InstanceState, ObservedId, Setting};
use crate::error::{Error, Result};
use crate::run::exchange::Values;
use crate::system::{Algorithm, TypedValue};
use std::path::Path;

const MAGIC: &[u8; 8] = b"SHIPCKPT";
const VERSION: u32 = 2;

/// FNV-1a 64-bit (Fowler, Noll, Vo), the file's checksum.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The file's bytes, written field by field.
#[derive(Default)]
struct Out(Vec<u8>);

impl Out {
    fn u8(&mut self, x: u8) {
        self.0.push(x);
    }
    fn u32(&mut self, x: u32) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    fn u64(&mut self, x: u64) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    fn f64(&mut self, x: f64) {
        self.u64(x.to_bits());
    }
    /// A count; the format's counts are u32.
    fn len(&mut self, n: usize, what: &str) -> Result<()> {
        let n = u32::try_from(n)
            .map_err(|_| Error::Other(format!("a checkpoint holds at most {} {what}", u32::MAX)))?;
        self.u32(n);
        Ok(())
    }
    fn str(&mut self, s: &str) -> Result<()> {
        self.len(s.len(), "bytes in a name")?;
        self.0.extend_from_slice(s.as_bytes());
        Ok(())
    }
}

/// The file's bytes, read field by field; every read is bounds-checked.
struct In<'a> {
    bytes: &'a [u8],
    pos: usize,
    file: &'a Path,
}

impl<'a> In<'a> {
    fn err(&self, message: String) -> Error {
        Error::Checkpoint {
            file: self.file.to_path_buf(),
            message,
        }
    }
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        let left = self.bytes.len() - self.pos;
        if n > left {
            return Err(self.err(format!(
                "truncated: {what} at byte {} needs {n} bytes, the file has {left} left",
                self.pos
            )));
        }
        let s = &self.bytes[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }
    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N]> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N, what)?);
        Ok(a)
    }
    fn u8(&mut self, what: &str) -> Result<u8> {
        Ok(self.array::<1>(what)?[0])
    }
    fn u32(&mut self, what: &str) -> Result<u32> {
        Ok(u32::from_le_bytes(self.array(what)?))
    }
    fn i32(&mut self, what: &str) -> Result<i32> {
        Ok(i32::from_le_bytes(self.array(what)?))
    }
    fn u64(&mut self, what: &str) -> Result<u64> {
        Ok(u64::from_le_bytes(self.array(what)?))
    }
    fn f64(&mut self, what: &str) -> Result<f64> {
        Ok(f64::from_bits(self.u64(what)?))
    }
    /// A u32 count of items of at least `min_size` bytes each, checked against the bytes left.
    fn count(&mut self, min_size: usize, what: &str) -> Result<usize> {
        let n = self.u32(what)? as usize;
        let left = self.bytes.len() - self.pos;
        if n.saturating_mul(min_size) > left {
            return Err(self.err(format!(
                "{n} {what} at byte {} need at least {} bytes, the file has {left} left (truncated or corrupt)",
                self.pos,
                n.saturating_mul(min_size)
            )));
        }
        Ok(n)
    }
    fn str(&mut self, what: &str) -> Result<String> {
        let n = self.u32(what)? as usize;
        let at = self.pos;
        let b = self.take(n, what)?;
        String::from_utf8(b.to_vec())
            .map_err(|_| self.err(format!("{what} at byte {at} is not UTF-8")))
    }
    /// `n` items read by `item`, after the count is checked.
    fn list<T>(
        &mut self,
        min_size: usize,
        what: &str,
        mut item: impl FnMut(&mut Self) -> Result<T>,
    ) -> Result<Vec<T>> {
        let n = self.count(min_size, what)?;
        let mut v = Vec::with_capacity(n);
        for _ in 0..n {
            v.push(item(self)?);
        }
        Ok(v)
    }
}

impl Checkpoint {
    /// Writes the checkpoint to `path`, creating its folder (through `<path>.part`, renamed
    /// into place, so that a reader never sees half a file).
    pub fn write(&self, path: &Path) -> Result<()> {
        let path = &crate::output_path::writable(path)?;
        let bytes = self.encode()?;
        let ctx = |what: &str| format!("writing checkpoint file {} ({what})", path.display());
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| Error::io(ctx("creating its folder"), e))?;
        }
        let mut part = path.as_os_str().to_owned();
        part.push(".part");
        let part = std::path::PathBuf::from(part);
        std::fs::write(&part, &bytes).map_err(|e| Error::io(ctx("writing"), e))?;
        std::fs::rename(&part, path).map_err(|e| Error::io(ctx("renaming"), e))
    }

    /// Reads a checkpoint written by [`Checkpoint::write`]; a file that is not one, of another
    /// version, truncated or corrupt is an error naming the file.
    pub fn read(path: &Path) -> Result<Checkpoint> {
        let bytes = crate::limits::read_bytes_limited(path, crate::limits::MAX_CHECKPOINT)
            .map_err(|e| Error::Checkpoint {
                file: path.to_path_buf(),
                message: format!("cannot read it: {e}"),
            })?;
        Checkpoint::decode(&bytes, path)
    }

    /// The file's bytes.
    pub fn encode(&self) -> Result<Vec<u8>> {
        let mut o = Out::default();
        o.0.extend_from_slice(MAGIC);
        o.u32(VERSION);
        o.u64(self.step);
        o.f64(self.time);
        encode_fingerprint(&mut o, &self.fingerprint)?;
        let v = &self.values;
        o.len(v.real.len(), "Real values")?;
        v.real.iter().for_each(|&x| o.f64(x));
        for ints in [&v.integer, &v.boolean] {
            o.len(ints.len(), "Integer or Boolean values")?;
            ints.iter().for_each(|&x| o.u32(x as u32));
        }
        o.len(self.states.len(), "instance states")?;
        for s in &self.states {
            o.str(&s.name)?;
            o.u64(s.bytes.len() as u64);
            o.0.extend_from_slice(&s.bytes);
        }
        let sum = fnv1a(&o.0);
        o.u64(sum);
        Ok(o.0)
    }

    /// Decodes the bytes of checkpoint file `file`.
    pub fn decode(bytes: &[u8], file: &Path) -> Result<Checkpoint> {
        let mut r = In {
            bytes,
            pos: 0,
            file,
        };
        if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
            return Err(r.err("not a shipsim checkpoint file (no SHIPCKPT magic)".into()));
        }
        r.pos = MAGIC.len();
        let version = r.u32("the version")?;
        if version != VERSION {
            return Err(r.err(format!(
                "checkpoint format version {version}; this shipsim reads version {VERSION}{}",
                if version < VERSION {
                    " (the file is from an older shipsim: take the checkpoint again)"
                } else {
                    " (the file is from a newer shipsim)"
                }
            )));
        }
        let step = r.u64("the step")?;
        let time = r.f64("the time")?;
        let fingerprint = decode_fingerprint(&mut r)?;
        let values = Values {
            real: r.list(8, "Real values", |r| r.f64("a Real value"))?,
            integer: r.list(4, "Integer values", |r| r.i32("an Integer value"))?,
            boolean: r.list(4, "Boolean values", |r| r.i32("a Boolean value"))?,
            // String values are recorded only, never exchanged: read again after the resume
            string: Vec::new(),
        };
        let states = r.list(12, "instance states", |r| {
            let name = r.str("an instance name")?;
            let what = format!("the state of '{name}'");
            let n = r.u64(&what)?;
            let n = usize::try_from(n).unwrap_or(usize::MAX);
            let bytes = r.take(n, &what)?.to_vec();
            Ok(InstanceState { name, bytes })
        })?;
        let end = r.pos;
        let sum = r.u64("the checksum")?;
        if sum != fnv1a(&bytes[..end]) {
            return Err(r.err("corrupt: the checksum does not match the contents".into()));
        }
        if r.pos != bytes.len() {
            return Err(r.err(format!(
                "{} byte(s) after the checksum",
                bytes.len() - r.pos
            )));
        }
        Ok(Checkpoint {
            step,
            time,
            values,
            states,
            fingerprint,
        })
    }
}

fn encode_fingerprint(o: &mut Out, f: &Fingerprint) -> Result<()> {
    o.f64(f.start_time);
    o.f64(f.step_size);
    o.u64(f.n_steps);
    o.u8(match f.algorithm {
        Algorithm::Jacobi => 0,
        Algorithm::GaussSeidel => 1,
    });
    o.len(f.instances.len(), "instances")?;
    for i in &f.instances {
        o.str(&i.name)?;
        o.str(&i.guid)?;
        o.str(&i.fmu_hash)?;
        o.u32(i.step_multiple);
    }
    o.len(f.order.len(), "instances")?;
    f.order.iter().for_each(|&i| o.u32(i));
    o.len(f.observed.len(), "observed variables")?;
    for v in &f.observed {
        o.u32(v.instance);
        o.u8(v.kind);
        o.u32(v.vr);
        o.str(&v.label)?;
    }
    o.len(f.couplings.len(), "connections")?;
    for c in &f.couplings {
        encode_coupling(o, c)?;
    }
    o.len(f.starts.len(), "start values")?;
    for s in &f.starts {
        o.u32(s.instance);
        o.u32(s.vr);
        encode_value(o, &s.value)?;
        o.str(&s.label)?;
    }
    o.len(f.events.len(), "events")?;
    for e in &f.events {
        o.u64(e.step);
        o.u32(e.instance);
        o.u32(e.vr);
        encode_value(o, &e.value)?;
        o.str(&e.label)?;
    }
    Ok(())
}

fn encode_coupling(o: &mut Out, c: &Coupling) -> Result<()> {
    o.u32(c.to_instance);
    o.u32(c.to_vr);
    o.f64(c.gain);
    o.f64(c.offset);
    let boolean = c.mapping.as_ref().is_some_and(|m| m.0);
    o.u8(u8::from(c.sum) | u8::from(c.mapping.is_some()) << 1 | u8::from(boolean) << 2);
    if let Some((_, pairs)) = &c.mapping {
        o.len(pairs.len(), "mapping entries")?;
        for &(a, b) in pairs {
            o.u32(a as u32);
            o.u32(b as u32);
        }
    }
    o.str(&c.label)
}

fn encode_value(o: &mut Out, v: &TypedValue) -> Result<()> {
    match v {
        TypedValue::Real(x) => {
            o.u8(0);
            o.f64(*x);
        }
        TypedValue::Integer(i) => {
            o.u8(1);
            o.u32(*i as u32);
        }
        TypedValue::Boolean(b) => {
            o.u8(2);
            o.u8(u8::from(*b));
        }
        TypedValue::String(s) => {
            o.u8(3);
            o.str(s)?;
        }
    }
    Ok(())
}

fn decode_value(r: &mut In) -> Result<TypedValue> {
    let at = r.pos;
    Ok(match r.u8("a value's type")? {
        0 => TypedValue::Real(r.f64("a Real value")?),
        1 => TypedValue::Integer(r.i32("an Integer value")?),
        2 => TypedValue::Boolean(r.u8("a Boolean value")? != 0),
        3 => TypedValue::String(r.str("a String value")?),
        t => return Err(r.err(format!("unknown value type {t} at byte {at}"))),
    })
}

fn decode_coupling(r: &mut In) -> Result<Coupling> {
    let to_instance = r.u32("a connection")?;
    let to_vr = r.u32("a connection")?;
    let gain = r.f64("a connection's gain")?;
    let offset = r.f64("a connection's offset")?;
    let at = r.pos;
    let flags = r.u8("a connection's flags")?;
    if flags > 7 {
        return Err(r.err(format!("unknown connection flags {flags} at byte {at}")));
    }
    let mapping = match flags & 2 {
        0 => None,
        _ => {
            let pairs = r.list(8, "mapping entries", |r| {
                Ok((r.i32("a mapping entry")?, r.i32("a mapping entry")?))
            })?;
            Some((flags & 4 != 0, pairs))
        }
    };
    Ok(Coupling {
        to_instance,
        to_vr,
        gain,
        offset,
        sum: flags & 1 != 0,
        mapping,
        label: r.str("a connection's label")?,
    })
}

fn decode_fingerprint(r: &mut In) -> Result<Fingerprint> {
    let start_time = r.f64("the start time")?;
    let step_size = r.f64("the step size")?;
    let n_steps = r.u64("the number of steps")?;
    let at = r.pos;
    let algorithm = match r.u8("the algorithm")? {
        0 => Algorithm::Jacobi,
        1 => Algorithm::GaussSeidel,
        a => return Err(r.err(format!("unknown algorithm code {a} at byte {at}"))),
    };
    let instances = r.list(16, "instances", |r| {
        Ok(InstanceId {
            name: r.str("an instance name")?,
            guid: r.str("a GUID")?,
            fmu_hash: r.str("an FMU hash")?,
            step_multiple: r.u32("a step multiple")?,
        })
    })?;
    let order = r.list(4, "entries of the stepping order", |r| {
        r.u32("the stepping order")
    })?;
    let observed = r.list(13, "observed variables", |r| {
        Ok(ObservedId {
            instance: r.u32("an observed variable")?,
            kind: r.u8("an observed variable")?,
            vr: r.u32("an observed variable")?,
            label: r.str("an observed variable's label")?,
        })
    })?;
    let couplings = r.list(29, "connections", decode_coupling)?;
    let starts = r.list(13, "start values", |r| {
        Ok(Setting {
            instance: r.u32("a start value")?,
            vr: r.u32("a start value")?,
            value: decode_value(r)?,
            label: r.str("a start value's label")?,
            step: 0,
        })
    })?;
    let events = r.list(21, "events", |r| {
        Ok(Setting {
            step: r.u64("an event")?,
            instance: r.u32("an event")?,
            vr: r.u32("an event")?,
            value: decode_value(r)?,
            label: r.str("an event's label")?,
        })
    })?;
    Ok(Fingerprint {
        start_time,
        step_size,
        n_steps,
        algorithm,
        instances,
        order,
        observed,
        couplings,
        starts,
        events,
    })
}
