//! Approaching the zero of a switching component (the velocity under dry friction) in
//! shrinking steps instead of stepping over it.
//!
//! Why: near a velocity reversal the smoothed friction `v/sqrt(v² + ε²)` and the speed-dependent
//! static excess `ΔT/(1 + η|v|)` make the right-hand side nearly non-smooth at `v = 0`. An
//! error-controlled explicit method keeps proposing steps across the reversal, is rejected
//! (error estimates of 1e4 are typical), shrinks by at most 5×, grows again, and is rejected
//! again: on the paper's sweep ≈ 22 trials before each of the ≈ 280 reversals, 7 of them
//! rejected. The distance in time to the reversal, `τ`, is the natural step scale there (the
//! nearest singularities of the smoothed terms lie about `τ` away), so after each accepted step
//! the next one is capped at [`APPROACH_FRACTION`]`·τ`: the steps shrink geometrically with the
//! distance and are accepted. The cap is lifted once it would be smaller than half the step
//! that crossed the last reversal (the width of the smoothing band in time, learned from the
//! run; before the first crossing nothing is capped), so the band itself is crossed in an
//! error-controlled step — of at most [`CROSSING_GROWTH`] times the last crossing step: the
//! error controller, after the small steps of the approach, proposes a larger one, which the
//! band rejects (error estimates near 10; 1 rejection a reversal on the paper's sweep). The
//! margin above 1 lets the learned width grow again from one reversal to the next (at 1 it
//! could only shrink). The cap only ever shortens a step: the error control decides as before.

/// Fraction of the predicted time to the zero that the next step may cover.
const APPROACH_FRACTION: f64 = 0.6;
/// No cap below this fraction of the last step that crossed a zero ...
const FLOOR_OF_CROSSING: f64 = 0.5;
/// ... where the step is at most this multiple of that crossing step.
const CROSSING_GROWTH: f64 = 1.1;

/// What the integrator knows about the switching component `j` of the state.
#[derive(Clone, Copy, Debug)]
pub(super) struct Approach {
    j: usize,
    /// Size of the last accepted step over which component `j` changed sign.
    h_cross: f64,
}

impl Approach {
    /// Watch component `j`.
    pub(super) fn new(j: usize) -> Self {
        Approach {
            j,
            h_cross: f64::INFINITY,
        }
    }

    /// The watched component.
    pub(super) fn component(&self) -> usize {
        self.j
    }

    /// Record an accepted step of size `h` from `y_old` to `y_new`.
    pub(super) fn accepted(&mut self, y_old: &[f64], y_new: &[f64], h: f64) {
        if y_old[self.j] * y_new[self.j] <= 0.0 {
            self.h_cross = h;
        }
    }

    /// The next step size: `h_next` (the error controller's proposal), capped at the
    /// approach fraction of the predicted time to the zero of component `j`, or, that close to
    /// the zero, at the crossing growth times the last crossing step. `(y, f)` is the
    /// state and its derivative at the new step start, `f_old_j` the derivative of component
    /// `j` one step (`h`) earlier (for its rate of change).
    pub(super) fn cap(&self, h_next: f64, y: &[f64], f: &[f64], f_old_j: f64, h: f64) -> f64 {
        let (v, a) = (y[self.j], f[self.j]);
        if !(v * a < 0.0) {
            return h_next;
        }
        let tau = time_to_zero(v, a, (a - f_old_j) / h);
        let capped = APPROACH_FRACTION * tau;
        if capped > FLOOR_OF_CROSSING * self.h_cross {
            h_next.min(capped)
        } else {
            h_next.min(CROSSING_GROWTH * self.h_cross)
        }
    }
}

/// The first positive time at which `v + a·s + ½·j·s²` vanishes, for `v·a < 0`: the root of
/// the quadratic near the linear guess `−v/a` when it is real and earlier, else `−v/a`.
fn time_to_zero(v: f64, a: f64, j: f64) -> f64 {
    let linear = -v / a;
    let disc = a * a - 2.0 * j * v;
    if !(disc > 0.0) {
        return linear;
    }
    // The root that tends to −v/a as j → 0, in the form without cancellation.
    let s = 2.0 * v / (-a - a.signum() * disc.sqrt());
    if s > 0.0 && s < linear {
        s
    } else {
        linear
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_to_zero_solves_the_quadratic_and_falls_back_to_the_linear_guess() {
        // v = 1, a = −1, j = −0.5: 1 − s − s²/4 = 0 → s = 2(√2 − 1).
        let s = time_to_zero(1.0, -1.0, -0.5);
        assert!((s - 2.0 * (2.0f64.sqrt() - 1.0)).abs() < 1e-12, "{s}");
        assert!((1.0 - s - 0.25 * s * s).abs() < 1e-12);
        // Decelerating less and less (j > 0 large): no real root, the linear guess.
        assert_eq!(time_to_zero(1.0, -1.0, 10.0), 1.0);
        // Same for a negative velocity rising to zero.
        let s = time_to_zero(-1.0, 1.0, 0.5);
        assert!((-1.0 + s + 0.25 * s * s).abs() < 1e-12, "{s}");
    }

    #[test]
    fn caps_only_towards_a_zero_and_only_above_the_learned_floor() {
        let mut ap = Approach::new(1);
        let (y, f) = ([0.0, 1e-3], [1e-3, -1.0]); // τ = 1e-3 s ahead
                                                  // Before any crossing: no floor known, no cap.
        assert_eq!(ap.cap(1.0, &y, &f, -1.0, 1e-2), 1.0);
        ap.accepted(&[0.0, 1e-4], &[0.0, -1e-4], 1e-5);
        let h = ap.cap(1.0, &y, &f, -1.0, 1e-2);
        assert!((h - APPROACH_FRACTION * 1e-3).abs() < 1e-15, "{h}");
        // A smaller proposal stands.
        assert_eq!(ap.cap(1e-4, &y, &f, -1.0, 1e-2), 1e-4);
        // Moving away from zero: no cap.
        assert_eq!(ap.cap(1.0, &y, &[1e-3, 1.0], 1.0, 1e-2), 1.0);
        // Closer to the zero than the floor: the step may cross, at most a little longer than
        // the last crossing step.
        let near = [0.0, 1e-6];
        assert_eq!(ap.cap(1.0, &near, &f, -1.0, 1e-2), CROSSING_GROWTH * 1e-5);
        assert_eq!(ap.cap(1e-6, &near, &f, -1.0, 1e-2), 1e-6);
    }
}
