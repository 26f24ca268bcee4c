"""How results show themselves in a notebook: small HTML tables and figures.

A :class:`Figure` holds the lab's own picture (the report's SVG and its PNG, drawn by the Rust
side), shows inline in Jupyter and saves to a file (``.svg`` or ``.png`` by extension).
"""

import base64
import os
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
        """An ``<img>`` of the PNG, inline (base64), for a result's HTML."""
        data = base64.b64encode(self.png).decode("ascii")
        return (f'<img alt="{escape(self.name)}" style="max-width:{width}" '
                f'src="data:image/png;base64,{data}"/>')

    def __repr__(self):
        return f"Figure({self.name!r}: {len(self.svg)} characters of SVG, {len(self.png)} bytes of PNG)"
