"""Campaigns from Python: run in process into their folder, the same table and joint fit as
`stf-lab campaign` writes, a rerun that skips finished units, and the rows as a DataFrame."""

import json
import subprocess

import pytest

import stf_lab

from test_parity import _same

CAMPAIGN = "experiments/campaign/campaign.toml"
TIMING = {"wall_seconds", "joint_fit_seconds"}


def _untimed(value):
    if isinstance(value, dict):
        return {k: _untimed(v) for k, v in value.items() if k not in TIMING}
    if isinstance(value, list):
        return [_untimed(v) for v in value]
    return value


def test_a_campaign_from_python_is_the_command_lines(repo, stf_lab_bin, tmp_path):
    res = stf_lab.campaign(CAMPAIGN, tmp_path / "py")
    subprocess.run([stf_lab_bin, "campaign", CAMPAIGN, "--out", str(tmp_path / "cli"),
                    "--quiet", "--jobs", "2"], check=True, capture_output=True, text=True)
    cli = json.loads((tmp_path / "cli" / "campaign.json").read_text())
    cli_global = json.loads((tmp_path / "cli" / "global.json").read_text())
    _same(_untimed(res.to_dict()["rows"]), _untimed(cli["rows"]))
    _same(_untimed(res.global_fit), _untimed(cli_global))
    assert (tmp_path / "py" / "report.html").is_file()
    assert res.units == 10 and res.failed == 0 and len(res.rows) == 20
    assert res.verdict.startswith("sharing supported"), res.verdict

    df = res.to_pandas()
    assert len(df) == 20 and {"record", "model", "status", "F0", "concentration", "K", "K_se"} <= set(df.columns)
    assert df["K"].notna().sum() == 10
    params = res.global_params()
    assert list(params["name"]) == ["K0", "K_p", "n"]
    assert "Joint fit of power_law" in res._repr_html_()

    again = stf_lab.campaign(CAMPAIGN, tmp_path / "py")
    _same(_untimed(again.rows), _untimed(res.rows))
    read = stf_lab.read_campaign(tmp_path / "py")
    assert read.rows == again.rows


def test_a_campaign_that_is_not_there_is_an_experiment_error(repo, tmp_path):
    with pytest.raises(stf_lab.ExperimentError, match="missing.toml"):
        stf_lab.campaign("missing.toml", tmp_path / "out")
