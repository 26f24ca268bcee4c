"""Each workflow on the bundled examples: simulate, fit (force and trajectory level), compare;
results as attributes, dicts and DataFrames."""

import numpy as np
import pytest

import stf_lab


def test_simulate_remakes_the_bundled_record(repo):
    rec = stf_lab.simulate("experiments/power_law_fit.toml")
    bundled = stf_lab.read_record("experiments/records/power_law_sweep.csv")
    assert rec.signals == bundled.signals
    for name in bundled.signals:
        np.testing.assert_array_equal(getattr(rec, name), getattr(bundled, name), err_msg=name)
    # The run's summary, as the sidecar beside the bundled record states it.
    import json

    sidecar = json.loads(open("experiments/records/power_law_sweep.json").read())
    assert {k: rec.summary[k] for k in sidecar["summary"]} == sidecar["summary"]


def test_a_built_experiment_simulates_like_its_file(repo):
    exp = stf_lab.Experiment.build(
        "experiments",
        simulate={"sweep": {"w0": 3.0, "alpha": 0.1, "t0": 0.0, "t1": 60.0}, "rate": 200.0,
                  "noise": True, "seed": 7,
                  "truth": [("power_law", {"K": 4.0, "n": 1.5})]},
    )
    rec = stf_lab.simulate(exp)
    bundled = stf_lab.read_record("experiments/records/power_law_sweep.csv")
    np.testing.assert_array_equal(rec.x, bundled.x)


@pytest.fixture(scope="module")
def power_law_fit():
    import os
    from conftest import REPO

    here = os.getcwd()
    os.chdir(REPO)
    try:
        return stf_lab.fit("experiments/power_law_fit.toml")
    finally:
        os.chdir(here)


def test_fit_names_the_power_law_best_and_recovers_it(power_law_fit):
    res = power_law_fit
    assert [m.label for m in res.models] == ["viscous", "power_law", "power_law+added_mass",
                                              "power_law#2"] or len(res.models) == 4
    assert res.best.name == "power_law"
    pl = res["power_law"]
    assert pl.params["K"] == pytest.approx(4.0, rel=0.05)
    assert pl.params["n"] == pytest.approx(1.5, rel=0.05)
    assert abs(pl.params["K"] - 4.0) < 3 * pl.std_errors["K"] + 0.05
    assert res["viscous"].rms > 1.2 * pl.rms
    assert res.level == "force" and res.unit == "N"
    assert pl.fitted.shape == res.t.shape == res.measured.shape
    assert "power_law" in res.verdict


def test_fit_converts_to_dict_and_pandas(power_law_fit):
    d = power_law_fit.to_dict()
    assert {"experiment", "record", "level", "samples", "models"} <= set(d)
    df = power_law_fit.to_pandas()
    assert list(df.columns) == ["model", "parameter", "value", "std_error", "unit", "fixed",
                                "at_bound"]
    k = df[(df.model == "power_law") & (df.parameter == "K")]
    assert k.unit.item() == "N·(s/m)ⁿ"
    assert k.value.item() == power_law_fit["power_law"].params["K"]


def test_a_trajectory_fit_runs_on_x_alone(repo, tmp_path):
    exp = stf_lab.Experiment.build(
        "experiments",
        data="records/power_law_sweep.csv",
        fit={"level": "trajectory"},
        models=[("power_law", {"K": 3.0, "n": 1.5})],
    )
    res = stf_lab.fit(exp)
    assert res.level == "trajectory" and res.unit == "m"
    assert res["power_law"].params["K"] == pytest.approx(4.0, rel=0.1)


def test_compare_ranks_the_models_by_regime(repo):
    res = stf_lab.compare("experiments/jamming_compare.toml")
    assert res.best_by_regime["resonance"] == "jamming_on_off"
    df = res.to_pandas()
    assert {"model", "regime"} <= set(df.columns)
    assert set(df.model) == {m.label for m in res.models}
    assert res.params_frame().shape[0] > 0


def test_discover_names_the_hidden_cubic_spring(repo):
    res = stf_lab.discover("experiments/discovery.toml")
    assert res.effects == ["cubic_stiffness"]
    assert res.gap_after < 0.5 * res.gap_before and res.gap_unit == "N"
    assert res.gap_after < 1.2 * res.noise_floor
    assert "cubic_stiffness" in res.models_entry and "[[models]]" in res.models_entry
    df = res.to_pandas()
    assert df[df.accepted].candidate.tolist() == ["cubic_stiffness"]
    assert res.base.shape == res.final.shape == res.t.shape
    assert "cubic_stiffness" in res._repr_html_()


def test_discover_at_trajectory_level_refits_the_oscillator(repo):
    res = stf_lab.discover("experiments/trajectory_discovery.toml")
    assert res.level == "trajectory" and res.effects == ["cubic_stiffness"]
    assert res.to_dict()["s_after_mm2"] < res.to_dict()["s_before_mm2"]


def test_the_paper_identification_runs_in_stages(repo):
    res = stf_lab.fit("experiments/paper_identification.toml")
    assert isinstance(res, stf_lab.IdentifyResult) and len(res.stages) == 2
    assert res.system["k"] == pytest.approx(269.93, rel=0.05)
    assert set(res.to_pandas().model) == {"stage 1", "stage 2"}


def test_validation_on_a_second_record_scores_every_fit(repo, tmp_path):
    # A second record of the same truth with another noise seed, written as a CSV.
    second = stf_lab.simulate(stf_lab.Experiment.build(
        "experiments",
        simulate={"sweep": {"w0": 3.0, "alpha": 0.1, "t0": 0.0, "t1": 60.0}, "rate": 200.0,
                  "seed": 8, "truth": [("power_law", {"K": 4.0, "n": 1.5})]},
    ))
    second.save_csv(tmp_path / "second.csv")
    exp = stf_lab.Experiment.build("experiments", data="records/power_law_sweep.csv",
                                   models=["viscous", "power_law"],
                                   validate=tmp_path / "second.csv")
    res = stf_lab.fit(exp)
    pl, visc = res["power_law"], res["viscous"]
    assert pl.validation["samples"] == len(second)
    assert pl.validation_rms == pytest.approx(pl.rms, rel=0.1)
    assert visc.validation_rms > 1.2 * pl.validation_rms
