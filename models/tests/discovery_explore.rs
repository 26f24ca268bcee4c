mod discovery_support;
use discovery_support::*;
use stf_core::discovery::DiscoverySettings;

#[test]
#[ignore]
fn explore() {
    let which = std::env::var("CASE").unwrap_or_default();
    let exact = std::env::var("EXACT").is_ok();
    let seed: u64 = std::env::var("SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(1);
    let cases: Vec<(&str, Vec<Part>, &str)> = vec![
        ("viscous", vec![("power_law", &[20.0, 2.5]), ("viscous", &[1.0])], "power_law"),
        ("power_law", vec![("viscous", &[1.0]), ("power_law", &[20.0, 2.5])], "viscous"),
        ("added_mass", vec![("power_law", &[5.0, 1.6]), ("added_mass", &[0.3])], "power_law"),
        ("yield", vec![("power_law", &[5.0, 1.6]), ("yield", &[0.08, 1e-3])], "power_law"),
        ("wall_impact", vec![("power_law", &[5.0, 1.6]), ("wall_impact", &[200.0, 0.02, 1.5, 0.5])], "power_law"),
        ("cubic_stiffness", vec![("power_law", &[5.0, 1.6]), ("cubic_stiffness", &[1e4])], "power_law"),
        ("maxwell", vec![("power_law", &[5.0, 1.6]), ("maxwell", &[1.0, 0.05])], "power_law"),
        ("jamming_on_off", vec![("power_law", &[5.0, 1.6]), ("jamming_on_off", &[20.0, 2.0, 0.08, 0.004])], "power_law"),
        ("base", vec![("power_law", &[5.0, 1.6])], "power_law"),
        ("two", vec![("power_law", &[5.0, 1.6]), ("cubic_stiffness", &[2e4]), ("added_mass", &[0.2])], "power_law"),
    ];
    for (name, truth, base) in cases {
        if !which.is_empty() && which != name { continue; }
        let t0 = std::time::Instant::now();
        let case = record(&truth, seed, exact);
        let tsim = t0.elapsed().as_secs_f64();
        let d = discover(&case, base, &DiscoverySettings::default());
        eprintln!("sim {tsim:.1}s; max|x| {:.4} max|v| {:.4}",
            case.x.iter().fold(0.0f64, |m, v| m.max(v.abs())), case.v.iter().fold(0.0f64, |m, v| m.max(v.abs())));
        print(name, &case, &d);
        eprintln!("   final fit: {:?} {:?}", d.final_fit.convergence, d.final_fit.log);
        eprintln!("total {:.1}s", t0.elapsed().as_secs_f64());
    }
}
