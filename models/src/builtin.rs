//! The shape every built-in model shares, written once: [`builtin!`] declares a model's
//! struct, its parameter specs, `new`/`Default`, its `ENTRY` in the table of `lib.rs`
//! (name, summary, constructor), and the `name`/`summary`/`params` of its `ForceModel`
//! impl; the model's file states only its name, summary, parameters and physics (`force`,
//! `gradient`, …).
//!
//! A macro rather than a trait with default methods: `ForceModel` (in core) needs `params`
//! to lend a slice the model owns, and a trait cannot add fields to a struct.

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

pub(crate) use builtin;
