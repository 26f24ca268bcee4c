"""The lab's workflows from Python: simulate, fit (the oscillator's staged identification
too), compare, discover — the study layer's calls, as the command line makes them. Each takes an :class:`stf_lab.Experiment` (or an experiment file's path), runs
in process what the command line runs — the same calls, the same numbers — and writes
nothing. Long runs release the GIL; Ctrl-C or the notebook's stop button raises
:class:`stf_lab.Interrupted`. ``progress`` is a callable taking ``(status, elapsed_s)``,
called at the start and about ten times a second; ``progress=True`` prints a status line.
"""

import sys

from . import _stf_lab
from .experiment import as_experiment
from .record import Record
from .results import CompareResult, DiscoveryResult, FitResult, IdentifyResult

__all__ = ["simulate", "fit", "identify", "compare", "discover"]


class _StatusLine:
    """``progress=True``: the status and the time on one line of stderr, rewritten in place."""

    def __init__(self):
        self.last = None

    def done(self):
        if self.last is not None:
            sys.stderr.write("\n")
            sys.stderr.flush()

    def __call__(self, status, elapsed):
        text = f"{status}  [{elapsed:.0f} s]"
        if text != self.last:
            sys.stderr.write("\r" + text.ljust(len(self.last or "")))
            sys.stderr.flush()
            self.last = text


def _progress(progress):
    if progress is True:
        return _StatusLine()
    return progress or None


def _call(function, path, text, progress):
    """``function(path, text, progress)`` with a status line ended when it returns or fails."""
    progress = _progress(progress)
    try:
        return function(path, text, progress)
    finally:
        if isinstance(progress, _StatusLine):
            progress.done()


def _args(experiment):
    exp = as_experiment(experiment)
    return exp, exp.path, exp.text if exp.built else None


def simulate(experiment, progress=None):
    """The synthetic record of the experiment's ``[simulate]`` section (``stf-lab simulate``
    without its files): the oscillator with the hidden ``truth`` models, the rig's sensors."""
    exp, path, text = _args(experiment)
    return Record(_call(_stf_lab.simulate, path, text, progress))


def fit(experiment, progress=None):
    """Fit every model of the experiment to its record (``stf-lab fit``): a :class:`FitResult`
    (force or trajectory level, as the record and ``[fit] level`` say; each model scored on
    ``[validate]``'s second record when there is one). An experiment of ``[[identify]]``
    stages is identified instead (:func:`identify`)."""
    exp, path, text = _args(experiment)
    if exp.has_stages:
        return IdentifyResult(_call(_stf_lab.identify, path, text, progress), exp)
    return FitResult(_call(_stf_lab.fit, path, text, progress), exp)


def identify(experiment, progress=None):
    """The oscillator's staged identification of ``[[identify]]`` (``stf-lab fit`` on such an
    experiment): an :class:`IdentifyResult`."""
    exp, path, text = _args(experiment)
    return IdentifyResult(_call(_stf_lab.identify, path, text, progress), exp)


def discover(experiment, progress=None):
    """Find, name and add the effect the ``[discover] base`` misses (``stf-lab discover``): a
    :class:`DiscoveryResult`."""
    exp, path, text = _args(experiment)
    return DiscoveryResult(_call(_stf_lab.discover, path, text, progress), exp)


def compare(experiment, progress=None):
    """Fit, then compare the models regime by regime (``stf-lab compare``): a
    :class:`CompareResult`."""
    exp, path, text = _args(experiment)
    return CompareResult(_call(_stf_lab.compare, path, text, progress), exp)
