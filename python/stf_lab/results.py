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

__all__ = ["Param", "ModelFit", "FitResult", "CompareResult", "DiscoveryResult", "IdentifyResult"]


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
        fitted = dict(outcome["curves"])
        self.warnings_of_inputs = list(outcome.get("warnings", []))
        entries = self._entries()
        self.models = [
            ModelFit(e, [r for r in self._rows if r["model"] == e["label"]], fitted.get(e["label"]))
            for e in entries
        ]
        # The verdict's choice, as fit.json states it (else by the same rule, computed).
        verdict = self._doc.get("verdict")
        label = verdict.get("best") if isinstance(verdict, dict) else None
        best = outcome["best"]
        if label is not None:
            self.best = self[label]
        else:
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
            self._figure = _figure("measured_vs_fitted", self.level, self.t, self.measured, curves)
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
        fig = _figure_html(self)
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


def _figure(name, level, t, measured, curves):
    d = _stf_lab.measured_vs_fitted(level, t, measured, curves)
    return Figure(name, d["svg"], d["png"])


def _figure_html(result):
    try:
        return result.figure().html()
    except Exception as e:  # a figure that cannot be drawn must not hide the result
        return f"<p>(figure not drawn: {escape(str(e))})</p>"


class DiscoveryResult:
    """``stf-lab discover`` in Python: the effects named and added to the base model.

    Attributes of ``discovery.json``: ``effects`` (names, in order), ``gap_before`` and
    ``gap_after`` (RMS of measured − modelled signal, in ``gap_unit``: N, or m at trajectory
    level), ``noise_floor``, ``steps``, ``final_model`` (its ``params``, ``std_errors`` and
    ``experiment_entry``: a ``[[models]]`` entry ``fit`` and ``compare`` accept), ``validation``;
    ``verdict`` (the report's first paragraph); the arrays ``t``, ``measured``, ``base`` and
    ``final`` (the measured signal and both models' curves of it). ``to_pandas()`` gives every
    candidate's scores at every step.
    """

    def __init__(self, outcome, experiment):
        self.experiment = experiment
        self._doc = json.loads(outcome["json"])
        self.verdict = outcome["verdict"]
        self.level = outcome["level"]
        self.t = outcome["t"]
        self.measured = outcome["measured"]
        curves = dict(outcome["curves"])
        self.base, self.final = curves["base"], curves["final"]
        self.models_entry, self.system_entry = outcome["entries"]
        self.warnings_of_inputs = list(outcome.get("warnings", []))
        d = self._doc
        self.record = d["record"]
        self.base_model = d["base"]
        self.effects = d["effects"]
        self.gap_before, self.gap_after = d["gap_before"], d["gap_after"]
        self.gap_unit = d["gap_unit"]
        self.noise_floor = d["noise_floor"]
        self.steps = d["steps"]
        self.final_model = d["final_model"]
        self.validation = d.get("validation")
        self.notes = d.get("notes", [])
        self._figure = None

    def to_dict(self):
        """The command line's JSON (``discovery.json``)."""
        return self._doc

    def to_pandas(self):
        """Every candidate at every step: step, candidate, held-out RMS, gain z, effective n,
        explained share, ΔBIC, significant, accepted."""
        import pandas as pd

        rows = []
        for i, step in enumerate(self.steps, 1):
            for c in step["candidates"]:
                rows.append({"step": i, "current": step["current"], "candidate": c["name"],
                             "holdout_rms": c["holdout_rms"], "gain_z": c["gain_z"],
                             "effective_n": c["effective_n"],
                             "explained_share": c["explained_share"],
                             "delta_bic": c["delta_bic"], "significant": c["significant"],
                             "accepted": step["accepted"] == c["name"]})
        return pd.DataFrame(rows)

    def figure(self):
        """The measured signal against the base's and the final model's curves."""
        if self._figure is None:
            curves = [(f"base ({self.base_model})", self.base), ("final", self.final)]
            self._figure = _figure("discovered", self.level, self.t, self.measured, curves)
        return self._figure

    def __repr__(self):
        named = ", ".join(self.effects) or "nothing"
        return (f"DiscoveryResult({self.record}: from {self.base_model!r} named {named}; gap "
                f"{fmt(self.gap_before, 4)} → {fmt(self.gap_after, 4)} {self.gap_unit} against a "
                f"floor of {fmt(self.noise_floor, 4)})\n  {self.verdict}")

    def _repr_html_(self):
        rows = [[i, s["current"], s["accepted"] or "—", ", ".join(s.get("tie_with", [])) or "",
                 s["verdict"]] for i, s in enumerate(self.steps, 1)]
        steps = html_table(["step", "model", "accepted", "tied with", "verdict"], rows,
                           "Steps of the discovery")
        params = [[k, fmt(v, 8), fmt(self.final_model.get("std_errors", {}).get(k), 3)]
                  for k, v in self.final_model.get("params", {}).items()]
        final = html_table(["parameter", "value", "std. error"], params,
                           f"Final model: {self.final_model.get('name', '')} (SI units)")
        return (f"<div class='stf-lab-result'><h4>Discovery: {escape(str(self.record))}</h4>"
                f"<p>{escape(self.verdict)}</p>{steps}{final}"
                f"<pre>{escape(self.models_entry)}</pre>{_figure_html(self)}</div>")


