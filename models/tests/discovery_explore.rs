mod discovery_support;
use discovery_support::*;
use stf_core::discovery::DiscoverySettings;

#[test]
#[ignore]
fn explore() {
    let which = std::env::var("CASE").unwrap_or_default();
    let exact = std::env::var("EXACT").is_ok();
    let t0 = std::time::Instant::now();
    let cases: Vec<(&str, Vec<Part>, &str)> = vec![
        ("viscous", vec![("power_law", &[20.0, 2.5]), ("viscous", &[1.0])], "power_law"),
        ("base", vec![("power_law", &[5.0, 1.6])], "power_law"),
    ];
    for (name, truth, base) in cases {
        if !which.is_empty() && which != name { continue; }
        let case = record(&truth, 1, exact);
        eprintln!("sim {:.1}s; max|x| {:.4} max|v| {:.4}", t0.elapsed().as_secs_f64(),
            case.x.iter().fold(0.0f64, |m, v| m.max(v.abs())), case.v.iter().fold(0.0f64, |m, v| m.max(v.abs())));
        let d = discover(&case, base, &DiscoverySettings::default());
        print(name, &case, &d);
        eprintln!("total {:.1}s", t0.elapsed().as_secs_f64());
    }
}
