"""Results of the lab's workflows as Python objects.

Each result keeps the command line's JSON (``to_dict()`` is exactly ``fit.json`` or
``compare.json``), exposes its values as attributes, converts to pandas (``to_pandas()``: the
parameters table of ``params.csv``, the per-regime metrics of ``compare.csv``) and shows itself
in a notebook: the verdict, the parameters with units and errors, warnings, and the figure of
the record against every model, inline.
"""

import json
from html import escape

import numpy as np

from ._display import Figure, fmt, html_table
from . import _stf_lab

__all__ = ["Param", "ModelFit", "FitResult", "CompareResult"]


class Param:
    """A fitted (or held) parameter: ``value`` and ``std_error`` in SI ``unit``."""

    def __init__(self, row):
        self.model = row["model"]
        self.name = row["parameter"]
        self.value = row["value"]
        self.std_error = row["std_error"]
        self.unit = row["unit"]
        self.fixed = row["fixed"]
        self.at_bound = row["at_bound"]

    def __repr__(self):
        err = "held" if self.fixed else f"± {fmt(self.std_error, 3)}"
        unit = f" {self.unit}" if self.unit else ""
        return f"{self.name} = {fmt(self.value, 8)} {err}{unit}"


class ModelFit:
    """One model fitted to the record: its values, errors, residual, criteria and warnings.

    ``params`` and ``std_errors`` map parameter names to SI values (as ``fit.json``);
    ``table`` lists :class:`Param` with units; ``fitted`` is the model's prediction of the
    measured signal (``f_stf`` N, or ``x`` m at trajectory level) at the record's times.
    """

    def __init__(self, entry, rows, fitted):
        self.entry = entry
        self.name = entry["name"]
        self.label = entry["label"]
        self.level = entry["level"]
        self.params = entry["params"]
        self.std_errors = entry["std_errors"]
        self.rms = entry["rms"]
        self.rms_unit = entry["rms_unit"]
        self.aic = entry["aic"]
        self.bic = entry["bic"]
        self.converged = entry["converged"]
        self.warnings = entry["warnings"]
        self.noise_floor = entry.get("noise_floor")
        self.validation = entry.get("validation")
        self.validation_rms = entry.get("validation_rms")
        self.system = entry.get("system")
        corr = entry.get("correlation") or []
        self.correlation = np.array([[np.nan if v is None else v for v in r] for r in corr],
                                    dtype=float)
        self.table = [Param(r) for r in rows]
        self.fitted = fitted

    def to_dict(self):
        """This model's entry of ``fit.json``."""
        return self.entry

    def __repr__(self):
        free = ", ".join(repr(p) for p in self.table if not p.fixed)
        warn = f"; {len(self.warnings)} warning(s)" if self.warnings else ""
        return f"ModelFit({self.label}: rms {fmt(self.rms, 4)} {self.rms_unit}, AIC {fmt(self.aic, 8)}; {free}{warn})"


def _params_frame(rows):
    import pandas as pd

    columns = ["model", "parameter", "value", "std_error", "unit", "fixed", "at_bound"]
    return pd.DataFrame(rows, columns=columns)


