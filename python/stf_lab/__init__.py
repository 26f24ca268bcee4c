"""stf_lab: a lab for shear-thickening fluid (STF) force models, from Python.

The same lab as the ``stf-lab`` command line, in process::

    import stf_lab
    rec = stf_lab.read_record("experiments/records/power_law_sweep.csv")
    res = stf_lab.fit("experiments/power_law_fit.toml")
    res.best, res.to_pandas()        # the verdict's model, the parameters table
    res                              # in a notebook: verdict, parameters, figure

Records (:func:`read_record`, :meth:`Record.from_arrays`), models (:func:`models`,
:func:`model`), experiments (:class:`Experiment`: a file, or built in code), workflows
(:func:`simulate`, :func:`fit`, :func:`identify`, :func:`compare`, :func:`discover`), campaigns
(:func:`campaign`, :func:`read_campaign`) and the exceptions (:class:`StfLabError` and
its kinds).
"""

from ._errors import (
    DiscoveryError,
    ExperimentError,
    FitError,
    Interrupted,
    ModelError,
    RecordError,
    StfLabError,
)
from ._stf_lab import __version__
from ._display import Figure
from .campaign import CampaignResult, campaign, read_campaign
from .experiment import Experiment
from .models import Model, ParamSpec, model, models
from .record import Record, read_record
from .results import CompareResult, DiscoveryResult, FitResult, IdentifyResult, ModelFit, Param
from .workflows import compare, discover, fit, identify, simulate

__all__ = [
    "__version__",
    "StfLabError",
    "RecordError",
    "ExperimentError",
    "ModelError",
    "FitError",
    "DiscoveryError",
    "Interrupted",
    "Figure",
    "Experiment",
    "Model",
    "ParamSpec",
    "model",
    "models",
    "Record",
    "read_record",
    "FitResult",
    "CompareResult",
    "DiscoveryResult",
    "IdentifyResult",
    "ModelFit",
    "Param",
    "simulate",
    "fit",
    "identify",
    "compare",
    "discover",
    "campaign",
    "read_campaign",
    "CampaignResult",
]
