//! A model parameter that follows a measured channel of the record (a control voltage, a
//! temperature): the parameter P becomes a law of the channel's value c at each instant,
//!
//! | law | P(c) | coefficients |
//! |---|---|---|
//! | [`Law::Linear`] | P_gain·c | `P_gain` |
//! | [`Law::Affine`] | P_base + P_gain·c | `P_base`, `P_gain` |
//! | [`Law::Power`] | P_base + P_gain·\|c\|^P_exp | `P_base`, `P_gain`, `P_exp` |
//!
//! [`ChannelLaw`] wraps a model: it replaces P among the parameters by the law's coefficients
//! (in P's place), reads the channel at the state's time ([`MeasuredChannel::at`], linear
//! interpolation, so a trajectory integrator's intermediate stages see it too) and hands the
//! wrapped model P's value, clamped into P's bounds. Being a model, it goes wherever a model
//! goes: force and trajectory fits, sums, discovery's base. Starts and bounds (the design
//! page's "Parameters that follow a measured channel"): `P_base` starts at P's default within
//! P's bounds, `P_gain` at 0 within ± P's range over the channel's largest |c|, `P_exp` at 1
//! within [0.1, 4].

use std::sync::Arc;

use crate::physics::force_model::{ForceModel, ModelError, ModelState};
use crate::physics::param_spec::ParamSpec;

/// Bounds of a power law's exponent.
pub const EXPONENT_BOUNDS: (f64, f64) = (0.1, 4.0);

/// How a parameter follows its channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Law {
    /// P = P_gain·c: zero when the channel is.
    Linear,
    /// P = P_base + P_gain·c.
    Affine,
    /// P = P_base + P_gain·|c|^P_exp: a power law with an offset.
    Power,
}

impl Law {
    /// The law named `name` (`linear`, `affine`, `power`).
    pub fn named(name: &str) -> Option<Law> {
        match name {
            "linear" => Some(Law::Linear),
            "affine" => Some(Law::Affine),
            "power" => Some(Law::Power),
            _ => None,
        }
    }

    /// Its name in experiment files.
    pub fn name(self) -> &'static str {
        match self {
            Law::Linear => "linear",
            Law::Affine => "affine",
            Law::Power => "power",
        }
    }

    /// The suffixes of its coefficients' names, in their order.
    pub fn coefficients(self) -> &'static [&'static str] {
        match self {
            Law::Linear => &["gain"],
            Law::Affine => &["base", "gain"],
            Law::Power => &["base", "gain", "exp"],
        }
    }

    /// P at channel value `c` with coefficients `k` (in [`Law::coefficients`]' order).
    #[inline]
    pub fn value(self, k: &[f64], c: f64) -> f64 {
        match self {
            Law::Linear => k[0] * c,
            Law::Affine => k[0] + k[1] * c,
            Law::Power => k[0] + k[1] * c.abs().powf(k[2]),
        }
    }

    /// ∂P/∂k at `c`, written to `d` (one entry per coefficient).
    #[inline]
    fn derivatives(self, k: &[f64], c: f64, d: &mut [f64]) {
        match self {
            Law::Linear => d[0] = c,
            Law::Affine => {
                d[0] = 1.0;
                d[1] = c;
            }
            Law::Power => {
                let a = c.abs();
                let pw = a.powf(k[2]);
                d[0] = 1.0;
                d[1] = pw;
                d[2] = if a > 0.0 { k[1] * pw * a.ln() } else { 0.0 };
            }
        }
    }
}

/// A measured column of the record on its time grid, read at any time by linear
/// interpolation (held at its end values outside the grid).
#[derive(Clone, Debug, PartialEq)]
pub struct MeasuredChannel {
    name: String,
    t: Vec<f64>,
    values: Vec<f64>,
}

impl MeasuredChannel {
    /// The channel `name` sampled at the strictly increasing times `t`; an error when the
    /// lengths differ, it is empty, or a value is not finite.
    pub fn new(name: &str, t: Vec<f64>, values: Vec<f64>) -> Result<Self, ModelError> {
        let bad = |why: String| Err(ModelError::new(format!("channel `{name}`"), why));
        if t.len() != values.len() || t.is_empty() {
            return bad(format!(
                "{} times and {} values: it needs one value per sample",
                t.len(),
                values.len()
            ));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return bad(format!("value {} (sample {i}) is not a number", values[i]));
        }
        if t.windows(2).any(|w| w[1] <= w[0]) {
            return bad("its times must increase strictly".into());
        }
        Ok(MeasuredChannel {
            name: name.to_string(),
            t,
            values,
        })
    }

