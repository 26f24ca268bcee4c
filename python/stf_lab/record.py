"""Records: the rig's time series (t, x, and phi, f_stf, omega, u where present), in SI units.

Read one from a file (CSV or MATLAB ``.mat``, laid out as the data contract says or as an
experiment's ``[data]`` keys say), or build one from numpy arrays with their units and a
sample rate. The columns are read-only float64 numpy arrays that own the buffers the Rust
reader filled (no copy on the way). ``Record.to_pandas()`` gives a DataFrame.
"""

import json
import os

import numpy as np

from . import _stf_lab
from ._display import html_table

__all__ = ["Record", "read_record"]

#: The signals of the data contract, in order, with their SI units.
SIGNALS = (
    ("t", "s"),
    ("x", "m"),
    ("phi", "rad"),
    ("f_stf", "N"),
    ("omega", "rad/s"),
    ("u", "N"),
)


def _frozen(a):
    if a is None:
        return None
    a = np.asarray(a)
    a.flags.writeable = False
    return a


class Record:
    """A record in SI units: ``t`` (s), ``x`` (m), and ``phi`` (rad), ``f_stf`` (N),
    ``omega`` (rad/s), ``u`` (N) or ``None`` where absent; ``source`` says where it came from.

    Build one with :func:`read_record`, :meth:`Record.from_arrays` or :func:`stf_lab.simulate`.
    """

    def __init__(self, columns):
        self.source = columns.get("source", "(memory)")
        summary = columns.get("summary")
        #: For a simulated record: the run's summary as ``stf-lab simulate``'s sidecar states
        #: it (``peak_x_m``, ``peak_omega_rad_s``, ``breakaway_omega_rad_s``, …); else None.
        self.summary = json.loads(summary) if summary else None
        for name, _ in SIGNALS:
            setattr(self, name, _frozen(columns.get(name)))

    @classmethod
    def from_arrays(cls, t=None, x=None, *, phi=None, f_stf=None, omega=None, u=None,
                    rate=None, t0=0.0, units=None, gains=None, per_rev=None):
        """A record from arrays: ``x`` and either ``t`` or a sample ``rate`` (Hz, from ``t0``).

        ``units`` maps a signal to the unit it is given in (``{"x": "mm", "phi": "deg"}``;
        the names of an experiment's ``[data] units``: s/ms/us, m/mm/um, rad/deg/counts,
        rad/s/rpm/Hz, N/mN, and V with ``gains``, counts with ``per_rev``); the rest are SI.
        The record is checked as a file's would be (equal lengths, finite values, increasing
        t): a :class:`stf_lab.RecordError` says what and where.
        """
        given = {"t": t, "x": x, "phi": phi, "f_stf": f_stf, "omega": omega, "u": u}
        columns = {k: np.ascontiguousarray(v, dtype=np.float64) for k, v in given.items()
                   if v is not None}
        return cls(_stf_lab.record_from_arrays(columns, units, rate, t0, gains, per_rev))

    def __len__(self):
        return len(self.t)

    @property
    def signals(self):
        """The names of the signals present, in the data contract's order."""
        return [name for name, _ in SIGNALS if getattr(self, name) is not None]

    @property
    def duration(self):
        """The time the record spans, s."""
        return float(self.t[-1] - self.t[0]) if len(self) else 0.0

    @property
    def rate(self):
        """The mean sample rate, Hz (NaN with fewer than two samples)."""
        return (len(self) - 1) / self.duration if len(self) > 1 and self.duration > 0 else float("nan")

    def to_dict(self):
        """The record as a dict of its present signals (numpy arrays) and ``source``."""
        d = {name: getattr(self, name) for name in self.signals}
        d["source"] = self.source
        return d

    def save_csv(self, path):
        """Write the record as a CSV of the data contract (a header row, the present signals
        in SI units, every number in a form that reads back to the same double), so that an
        experiment's ``[data] file`` can name it. Returns the path."""
        path = os.fspath(path)
        columns = np.column_stack([getattr(self, name) for name in self.signals])
        np.savetxt(path, columns, delimiter=",", fmt="%.17g", header=",".join(self.signals),
                   comments="")
        return path

    def to_pandas(self):
        """The record as a pandas DataFrame, one column per present signal (SI units)."""
        import pandas as pd

        return pd.DataFrame({name: getattr(self, name) for name in self.signals})

    def __repr__(self):
        return (f"Record({self.source!r}: {len(self)} samples, {self.duration:.3g} s at "
                f"{self.rate:.4g} Hz; {', '.join(self.signals)})")

    def _repr_html_(self):
        rows = []
        units = dict(SIGNALS)
        for name in self.signals:
            a = getattr(self, name)
            rows.append([name, units[name], f"{a.min():.6g}", f"{a.max():.6g}"])
        head = (f"<p><b>Record</b> {_esc(self.source)}: {len(self)} samples, "
                f"{self.duration:.4g} s at {self.rate:.5g} Hz</p>")
        return head + html_table(["signal", "unit", "min", "max"], rows)


def _esc(text):
    from html import escape

    return escape(str(text))


def read_record(path, experiment=None):
    """Read the record at ``path`` (``.csv`` or ``.mat``, by extension).

    Without ``experiment`` the file follows the data contract (columns ``t, phi, x`` and
    optionally ``f_stf, omega, u`` in SI). With one (an :class:`stf_lab.Experiment`, or the path
    of an experiment file), its ``[data]`` keys say the layout: column names or numbers,
    units, offsets, a sample rate, separators, calibration. Bad input is a
    :class:`stf_lab.RecordError` naming the file, row and column.
    """
    path = os.fspath(path)
    if experiment is None:
        return Record(_stf_lab.read_record(path))
    from .experiment import Experiment

    exp = experiment if isinstance(experiment, Experiment) else Experiment.load(experiment)
    return Record(_stf_lab.read_record(path, exp.path, exp.text))
