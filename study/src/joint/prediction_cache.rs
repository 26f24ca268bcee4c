//! The last few predictions of one record in a joint fit, by the exact parameter values they
//! were made at.
//!
//! A joint fit's finite-difference Jacobian moves one entry of θ at a time. A per-record
//! parameter (`x0@3`) changes only its own record's values, so every other record is asked
//! again for the prediction it made at the base point. At trajectory level each prediction is
//! a simulation: without this cache a Jacobian re-simulates every record for every column
//! (records × columns simulations), with it a per-record column costs one simulation. A
//! prediction depends only on its values (simulations are deterministic), so a hit returns
//! exactly what predicting again would: the fit is the same, only faster. Written here
//! rather than taken from a caching crate: it is a dozen lines keyed by bit-equal `f64`
//! vectors, which the general crates (hashing keys) do not offer.

use std::sync::{Arc, Mutex};

/// Predictions kept per record: the base point, the two noise probes, and the record's own
/// difference steps of a Jacobian, with room to spare.
const KEPT: usize = 16;

/// A prediction and the values it was made at.
type Entry = (Vec<f64>, Arc<Vec<f64>>);

/// A record's recent predictions, most recently used first.
#[derive(Default)]
pub struct PredictionCache {
    entries: Mutex<Vec<Entry>>,
}

impl PredictionCache {
    /// The prediction at `values`: the one kept if the values are bit-equal, else
    /// `predict(values)`, kept. An error is returned, not kept.
    pub fn get_or_predict<E>(
        &self,
        values: &[f64],
        predict: impl FnOnce() -> Result<Vec<f64>, E>,
    ) -> Result<Arc<Vec<f64>>, E> {
        if let Some(hit) = self.lookup(values) {
            return Ok(hit);
        }
        let predicted = Arc::new(predict()?);
        let mut entries = self.lock();
        entries.insert(0, (values.to_vec(), predicted.clone()));
        entries.truncate(KEPT);
        Ok(predicted)
    }

    fn lookup(&self, values: &[f64]) -> Option<Arc<Vec<f64>>> {
        let mut entries = self.lock();
        let same = |v: &[f64]| {
            v.len() == values.len()
                && v.iter()
                    .zip(values)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
        };
        let i = entries.iter().position(|(v, _)| same(v))?;
        let entry = entries.remove(i);
        let hit = entry.1.clone();
        entries.insert(0, entry);
        Some(hit)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<Entry>> {
        self.entries
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    #[test]
    fn a_prediction_is_made_once_per_values_and_errors_are_not_kept() {
        let cache = PredictionCache::default();
        let calls = Cell::new(0);
        let predict = |v: f64| {
            calls.set(calls.get() + 1);
            Ok::<_, String>(vec![v * 2.0])
        };
        assert_eq!(
            *cache.get_or_predict(&[1.0], || predict(1.0)).unwrap(),
            [2.0]
        );
        assert_eq!(
            *cache.get_or_predict(&[1.0], || predict(1.0)).unwrap(),
            [2.0]
        );
        assert_eq!(calls.get(), 1);
        cache
            .get_or_predict(&[1.0 + 1e-15], || predict(1.0))
            .unwrap();
        assert_eq!(calls.get(), 2);
        let failed = cache.get_or_predict(&[5.0], || Err::<Vec<f64>, _>("diverged".to_string()));
        assert!(failed.is_err());
        cache.get_or_predict(&[5.0], || predict(5.0)).unwrap();
        assert_eq!(calls.get(), 3);
    }

    #[test]
    fn the_most_recently_used_prediction_survives_a_flood_of_others() {
        let cache = PredictionCache::default();
        let calls = Cell::new(0);
        let predict = |v: f64| {
            calls.set(calls.get() + 1);
            Ok::<_, String>(vec![v])
        };
        cache.get_or_predict(&[0.0], || predict(0.0)).unwrap();
        for i in 1..100 {
            cache
                .get_or_predict(&[f64::from(i)], || predict(f64::from(i)))
                .unwrap();
            cache.get_or_predict(&[0.0], || predict(0.0)).unwrap();
        }
        assert_eq!(calls.get(), 100);
    }
}