    /// Its name (the record's column).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The value at time `t`.
    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        let n = self.t.len();
        let i = self.t.partition_point(|&ti| ti <= t);
        if i == 0 {
            return self.values[0];
        }
        if i == n {
            return self.values[n - 1];
        }
        let (t0, t1) = (self.t[i - 1], self.t[i]);
        let w = (t - t0) / (t1 - t0);
        self.values[i - 1] + w * (self.values[i] - self.values[i - 1])
    }

    /// The largest |c| it reaches.
    pub fn max_abs(&self) -> f64 {
        self.values.iter().fold(0.0, |m, v| m.max(v.abs()))
    }
}

/// Most parameters a wrapped model may have for the per-sample buffer on the stack.
const STACK: usize = 32;

/// A model with one parameter replaced by a law of a measured channel; see the module doc.
pub struct ChannelLaw {
    inner: Arc<dyn ForceModel>,
    /// Where the parameter sits among the inner model's parameters.
    index: usize,
    law: Law,
    channel: Arc<MeasuredChannel>,
    /// The inner parameter's bounds: the law's value is clamped into them.
    bounds: (f64, f64),
    specs: Vec<ParamSpec>,
    /// Its own name, where it stands as an effect of its own ([`ChannelLaw::named`]).
    name: Option<String>,
}

impl ChannelLaw {
    /// `inner` with its parameter `param` following `channel` by `law`; an error naming the
    /// model when it has no such parameter.
    pub fn new(
        inner: Arc<dyn ForceModel>,
        param: &str,
        law: Law,
        channel: Arc<MeasuredChannel>,
    ) -> Result<Self, ModelError> {
        let specs = inner.params();
        let Some(index) = specs.iter().position(|s| s.name == param) else {
            let known: Vec<&str> = specs.iter().map(|s| s.name.as_str()).collect();
            return Err(ModelError::new(
                inner.name(),
                format!(
                    "has no parameter `{param}` to follow channel `{}`; its parameters: {}",
                    channel.name(),
                    known.join(", ")
                ),
            ));
        };
        if specs.len() > STACK {
            return Err(ModelError::new(
                inner.name(),
                format!("a law needs a model of at most {STACK} parameters"),
            ));
        }
        let p = &specs[index];
        let coefficient_specs = coefficient_specs(p, law, &channel);
        let mut all: Vec<ParamSpec> = specs[..index].to_vec();
        all.extend(coefficient_specs);
        all.extend_from_slice(&specs[index + 1..]);
        Ok(ChannelLaw {
            bounds: (p.min, p.max),
            inner,
            index,
            law,
            channel,
            specs: all,
            name: None,
        })
    }

    /// The same model under its own name (and as a single term), where it stands beside the
    /// model it wraps in a sum: discovery's "P follows the channel" effect.
    pub fn named(mut self, name: impl Into<String>) -> Self {
        self.name = Some(name.into());
        self
    }

    /// The law.
    pub fn law(&self) -> Law {
        self.law
    }

    /// The inner model's parameter values at time `t`, written to `out`, from this model's
    /// values `p`; the number written.
    #[inline]
    fn inner_values(&self, p: &[f64], t: f64, out: &mut [f64; STACK]) -> Result<usize, ModelError> {
        let nk = self.law.coefficients().len();
        let n = self.specs.len() + 1 - nk;
        if p.len() < self.specs.len() {
            return Err(ModelError::new(
                self.inner.name(),
                format!(
                    "expects {} parameter values, got {}",
                    self.specs.len(),
                    p.len()
                ),
            ));
        }
        let (lo, hi) = self.bounds;
        let value = self
            .law
            .value(&p[self.index..self.index + nk], self.channel.at(t));
        out[..self.index].copy_from_slice(&p[..self.index]);
        out[self.index] = value.clamp(lo, hi);
        out[self.index + 1..n].copy_from_slice(&p[self.index + nk..self.specs.len()]);
        Ok(n)
    }
}

