"""How results show themselves in a notebook: small HTML tables and figures.

A :class:`Figure` holds the lab's own picture (the report's SVG and its PNG, drawn by the Rust
side), shows inline in Jupyter — its SVG, as the HTML report does — and saves to a file
(``.svg`` or ``.png`` by extension).
"""

import base64
import os
import re
from html import escape

__all__ = ["Figure", "html_table", "fmt"]


def fmt(value, digits=6):
    """A number for a table: ``digits`` significant digits, ``—`` for None."""
    if value is None:
        return "—"
    if isinstance(value, float):
        return f"{value:.{digits}g}"
    return str(value)


def html_table(columns, rows, caption=None):
    """An HTML table of ``rows`` (lists of cells, already text) under ``columns``."""
    head = "".join(f"<th>{escape(str(c))}</th>" for c in columns)
    body = "".join(
        "<tr>" + "".join(f"<td>{escape(str(cell))}</td>" for cell in row) + "</tr>" for row in rows
    )
    cap = f"<caption>{escape(caption)}</caption>" if caption else ""
    return f'<table class="stf-lab">{cap}<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>'


class Figure:
    """One of the lab's figures: ``svg`` (text) and ``png`` (bytes), the same picture."""

    def __init__(self, name, svg, png):
        self.name = name
        self.svg = svg
        self.png = png

    def save(self, path):
        """Write the figure to ``path``: SVG or PNG by its extension. Returns the path."""
        path = os.fspath(path)
        ext = os.path.splitext(path)[1].lower()
        if ext == ".svg":
            with open(path, "w", encoding="utf-8") as f:
                f.write(self.svg)
        elif ext == ".png":
            with open(path, "wb") as f:
                f.write(self.png)
        else:
            raise ValueError(f"{path}: a figure is saved as .svg or .png")
        return path

    def _repr_svg_(self):
        return self.svg

    def _repr_png_(self):
        return self.png

    def html(self, width="100%"):
        """The SVG inline, for a result's HTML, as the HTML report shows it: sharp at any zoom,
        at its drawing's size (its ``viewBox``, in CSS px; the SVG's width and height state its
        print size in mm), at most ``width``. A figure without an ``<svg>`` element shows its
        PNG."""
        at = self.svg.find("<svg")
        if at < 0:
            data = base64.b64encode(self.png).decode("ascii")
            return (f'<img alt="{escape(self.name)}" style="max-width:{width}" '
                    f'src="data:image/png;base64,{data}"/>')
        svg = self.svg[at:]
        tag = svg[:svg.find(">")]
        size = re.search(r' viewBox="[-\d.]+ [-\d.]+ ([\d.]+) ([\d.]+)"', tag)
        style = f"max-width:{width}; height:auto"
        if size:
            w, h = size.groups()
            style = f"width:{w}px; max-width:{width}; height:auto; aspect-ratio:{w} / {h}"
        return svg.replace("<svg", f'<svg role="img" aria-label="{escape(self.name)}" style="{style}"', 1)

    def __repr__(self):
        return f"Figure({self.name!r}: {len(self.svg)} characters of SVG, {len(self.png)} bytes of PNG)"
