//! A value derived from a model's parameters (or slowly changing inputs) and kept between steps,
//! so that a step does not recompute it while they stay the same.
//!
//! A [`Memo`] is not part of the model's state: it is recomputed, by the same code, whenever its
//! key differs bit for bit from the one it was computed for, so results never depend on it.
//! Hence it compares equal to any other memo, starts empty, and a model marks the field
//! `#[serde(skip)]` (a serialized or restored model simply recomputes it on its next use).

/// Values `V` computed for keys `K` (compared with `==`: use bit patterns for floats, see
/// [`bits`]), the `N` most recently used ones kept. `N` = 2 suits values that depend on the
/// communication step: a master's steps t_(k+1) − t_k on a rounded time grid alternate between
/// neighbouring floats.
#[derive(Clone, Debug)]
pub struct Memo<K, V, const N: usize = 1>([Option<(K, V)>; N]);

impl<K, V, const N: usize> Default for Memo<K, V, N> {
    fn default() -> Self {
        Memo(std::array::from_fn(|_| None))
    }
}

/// Memos do not take part in a model's equality (they are derived, see the module docs).
impl<K, V, const N: usize> PartialEq for Memo<K, V, N> {
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

impl<K: PartialEq, V, const N: usize> Memo<K, V, N> {
    /// The slot holding `key`, moved to the front (most recently used).
    #[inline]
    fn find(&mut self, key: &K) -> bool {
        match self
            .0
            .iter()
            .position(|e| matches!(e, Some((k, _)) if k == key))
        {
            Some(i) => {
                for k in (1..=i).rev() {
                    self.0.swap(k, k - 1);
                }
                true
            }
            None => false,
        }
    }

    /// The front slot's value (present after `find` or `put`).
    #[inline]
    fn front(&self) -> &V {
        match &self.0[0] {
            Some((_, v)) => v,
            None => unreachable!("filled before"),
        }
    }

    /// The value for `key`: a kept one computed for the same key, else `compute()` (which is
    /// then kept, in place of the least recently used).
    #[inline]
    pub fn get(&mut self, key: K, compute: impl FnOnce() -> V) -> &V {
        if !self.find(&key) {
            let value = compute();
            self.put(key, value);
        }
        self.front()
    }

    /// [`Memo::get`] for a computation that can fail (a failure is not kept).
    pub fn try_get<E>(&mut self, key: K, compute: impl FnOnce() -> Result<V, E>) -> Result<&V, E> {
        if !self.find(&key) {
            let value = compute()?;
            self.put(key, value);
        }
        Ok(self.front())
    }

    /// The kept value computed for `key`, which the memo then no longer holds.
    #[inline]
    pub fn take(&mut self, key: &K) -> Option<V> {
        if !self.find(key) {
            return None;
        }
        let kept = self.0[0].take().map(|(_, v)| v);
        for k in 1..N {
            self.0.swap(k - 1, k);
        }
        kept
    }
}

impl<K, V, const N: usize> Memo<K, V, N> {
    /// Keeps `value`, computed for `key`, in place of the least recently used.
    #[inline]
    pub fn put(&mut self, key: K, value: V) {
        for k in (1..N).rev() {
            self.0.swap(k, k - 1);
        }
        self.0[0] = Some((key, value));
    }

    /// Forgets the kept values (when what they were derived from changes).
    pub fn clear(&mut self) {
        self.0.iter_mut().for_each(|e| *e = None);
    }
}

/// Bit patterns of floats, for keys that must distinguish −0 from +0 (and compare NaNs by
/// payload).
pub fn bits<const N: usize>(values: [f64; N]) -> Bits<N> {
    Bits(values.map(f64::to_bits))
}

/// A key of bit patterns. Its `==` is one branch-free pass (an array's `==` of more than a few
/// elements is a `memcmp` call).
#[derive(Clone, Copy, Debug)]
pub struct Bits<const N: usize>(pub [u64; N]);

impl<const N: usize> PartialEq for Bits<N> {
    #[inline]
    fn eq(&self, other: &Self) -> bool {
        self.0.iter().zip(&other.0).fold(0, |d, (a, b)| d | (a ^ b)) == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recomputes_only_for_a_new_key() {
        let mut calls = 0;
        let mut m: Memo<Bits<1>, f64> = Memo::default();
        let mut get = |m: &mut Memo<Bits<1>, f64>, x: f64| {
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

    /// Two slots: alternating keys are computed once each; a third key evicts the least
    /// recently used.
    #[test]
    fn two_slots_keep_the_two_most_recent_keys() {
        let mut calls = Vec::new();
        let mut m: Memo<u8, u32, 2> = Memo::default();
        let mut get = |m: &mut Memo<u8, u32, 2>, k: u8| {
            *m.get(k, || {
                calls.push(k);
                u32::from(k) * 10
            })
        };
        for k in [1, 2, 1, 2, 1, 3, 1, 2, 2] {
            assert_eq!(get(&mut m, k), u32::from(k) * 10);
        }
        // 1, 2 computed; 3 evicts 2 (1 was used after it); 2 evicts 3
        assert_eq!(calls, [1, 2, 3, 2]);
        assert_eq!(m.take(&1), Some(10));
        assert_eq!(m.take(&1), None);
        assert_eq!(m.take(&2), Some(20));
        assert_eq!(m.take(&2), None);
    }

    fn m_with(v: u8) -> Memo<u8, u8> {
        let mut m = Memo::default();
        m.get(0, || v);
        m
    }
}