class IdentifyResult:
    """The staged identification of ``[[identify]]`` (``stf-lab fit`` on such an experiment):
    each stage's oscillator fit against its record's displacement.

    ``stages`` (``fit.json``'s: record, free parameters, values, errors, S(μ) in mm², warnings),
    ``system`` (the oscillator after the last stage), ``to_pandas()`` (``params.csv``: one
    row per stage and parameter), ``t``/``measured`` and the last stage's simulated x.
    """

    def __init__(self, outcome, experiment):
        self.experiment = experiment
        self._doc = json.loads(outcome["json"])
        self._rows = json.loads(outcome["params_table"])
        self.level = "trajectory"
        self.t = outcome["t"]
        self.measured = outcome["measured"]
        self.simulated = dict(outcome["curves"])
        self.stages = self._doc["stages"]
        self.system = self._doc["system"]
        self.warnings = self._doc["models"][0]["warnings"]
        self._figure = None

    def to_dict(self):
        """The command line's JSON (the identification's ``fit.json``)."""
        return self._doc

    def to_pandas(self):
        """The parameters table (``params.csv``): one row per stage and parameter."""
        return _params_frame(self._rows)

    def figure(self):
        """The last stage's measured displacement against the identified oscillator's."""
        if self._figure is None:
            label = list(self.simulated)[-1]
            curves = [(label, self.simulated[label])]
            self._figure = _figure("identified", "trajectory", self.t, self.measured, curves)
        return self._figure

    def __repr__(self):
        parts = [f"stage {i}: S(μ) = {fmt(s.get('s_mm2'), 4)} mm²" for i, s in
                 enumerate(self.stages, 1)]
        return f"IdentifyResult({'; '.join(parts)}; system {self.system})"

    def _repr_html_(self):
        rows = [[r["model"], r["parameter"], fmt(r["value"], 8), fmt(r["std_error"], 3),
                 r["unit"]] for r in self._rows]
        table = html_table(["stage", "parameter", "value", "std. error", "unit"], rows,
                           "Identified parameters (SI units)")
        stages = "".join(f"<li>stage {i} ({escape(s['record'])}): S(μ) = "
                         f"{fmt(s.get('s_mm2'), 4)} mm²</li>" for i, s in enumerate(self.stages, 1))
        return (f"<div class='stf-lab-result'><h4>Identification</h4><ul>{stages}</ul>{table}"
                f"{_figure_html(self)}</div>")
