"""Markdown pieces shared by the reports of bench/ (report.py and
scaling_report.py): numbers for tables, tables, target verdicts and the
provenance lines of a CSV."""
import math


def fmt(value):
    """A number for a table: integers as such, else 3 significant digits;
    '-' for nan."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    if float(value).is_integer() and abs(value) < 1e6:
        return str(int(value))
    if abs(value) >= 1000:
        return f"{value:.0f}"
    return f"{value:#.3g}".rstrip(".")


def sci(value):
    """An error for a table: 3 digits in e-format, '-' for nan."""
    return "-" if value is None or math.isnan(value) else f"{value:.3e}"


def table(columns, rows):
    """A markdown table."""
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return lines


def status(measured, limit):
    """"met" or "missed by X%" for a measured value against an upper limit."""
    if measured is None or math.isnan(measured):
        return "not measured"
    return "met" if measured <= limit else f"missed by {100 * (measured / limit - 1):.0f}%"


def provenance(header):
    """One line: date, commit, machine of a CSV header, and whether it is partial."""
    line = (f"Measured {header.get('date', '?')} on {header.get('host', '?')} ({header.get('cores', '?')} cores), "
            f"commit {header.get('commit', '?')} (dirty: {header.get('dirty', '?')}), "
            f"{header.get('elapsed_s', '?')} s in all.")
    if header.get("status") != "complete":
        line += " **Incomplete: the benchmark was interrupted; the table shows what finished.**"
    return line


def commands(header, rows, columns=("command",)):
    """The bench command line and one solver command of each kind."""
    lines = ["Command:", "", f"    {header.get('command', '?')}", ""]
    if rows:
        lines += ["Example of the runs it makes (every run is in the CSV's command column):", ""]
        lines += [f"    {rows[0][c]}" for c in columns if rows[0].get(c)]
        lines.append("")
    return lines
