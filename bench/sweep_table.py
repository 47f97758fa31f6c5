"""accuracy_sweep's tables read by their column names (share%, noise%, ...):
a column added to the sweep then shifts nothing a script reads (two scripts
read fixed positions from the end and took med% for the share once
all_noise% was added)."""
import subprocess


def run_sweep(script, args):
    """accuracy_sweep's stdout for `args` (its path first); a missing binary or a
    failed run ends the calling script with the sweep's own message."""
    try:
        run = subprocess.run(args, capture_output=True, text=True)
    except OSError as e:
        raise SystemExit(f"{script}: cannot run {args[0]}: {e.strerror} (build it, or give --sweep)")
    if run.returncode != 0:
        raise SystemExit(f"{script}: {' '.join(args)} failed (exit {run.returncode}):\n{run.stderr}")
    return run.stdout


def header_columns(text):
    """The column names of the first header line of accuracy_sweep's output
    (the words after `scene`)."""
    for line in text.splitlines():
        fields = line.split()
        if fields and fields[0] == "scene":
            return fields[1:]
    raise SystemExit("no header line (scene share% ...) in accuracy_sweep's output")


def row_values(line, columns, wanted):
    """(label, [values of the `wanted` columns]) of a scene or band row: its
    last len(columns) words are the columns' values ('-': None), the words
    before them its label."""
    fields = line.split()
    missing = [c for c in wanted if c not in columns]
    if missing or len(fields) <= len(columns):
        raise SystemExit(f"accuracy_sweep's row does not hold the columns {', '.join(wanted)} "
                         f"(header: {' '.join(columns)}): {line.strip()!r}")
    cells = dict(zip(columns, fields[-len(columns):]))
    values = [None if cells[c] == "-" else float(cells[c]) for c in wanted]
    return " ".join(fields[:-len(columns)]), values
