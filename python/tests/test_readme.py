"""The README's Python example runs as printed (matplotlib without a display)."""
import os
import re

import pytest

from conftest import DATA

README = os.path.join(os.path.dirname(__file__), "..", "..", "README.md")


def test_readme_example_runs(tmp_path, capsys):
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    text = open(README, encoding="utf-8").read()
    block = re.search(r"<!-- python-example.*?-->\n```python\n(.*?)```", text, re.S).group(1)
    code_lines = [l for l in block.splitlines() if l.strip()]
    assert len(code_lines) <= 12  # the short example the README promises
    code = block.replace('"../shared/data/', '"%s/' % DATA)
    exec(compile(code, "README.md", "exec"), {"__name__": "readme"})
    out = capsys.readouterr().out
    assert re.search(r"\d+% of the events have a lifetime", out)
    import matplotlib.pyplot as plt
    image = plt.gca().get_images()[0].get_array()
    assert image.shape[2] == 3 and image.shape[1] > 3 * 128  # the compare frame: 3 panels
    plt.close("all")


def test_io_readmes_numpy_snippet_reads_a_bin_as_read_augmented_does(tmp_path):
    """The `.bin` snippet of io/README.md (NumPy alone, sizes from the header) gives read_augmented's
    events; it hard-coded the 32-byte sizes that its text says not to."""
    import numpy as np
    import evlife
    from conftest import assert_same_events, cli
    text = open(os.path.join(os.path.dirname(README), "io", "README.md"), encoding="utf-8").read()
    block = re.search(r"In NumPy \(`evlife.read_augmented` does it for you\).*?\n```python\n(.*?)```", text, re.S).group(1)
    path = str(tmp_path / "stripes.bin")
    cli("process", os.path.join(DATA, "reference", "stripes.mat"), "-o", path)
    scope = {"np": np, "path": path}
    exec(compile(block, "io/README.md", "exec"), scope)
    expected, sensor = evlife.read_augmented(path)
    assert (int(scope["head"]["width"]), int(scope["head"]["height"])) == sensor
    assert_same_events(scope["events"], expected)
