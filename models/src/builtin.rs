//! The shape every built-in model shares, written once: [`builtin!`] declares a model's
//! struct, its parameter specs, `new`/`Default`, its `ENTRY` in the table of `lib.rs`
//! (name, summary, constructor), and the `name`/`summary`/`params` of its `ForceModel`
//! impl; the model's file states only its name, summary, parameters and physics (`force`,
//! `gradient`, …).
//!
//! A macro rather than a trait with default methods: `ForceModel` (in core) needs `params`
//! to lend a slice the model owns, and a trait cannot add fields to a struct.
//!
//! [`linear_builtin!`] declares, on top of it, a model linear in its one parameter,
//! `F = c·φ(state)` (`viscous`, `linear_spring`, `cubic_stiffness`): its equation, force and
//! gradient all come from the one law.

/// Declare a built-in model:
///
/// ```text
/// builtin! {
///     /// Doc of the struct.
///     Viscous: "viscous", "Newtonian drag F = c_s·v",
///     params [ParamSpec::new("c_s", "N·s/m", 2.0, 0.0, 1e4, "damping coefficient")];
///     impl { fn force(…) … }
/// }
/// ```
///
/// makes `pub struct Viscous` with `new()`, `Default` and `ENTRY` (its [`crate::BuiltinEntry`])
/// and its `ForceModel` impl: `name`, `summary`, `params` and the methods in the `impl` block.
macro_rules! builtin {
    (
        $(#[$attr:meta])*
        $ty:ident: $name:literal, $summary:literal,
        params [$($spec:expr),+ $(,)?];
        impl { $($body:tt)* }
    ) => {
        $(#[$attr])*
        pub struct $ty {
            specs: Vec<stf_core::physics::param_spec::ParamSpec>,
        }

        impl $ty {
            /// The model with its parameters at their defaults (the module doc's table).
            pub fn new() -> Self {
                $ty { specs: vec![$($spec),+] }
            }

            /// Its entry in [`crate::BUILTINS`].
            pub const ENTRY: $crate::BuiltinEntry = $crate::BuiltinEntry {
                name: $name,
                summary: $summary,
                build: || std::sync::Arc::new($ty::new()),
            };
        }

        impl Default for $ty {
            fn default() -> Self {
                Self::new()
            }
        }

        impl stf_core::physics::force_model::ForceModel for $ty {
            fn name(&self) -> &str {
                $name
            }
            fn summary(&self) -> &str {
                $summary
            }
            fn params(&self) -> &[stf_core::physics::param_spec::ParamSpec] {
                &self.specs
            }
            $($body)*
        }
    };
}

/// Declare a built-in model linear in its one parameter `c`, `F = c·φ(state)`:
///
/// ```text
/// linear_builtin! {
///     /// Doc of the struct.
///     Viscous: "viscous", "Newtonian drag F = c_s·v",
///     param ParamSpec::new("c_s", "N·s/m", 2.0, 0.0, 1e4, "damping coefficient");
///     law "v", |c, s| c * s.v;
/// }
/// ```
///
/// makes the model of [`builtin!`] whose force is the law at the parameter's value, whose
/// gradient is the law at `c = 1` (exactly φ: 1·y = y in floating point, so the law may
/// multiply `c` in first, as `c * x * x * x` does) and whose equation is `value·symbol`
/// (`2.01·v`).
macro_rules! linear_builtin {
    (
        $(#[$attr:meta])*
        $ty:ident: $name:literal, $summary:literal,
        param $spec:expr;
        law $symbol:literal, |$c:ident, $s:ident| $law:expr;
    ) => {
        $crate::builtin::builtin! {
            $(#[$attr])*
            $ty: $name, $summary,
            params [$spec];
            impl {
                /// The law with its value, `value·symbol`.
                fn equation(&self, values: &[String]) -> Option<String> {
                    let [c] = values else { return None };
                    Some(format!("{c}·{}", $symbol))
                }
                #[inline]
                fn force(
                    &self,
                    p: &[f64],
                    s: &stf_core::physics::force_model::ModelState,
                    _dz: &mut [f64],
                ) -> Result<f64, stf_core::physics::force_model::ModelError> {
                    let [c] = $crate::values::take(self.name(), p)?;
                    Ok(Self::law(c, s))
                }
                fn gradient(
                    &self,
                    p: &[f64],
                    s: &stf_core::physics::force_model::ModelState,
                    _a: f64,
                    grad: &mut [f64],
                ) -> Result<bool, stf_core::physics::force_model::ModelError> {
                    $crate::values::take::<1>(self.name(), p)?;
                    grad[0] = Self::law(1.0, s);
                    Ok(true)
                }
            }
        }

        impl $ty {
            /// The force at coefficient `c` in state `s`.
            #[inline]
            fn law($c: f64, $s: &stf_core::physics::force_model::ModelState) -> f64 {
                $law
            }
        }
    };
}

/// In a state model's `impl` block of [`builtin!`]: `rates` and `mass_and_force` as its
/// `force` (no mass), forced inline. The integration along a record calls them at every stage;
/// the trait's provided versions, which they repeat, are not inlined with the law.
macro_rules! state_forwards {
    () => {
        #[inline(always)]
        fn rates(
            &self,
            p: &[f64],
            s: &stf_core::physics::force_model::ModelState,
            dz: &mut [f64],
        ) -> Result<(), stf_core::physics::force_model::ModelError> {
            self.force(p, s, dz).map(|_| ())
        }
        #[inline(always)]
        fn mass_and_force(
            &self,
            p: &[f64],
            s: &stf_core::physics::force_model::ModelState,
            dz: &mut [f64],
        ) -> Result<(f64, f64), stf_core::physics::force_model::ModelError> {
            Ok((0.0, self.force(p, s, dz)?))
        }
    };
}

pub(crate) use builtin;
pub(crate) use linear_builtin;
pub(crate) use state_forwards;
