"""The model registry from Python: built-ins with parameters and units, sums, scripts."""

import pytest

import stf_lab

BUILTINS = ["viscous", "power_law", "added_mass", "jamming_on_off", "yield", "wall_impact",
            "cubic_stiffness", "maxwell", "bouc_wen", "linear_spring"]


def test_every_builtin_is_listed_with_its_parameters():
    listed = {m.name: m for m in stf_lab.models()}
    assert set(BUILTINS) <= set(listed)
    K = {p.name: p for p in listed["power_law"].params}["K"]
    assert K.unit == "N·(s/m)ⁿ"
    assert K.min < K.default < K.max
    assert [p.name for p in listed["added_mass"].params] == ["m_a"]
    assert {p.name: p.unit for p in listed["viscous"].params} == {"c_s": "N·s/m"}


def test_scripts_of_a_folder_are_listed(repo):
    names = [m.name for m in stf_lab.models("models/scripts") if m.is_script]
    assert any(n.endswith("power_law.rhai") for n in names)


def test_a_sum_names_its_parameters_as_a_fit_does():
    m = stf_lab.model("power_law + added_mass")
    assert [p.name for p in m.params] == ["K", "n", "m_a"]
    assert m.to_pandas().columns.tolist() == ["name", "unit", "default", "min", "max", "doc"]


def test_an_unknown_model_lists_the_known_ones():
    with pytest.raises(stf_lab.ModelError) as e:
        stf_lab.model("power_lwa")
    assert "power_lwa" in str(e.value) and "viscous" in str(e.value)