class FitResult:
    """``stf-lab fit`` in Python: every model of the experiment fitted to its record.

    Attributes: ``models`` (list of :class:`ModelFit`, in the experiment's order, also by label
    through ``result["power_law"]``), ``best`` (the verdict's choice: the simplest model within
    ΔAIC 2 of the lowest), ``verdict`` (the report's first paragraph), ``level``, ``record``,
    ``samples``, and the arrays ``t`` and ``measured`` (the signal fitted).
    """

    kind = "fit"

    def __init__(self, outcome, experiment):
        self.experiment = experiment
        self._doc = json.loads(outcome["json"])
        self._rows = json.loads(outcome["params_table"])
        self.verdict = outcome["verdict"]
        self.level = outcome["level"]
        self.t = outcome["t"]
        self.measured = outcome["measured"]
        fitted = dict(outcome["fitted"])
        entries = self._entries()
        self.models = [
            ModelFit(e, [r for r in self._rows if r["model"] == e["label"]], fitted.get(e["label"]))
            for e in entries
        ]
        best = outcome["best"]
        self.best = self.models[best] if best is not None else None
        self.record = self._doc.get("record")
        self.samples = self._doc.get("samples", len(self.t))
        self._figure = None

    def _entries(self):
        return self._doc["models"]

    def __getitem__(self, label):
        for m in self.models:
            if m.label == label:
                return m
        raise KeyError(f"{label!r}: the models are {', '.join(m.label for m in self.models)}")

    @property
    def unit(self):
        """The unit of the fitted signal and of ``rms``: ``N`` or ``m``."""
        return "N" if self.level == "force" else "m"

    @property
    def warnings(self):
        """Every model's warnings, as ``(label, warning)`` pairs."""
        return [(m.label, w) for m in self.models for w in m.warnings]

    def to_dict(self):
        """The command line's JSON (``fit.json``; ``compare.json`` for a comparison)."""
        return self._doc

    def to_pandas(self):
        """The parameters table (``params.csv``): model, parameter, value, std_error, unit,
        fixed, at_bound."""
        return _params_frame(self._rows)

    def figure(self):
        """The report's figure of the measured signal against every fitted model."""
        if self._figure is None:
            curves = [(m.label, m.fitted) for m in self.models if m.fitted is not None]
            d = _stf_lab.measured_vs_fitted(self.level, self.t, self.measured, curves)
            self._figure = Figure("measured_vs_fitted", d["svg"], d["png"])
        return self._figure

    def __repr__(self):
        lines = [f"{type(self).__name__}({self.record}: {len(self.models)} model(s) at "
                 f"{self.level} level on {self.samples} samples)", f"  {self.verdict}"]
        lines += [f"  {m!r}" for m in self.models]
        return "\n".join(lines)

    def _models_html(self):
        aics = [m.aic for m in self.models if m.aic is not None]
        low = min(aics) if aics else None
        rows = []
        for m in self.models:
            d_aic = m.aic - low if (m.aic is not None and low is not None) else None
            rows.append([m.label, f"{fmt(m.rms, 4)} {m.rms_unit}", fmt(m.aic, 8), fmt(d_aic, 3),
                         "yes" if m.converged else "no", len(m.warnings)])
        return html_table(["model", "RMS", "AIC", "ΔAIC", "converged", "warnings"], rows,
                          "Models, in the experiment's order")

    def _params_html(self):
        rows = [[p.model, p.name, fmt(p.value, 8), "held" if p.fixed else fmt(p.std_error, 3),
                 p.unit, "on a bound" if p.at_bound else ""] for p in self._rows_params()]
        return html_table(["model", "parameter", "value", "std. error", "unit", ""], rows,
                          "Fitted parameters (SI units)")

    def _rows_params(self):
        return [p for m in self.models for p in m.table]

    def _warnings_html(self):
        if not self.warnings:
            return ""
        items = "".join(f"<li><b>{escape(label)}</b>: {escape(w['message'])}</li>"
                        for label, w in self.warnings)
        return f"<div><b>⚠ Warnings</b><ul>{items}</ul></div>"

    def _extra_html(self):
        return ""

    def _repr_html_(self):
        try:
            fig = self.figure().html()
        except Exception as e:  # a figure that cannot be drawn must not hide the result
            fig = f"<p>(figure not drawn: {escape(str(e))})</p>"
        title = "Fit" if self.kind == "fit" else "Comparison"
        return (f"<div class='stf-lab-result'><h4>{title}: {escape(str(self.record))}</h4>"
                f"<p>{escape(self.verdict)}</p>{self._warnings_html()}{self._extra_html()}"
                f"{self._models_html()}{self._params_html()}{fig}</div>")


class CompareResult(FitResult):
    """``stf-lab compare`` in Python: the fits, then the models compared regime by regime.

    Besides a :class:`FitResult`'s attributes: ``measured_regimes`` (the record's noise, cycles
    per regime, boundaries), ``ranking``, ``loop_rankings`` and ``best_by_regime`` of
    ``compare.json``; ``to_pandas()`` gives the per-regime metrics (``compare.csv``) and
    ``params_frame()`` the parameters table.
    """

    kind = "compare"

    def __init__(self, outcome, experiment):
        super().__init__(outcome, experiment)
        self._regime_rows = json.loads(outcome["regimes_table"])
        self.measured_regimes = self._doc["measured"]
        self.ranking = self._doc["ranking"]
        self.loop_rankings = self._doc["loop_rankings"]
        self.best_by_regime = self._doc["best"]
        self.comparisons = {m["label"]: m for m in self._doc["models"]}

    def _entries(self):
        return [m["fit"] for m in self._doc["models"]]

    def to_pandas(self):
        """The per-regime metrics (``compare.csv``): one row per model and regime."""
        import pandas as pd

        return pd.DataFrame(self._regime_rows)

    def params_frame(self):
        """The parameters table (``params.csv``'s columns)."""
        return _params_frame(self._rows)

    def _extra_html(self):
        rows = [[r, fmt(self.best_by_regime.get(r))] for r in
                ("pre_resonance", "resonance", "post_resonance", "overall")]
        return html_table(["regime", "best model"], rows, "Best model by relative force RMS error")
