"""bench/photoreceptor_figure.py's parser and driver against a stand-in for
accuracy_sweep (rows laid out as accuracy_sweep --bands prints them)."""
import math
import subprocess
import sys
import textwrap

import pytest

from stand_ins import load_script, script_path, sweep_stand_in

SCRIPT = script_path("photoreceptor_figure")
figure = load_script("photoreceptor_figure")

# With all_noise%, the column the sweep added after the scripts were written
# (they read fixed positions from the end, and took med% for the share).
SWEEP_OUTPUT = textwrap.dedent("""\
    scene                                                            share%     med%     p90%  dir_deg   noise% all_noise%
    edges 346x260, 0.6 s, dvs pixels                                  83.53     7.91    41.50     3.27    97.60      88.88
    edges 346x260, 0.6 s, dvs-dim pixels                              79.21     7.09    30.52     3.01    97.40      89.12

    edges 346x260, 0.6 s, dvs pixels, by true lifetime (share of events% in the band first):
      lifetime 0..500 us              16.9%                           45.02    30.17   683.39    27.14        -          -
      lifetime 2000..5000 us          12.9%                           96.90     5.93    17.63     2.69        -          -
      lifetime >= 20000 us             9.6%                           99.90     4.62    12.92     1.90        -          -

    edges 346x260, 0.6 s, dvs-dim pixels, by true lifetime (share of events% in the band first):
      lifetime 0..500 us              14.6%                           20.81   101.49  1918.08    34.20        -          -
    """)


def test_parse_bands_takes_the_rows_of_its_scene_only():
    def same(got, expected):
        assert len(got) == len(expected)
        for g, e in zip(got, expected):
            assert g[:2] == e[:2] and g[2:] == pytest.approx(e[2:])

    same(figure.parse_bands(SWEEP_OUTPUT, "edges 346x260, 0.6 s, dvs pixels"),
         [(0.0, 500.0, 0.4502, 0.3017), (2000.0, 5000.0, 0.969, 0.0593), (20000.0, math.inf, 0.999, 0.0462)])
    same(figure.parse_bands(SWEEP_OUTPUT, "edges 346x260, 0.6 s, dvs-dim pixels"), [(0.0, 500.0, 0.2081, 1.0149)])
    assert figure.parse_bands(SWEEP_OUTPUT, "rotating bar") == []


def test_band_centres_and_time_constant():
    assert figure.band_centre_us(2000.0, 5000.0) == pytest.approx(math.sqrt(2000.0 * 5000.0))
    assert figure.band_centre_us(0.0, 500.0) == pytest.approx(math.sqrt(250.0 * 500.0))
    assert figure.band_centre_us(20000.0, math.inf) == 40000.0
    assert figure.time_constant_us(100.0) == pytest.approx(1591.549, rel=1e-6)



def test_every_cutoff_is_swept_and_printed(tmp_path):
    log = tmp_path / "args.log"
    sweep = sweep_stand_in(tmp_path, textwrap.dedent(f"""\
        import sys
        with open({str(log)!r}, "a") as f:
            f.write(" ".join(sys.argv[1:]) + "\\n")
        sys.stdout.write({SWEEP_OUTPUT!r})
        """))
    out = subprocess.run([sys.executable, SCRIPT, "--sweep", sweep, "--", "--set", "estimator.x=1"],
                         capture_output=True, text=True, check=True).stdout
    calls = log.read_text().splitlines()
    assert calls == [f"--bands --pixel cutoff-hz={c:g} --set estimator.x=1" for c in figure.CUTOFFS_HZ]
    assert out.count("96.90 % with a lifetime") == len(figure.CUTOFFS_HZ)


def test_a_scene_without_band_rows_is_an_error(tmp_path):
    sweep = sweep_stand_in(tmp_path, f"import sys\nsys.stdout.write({SWEEP_OUTPUT!r})\n")
    run = subprocess.run([sys.executable, SCRIPT, "--sweep", sweep, "--scene", "rotating bar"],
                         capture_output=True, text=True)
    assert run.returncode != 0
    assert "no band rows for scene 'rotating bar'" in run.stderr
