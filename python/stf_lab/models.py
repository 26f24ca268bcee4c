"""The models a fit can use: the built-ins (``viscous``, ``power_law``, ``added_mass``, …),
rhai scripts, and sums of them (``"power_law + added_mass"``), each with its parameters —
name, unit, default, bounds and a line of doc — as ``stf-lab models`` lists them.
"""

import os

from . import _stf_lab
from ._display import fmt, html_table

__all__ = ["Model", "ParamSpec", "models", "model"]


class ParamSpec:
    """A model parameter: ``name``, SI ``unit``, ``default``, bounds ``min``/``max``, ``doc``."""

    def __init__(self, d):
        self.name = d["name"]
        self.unit = d["unit"]
        self.default = d["default"]
        self.min = d["min"]
        self.max = d["max"]
        self.doc = d["doc"]

    def __repr__(self):
        unit = f" {self.unit}" if self.unit else ""
        return f"{self.name} = {fmt(self.default)}{unit} in [{fmt(self.min)}, {fmt(self.max)}]"


class Model:
    """A force model: ``name`` (or a script's path), ``summary``, ``params`` (ParamSpec list)."""

    def __init__(self, d):
        self.name = d["name"]
        self.summary = d["summary"]
        self.is_script = d["is_script"]
        self.params = [ParamSpec(p) for p in d["params"]]

    def to_dict(self):
        """The model as a plain dict."""
        return {"name": self.name, "summary": self.summary, "is_script": self.is_script,
                "params": [vars(p).copy() for p in self.params]}

    def to_pandas(self):
        """The parameters as a DataFrame: name, unit, default, min, max, doc."""
        import pandas as pd

        return pd.DataFrame([vars(p) for p in self.params],
                            columns=["name", "unit", "default", "min", "max", "doc"])

    def __repr__(self):
        return f"Model({self.name!r}: {', '.join(repr(p) for p in self.params)})"

    def _repr_html_(self):
        rows = [[p.name, p.unit, fmt(p.default), fmt(p.min), fmt(p.max), p.doc] for p in self.params]
        return (f"<p><b>{self.name}</b> — {self.summary}</p>"
                + html_table(["parameter", "unit", "default", "min", "max", "doc"], rows))


def models(script_dir=None):
    """Every built-in model, then the ``*.rhai`` scripts of ``script_dir`` if given."""
    d = None if script_dir is None else os.fspath(script_dir)
    return [Model(m) for m in _stf_lab.list_models(d)]


def model(spec, base_dir="."):
    """The model ``spec`` names: a built-in, a script path (relative to ``base_dir``) or a sum
    ``"a + b"``; its parameters as a fit names them. :class:`stf_lab.ModelError` if unknown."""
    return Model(_stf_lab.describe_model(os.fspath(spec), os.fspath(base_dir)))
