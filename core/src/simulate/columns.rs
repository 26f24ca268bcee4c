//! The columns of a simulated run, filled sample by sample: the drive (and rotor angle) at each
//! output time, and the state and forces at each sample.
//!
//! The samples are independent of each other once the integration has produced the states, so
//! a long run fills them on two threads ([`PARALLEL_SAMPLES`]); the drive depends on time alone
//! and is evaluated while the integration runs.

use crate::numerics::integrate::SimError;
use crate::physics::excitation::Excitation;
use crate::physics::oscillator::Oscillator;
use crate::physics::oscillator_params::OscillatorParams;

/// Sampled states with their times and driving forces (a window of a run's samples).
#[derive(Clone, Copy)]
pub(super) struct Rows<'r> {
    pub(super) states: &'r [f64],
    pub(super) dim: usize,
    pub(super) times: &'r [f64],
    pub(super) drive: &'r [f64],
}

impl<'r> Rows<'r> {
    /// Samples `from..to`.
    pub(super) fn window(&self, from: usize, to: usize) -> Rows<'r> {
        Rows {
            states: &self.states[from * self.dim..to * self.dim],
            dim: self.dim,
            times: &self.times[from..to],
            drive: &self.drive[from..to],
        }
    }

    /// Write the state and the forces of each sample into `out` (as long as the window); the
    /// first model error ends it.
    pub(super) fn fill(&self, osc: &Oscillator, mut out: Columns) -> Result<(), SimError> {
        let mut dz = vec![0.0; osc.n_internal()];
        let [x, v, a, f_stf, z @ ..] = out.0.as_mut_slice() else {
            unreachable!("the columns start with x, v, a and F_STF")
        };
        let rows = self
            .states
            .chunks_exact(self.dim)
            .zip(self.times)
            .zip(self.drive);
        // The four kinematic columns by name, the internal states (if any) in a loop: no
        // per-sample iteration over a list of columns where there is no model.
        for (i, ((y, &t), &d)) in rows.enumerate() {
            let f = osc.forces_with_drive(t, y, d, &mut dz)?;
            (x[i], v[i], a[i], f_stf[i]) = (y[0], y[1], f.a, f.f_stf);
            for (column, &value) in z.iter_mut().zip(&y[2..]) {
                column[i] = value;
            }
        }
        Ok(())
    }
}

/// The output columns of a window of samples: x, v, a, F_STF, then the model's internal
/// states.
pub(super) struct Columns<'c>(pub(super) Vec<&'c mut [f64]>);

impl<'c> Columns<'c> {
    /// Samples `..mid` and `mid..`.
    pub(super) fn split_at(self, mid: usize) -> (Columns<'c>, Columns<'c>) {
        let (first, second) = self.0.into_iter().map(|c| c.split_at_mut(mid)).unzip();
        (Columns(first), Columns(second))
    }
}

/// From this many samples on, [`Simulation`] uses a second thread: for the drive while it
/// integrates, then for half of the samples' forces (below, the thread would cost more than it
/// saves: a spawn is ≈ 20–50 µs, a sample's drive or forces ≈ 10–15 ns).
pub(super) const PARALLEL_SAMPLES: usize = 20_000;

/// The driving force at each sample and, for a rotor, its angle and speed.
pub(super) struct DriveColumns {
    pub(super) force: Vec<f64>,
    pub(super) phi: Option<Vec<f64>>,
    pub(super) omega: Option<Vec<f64>>,
}

impl DriveColumns {
    pub(super) fn at(excitation: &Excitation, p: &OscillatorParams, times: &[f64]) -> Self {
        let Excitation::Rotor(angle) = excitation else {
            return DriveColumns {
                force: times.iter().map(|&t| excitation.force(t, p)).collect(),
                phi: None,
                omega: None,
            };
        };
        // Angle and speed first, then the force over both columns (the same values as
        // `Excitation::force_and_angle` at each time, without tuples to unzip).
        let (phi, omega): (Vec<f64>, Vec<f64>) = times.iter().map(|&t| angle.at(t)).unzip();
        let force = phi
            .iter()
            .zip(&omega)
            .map(|(&phi, &w)| Excitation::rotor_force(p, phi, w))
            .collect();
        DriveColumns {
            force,
            phi: Some(phi),
            omega: Some(omega),
        }
    }
}
