//! `stf-lab models`: list the models with their parameters.

use anyhow::Result;

/// Print every built-in model with its parameters and one line of doc.
pub fn list() -> Result<()> {
    for entry in stf_models::BUILTINS {
        let model = (entry.build)();
        println!("{}  —  {}", entry.name, entry.summary);
        for p in model.params() {
            println!(
                "    {:<10} {:>10} [{}, {}] {:<12} {}",
                p.name, p.default, p.min, p.max, p.unit, p.doc
            );
        }
    }
    Ok(())
}
