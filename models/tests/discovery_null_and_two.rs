//! Discovery names nothing when the base is the truth, and names two hidden effects in the
//! order of how much they explain. Records as in `discovery_effects.rs`.

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
#[ignore = "fails: with cubic_stiffness (k3 = 2e4) and added_mass (0.1 kg) hidden, wall_impact \
            (which contains a cubic spring: gap 0, p = 3) is named first (held-out 0.0867 → \
            0.0365 N) and added_mass is then not significant; the confusable pair is not yet \
            decided by held-out evidence"]
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
    assert!(d.gap_after <= 1.2 * d.noise_floor, "{}", d.gap_after);
}
