"""Python numbers are the command line's numbers: the JSON a workflow returns equals, key for
key and to the last digit, the file `stf-lab` writes for the same experiment."""

import csv
import json
import math
import subprocess

import pytest

import stf_lab


def _run(bin_path, command, experiment, out):
    subprocess.run([bin_path, command, experiment, "--out", str(out), "--quiet"], check=True,
                   capture_output=True, text=True)


def _same(a, b, path="$"):
    """Assert the JSON values equal, floats exactly; say where they differ."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), f"{path}: keys {set(a) ^ set(b)}"
        for k in a:
            _same(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), f"{path}: lengths"
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{path}[{i}]")
    elif isinstance(a, float) and math.isnan(a):
        assert isinstance(b, float) and math.isnan(b), path
    else:
        assert a == b, f"{path}: {a!r} != {b!r}"


def test_fit_json_is_the_command_lines(repo, stf_lab_bin, tmp_path):
    exp = "experiments/power_law_fit.toml"
    _run(stf_lab_bin, "fit", exp, tmp_path / "out")
    cli = json.loads((tmp_path / "out" / "fit.json").read_text())
    res = stf_lab.fit(exp)
    _same(res.to_dict(), cli)
    with open(tmp_path / "out" / "params.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    df = res.to_pandas()
    assert len(rows) == len(df)
    for row, (_, p) in zip(rows, df.iterrows()):
        assert (row["model"], row["parameter"]) == (p.model, p.parameter)
        assert float(row["value"]) == p.value


def test_compare_json_is_the_command_lines(repo, stf_lab_bin, tmp_path):
    exp = "experiments/jamming_compare.toml"
    _run(stf_lab_bin, "compare", exp, tmp_path / "out")
    cli = json.loads((tmp_path / "out" / "compare.json").read_text())
    _same(stf_lab.compare(exp).to_dict(), cli)


def _without(doc, key):
    """`doc` without `key` anywhere (a run's wall time, which no two runs share)."""
    if isinstance(doc, dict):
        return {k: _without(v, key) for k, v in doc.items() if k != key}
    if isinstance(doc, list):
        return [_without(v, key) for v in doc]
    return doc


@pytest.mark.parametrize("experiment", ["experiments/discovery.toml",
                                        "experiments/trajectory_discovery.toml"])
def test_discovery_json_is_the_command_lines(repo, stf_lab_bin, tmp_path, experiment):
    _run(stf_lab_bin, "discover", experiment, tmp_path / "out")
    cli = json.loads((tmp_path / "out" / "discovery.json").read_text())
    res = stf_lab.discover(experiment)
    _same(_without(res.to_dict(), "wall_seconds"), _without(cli, "wall_seconds"))


def test_the_identifications_fit_json_is_the_command_lines(repo, stf_lab_bin, tmp_path):
    exp = "experiments/paper_identification.toml"
    _run(stf_lab_bin, "fit", exp, tmp_path / "out")
    cli = json.loads((tmp_path / "out" / "fit.json").read_text())
    _same(stf_lab.fit(exp).to_dict(), cli)
