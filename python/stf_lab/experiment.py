"""Experiments: what to simulate, which record to read and how, which models to fit.

An :class:`Experiment` is an experiment file's text and where it lives — read from a TOML file
(``Experiment.load("experiments/power_law_fit.toml")``) or built in code with the same keys
(``Experiment.build(data="rec.csv", models=["viscous", "power_law + added_mass"])``), which
writes that text. Either way the lab checks it as ``stf-lab`` checks a file: a mistake is an
:class:`stf_lab.ExperimentError` naming the file, line and key (for a built experiment, the
line of :attr:`Experiment.text`).
"""

import math
import os

from . import _stf_lab

__all__ = ["Experiment"]

#: The name a built experiment goes by in messages (in its ``base_dir``).
BUILT_NAME = "(python experiment).toml"

#: Sections in the order an experiment file usually has them.
_ORDER = ("data", "system", "integrator", "filter", "fit", "regimes", "simulate", "discover",
          "validate", "output", "scripts")


def _toml_key(key):
    key = str(key)
    bare = key and all(c.isalnum() or c in "_-" for c in key)
    return key if bare else _toml_value(key)


def _toml_value(v):
    """``v`` as an inline TOML value (str, bool, int, float, list, dict)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
        return repr(v)
    if isinstance(v, (str, os.PathLike)):
        s = os.fspath(v).replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
        return f'"{s}"'
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_toml_key(k)} = {_toml_value(x)}" for k, x in v.items()) + " }"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if hasattr(v, "item"):  # a numpy scalar
        return _toml_value(v.item())
    raise TypeError(f"{v!r}: an experiment value is a number, string, bool, list or dict")


def _model_entry(m):
    """A ``[[models]]`` entry: a spec (``"power_law"``, ``"a + b"``, ``"x.rhai"``), a
    ``(spec, params)`` pair or a dict of the entry's keys (``model`` for the spec)."""
    if isinstance(m, dict):
        entry = dict(m)
        spec = entry.pop("model", None)
    elif isinstance(m, (tuple, list)):
        spec, params = m
        entry = {"params": params} if params else {}
    else:
        spec, entry = m, {}
    if spec is not None:
        terms = [t.strip() for t in os.fspath(spec).split("+")]
        key = "script" if terms[0].endswith(".rhai") else "name"
        head = {key: terms[0]}
        if len(terms) > 1:
            head["plus"] = terms[1:]
        entry = {**head, **entry}
    return entry


def _section_lines(name, body):
    if isinstance(body, (list, tuple)):  # an array of tables
        out = []
        for entry in body:
            out += ["", f"[[{name}]]"] + [f"{_toml_key(k)} = {_toml_value(v)}" for k, v in entry.items()]
        return out
    lines, tables = ["", f"[{name}]"], []
    for k, v in body.items():
        if isinstance(v, (list, tuple)) and v and all(isinstance(e, dict) for e in v) and k == "truth":
            tables.append((f"{name}.{k}", [_model_entry(e) for e in v]))
        else:
            lines.append(f"{_toml_key(k)} = {_toml_value(v)}")
    for sub, entries in tables:
        lines += _section_lines(sub, entries)
    return lines


def _to_toml(sections):
    lines = ["# built by stf_lab.Experiment.build"]
    names = sorted(sections, key=lambda s: _ORDER.index(s) if s in _ORDER else len(_ORDER))
    for name in names:
        lines += _section_lines(name, sections[name])
    return "\n".join(lines) + "\n"


class Experiment:
    """An experiment: its TOML :attr:`text` and its :attr:`path` (relative paths in it start
    from the path's folder; for a built experiment the path names it in messages)."""

    def __init__(self, path, text=None):
        self.path = os.fspath(path)
        self.text = text
        self.built = text is not None
        if text is None:
            with open(self.path, encoding="utf-8") as f:
                self.text = f.read()
        _stf_lab.check_experiment(self.path, text)

    @property
    def has_stages(self):
        """Whether the experiment holds ``[[identify]]`` stages."""
        return any(line.strip().startswith("[[identify]]") for line in self.text.splitlines())

    @classmethod
    def load(cls, path):
        """The experiment file at ``path``, checked (:class:`stf_lab.ExperimentError` if not valid)."""
        return cls(path)

    @classmethod
    def build(cls, base_dir=".", *, models=(), **sections):
        """An experiment from the keys of an experiment file (see docs/experiments.md),
        checked as a file is.

        ``models`` lists the models to fit: names (``"viscous"``), sums
        (``"power_law + added_mass"``), rhai script paths, each alone or as ``(spec, params)``
        with ``params`` as in a file (``{"K": 2.0, "n": {"value": 1.2, "min": 1.0}}``).
        Every other keyword is a section: ``data="rec.csv"`` (or a dict of ``[data]`` keys),
        ``system={...}``, ``fit={...}``, ``simulate={..., "truth": ["power_law"]}``,
        ``discover={"base": "power_law"}``, ``validate="other.csv"``, …. Paths are relative to
        ``base_dir``.
        """
        secs = {}
        for name, body in sections.items():
            if body is None:
                continue
            if name in ("data", "validate") and not isinstance(body, dict):
                body = {"file": os.fspath(body)}
            secs[name] = dict(body)
        if models:
            secs["models"] = [_model_entry(m) for m in models]
        if "simulate" in secs and "truth" in secs["simulate"]:
            secs["simulate"]["truth"] = [
                _model_entry(t) for t in secs["simulate"]["truth"]
            ]
        return cls(os.path.join(os.fspath(base_dir), BUILT_NAME), _to_toml(secs))

    def __repr__(self):
        kind = "built" if self.built else "file"
        return f"Experiment({self.path!r}, {kind}, {len(self.text.splitlines())} lines)"

    def _repr_html_(self):
        from html import escape

        return (f"<p><b>Experiment</b> {escape(self.path)}</p>"
                f"<pre>{escape(self.text)}</pre>")


def as_experiment(experiment):
    """``experiment`` as an :class:`Experiment` (a path is loaded)."""
    if isinstance(experiment, Experiment):
        return experiment
    return Experiment.load(experiment)
