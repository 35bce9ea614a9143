//! Mutations of a serialized FMU state. The first [`HEADER`] bytes are kept: in our export
//! layer they are the model's GUID tag (8 bytes) and the layout version (4 bytes), which
//! fmi2DeSerializeFMUstate checks first; a mutation there is refused before the body is read,
//! so it would test nothing beyond that check (the probe kept them valid too).

use super::rng::Rng;
use std::fmt;

pub const HEADER: usize = 12;

/// Special doubles written over 8 bytes of a state (the Waves state of the probe held an
/// internal step of 1.5e-40 that the parameter check refuses).
const F64S: [f64; 13] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    0.0,
    -1.0,
    5e-324,
    1.5e-40,
    1e-300,
    1e300,
    -1e300,
    1e9,
    f64::MAX,
    1e-9,
];
/// Special integers (lengths, counts, enum tags) written over 8 or 4 bytes.
const U64S: [u64; 8] = [0, 1, 3, 255, 1 << 32, 1 << 40, u64::MAX, 1 << 63];
const U32S: [u32; 6] = [0, 1, 7, 255, u32::MAX, 1 << 31];

/// One change to the bytes of a state; offsets are absolute.
#[derive(Clone, Debug, PartialEq)]
pub enum Mutation {
    Bit { at: usize, bit: u8 },
    Byte { at: usize, value: u8 },
    F64 { at: usize, value: f64 },
    U64 { at: usize, value: u64 },
    U32 { at: usize, value: u32 },
    Truncate { len: usize },
    Append { n: usize },
}

impl fmt::Display for Mutation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Mutation::Bit { at, bit } => write!(f, "@{at}:bit{bit}"),
            Mutation::Byte { at, value } => write!(f, "@{at}:byte={value}"),
            Mutation::F64 { at, value } => write!(f, "@{at}:f64={}", super::calls::num(*value)),
            Mutation::U64 { at, value } => write!(f, "@{at}:u64={value}"),
            Mutation::U32 { at, value } => write!(f, "@{at}:u32={value}"),
            Mutation::Truncate { len } => write!(f, "truncate={len}"),
            Mutation::Append { n } => write!(f, "append={n}"),
        }
    }
}

/// One to four mutations of a state of `len` bytes (none when it is all header).
pub fn draw(rng: &mut Rng, len: usize) -> Vec<Mutation> {
    if len <= HEADER {
        return Vec::new();
    }
    let body = len - HEADER;
    let n = 1 + rng.below(4);
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let at = HEADER + rng.below(body);
        out.push(match rng.weighted(&[20, 15, 30, 15, 12, 4, 4]) {
            0 => Mutation::Bit {
                at,
                bit: rng.below(8) as u8,
            },
            1 => Mutation::Byte {
                at,
                value: rng.next_u64() as u8,
            },
            2 => Mutation::F64 {
                at,
                value: *rng.pick(&F64S),
            },
            3 => Mutation::U64 {
                at,
                value: *rng.pick(&U64S),
            },
            4 => Mutation::U32 {
                at,
                value: *rng.pick(&U32S),
            },
            5 => Mutation::Truncate { len: at },
            _ => Mutation::Append {
                n: 1 + rng.below(64),
            },
        });
    }
    out
}

/// Applies the mutations in order (writes past the end are cut; the header is never touched).
pub fn apply(bytes: &[u8], mutations: &[Mutation]) -> Vec<u8> {
    let mut b = bytes.to_vec();
    let put = |b: &mut Vec<u8>, at: usize, data: &[u8]| {
        for (i, x) in data.iter().enumerate() {
            if at + i >= HEADER && at + i < b.len() {
                b[at + i] = *x;
            }
        }
    };
    for m in mutations {
        match *m {
            Mutation::Bit { at, bit } => {
                if at >= HEADER && at < b.len() {
                    b[at] ^= 1 << bit;
                }
            }
            Mutation::Byte { at, value } => put(&mut b, at, &[value]),
            Mutation::F64 { at, value } => put(&mut b, at, &value.to_le_bytes()),
            Mutation::U64 { at, value } => put(&mut b, at, &value.to_le_bytes()),
            Mutation::U32 { at, value } => put(&mut b, at, &value.to_le_bytes()),
            Mutation::Truncate { len } => b.truncate(len.max(HEADER)),
            Mutation::Append { n } => b.extend((0..n).map(|i| (i * 37 + 11) as u8)),
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_header_is_never_changed() {
        let base: Vec<u8> = (0..40u8).collect();
        let mut rng = Rng::new(5);
        for _ in 0..2000 {
            let m = draw(&mut rng, base.len());
            let out = apply(&base, &m);
            assert_eq!(&out[..HEADER], &base[..HEADER], "{m:?}");
        }
        // Explicit writes that start inside the header leave it alone.
        let out = apply(&base, &[Mutation::U64 { at: 8, value: 0 }]);
        assert_eq!(&out[..12], &base[..12]);
        assert_eq!(&out[12..16], &[0, 0, 0, 0]);
    }

    #[test]
    fn a_double_is_written_little_endian() {
        let base = vec![0u8; 24];
        let out = apply(&base, &[Mutation::F64 { at: 14, value: 1.0 }]);
        assert_eq!(&out[14..22], &[0, 0, 0, 0, 0, 0, 0xf0, 0x3f]);
    }
}
