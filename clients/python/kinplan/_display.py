"""Notebook display: small HTML tables for results (`_repr_html_`)."""
from __future__ import annotations

import html
from typing import Iterable, Tuple


def html_table(title: str, rows: Iterable[Tuple[str, object]], note: str = "") -> str:
    """A two-column table: `title` as its caption, one (name, value) per row."""
    body = "".join(
        f"<tr><th style='text-align:left'>{html.escape(str(k))}</th>"
        f"<td style='text-align:left'>{html.escape(_fmt(v))}</td></tr>"
        for k, v in rows
    )
    foot = f"<caption style='caption-side:bottom'>{html.escape(note)}</caption>" if note else ""
    return f"<table><caption><b>{html.escape(title)}</b></caption>{body}{foot}</table>"


def _fmt(v: object) -> str:
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)
