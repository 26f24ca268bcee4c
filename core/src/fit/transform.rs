//! Bounds honoured by a change of variables, never by clipping.
//!
//! The optimisers work on unbounded internal coordinates `u`; each parameter maps `u` to its
//! user value `x` inside its bounds. The maps are scaled so that `u = 0` is the start value
//! and `dx/du = scale` there, so a unit step in `u` is one "typical size" of the parameter for
//! every kind of bound:
//!
//! ```text
//! no bounds        x = x0 + s·u
//! lower bound a    x = a + d·exp(s·u/d),            d = x0 − a
//! upper bound b    x = b − d·exp(−s·u/d),           d = b − x0
//! both a < b       x = a + (b − a)·σ(w0 + c·u),     σ(w) = 1/(1 + e^−w),  σ(w0) = (x0 − a)/(b − a)
//! ```
//!
//! A start value on a bound is moved just inside it (by 1e-3 of the scale or of the width),
//! since the interior maps never reach their bounds; a start inside stays where it is, however
//! close to a bound (within 1e-12 of the width, for rounding). The scale is capped at the distance to
//! the nearest bound (and a quarter of the width): otherwise a unit step from a start near a
//! bound would saturate the map, where its slope vanishes and an optimiser gets stuck.

/// The four shapes of bound.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Shape {
    Free,
    Lower { d: f64 },
    Upper { d: f64 },
    Both { w0: f64, c: f64 },
}

/// The change of variables of one parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundTransform {
    min: f64,
    max: f64,
    x0: f64,
    scale: f64,
    shape: Shape,
}

/// Largest |w| of the logistic map explored by a global search (σ ∈ [1.2e-4, 1 − 1.2e-4]).
const LOGIT_SPAN: f64 = 9.0;
/// Closest an interior start may lie to a bound of two, as a fraction of the width (a start
/// closer than this is moved to it; one on the bound moves by 1e-3 of the width).
const EDGE: f64 = 1e-12;
/// Half-width of the global search box, in units of the scale, for maps without two bounds.
const FREE_SPAN: f64 = 5.0;

fn logistic(w: f64) -> f64 {
    1.0 / (1.0 + (-w).exp())
}

impl BoundTransform {
    /// The map for a parameter starting at `x0` with bounds `[min, max]` (either may be
    /// infinite) and typical size `scale` (> 0). The caller has checked `min < max` and
    /// `min ≤ x0 ≤ max`.
    pub fn new(x0: f64, min: f64, max: f64, scale: f64) -> Self {
        let scale = if scale > 0.0 && scale.is_finite() {
            scale
        } else {
            1.0
        };
        let (x0, scale, shape) = match (min.is_finite(), max.is_finite()) {
            (false, false) => (x0, scale, Shape::Free),
            (true, false) => {
                let x0 = x0.max(min + 1e-3 * scale);
                (x0, scale.min(x0 - min), Shape::Lower { d: x0 - min })
            }
            (false, true) => {
                let x0 = x0.min(max - 1e-3 * scale);
                (x0, scale.min(max - x0), Shape::Upper { d: max - x0 })
            }
            (true, true) => {
                let width = max - min;
                // Only a start on (or numerically at) a bound moves: an interior start stays
                // where it is however close to a bound (moving k = 554 in [0, 1e9] to the
                // "inside" 1e6 made a fit from the optimum start far from it).
                let s = (x0 - min) / width;
                let x0 = if (EDGE..=1.0 - EDGE).contains(&s) {
                    x0
                } else if s > 0.0 && s < 1.0 {
                    x0.clamp(min + EDGE * width, max - EDGE * width)
                } else {
                    let nudge = 1e-3 * width;
                    x0.clamp(min + nudge, max - nudge)
                };
                let scale = scale.min(0.25 * width).min(x0 - min).min(max - x0);
                let s0 = (x0 - min) / width;
                let w0 = (s0 / (1.0 - s0)).ln();
                let c = scale / (width * s0 * (1.0 - s0));
                (x0, scale, Shape::Both { w0, c })
            }
        };
        BoundTransform {
            min,
            max,
            x0,
            scale,
            shape,
        }
    }

    /// The start value actually used (moved inside if it was on a bound).
    pub fn start(&self) -> f64 {
        self.x0
    }

    /// The user value at internal coordinate `u`; always within the bounds.
    pub fn to_user(&self, u: f64) -> f64 {
        match self.shape {
            Shape::Free => self.x0 + self.scale * u,
            Shape::Lower { d } => self.min + d * (self.scale * u / d).exp(),
            Shape::Upper { d } => self.max - d * (-self.scale * u / d).exp(),
            Shape::Both { w0, c } => {
                // The clamp only guards the last bit of rounding; σ itself lies in [0, 1].
                (self.min + (self.max - self.min) * logistic(w0 + c * u)).clamp(self.min, self.max)
            }
        }
    }

    /// The slope `dx/du` of the map at internal coordinate `u`.
    pub fn slope(&self, u: f64) -> f64 {
        match self.shape {
            Shape::Free => self.scale,
            Shape::Lower { d } => self.scale * (self.scale * u / d).exp(),
            Shape::Upper { d } => self.scale * (-self.scale * u / d).exp(),
            Shape::Both { w0, c } => {
                let s = logistic(w0 + c * u);
                (self.max - self.min) * s * (1.0 - s) * c
            }
        }
    }

    /// Whether the map is flat at `u` (its slope below 1 % of the scale): the parameter
    /// presses on a bound.
    pub fn saturated(&self, u: f64) -> bool {
        self.slope(u) < 1e-2 * self.scale
    }

