#!/usr/bin/env bash
# Replicates of the bundled campaign, to check the global fit's error bars: the 10 records
# made again with other noise seeds (4) and sweep rates (0.3 and 0.2 rad/s²), then both
# campaigns (force level: campaign.toml; trajectory level: trajectory_campaign.toml) run on
# each. Prints each global parameter's value, standard error and z = (value − truth)/error.
#
#   cargo build --release && experiments/campaign/replicates.sh /tmp/replicates
set -euo pipefail
out=${1:?usage: replicates.sh OUT_DIR}
here=$(cd "$(dirname "$0")" && pwd)
bin=${STF_LAB:-$here/../../target/release/stf-lab}
for alpha in 0.3 0.2; do
  for s in 1 2 3 4; do
    d=$out/alpha${alpha}_seed$s
    rm -rf "$d" && mkdir -p "$d/records"
    cp "$here"/*.toml "$d/" && cp "$here"/records/*.toml "$d/records/"
    for t in "$d"/records/*.toml; do
      sed -i -E "s/^seed = ([0-9]+)/seed = \1$s$s/; s/alpha = 0.3/alpha = $alpha/" "$t"
      "$bin" -q simulate "$t" --out "${t%.toml}.csv" >/dev/null
    done
    "$bin" -q campaign "$d/campaign.toml" --out "$d/force" -j 2 >/dev/null
    "$bin" -q campaign "$d/trajectory_campaign.toml" --out "$d/trajectory" -j 2 >/dev/null
  done
done
python3 - "$out" <<'PY'
import glob, json, sys
truth = {"K0": 4.0, "K_p": 6.0, "n": 1.5}
for level in ["force", "trajectory"]:
    z = {k: [] for k in truth}
    for d in sorted(glob.glob(f"{sys.argv[1]}/alpha*")):
        g = json.load(open(f"{d}/{level}/global.json"))
        p = {q["name"]: (q["value"], q["std_error"]) for q in g["params"]}
        cells = []
        for k, t in truth.items():
            v, se = p[k]
            z[k].append((v - t) / se)
            cells.append(f"{k} {v:.4f} ± {se:.4f} (z {z[k][-1]:+.2f})")
        print(f"{level:10s} {d.split('/')[-1]:18s} " + "  ".join(cells) + f"  supported {g['supported']}")
    for k, zs in z.items():
        n = len(zs)
        rms = (sum(x * x for x in zs) / n) ** 0.5
        print(f"{level}: {k} within 1σ {sum(abs(x) < 1 for x in zs)}/{n}, within 2σ "
              f"{sum(abs(x) < 2 for x in zs)}/{n}, rms z {rms:.2f}")
PY