/// The specs of `law`'s coefficients for the parameter `p` following `channel`.
fn coefficient_specs(p: &ParamSpec, law: Law, channel: &MeasuredChannel) -> Vec<ParamSpec> {
    let reach = channel.max_abs();
    let range = p.max - p.min;
    let gain_bound = if reach > 0.0 && range.is_finite() {
        // With an exponent, |c|^e over its bounds is smallest at one end.
        let spread = match law {
            Law::Power => reach
                .powf(EXPONENT_BOUNDS.0)
                .min(reach.powf(EXPONENT_BOUNDS.1)),
            _ => reach,
        };
        range / spread
    } else {
        f64::INFINITY
    };
    let unit = format!("{}/[{}]", p.unit, channel.name());
    law.coefficients()
        .iter()
        .map(|&suffix| {
            let name = format!("{}_{suffix}", p.name);
            match suffix {
                "base" => {
                    let mut s = ParamSpec::new(
                        &name,
                        &p.unit,
                        p.default,
                        p.min,
                        p.max,
                        &format!("{} where `{}` is 0", p.name, channel.name()),
                    );
                    s.same_as = p.same_as;
                    s
                }
                "gain" => ParamSpec::new(
                    &name,
                    &unit,
                    0.0,
                    -gain_bound,
                    gain_bound,
                    &format!(
                        "how {} follows `{}` ({} law)",
                        p.name,
                        channel.name(),
                        law.name()
                    ),
                ),
                _ => ParamSpec::new(
                    &name,
                    "",
                    1.0,
                    EXPONENT_BOUNDS.0,
                    EXPONENT_BOUNDS.1,
                    &format!("exponent of |{}| in {}", channel.name(), p.name),
                ),
            }
        })
        .collect()
}

