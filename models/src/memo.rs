//! A value derived from a model's parameters (or slowly changing inputs) and kept between steps,
//! so that a step does not recompute it while they stay the same.
//!
//! A [`Memo`] is not part of the model's state: it is recomputed, by the same code, whenever its
//! key differs bit for bit from the one it was computed for, so results never depend on it.
//! Hence it compares equal to any other memo, starts empty, and a model marks the field
//! `#[serde(skip)]` (a serialized or restored model simply recomputes it on its next use).

/// A value `V` computed for a key `K` (compared with `==`: use bit patterns for floats, see
/// [`bits`]).
#[derive(Clone, Debug)]
pub struct Memo<K, V>(Option<(K, V)>);

impl<K, V> Default for Memo<K, V> {
    fn default() -> Self {
        Memo(None)
    }
}

/// Memos do not take part in a model's equality (they are derived, see the module docs).
impl<K, V> PartialEq for Memo<K, V> {
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

impl<K: PartialEq, V> Memo<K, V> {
    /// The value for `key`: the kept one if it was computed for the same key, else `compute()`
    /// (which is then kept).
    #[inline]
    pub fn get(&mut self, key: K, compute: impl FnOnce() -> V) -> &V {
        if !matches!(&self.0, Some((k, _)) if *k == key) {
            self.0 = Some((key, compute()));
        }
        match &self.0 {
            Some((_, v)) => v,
            None => unreachable!("just filled"),
        }
    }
}

impl<K: PartialEq, V> Memo<K, V> {
    /// [`Memo::get`] for a computation that can fail (a failure is not kept).
    pub fn try_get<E>(&mut self, key: K, compute: impl FnOnce() -> Result<V, E>) -> Result<&V, E> {
        if !matches!(&self.0, Some((k, _)) if *k == key) {
            self.0 = Some((key, compute()?));
        }
        match &self.0 {
            Some((_, v)) => Ok(v),
            None => unreachable!("just filled"),
        }
    }

    /// The kept value if it was computed for `key` (the memo is then empty).
    #[inline]
    pub fn take(&mut self, key: &K) -> Option<V> {
        match self.0.take() {
            Some((k, v)) if k == *key => Some(v),
            other => {
                self.0 = other;
                None
            }
        }
    }
}

impl<K, V> Memo<K, V> {
    /// Keeps `value`, computed for `key`.
    #[inline]
    pub fn put(&mut self, key: K, value: V) {
        self.0 = Some((key, value));
    }

    /// Forgets the kept value (when what it was derived from changes).
    pub fn clear(&mut self) {
        self.0 = None;
    }
}

/// Bit patterns of floats, for keys that must distinguish −0 from +0 (and compare NaNs by
/// payload).
pub fn bits<const N: usize>(values: [f64; N]) -> [u64; N] {
    values.map(f64::to_bits)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recomputes_only_for_a_new_key() {
        let mut calls = 0;
        let mut m: Memo<[u64; 1], f64> = Memo::default();
        let mut get = |m: &mut Memo<[u64; 1], f64>, x: f64| {
            *m.get(bits([x]), || {
                calls += 1;
                2.0 * x
            })
        };
        assert_eq!(get(&mut m, 1.5), 3.0);
        assert_eq!(get(&mut m, 1.5), 3.0);
        assert_eq!(get(&mut m, 0.0), 0.0);
        // −0 is a different key from +0
        assert_eq!(get(&mut m, -0.0).to_bits(), (-0.0f64).to_bits());
        assert_eq!(get(&mut m, -0.0).to_bits(), (-0.0f64).to_bits());
        assert_eq!(calls, 3);
        assert!(Memo::<u8, u8>::default() == m_with(1));
    }

    #[test]
    fn take_put_and_clear() {
        let mut m = m_with(7);
        assert_eq!(m.take(&1), None);
        assert_eq!(m.take(&0), Some(7));
        assert_eq!(m.take(&0), None);
        m.put(2, 9);
        m.clear();
        assert_eq!(m.take(&2), None);
        m.put(2, 9);
        assert_eq!(*m.get(2, || unreachable!("kept")), 9);
        // a failure is not kept
        assert_eq!(m.try_get(3, || Err::<u8, _>("no")), Err("no"));
        assert_eq!(m.try_get(2, || Err::<u8, &str>("kept")), Ok(&9));
        assert_eq!(m.try_get(3, || Ok::<u8, ()>(4)), Ok(&4));
    }

    fn m_with(v: u8) -> Memo<u8, u8> {
        let mut m = Memo::default();
        m.get(0, || v);
        m
    }
}
