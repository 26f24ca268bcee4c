"""Campaigns from Python: ``stf-lab campaign`` over many records, run in this process one unit
after another (the same units, study calls and writers as the command line, the same table,
report and ``[global]`` joint fit), into the campaign's output folder.

A :class:`CampaignResult` is read from that folder (``campaign.json`` and ``global.json``), so
the numbers in Python are the files' numbers: ``rows`` (one per model and record, as
``campaign.csv``), ``to_pandas()`` (the rows with conditions and parameters as columns),
``global_fit`` and ``global_params()`` for a ``[global]`` section, and a notebook display.
"""

import json
import os
from html import escape

from . import _stf_lab
from ._display import fmt, html_table

__all__ = ["campaign", "read_campaign", "CampaignResult"]


def campaign(path, out, force=False, progress=None):
    """Run the campaign file ``path`` into the folder ``out`` (``stf-lab campaign PATH --out
    OUT``; units already finished with the same inputs are skipped unless ``force``): a
    :class:`CampaignResult`. A unit that fails raises the command line's error after the table
    is written (read it with :func:`read_campaign`); Ctrl-C stops between units' steps."""
    from .workflows import _progress, _StatusLine

    shown = _progress(progress)
    try:
        texts = _stf_lab.campaign(os.fspath(path), os.fspath(out), force, shown)
    finally:
        if isinstance(shown, _StatusLine):
            shown.done()
    return CampaignResult(out, *texts)


def read_campaign(out):
    """The :class:`CampaignResult` of a campaign folder written earlier (by Python or by
    ``stf-lab campaign``)."""
    return CampaignResult(out, *_stf_lab.read_campaign(os.fspath(out)))


class CampaignResult:
    """A campaign's table (``campaign.json``) and ``[global]`` joint fit (``global.json``).

    ``rows``: one dict per model and record (``unit``, ``record``, ``command``, ``model``,
    ``status``, ``rms``, ``conditions``, ``params`` …); ``units``, ``failed``;
    ``global_fit``: the joint fit's JSON (``None`` without ``[global]``) and ``verdict``."""

    def __init__(self, out, campaign_text, global_text=None):
        self.out = os.fspath(out)
        self._doc = json.loads(campaign_text)
        self.global_fit = json.loads(global_text) if global_text else None
        self.rows = self._doc["rows"]
        self.units = self._doc["units"]
        self.failed = self._doc["failed"]
        self.conditions = self._doc["conditions"]

    @property
    def verdict(self):
        """The joint fit's verdict, or how many units ended well."""
        if self.global_fit is not None:
            return self.global_fit["verdict"]
        return f"{self.units - self.failed} of {self.units} unit(s) ran; {self.failed} failed."

    def to_dict(self):
        """``campaign.json`` as written, with ``global.json`` under ``"global"`` when there is one."""
        doc = dict(self._doc)
        if self.global_fit is not None:
            doc["global"] = self.global_fit
        return doc

    def to_pandas(self):
        """The campaign's rows: one per model and record; each condition a column, each
        parameter two (``K``, ``K_se``)."""
        import pandas as pd

        flat = []
        for row in self.rows:
            r = {k: v for k, v in row.items() if k not in ("conditions", "params", "warnings", "effects")}
            r["warnings"] = ", ".join(row.get("warnings") or [])
            if row.get("effects") is not None:
                r["effects"] = ", ".join(row["effects"])
            for name, value in (row.get("conditions") or {}).items():
                r[f"condition {name}" if name in r else name] = value
            for name, p in (row.get("params") or {}).items():
                r[name] = p["value"]
                r[f"{name}_se"] = p["std_error"]
            flat.append(r)
        return pd.DataFrame(flat)

    def global_params(self):
        """The joint fit's parameters (name, role, value, std_error) as a DataFrame; ``None``
        without ``[global]``."""
        if self.global_fit is None:
            return None
        import pandas as pd

        return pd.DataFrame(self.global_fit["params"])

    def __repr__(self):
        return (f"CampaignResult({self.out}: {self.units} unit(s), {len(self.rows)} row(s), "
                f"{self.failed} failed)\n  {self.verdict}")

    def _repr_html_(self):
        parts = [f"<div class='stf-lab-result'><h4>Campaign: {escape(self.out)}</h4>",
                 f"<p>{escape(self.verdict)}</p>"]
        if self.global_fit is not None:
            rows = [[p["name"], p["role"], fmt(p["value"], 8), fmt(p["std_error"], 3)]
                    for p in self.global_fit["params"]]
            parts.append(html_table(["parameter", "role", "value", "std. error"], rows,
                                    f"Joint fit of {self.global_fit['model']} over the records"))
        shown = self.rows[:20]
        rows = [[r["unit"], r["record"], r.get("model") or "—", r["status"],
                 f"{fmt(r.get('rms'), 4)} {r.get('rms_unit') or ''}"] for r in shown]
        more = f" (first {len(shown)} of {len(self.rows)})" if len(self.rows) > len(shown) else ""
        parts.append(html_table(["unit", "record", "model", "status", "RMS"], rows,
                                f"Units{more}"))
        parts.append("</div>")
        return "".join(parts)