impl ForceModel for ChannelLaw {
    fn name(&self) -> &str {
        self.name.as_deref().unwrap_or_else(|| self.inner.name())
    }
    fn summary(&self) -> &str {
        self.inner.summary()
    }
    fn terms(&self) -> Vec<&str> {
        match &self.name {
            Some(name) => vec![name.as_str()],
            None => self.inner.terms(),
        }
    }
    fn params(&self) -> &[ParamSpec] {
        &self.specs
    }
    fn n_internal(&self) -> usize {
        self.inner.n_internal()
    }
    fn initial_internal(&self, p: &[f64], z0: &mut [f64]) {
        let mut buf = [0.0; STACK];
        match self.inner_values(p, f64::NEG_INFINITY, &mut buf) {
            Ok(n) => self.inner.initial_internal(&buf[..n], z0),
            Err(_) => z0.fill(0.0),
        }
    }
    fn added_mass(&self, p: &[f64], s: &ModelState) -> Result<f64, ModelError> {
        let mut buf = [0.0; STACK];
        let n = self.inner_values(p, s.t, &mut buf)?;
        self.inner.added_mass(&buf[..n], s)
    }
    fn force(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<f64, ModelError> {
        let mut buf = [0.0; STACK];
        let n = self.inner_values(p, s.t, &mut buf)?;
        self.inner.force(&buf[..n], s, dz)
    }
    fn mass_and_force(
        &self,
        p: &[f64],
        s: &ModelState,
        dz: &mut [f64],
    ) -> Result<(f64, f64), ModelError> {
        let mut buf = [0.0; STACK];
        let n = self.inner_values(p, s.t, &mut buf)?;
        self.inner.mass_and_force(&buf[..n], s, dz)
    }
    fn rates(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<(), ModelError> {
        let mut buf = [0.0; STACK];
        let n = self.inner_values(p, s.t, &mut buf)?;
        self.inner.rates(&buf[..n], s, dz)
    }
    /// The chain rule through the law: the inner model's gradient (where it gives one) times
    /// ∂P/∂coefficient; zero for the coefficients while the law's value is clamped.
    fn gradient(
        &self,
        p: &[f64],
        s: &ModelState,
        a: f64,
        grad: &mut [f64],
    ) -> Result<bool, ModelError> {
        let mut buf = [0.0; STACK];
        let n = self.inner_values(p, s.t, &mut buf)?;
        let mut inner = [0.0; STACK];
        if !self.inner.gradient(&buf[..n], s, a, &mut inner[..n])? {
            return Ok(false);
        }
        let nk = self.law.coefficients().len();
        let (i, m) = (self.index, self.specs.len());
        grad[..i].copy_from_slice(&inner[..i]);
        grad[i + nk..m].copy_from_slice(&inner[i + 1..n]);
        let c = self.channel.at(s.t);
        let k = &p[i..i + nk];
        let (lo, hi) = self.bounds;
        let v = self.law.value(k, c);
        let mut d = [0.0; 3];
        self.law.derivatives(k, c, &mut d[..nk]);
        let through = if v < lo || v > hi { 0.0 } else { inner[i] };
        for (g, dk) in grad[i..i + nk].iter_mut().zip(&d[..nk]) {
            *g = through * dk;
        }
        Ok(true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Lin(Vec<ParamSpec>);
    impl ForceModel for Lin {
        fn name(&self) -> &str {
            "lin"
        }
        fn params(&self) -> &[ParamSpec] {
            &self.0
        }
        fn force(&self, p: &[f64], s: &ModelState, _: &mut [f64]) -> Result<f64, ModelError> {
            Ok(p[0] * s.v + p[1] * s.x)
        }
        fn gradient(
            &self,
            _p: &[f64],
            s: &ModelState,
            _a: f64,
            g: &mut [f64],
        ) -> Result<bool, ModelError> {
            g[0] = s.v;
            g[1] = s.x;
            Ok(true)
        }
    }

    fn lin() -> Arc<dyn ForceModel> {
        Arc::new(Lin(vec![
            ParamSpec::new("c", "N·s/m", 1.0, 0.0, 10.0, "damping"),
            ParamSpec::new("k", "N/m", 2.0, 0.0, 100.0, "stiffness"),
        ]))
    }

    fn step_channel() -> Arc<MeasuredChannel> {
        Arc::new(MeasuredChannel::new("u", vec![0.0, 1.0, 2.0], vec![0.0, 0.0, 2.0]).unwrap())
    }

    #[test]
    fn the_channel_interpolates_and_holds_its_ends() {
        let ch = step_channel();
        assert_eq!(ch.at(-1.0), 0.0);
        assert_eq!(ch.at(1.5), 1.0);
        assert_eq!(ch.at(5.0), 2.0);
        assert_eq!(ch.max_abs(), 2.0);
        assert!(MeasuredChannel::new("u", vec![0.0, 0.0], vec![1.0, 2.0]).is_err());
        assert!(MeasuredChannel::new("u", vec![0.0], vec![f64::NAN]).is_err());
        assert!(MeasuredChannel::new("u", vec![0.0, 1.0], vec![1.0]).is_err());
    }

    #[test]
    fn the_coefficients_take_the_parameters_place_and_the_law_drives_it() {
        let m = ChannelLaw::new(lin(), "c", Law::Affine, step_channel()).unwrap();
        let names: Vec<&str> = m.params().iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["c_base", "c_gain", "k"]);
        // Gain bounds: c's range 10 over |u| up to 2.
        assert_eq!(m.params()[1].min, -5.0);
        let s = ModelState {
            t: 2.0,
            x: 0.5,
            v: 1.0,
            z: &[],
        };
        // c = 1 + 2·2 = 5; F = 5·1 + 4·0.5.
        assert_eq!(m.force(&[1.0, 2.0, 4.0], &s, &mut []).unwrap(), 7.0);
        // Clamped into c's bounds [0, 10]: 1 + 2·8 → 10.
        assert_eq!(m.force(&[1.0, 8.0, 4.0], &s, &mut []).unwrap(), 12.0);
        assert!(ChannelLaw::new(lin(), "nope", Law::Linear, step_channel()).is_err());
    }

    #[test]
    fn the_gradient_is_the_chain_rule_and_matches_differences() {
        for law in [Law::Linear, Law::Affine, Law::Power] {
            let m = ChannelLaw::new(lin(), "c", law, step_channel()).unwrap();
            let p: Vec<f64> = match law {
                Law::Linear => vec![1.5, 4.0],
                Law::Affine => vec![0.5, 1.5, 4.0],
                Law::Power => vec![0.5, 1.5, 1.3, 4.0],
            };
            let s = ModelState {
                t: 1.7,
                x: 0.3,
                v: 0.8,
                z: &[],
            };
            let mut g = vec![0.0; p.len()];
            assert!(m.gradient(&p, &s, 0.0, &mut g).unwrap());
            for j in 0..p.len() {
                let h = 1e-6;
                let (mut up, mut dn) = (p.clone(), p.clone());
                up[j] += h;
                dn[j] -= h;
                let fd = (m.force(&up, &s, &mut []).unwrap() - m.force(&dn, &s, &mut []).unwrap())
                    / (2.0 * h);
                assert!((fd - g[j]).abs() < 1e-6, "{law:?} {j}: {fd} vs {}", g[j]);
            }
        }
    }
}
