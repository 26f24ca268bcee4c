//! Synthetic records: a simulated run sampled through realistic sensors.
//!
//! The sensors of the source study's rig, as defaults ([`SensorNoise::RIG`]):
//! displacement with Gaussian noise σ = 0.05 mm, then quantized to 0.01 mm; the STF force with
//! Gaussian noise σ = 0.02 N; the rotor angle from a 2048-count encoder. The random stream is
//! seeded, so the same seed gives the same bytes.

use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use serde::Serialize;

use crate::data::record::Record;
use crate::simulate::Trajectory;

/// Noise and quantization of the rig's sensors.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SensorNoise {
    /// Displacement noise σ, m.
    pub x_sigma: f64,
    /// Displacement quantum, m (0: none).
    pub x_quantum: f64,
    /// Force noise σ, N.
    pub f_sigma: f64,
    /// Encoder counts per revolution (0: exact angle).
    pub encoder_counts: u32,
}

impl SensorNoise {
    /// The rig's sensors.
    pub const RIG: SensorNoise = SensorNoise {
        x_sigma: 5e-5,
        x_quantum: 1e-5,
        f_sigma: 0.02,
        encoder_counts: 2048,
    };

    /// Exact samples.
    pub const NONE: SensorNoise = SensorNoise {
        x_sigma: 0.0,
        x_quantum: 0.0,
        f_sigma: 0.0,
        encoder_counts: 0,
    };

    /// Whether any noise or quantization is applied.
    pub fn is_exact(&self) -> bool {
        *self == Self::NONE
    }
}

fn quantize(value: f64, quantum: f64) -> f64 {
    if quantum > 0.0 {
        (value / quantum).round() * quantum
    } else {
        value
    }
}

/// Sample `run` through sensors with `noise`, seeded by `seed`.
///
/// Columns: `t`, `x`, `f_stf` (true STF force plus noise), `phi` for a rotor drive (unwrapped
/// encoder angle), `u` for a measured-force drive, and `omega` only for exact records (a real
/// rig has no tachometer; ω comes from the derivative filter).
pub fn sample_record(run: &Trajectory, noise: &SensorNoise, seed: u64, rotor: bool) -> Record {
    let mut rng = StdRng::seed_from_u64(seed);
    let gauss = |sigma: f64| Normal::new(0.0, sigma).ok();
    let (nx, nf) = (gauss(noise.x_sigma), gauss(noise.f_sigma));
    let mut x = Vec::with_capacity(run.t.len());
    let mut f = Vec::with_capacity(run.t.len());
    for (&xi, &fi) in run.x.iter().zip(&run.f_stf) {
        let ex = nx
            .filter(|_| noise.x_sigma > 0.0)
            .map_or(0.0, |d| d.sample(&mut rng));
        let ef = nf
            .filter(|_| noise.f_sigma > 0.0)
            .map_or(0.0, |d| d.sample(&mut rng));
        x.push(quantize(xi + ex, noise.x_quantum));
        f.push(fi + ef);
    }
    let phi = run.phi.as_ref().filter(|_| rotor).map(|phi| {
        let quantum = if noise.encoder_counts > 0 {
            std::f64::consts::TAU / f64::from(noise.encoder_counts)
        } else {
            0.0
        };
        phi.iter().map(|&p| quantize(p, quantum)).collect()
    });
    Record {
        source: "(synthetic)".into(),
        t: run.t.clone(),
        x,
        phi,
        f_stf: Some(f),
        omega: run.omega.clone().filter(|_| noise.is_exact() && rotor),
        u: (!rotor).then(|| run.drive.clone()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run() -> Trajectory {
        let t: Vec<f64> = (0..2000).map(|i| i as f64 * 1e-3).collect();
        Trajectory {
            x: t.iter().map(|t| 0.01 * (6.0 * t).sin()).collect(),
            f_stf: t.iter().map(|t| (6.0 * t).cos()).collect(),
            v: vec![0.0; t.len()],
            a: vec![0.0; t.len()],
            drive: vec![0.0; t.len()],
            phi: Some(t.iter().map(|t| 6.0 * t).collect()),
            omega: Some(vec![6.0; t.len()]),
            z: vec![],
            stats: Default::default(),
            t,
        }
    }

    #[test]
    fn noise_has_the_rig_statistics_and_is_reproducible() {
        let r = run();
        let a = sample_record(&r, &SensorNoise::RIG, 7, true);
        let b = sample_record(&r, &SensorNoise::RIG, 7, true);
        let c = sample_record(&r, &SensorNoise::RIG, 8, true);
        assert_eq!(a.x, b.x);
        assert_ne!(a.x, c.x);
        let f = a.f_stf.as_ref().unwrap();
        let n = f.len() as f64;
        let sd = (f
            .iter()
            .zip(&r.f_stf)
            .map(|(m, t)| (m - t).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
        assert!((sd - 0.02).abs() < 0.002, "force noise sd {sd}");
        for x in &a.x {
            let q = x / 1e-5;
            assert!(
                (q - q.round()).abs() < 1e-6,
                "x not on the 0.01 mm grid: {x}"
            );
        }
        let step = std::f64::consts::TAU / 2048.0;
        for p in a.phi.as_ref().unwrap() {
            assert!(((p / step) - (p / step).round()).abs() < 1e-6);
        }
        assert!(a.omega.is_none());
    }

    #[test]
    fn exact_records_are_the_run() {
        let r = run();
        let a = sample_record(&r, &SensorNoise::NONE, 1, true);
        assert_eq!(a.x, r.x);
        assert_eq!(a.f_stf.as_ref().unwrap(), &r.f_stf);
        assert_eq!(a.omega.as_ref().unwrap(), r.omega.as_ref().unwrap());
    }
}
