//! A control channel for a simulated record: a signal switched at random between given
//! levels (a magnetorheological damper's coil voltage, a valve), each level held for an
//! exponentially distributed time of a given mean, the next level drawn among the others.
//! Seeded, so a record is reproducible; written as a column beside the record's signals, and
//! what a model parameter's law follows in the simulation.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

/// The levels the signal switches between and the mean time each is held, s.
#[derive(Clone, Debug, PartialEq)]
pub struct RandomLevels {
    /// At least two levels.
    pub levels: Vec<f64>,
    /// Mean hold time, s (positive).
    pub hold: f64,
}

impl RandomLevels {
    /// The signal at `times` (increasing) from `seed`: it starts at a random level and, at
    /// each switch, moves to another level drawn uniformly.
    pub fn sample(&self, times: &[f64], seed: u64) -> Vec<f64> {
        let mut rng = StdRng::seed_from_u64(seed);
        let n = self.levels.len();
        if n == 0 {
            return vec![0.0; times.len()];
        }
        let mut level = rng.random_range(0..n);
        let t0 = times.first().copied().unwrap_or(0.0);
        let mut until = t0 + self.draw_hold(&mut rng);
        times
            .iter()
            .map(|&t| {
                while t >= until && n > 1 {
                    level = (level + 1 + rng.random_range(0..n - 1)) % n;
                    until += self.draw_hold(&mut rng);
                }
                self.levels[level]
            })
            .collect()
    }

    /// An exponentially distributed hold time of mean `hold` (at least a millionth of it, so
    /// the switches always advance).
    fn draw_hold(&self, rng: &mut StdRng) -> f64 {
        let u: f64 = rng.random::<f64>();
        (-(1.0 - u).ln() * self.hold).max(1e-6 * self.hold)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn it_switches_between_its_levels_with_the_mean_hold_and_is_reproducible() {
        let signal = RandomLevels {
            levels: vec![0.0, 1.0],
            hold: 2.0,
        };
        let times: Vec<f64> = (0..200_001).map(|i| i as f64 * 0.01).collect();
        let a = signal.sample(&times, 7);
        assert_eq!(a, signal.sample(&times, 7));
        assert_ne!(a, signal.sample(&times, 8));
        assert!(a.iter().all(|&v| v == 0.0 || v == 1.0));
        let switches = a.windows(2).filter(|w| w[0] != w[1]).count();
        // 2 000 s at a mean hold of 2 s: about 1 000 switches (Poisson, σ ≈ 32).
        assert!((850..1150).contains(&switches), "{switches}");
        let share = a.iter().sum::<f64>() / a.len() as f64;
        assert!((0.4..0.6).contains(&share), "{share}");
    }
}