    /// The internal coordinate of user value `x`; `None` outside the open interior.
    pub fn to_internal(&self, x: f64) -> Option<f64> {
        let u = match self.shape {
            Shape::Free => (x - self.x0) / self.scale,
            Shape::Lower { d } => {
                if x.partial_cmp(&self.min) != Some(std::cmp::Ordering::Greater) {
                    return None;
                }
                d / self.scale * ((x - self.min) / d).ln()
            }
            Shape::Upper { d } => {
                if x.partial_cmp(&self.max) != Some(std::cmp::Ordering::Less) {
                    return None;
                }
                -d / self.scale * ((self.max - x) / d).ln()
            }
            Shape::Both { w0, c } => {
                if !(x > self.min && x < self.max) {
                    return None;
                }
                let s = (x - self.min) / (self.max - self.min);
                ((s / (1.0 - s)).ln() - w0) / c
            }
        };
        u.is_finite().then_some(u)
    }

    /// The box in `u` that a global search explores: the whole interior for two bounds
    /// (up to σ = 1.2e-4 from either end), ±5 scales (or e^±5 of the distance to the bound)
    /// otherwise.
    pub fn search_box(&self) -> (f64, f64) {
        match self.shape {
            Shape::Free => (-FREE_SPAN, FREE_SPAN),
            Shape::Lower { d } | Shape::Upper { d } => {
                let r = FREE_SPAN * d / self.scale;
                (-r, r)
            }
            Shape::Both { w0, c } => ((-LOGIT_SPAN - w0) / c, (LOGIT_SPAN - w0) / c),
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn bounds() -> impl Strategy<Value = (f64, f64)> {
        prop_oneof![
            Just((f64::NEG_INFINITY, f64::INFINITY)),
            (-1e3..1e3f64).prop_map(|a| (a, f64::INFINITY)),
            (-1e3..1e3f64).prop_map(|b| (f64::NEG_INFINITY, b)),
            (-1e3..1e3f64, 1e-3..1e3f64).prop_map(|(a, w)| (a, a + w)),
        ]
    }

    proptest! {
        #[test]
        fn user_values_never_leave_the_bounds(
            (min, max) in bounds(), t in 0.0..=1.0f64, scale in 1e-4..1e3f64, u in -1e6..1e6f64,
        ) {
            let x0 = match (min.is_finite(), max.is_finite()) {
                (true, true) => min + t * (max - min),
                (true, false) => min + t * 10.0,
                (false, true) => max - t * 10.0,
                _ => t,
            };
            let tr = BoundTransform::new(x0, min, max, scale);
            let x = tr.to_user(u);
            prop_assert!(x >= min && x <= max, "x = {x} outside [{min}, {max}]");
            prop_assert!(tr.to_user(0.0) == tr.start() || (tr.to_user(0.0) - tr.start()).abs() <= 1e-9 * (1.0 + tr.start().abs()));
        }

        #[test]
        fn round_trips_inside(
            (min, max) in bounds(), t in 0.01..0.99f64, v in 0.01..0.99f64, scale in 1e-2..1e2f64,
        ) {
            let pick = |f: f64| match (min.is_finite(), max.is_finite()) {
                (true, true) => min + f * (max - min),
                (true, false) => min + f * 10.0,
                (false, true) => max - f * 10.0,
                _ => f * 10.0 - 5.0,
            };
            let tr = BoundTransform::new(pick(t), min, max, scale);
            let x = pick(v);
            let u = tr.to_internal(x).unwrap();
            let back = tr.to_user(u);
            let width = if min.is_finite() && max.is_finite() { max - min } else { 10.0 };
            prop_assert!((back - x).abs() <= 1e-9 * (width + x.abs()), "{x} -> {u} -> {back}");
        }
    }

    #[test]
    fn unit_step_is_one_scale_at_the_start() {
        for (min, max) in [
            (f64::NEG_INFINITY, f64::INFINITY),
            (0.0, f64::INFINITY),
            (f64::NEG_INFINITY, 10.0),
            (0.0, 10.0),
        ] {
            let tr = BoundTransform::new(2.0, min, max, 0.5);
            let h = 1e-6;
            let slope = (tr.to_user(h) - tr.to_user(-h)) / (2.0 * h);
            assert!((slope - 0.5).abs() < 1e-6, "{min} {max}: slope {slope}");
        }
    }

    #[test]
    fn an_interior_start_stays_put_however_wide_the_bounds() {
        // A stiffness fitted to 554 in [0, 1e9]: the start of a refit must be 554, not the
        // 1e6 that "1e-3 of the width inside" would make it.
        for (x0, min, max) in [
            (554.0, 0.0, 1e9),
            (2.7e-9, 0.0, 10.0),
            (3.0 - 1e-6, 1.0, 3.0),
        ] {
            let tr = BoundTransform::new(x0, min, max, x0);
            assert_eq!(tr.start(), x0);
            assert!(
                (tr.to_user(0.0) - x0).abs() <= 1e-12 * x0,
                "{x0}: {}",
                tr.to_user(0.0)
            );
            // And the map still moves it by about one scale per unit step.
            let h = 1e-6;
            let slope = (tr.to_user(h) - tr.to_user(-h)) / (2.0 * h);
            let scale = x0.min(0.25 * (max - min)).min(max - x0);
            assert!((slope / scale - 1.0).abs() < 1e-3, "{x0}: slope {slope}");
        }
    }

    #[test]
    fn a_start_on_a_bound_moves_inside() {
        let tr = BoundTransform::new(1.0, 1.0, 4.0, 1.0);
        assert!(tr.start() > 1.0 && tr.start() < 1.01);
        let (lo, hi) = tr.search_box();
        assert!(tr.to_user(lo) > 1.0 && tr.to_user(hi) < 4.0 && lo < 0.0 && hi > 0.0);
    }
}
