"""The tables a command prints (rich), whole at any console width: `show`, `replace_box`, `lines`."""
from __future__ import annotations


#: what rich puts where it shortens a cell that does not fit the console (`show`)
ELLIPSIS = "…"


def show(table) -> None:
    """Print the rich `table` on standard output with every cell whole: framed if it fits the
    console's width (rich's, the terminal's or COLUMNS; 80 in a pipe or a log), else without its
    frame, else as plain lines (`lines`) — never a number shortened to "-0.597139061…", rich's
    way with a column the width cannot hold."""
    from rich.console import Console

    console = Console()
    for form in (table, replace_box(table)):
        with console.capture() as captured:
            console.print(form)
        if ELLIPSIS not in captured.get():
            console.print(form)
            return
    print("\n".join(lines(table)))


def replace_box(table):
    """`table` without its frame (a copy)."""
    from copy import copy

    frameless = copy(table)
    frameless.box, frameless.show_edge = None, False
    return frameless


def lines(table) -> list[str]:
    """The rich `table` as plain text (`show`): its title, a line per row ("header value" per
    non-empty cell, or the cells of a table without headers), its caption."""
    columns = list(table.columns)
    rows = zip(*(column.cells for column in columns))
    text = [str(table.title)] if table.title else []
    for row in rows:
        if table.show_header:
            text.append("  " + "; ".join(f"{c.header} {v}" for c, v in zip(columns, row) if str(v).strip()))
        else:
            text.append("  ".join(str(v) for v in row))
    return text + ([f"({table.caption})"] if table.caption else [])
