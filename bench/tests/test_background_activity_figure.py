"""bench/background_activity_figure.py against a stand-in for accuracy_sweep
(its table as printed today, with the all_noise% column it once misread)."""
import subprocess
import sys
import textwrap

import pytest

from stand_ins import load_script, script_path, sweep_stand_in

SCRIPT = script_path("background_activity_figure")
figure = load_script("background_activity_figure")

SWEEP_OUTPUT = textwrap.dedent("""\
    scene                                                            share%     med%     p90%  dir_deg   noise% all_noise%
    edges 346x260, 0.6 s, dvs pixels                                  99.81     3.40    11.48     1.52    98.01      88.88
    rotating bar 346x260, 150->1200 deg/s in 0.6 s, dvs pixels        99.99     2.52     7.22     2.12    99.49      98.40
    edges 346x260, 0.6 s, dvs-dim pixels                              95.49     4.91    17.17     2.18    97.77      89.12
    rotating bar 346x260, 150->1200 deg/s in 0.6 s, dvs-dim pixels    96.84     7.05    25.57     4.11    99.28      98.31
    """)


def test_the_share_and_the_noise_are_read_by_their_column_names(tmp_path):
    sweep = sweep_stand_in(tmp_path, f"import sys\nsys.stdout.write({SWEEP_OUTPUT!r})\n")
    rows = figure.sweep(sweep, 1.0, None)
    assert [r[0] for r in rows] == ["edges 346x260, 0.6 s, dvs pixels",
                                    "rotating bar 346x260, 150->1200 deg/s in 0.6 s, dvs pixels",
                                    "edges 346x260, 0.6 s, dvs-dim pixels",
                                    "rotating bar 346x260, 150->1200 deg/s in 0.6 s, dvs-dim pixels"]
    assert [r[1] for r in rows] == pytest.approx([0.9981, 0.9999, 0.9549, 0.9684])
    assert [r[2] for r in rows] == pytest.approx([0.9801, 0.9949, 0.9777, 0.9928])


def test_a_failing_or_missing_sweep_is_said_without_a_traceback(tmp_path):
    sweep = sweep_stand_in(tmp_path, "import sys\nsys.stderr.write('accuracy_sweep: bad --config\\\\n')\nsys.exit(2)\n")
    run = subprocess.run([sys.executable, SCRIPT, "--sweep", sweep], capture_output=True, text=True)
    assert run.returncode != 0
    assert "failed (exit 2)" in run.stderr and "accuracy_sweep: bad --config" in run.stderr
    assert "Traceback" not in run.stderr
    run = subprocess.run([sys.executable, SCRIPT, "--sweep", str(tmp_path / "none")], capture_output=True, text=True)
    assert run.returncode != 0
    assert "cannot run" in run.stderr and "Traceback" not in run.stderr
