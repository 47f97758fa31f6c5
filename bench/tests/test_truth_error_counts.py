"""bench/truth_error_counts.py on hand-made truth and output rows."""
import importlib.util
import os

import numpy as np
import pytest

SCRIPT = os.path.join(os.path.dirname(__file__), os.pardir, "truth_error_counts.py")
spec = importlib.util.spec_from_file_location("truth_error_counts", SCRIPT)
tec = importlib.util.module_from_spec(spec)
spec.loader.exec_module(tec)

TRUTH = np.array(
    [  # t_us, x, y, noise, lifetime_us, hot
        (60_000, 10, 10, 0, 1000.0, 0),  # within 10 %
        (60_000, 11, 10, 0, 1000.0, 0),  # within 30 %, not 10 %
        (60_000, 12, 10, 0, 1000.0, 0),  # off by 150 %
        (60_000, 13, 10, 0, 1000.0, 0),  # no lifetime
        (60_000, 14, 10, 1, 0.0, 0),  # noise, labelled noise
        (60_000, 15, 10, 1, 0.0, 0),  # noise given a lifetime
        (60_000, 16, 10, 0, 0.0, 1),  # hot pixel: not an edge event
        (10_000, 17, 10, 0, 1000.0, 0),  # warm-up: not scored
        (60_000, 1, 10, 0, 1000.0, 0),  # border: not scored
    ],
    dtype=[("t_us", float), ("x", float), ("y", float), ("noise", float), ("lifetime_us", float), ("hot", float)],
)
OUT = np.array([(1050.0,), (1200.0,), (2500.0,), (0.0,), (0.0,), (900.0,), (0.0,), (5000.0,), (5000.0,)],
               dtype=[("lifetime", float)])


def test_counts_score_edge_events_in_the_region_only():
    c = tec.counts(TRUTH, OUT, 346, 260)
    assert c["edge_events"] == 4
    assert c["with_lifetime"] == pytest.approx(0.75)
    assert c["within_10"] == pytest.approx(0.25)
    assert c["within_30"] == pytest.approx(0.5)
    assert c["off_over_100"] == pytest.approx(0.25)
    assert c["median_error"] == pytest.approx(0.2)
    assert c["noise_labelled_noise"] == pytest.approx(0.5)


def test_rows_of_different_recordings_are_refused():
    with pytest.raises(ValueError, match="not the same recording"):
        tec.counts(TRUTH, OUT[:-1], 346, 260)


def test_main_reads_csvs_and_prints_the_counts(tmp_path, capsys):
    truth_csv = tmp_path / "truth.csv"
    out_csv = tmp_path / "out.csv"
    truth_csv.write_text("t_us,x,y,p,noise,lifetime_us,nx,ny,burst_index,hot\n" + "".join(
        f"{int(r['t_us'])},{int(r['x'])},{int(r['y'])},1,{int(r['noise'])},{r['lifetime_us']},0,0,0,{int(r['hot'])}\n"
        for r in TRUTH))
    out_csv.write_text("x,y,t,p,lifetime,vx,vy,prediction_error\n" + "".join(
        f"0,0,0,1,{r['lifetime']},0,0,\n" for r in OUT))
    tec.main([str(truth_csv), str(out_csv)])
    printed = capsys.readouterr().out
    assert "4 edge events: 75.00 % with a lifetime" in printed
    assert "25.00 % off by more than 100 %" in printed
