//! Discovery names nothing when the base is the truth, and names two hidden effects in the
//! order of how much they explain. Records as in `discovery_effects.rs`.
//!
//! With cubic_stiffness and added_mass hidden, `wall_impact` (whose gap and exponent bend to
//! mimic a cubic spring softened by the added mass) wins the first step; once `added_mass` is
//! in, the earlier choice is tried again and `cubic_stiffness` explains the data as well with
//! one parameter instead of four, so it replaces `wall_impact` and the tie is reported.

mod discovery_support;

use discovery_support::{discover, print, record};
use stf_core::discovery::DiscoverySettings;

#[test]
fn no_false_discovery_on_the_base_alone() {
    for seed in [1, 2, 3] {
        let case = record(&[("power_law", &[5.0, 1.6])], seed, false);
        let d = discover(&case, "power_law", &DiscoverySettings::default());
        print(&format!("base alone, seed {seed}"), &case, &d);
        assert!(d.effects.is_empty(), "seed {seed}: {:#?}", d.notes);
        assert_eq!(d.gap_after, d.gap_before);
    }
}

#[test]
fn two_hidden_effects_are_named_in_order_of_size() {
    let case = record(
        &[
            ("power_law", &[5.0, 1.6]),
            ("cubic_stiffness", &[2e4]),
            ("added_mass", &[0.1]),
        ],
        1,
        false,
    );
    let d = discover(&case, "power_law", &DiscoverySettings::default());
    print("two effects", &case, &d);
    let (cubic, mass) = (case.part_rms(1), case.part_rms(2));
    let expected = if cubic > mass {
        ["cubic_stiffness", "added_mass"]
    } else {
        ["added_mass", "cubic_stiffness"]
    };
    assert_eq!(d.effects, expected, "{:#?}", d.notes);
    // The replacement is a step of its own that names what it replaced or why.
    let step = d.step_of("cubic_stiffness").unwrap();
    assert!(step.verdict.contains("cubic_stiffness"), "{}", step.verdict);
    assert!(d.gap_after <= 1.2 * d.noise_floor, "{}", d.gap_after);
}
