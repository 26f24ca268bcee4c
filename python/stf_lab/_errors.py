"""The exceptions of stf_lab: one small hierarchy, each carrying the command line's message.

Every error the Rust side reports arrives as one of these, with the same one-paragraph
message ``stf-lab`` prints after ``error:`` (the file, line and key where it has them)::

    StfLabError                 anything stf-lab reports (base class)
    ├── RecordError             a record cannot be read or is not usable (file, row, column)
    ├── ExperimentError         an experiment (file or built in Python) is not valid (file, line, key)
    ├── ModelError              a model name, sum or script cannot be resolved or evaluated
    ├── FitError                a fit, comparison or simulation cannot go on
    │   └── DiscoveryError      a discovery cannot go on
    └── Interrupted             Ctrl-C / the notebook's stop button; also a KeyboardInterrupt
"""

__all__ = [
    "StfLabError",
    "RecordError",
    "ExperimentError",
    "ModelError",
    "FitError",
    "DiscoveryError",
    "Interrupted",
]


class StfLabError(Exception):
    """Anything stf-lab reports; ``str(err)`` is the command line's message."""


class RecordError(StfLabError):
    """A record cannot be read or is not usable: the message names the file, row and column."""


class ExperimentError(StfLabError):
    """An experiment is not valid: the message names the file, line and key."""


class ModelError(StfLabError):
    """A model (built-in name, sum or rhai script) cannot be resolved or evaluated."""


class FitError(StfLabError):
    """A fit, comparison or simulation cannot go on."""


class DiscoveryError(FitError):
    """A discovery cannot go on (too few cycles, bad settings, …)."""


class Interrupted(StfLabError, KeyboardInterrupt):
    """The run was stopped (Ctrl-C, the notebook's stop button): no result, nothing written.

    It is a ``KeyboardInterrupt`` too, so code that stops on one stops on this (and, being
    a ``StfLabError``, ``except Exception`` catches it as well).
    """
