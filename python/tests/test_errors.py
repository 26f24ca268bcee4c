"""Every error is an exception of the package's hierarchy with the command line's message:
experiment files name the file, line and key; nothing panics into Python."""

import pytest

import stf_lab


def test_a_misspelled_key_names_file_line_and_key(tmp_path):
    exp = tmp_path / "exp.toml"
    exp.write_text('[data]\nfile = "r.csv"\n\n[system]\nstifnes = 3.0\n')
    with pytest.raises(stf_lab.ExperimentError) as e:
        stf_lab.Experiment.load(exp)
    msg = str(e.value)
    assert f"{exp}:5" in msg and "stifnes" in msg


def test_a_missing_record_names_the_key(tmp_path):
    exp = tmp_path / "exp.toml"
    exp.write_text('[data]\nfile = "missing.csv"\n\n[[models]]\nname = "viscous"\n')
    with pytest.raises(stf_lab.ExperimentError) as e:
        stf_lab.fit(exp)
    msg = str(e.value)
    assert msg.startswith(f"{exp}:1: ") and "`data.file`: no such record" in msg, msg
    assert "missing.csv" in msg


def test_a_built_experiment_names_its_line_and_key(tmp_path):
    with pytest.raises(stf_lab.ExperimentError) as e:
        stf_lab.Experiment.build(tmp_path, data="r.csv", fit={"levle": "force"})
    msg = str(e.value)
    assert "(python experiment).toml:" in msg and "levle" in msg, msg


def test_a_start_value_out_of_bounds_fails_the_fit_naming_it(repo):
    exp = stf_lab.Experiment.build("experiments", data="records/power_law_sweep.csv",
                                   models=[("power_law", {"K": -1.0})])
    with pytest.raises(stf_lab.StfLabError, match="K"):
        stf_lab.fit(exp)


def test_an_unknown_model_in_an_experiment_names_its_entry(repo):
    exp = stf_lab.Experiment.build("experiments", data="records/power_law_sweep.csv",
                                   models=["power_lwa"])
    with pytest.raises(stf_lab.ExperimentError) as e:
        stf_lab.fit(exp)
    msg = str(e.value)
    assert msg.startswith("experiments/(python experiment).toml:6: `models[0]`: unknown model")
    assert "viscous" in msg


def test_compare_needs_a_force_and_says_so(repo, tmp_path):
    rec = stf_lab.read_record("experiments/records/power_law_sweep.csv")
    lines = ["t,phi,x"] + [f"{t!r},{p!r},{x!r}" for t, p, x in zip(rec.t.tolist(), rec.phi.tolist(), rec.x.tolist())]
    (tmp_path / "no_force.csv").write_text("\n".join(lines) + "\n")
    exp = stf_lab.Experiment.build(tmp_path, data="no_force.csv", models=["viscous"])
    with pytest.raises(stf_lab.ExperimentError, match="the record needs `f_stf`"):
        stf_lab.compare(exp)


def test_a_progress_callback_that_fails_stops_the_run_with_its_error(repo):
    def broken(status, elapsed):
        raise ValueError("callback bug")

    with pytest.raises(ValueError, match="callback bug"):
        stf_lab.fit("experiments/power_law_fit.toml", progress=broken)


def test_a_script_that_fails_in_an_experiment_is_a_model_error(tmp_path):
    (tmp_path / "broken.rhai").write_text("fn params() { [\n")
    rec = tmp_path / "r.csv"
    rec.write_text("t,phi,x,f_stf\n" + "".join(f"{i / 100},{i / 10},{i / 1000},0.0\n" for i in range(50)))
    exp = stf_lab.Experiment.build(tmp_path, data="r.csv", models=["broken.rhai"])
    with pytest.raises(stf_lab.ModelError) as e:
        stf_lab.fit(exp)
    msg = str(e.value)
    assert "`models[0]`" in msg and "broken.rhai" in msg and "syntax error" in msg, msg
