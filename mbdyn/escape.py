"""Text made safe for the context it lands in: the one place every output escapes names.

Labels given in Python may be any printable text (``names.label_problem``), so a body
called ``</script><script>...`` or ``cost $\\foo{$`` is legal and must reach every output
as the literal text the user typed, never as markup, script or math:

* ``script_json``: a value written into an HTML page's own ``<script>`` block.  JSON does
  not escape ``</``, ``<!--`` or the line separators U+2028/9, so a string could end the
  block and open another; here ``<``, ``>``, ``&`` and those separators become ``\\uXXXX``
  escapes, which JavaScript reads back as the same characters.
  The HTML view writes no text as markup: its viewer shows every text through
  ``textContent``.
* ``mathtext``: text drawn by matplotlib, which reads ``$...$`` as TeX math (an unbalanced
  or unknown command there is an exception): every ``$`` escaped, so no math mode starts.
  Titles, axis and colour-bar labels, tick labels and annotations go through it; the labels
  of plotted lines through ``legend_label``, which also keeps a leading ``_`` in the legend.
* ``spreadsheet_cell``: a text cell of a CSV table; a cell that starts with ``= + - @`` or
  a tab/carriage return is a formula to a spreadsheet (``=HYPERLINK(...)``), so it gets a
  leading apostrophe, as OWASP's CSV-injection advice says.  Numbers are not text cells.
  A text that starts with an apostrophe itself gets one more, so that the escape can be
  undone exactly: ``spreadsheet_text`` (a reader of mbdyn's tables) drops one leading
  apostrophe.
"""
from __future__ import annotations

import json

_SCRIPT_ESCAPES = {"<": "\\u003c", ">": "\\u003e", "&": "\\u0026",
                   "\u2028": "\\u2028", "\u2029": "\\u2029"}


def script_json(value) -> str:
    """``value`` as JSON that cannot end or alter the ``<script>`` element around it."""
    text = json.dumps(value, allow_nan=False)
    return "".join(_SCRIPT_ESCAPES.get(c, c) for c in text)


def mathtext(text) -> str:
    """``text`` for a matplotlib label or title: shown literally, never as TeX math."""
    return str(text).replace("$", r"\$")


def legend_label(text) -> str:
    """``text`` as the label of a plotted line: ``mathtext``, and a leading ``_`` -- which
    matplotlib's legend reads as "leave this line out" -- behind a zero-width space."""
    text = mathtext(text)
    return "\u200b" + text if text.startswith("_") else text


FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")


def spreadsheet_cell(text) -> str:
    """A text cell that a spreadsheet shows as text, never evaluates as a formula."""
    text = str(text)
    return "'" + text if text.startswith(FORMULA_STARTS + ("'",)) else text


def spreadsheet_text(cell) -> str:
    """The text that ``spreadsheet_cell`` made ``cell`` from (its inverse)."""
    cell = str(cell)
    return cell[1:] if cell.startswith("'") else cell
