//! The frames between the master and an FMU host process, on two pipes (the child's stdin and
//! stdout; the FMU's own prints to stdout are sent to stderr in the child).
//!
//! Every frame is an 8-byte header, `u32 tag` and `u32 length`, then `length` payload bytes,
//! native-endian (both ends are the same executable on the same machine).
//!
//! - **Request** (master -> host): `tag` is an [`Op`](crate::slave::Op); the payload holds the call's arguments in
//!   order: value references as `u32`, Reals as `f64`, Integers and Booleans as `i32`, strings
//!   and byte strings as `u32` length + bytes, FMU-state handles as `u64`.
//! - **Log** (host -> master, [`LOG`]): `i32` status, then category and message as strings; any
//!   number of them before a reply, in the order the FMU logged.
//! - **Reply** (host -> master, [`REPLY`]): `i32` fmi2Status, then the call's results (the
//!   values read, a state handle, a size, bytes).
//!
//! One request, one reply: the master waits for the reply (with an optional time limit) before
//! it sends the next request.

/// The frame tag of a log message from the host.
pub const LOG: u32 = 0x100;
/// The frame tag of a reply from the host.
pub const REPLY: u32 = 0x101;
/// Header bytes of every frame.
pub const HEADER: usize = 8;
/// The largest frame either end accepts (a serialized state is at most 1 GiB, see
/// [`crate::slave::MAX_STATE_BYTES`]).
pub const MAX_FRAME: usize = (1 << 30) + 4096;

/// Appends native-endian values to a frame being written.
pub trait Put {
    fn put(self, out: &mut Vec<u8>);
}

macro_rules! put_num {
    ($($t:ty),*) => {$(
        impl Put for $t {
            #[inline(always)]
            fn put(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_ne_bytes());
            }
        }
        impl Put for &[$t] {
            #[inline(always)]
            fn put(self, out: &mut Vec<u8>) {
                for x in self {
                    out.extend_from_slice(&x.to_ne_bytes());
                }
            }
        }
    )*};
}
put_num!(u32, i32, u64, f64);

impl Put for &str {
    fn put(self, out: &mut Vec<u8>) {
        self.as_bytes().put(out);
    }
}

impl Put for &[u8] {
    fn put(self, out: &mut Vec<u8>) {
        (self.len() as u32).put(out);
        out.extend_from_slice(self);
    }
}

/// Reads native-endian values from a frame's payload; a short payload gives zeros and sets
/// `short` (the caller reports a malformed frame).
pub struct Reader<'a> {
    pub buf: &'a [u8],
    pub short: bool,
}

impl<'a> Reader<'a> {
    pub fn new(buf: &'a [u8]) -> Reader<'a> {
        Reader { buf, short: false }
    }

    #[inline(always)]
    fn take<const N: usize>(&mut self) -> [u8; N] {
        match self.buf.split_first_chunk::<N>() {
            Some((head, rest)) => {
                self.buf = rest;
                *head
            }
            None => {
                self.short = true;
                self.buf = &[];
                [0; N]
            }
        }
    }

    #[inline(always)]
    pub fn u32(&mut self) -> u32 {
        u32::from_ne_bytes(self.take())
    }
    #[inline(always)]
    pub fn i32(&mut self) -> i32 {
        i32::from_ne_bytes(self.take())
    }
    #[inline(always)]
    pub fn u64(&mut self) -> u64 {
        u64::from_ne_bytes(self.take())
    }
    #[inline(always)]
    pub fn f64(&mut self) -> f64 {
        f64::from_ne_bytes(self.take())
    }

    /// A length-prefixed byte string.
    pub fn bytes(&mut self) -> &'a [u8] {
        let n = self.u32() as usize;
        if n > self.buf.len() {
            self.short = true;
            self.buf = &[];
            return &[];
        }
        let (head, rest) = self.buf.split_at(n);
        self.buf = rest;
        head
    }

    pub fn string(&mut self) -> String {
        String::from_utf8_lossy(self.bytes()).into_owned()
    }

    /// `n` values read with `f` into `out` (cleared first).
    pub fn fill<T>(&mut self, out: &mut [T], mut f: impl FnMut(&mut Self) -> T) {
        for x in out.iter_mut() {
            *x = f(self);
        }
    }
}

/// Starts a frame with tag `tag` in `out` (cleared); [`finish`] writes its length.
#[inline(always)]
pub fn begin(out: &mut Vec<u8>, tag: u32) {
    out.clear();
    tag.put(out);
    0u32.put(out);
}

/// Writes the payload length of the frame in `out`.
#[inline(always)]
pub fn finish(out: &mut [u8]) {
    let n = (out.len() - HEADER) as u32;
    out[4..8].copy_from_slice(&n.to_ne_bytes());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_round_trip() {
        let mut out = Vec::new();
        begin(&mut out, REPLY);
        7i32.put(&mut out);
        [1.5f64, -0.0, f64::NAN].as_slice().put(&mut out);
        "é x".put(&mut out);
        finish(&mut out);
        assert_eq!(
            u32::from_ne_bytes(out[4..8].try_into().unwrap()) as usize,
            out.len() - 8
        );
        let mut r = Reader::new(&out[HEADER..]);
        assert_eq!(r.i32(), 7);
        assert_eq!(r.f64().to_bits(), 1.5f64.to_bits());
        assert_eq!(r.f64().to_bits(), (-0.0f64).to_bits());
        assert!(r.f64().is_nan());
        assert_eq!(r.string(), "é x");
        assert!(!r.short);
        assert_eq!(r.u32(), 0);
        assert!(r.short);
    }
}
