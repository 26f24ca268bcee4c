"""The README's walk-through in Python: simulate the paper's sweep, fit models to a record,
compare them regime by regime, discover a missing effect — the same numbers as the command
line, nothing written unless asked.

    pip install ./python
    python examples/python_walkthrough.py          # from the repository's root

In a notebook, end a cell with a result (``res``) to see its verdict, parameter table and
figure.
"""

import os
import sys

import stf_lab

os.chdir(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

# 1. The source study's 0.047 rad/s² sweep without STF: where is the resonance?
sweep = stf_lab.simulate("experiments/paper_sweep.toml")
run = sweep.summary  # the simulated run, before the sensors' noise
print(f"simulated {sweep.duration:.0f} s ({len(sweep)} samples); peak |x| = "
      f"{run['peak_x_m'] * 1e3:.2f} mm at ω = {run['peak_omega_rad_s']:.2f} rad/s; breakaway at "
      f"ω = {run['breakaway_omega_rad_s']:.2f} rad/s")

# 2. The models available, with their parameters and units.
for m in stf_lab.models():
    params = ", ".join(f"{p.name} [{p.unit or '-'}]" for p in m.params)
    print(f"  {m.name:<16} {params}")

# 3. Fit four models to a power-law record (K = 4, n = 1.5).
res = stf_lab.fit("experiments/power_law_fit.toml")
print(res.verdict)
print(res.to_pandas().to_string(index=False))
pl = res["power_law"]
print(f"power_law: K = {pl.params['K']:.4f} ± {pl.std_errors['K']:.4f}, "
      f"n = {pl.params['n']:.4f} ± {pl.std_errors['n']:.4f}, rms {pl.rms:.4f} {pl.rms_unit}")
if len(sys.argv) > 1:
    print("figure:", res.figure().save(os.path.join(sys.argv[1], "power_law_fit.svg")))

# 4. Compare four STF models on an on–off jamming record, regime by regime.
cmp = stf_lab.compare("experiments/jamming_compare.toml")
print(cmp.verdict)
print("best by regime:", cmp.best_by_regime)

# 5. Discovery: the effect a power law misses, named and added.
found = stf_lab.discover("experiments/discovery.toml")
print(found.verdict)
print(f"effects {found.effects}: gap {found.gap_before:.4f} → {found.gap_after:.4f} "
      f"{found.gap_unit} (noise floor {found.noise_floor:.4f})")
print(found.models_entry)

# 6. A fit built in code: the same record, the power law and a sum, at force level.
exp = stf_lab.Experiment.build("experiments", data="records/power_law_sweep.csv",
                               models=["power_law", "power_law + added_mass"])
print(stf_lab.fit(exp).verdict)
