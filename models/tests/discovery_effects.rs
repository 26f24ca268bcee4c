//! Discovery names each effect of the vocabulary (docs/ARCHITECTURE.md §5) hidden in a sweep record.
//!
//! Truth: a base model plus one effect contributing a share of the force; the record is the
//! forced rig swept 4 → 10 rad/s at 0.1 rad/s², sampled at 200 Hz with the rig's sensor noise,
//! v and a from the derivative filter (see `discovery_support`). Discovery from the base alone
//! must name exactly that effect and leave a gap within 1.2× the noise floor. When candidates
//! tie, the report must say so.

mod discovery_support;

use discovery_support::{discover, print, record, Part};
use stf_core::discovery::DiscoverySettings;

fn check(effect: &str, truth: &[Part], base: &str) {
    let case = record(truth, 1, false);
    let d = discover(&case, base, &DiscoverySettings::default());
    print(effect, &case, &d);
    assert_eq!(d.effects, [effect], "{:#?}", d.notes);
    assert!(
        d.gap_after <= 1.2 * d.noise_floor,
        "gap after {} N, floor {} N",
        d.gap_after,
        d.noise_floor
    );
    assert!(d.gap_after < d.gap_before);
    // Ties are said, not dropped.
    for s in &d.steps {
        for t in &s.tie_with {
            assert!(s.verdict.contains(t.as_str()), "{}", s.verdict);
        }
    }
}

#[test]
fn names_viscous_on_a_power_law() {
    check(
        "viscous",
        &[("power_law", &[20.0, 2.5]), ("viscous", &[1.0])],
        "power_law",
    );
}

#[test]
fn names_power_law_on_a_viscous_base() {
    check(
        "power_law",
        &[("viscous", &[1.0]), ("power_law", &[20.0, 2.5])],
        "viscous",
    );
}

#[test]
fn names_added_mass() {
    check(
        "added_mass",
        &[("power_law", &[5.0, 1.6]), ("added_mass", &[0.3])],
        "power_law",
    );
}

#[test]
fn names_yield() {
    check(
        "yield",
        &[("power_law", &[5.0, 1.6]), ("yield", &[0.08, 1e-3])],
        "power_law",
    );
}

#[test]
fn names_wall_impact() {
    check(
        "wall_impact",
        &[
            ("power_law", &[5.0, 1.6]),
            ("wall_impact", &[200.0, 0.02, 1.5, 0.5]),
        ],
        "power_law",
    );
}

#[test]
fn names_cubic_stiffness() {
    check(
        "cubic_stiffness",
        &[("power_law", &[5.0, 1.6]), ("cubic_stiffness", &[1e4])],
        "power_law",
    );
}

#[test]
fn names_maxwell() {
    check(
        "maxwell",
        &[("power_law", &[5.0, 1.6]), ("maxwell", &[1.0, 0.05])],
        "power_law",
    );
}

#[test]
fn names_jamming_on_off() {
    check(
        "jamming_on_off",
        &[
            ("power_law", &[5.0, 1.6]),
            ("jamming_on_off", &[20.0, 2.0, 0.08, 0.004]),
        ],
        "power_law",
    );
}

#[test]
fn names_bouc_wen() {
    check(
        "bouc_wen",
        &[("power_law", &[5.0, 1.6]), ("bouc_wen", &[0.3, 3e-3, 0.7])],
        "power_law",
    );
}

#[test]
fn names_linear_spring() {
    check(
        "linear_spring",
        &[("power_law", &[5.0, 1.6]), ("linear_spring", &[20.0])],
        "power_law",
    );
}
