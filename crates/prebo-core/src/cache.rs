//! The basis side of rows and row gradients, prepared once and reused between calls.
//!
//! An optimiser evaluates many trials against one basis: every energy of a refinement, every
//! trial of a replacement. The basis's symmetry images (`TᵀAT`, their Cholesky factors and
//! normalisations) and the kernels' prepared forms of them do not depend on the trial, so an
//! `Engine` keeps the last few, keyed by the exact bits of the basis parameters (`Keyed`) and the
//! type of the preparation: a hit gives what a rebuild would, bit for bit.
use std::any::{Any, TypeId};
use std::sync::{Arc, Mutex};

use crate::error::Result;

/// Parameters as a cache key: every value's exact bits, and enough lengths that two different
/// parameter sets never give the same key.
pub trait Keyed {
    fn key(&self) -> Vec<u64>;
}

/// Preparations kept (most recent first): a refinement alternates at most a row and a row
/// gradient against one basis, a sweep moves on to the next.
const KEPT: usize = 4;

/// `(key, preparation)` pairs, most recent first.
type Entries = Vec<(Key, Arc<dyn Any + Send + Sync>)>;

/// The type of a preparation and the bits of the parameters it was made from.
#[derive(PartialEq, Eq)]
struct Key {
    ty: TypeId,
    bits: Vec<u64>,
}

impl Key {
    fn new<T: Any>(p: &(impl Keyed + ?Sized)) -> Self {
        Self { ty: TypeId::of::<T>(), bits: p.key() }
    }
}

/// Basis-side preparations of one engine (module docs).
#[derive(Default)]
pub struct Cache {
    entries: Mutex<Entries>,
}

impl Cache {
    /// The preparation `T` of the basis `p`: the kept one, or `build()` (kept if it succeeds).
    pub fn get<T: Any + Send + Sync>(
        &self,
        p: &(impl Keyed + ?Sized),
        build: impl FnOnce() -> Result<T>,
    ) -> Result<Arc<T>> {
        let key = Key::new::<T>(p);
        let mut entries = self.lock();
        if let Some(at) = entries.iter().position(|(k, _)| *k == key) {
            let entry = entries.remove(at);
            let value = entry.1.clone();
            entries.insert(0, entry);
            return Ok(value.downcast::<T>().expect("the key holds the type"));
        }
        drop(entries); // build without the lock
        let value = Arc::new(build()?);
        let mut entries = self.lock();
        entries.insert(0, (key, value.clone()));
        entries.truncate(KEPT);
        Ok(value)
    }

    /// The entries; a poisoned lock (a panic elsewhere while holding it) only loses them.
    fn lock(&self) -> std::sync::MutexGuard<'_, Entries> {
        self.entries.lock().unwrap_or_else(|poisoned| {
            let mut entries = poisoned.into_inner();
            entries.clear();
            entries
        })
    }
}

impl std::fmt::Debug for Cache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Cache({} kept)", self.lock().len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Parameters `A` and `c_A`, keyed as `params::Exponents`.
    struct Params<'a> {
        a: &'a [f64],
        c_a: &'a [f64],
    }

    impl Keyed for Params<'_> {
        fn key(&self) -> Vec<u64> {
            let lengths = [self.a.len() as u64, self.c_a.len() as u64];
            lengths.into_iter().chain(self.a.iter().chain(self.c_a).map(|x| x.to_bits())).collect()
        }
    }

    fn params<'a>(a: &'a [f64], c: &'a [f64]) -> Params<'a> {
        Params { a, c_a: c }
    }

    #[test]
    fn a_hit_returns_the_kept_value_and_a_change_rebuilds() {
        let cache = Cache::default();
        let builds = std::cell::Cell::new(0);
        let get = |a: &[f64], c: &[f64]| {
            let p = params(a, c);
            *cache
                .get(&p, || {
                    builds.set(builds.get() + 1);
                    Ok(p.a[0] + p.c_a[0])
                })
                .unwrap()
        };
        let (a, c) = (vec![1.0, 0.0, 0.0, 1.0], vec![0.5]);
        assert_eq!(get(&a, &c), 1.5);
        assert_eq!(get(&a, &c), 1.5);
        assert_eq!(builds.get(), 1);
        let moved = vec![1.0 + f64::EPSILON, 0.0, 0.0, 1.0];
        assert_eq!(get(&moved, &c), 1.5 + f64::EPSILON);
        assert_eq!(builds.get(), 2);
        assert_eq!(get(&a, &[-0.5]), 0.5);
        assert_eq!(builds.get(), 3);
    }

    #[test]
    fn types_are_kept_apart_and_old_entries_dropped() {
        let cache = Cache::default();
        let (a, c) = (vec![2.0], vec![0.5]);
        let p = params(&a, &c);
        assert_eq!(*cache.get(&p, || Ok(1u32)).unwrap(), 1);
        assert_eq!(*cache.get(&p, || Ok(2.0f64)).unwrap(), 2.0);
        assert_eq!(*cache.get(&p, || Ok(3u32)).unwrap(), 1);
        for k in 0..KEPT {
            let a = vec![k as f64 + 10.0];
            cache.get(&params(&a, &c), || Ok(0u32)).unwrap();
        }
        assert_eq!(*cache.get(&p, || Ok(4u32)).unwrap(), 4);
    }

    #[test]
    fn a_failed_build_is_not_kept() {
        let cache = Cache::default();
        let (a, c) = (vec![2.0], vec![0.5]);
        let p = params(&a, &c);
        let err = cache.get::<u32>(&p, || Err(crate::CoreError::NotPositiveDefinite { function: 0 }));
        assert!(err.is_err());
        assert_eq!(*cache.get(&p, || Ok(5u32)).unwrap(), 5);
    }
}
