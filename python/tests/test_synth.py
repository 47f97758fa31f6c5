"""evlife.synth: the scenes of `evlife synth` with their ground truth."""
import numpy as np
import pytest

import evlife

from conftest import cli


def test_textured_equals_the_command_line(tmp_path):
    out = tmp_path / "texture.txt"
    cli("synth", "-o", out, "--scene", "textured", "--sensor", "120x120", "--duration", "0.2",
        "--seed", "4", "--refractory-us", "400", "--quiet")
    events, truth, features = evlife.synth("textured", sensor=(120, 120), duration=0.2, seed=4,
                                           refractory_us=400)
    assert events.dtype == evlife.EVENT_DTYPE and truth.dtype == evlife.TRUTH_DTYPE
    assert len(events) == len(truth) > 1000
    assert len(features) == 4 and features[0].startswith("texture tile 0")
    written = evlife.read(str(out), sensor=(120, 120))
    np.testing.assert_array_equal(written, events)


def test_bars_with_dvs_pixels_equal_the_command_line(tmp_path):
    out = tmp_path / "bars.txt"
    cli("synth", "-o", out, "--scene", "edges-bar", "--sensor", "160x120", "--duration", "0.1",
        "--pixel", "dvs-dim", "--latency-us", "300", "--quiet")
    events, truth, _ = evlife.synth("edges-bar", sensor=(160, 120), duration=0.1, pixel="dvs-dim",
                                    latency_us=300)
    np.testing.assert_array_equal(evlife.read(str(out), sensor=(160, 120)), events)
    assert (truth["burst_index"] > 0).any()


def test_truth_is_consistent_and_deterministic():
    events, truth, features = evlife.synth("mixed", sensor=(128, 128), duration=0.5, seed=3)
    again, truth_again, _ = evlife.synth("mixed", sensor=(128, 128), duration=0.5, seed=3)
    np.testing.assert_array_equal(events, again)
    np.testing.assert_array_equal(truth, truth_again)
    assert np.all(np.diff(events["t"]) >= 0)
    noise = truth["noise"]
    assert noise.any() and (~noise).any()
    assert np.all(truth["lifetime"][noise] == 0)
    assert np.all(truth["lifetime"][~noise] > 0)
    edges = ~noise
    np.testing.assert_allclose(np.hypot(truth["nx"][edges], truth["ny"][edges]), 1.0, atol=1e-9)
    assert truth["feature"][edges].max() < len(features)
    other, _, _ = evlife.synth("mixed", sensor=(128, 128), duration=0.5, seed=4)
    assert len(other) != len(events) or not np.array_equal(other, events)


def test_the_estimator_against_the_truth():
    # The README's use: score your own pipeline (here the estimator) per event.
    events, truth, _ = evlife.synth("edges", sensor=(240, 180), duration=0.4, pixel="dvs")
    out = evlife.process(events, sensor=(240, 180))
    scored = truth["scorable"] & ~truth["noise"] & (truth["margin_px"] >= 2) & (events["t"] > 50_000)
    got = scored & (out["lifetime"] > 0)
    assert got.sum() / scored.sum() > 0.9
    rel = np.abs(out["lifetime"][got] - truth["lifetime"][got]) / truth["lifetime"][got]
    assert np.median(rel) < 0.1


def test_bad_arguments_raise():
    with pytest.raises(ValueError, match="needs pixel='dvs' or 'dvs-dim'"):
        evlife.synth("textured", pixel="ideal")
    with pytest.raises(ValueError, match="expected edges, bar"):
        evlife.synth("stripes")
    with pytest.raises(ValueError, match="latency_us: needs pixel"):
        evlife.synth("bar", latency_us=300)
    with pytest.raises(ValueError, match="threshold"):
        evlife.synth("bar", pixel="dvs", threshold=100)
    with pytest.raises(ValueError, match="contrast"):
        evlife.synth("textured", contrast=0.3)
    with pytest.raises(ValueError, match="duration"):
        evlife.synth("bar", duration=0)
    with pytest.raises(TypeError, match="bogus"):
        evlife.synth("bar", pixel="dvs", bogus=1)
    with pytest.raises(TypeError, match="pixel: expected 'ideal', 'dvs' or 'dvs-dim', got int"):
        evlife.synth("bar", pixel=3)  # pybind's "Unable to cast" RuntimeError named nothing


def test_a_misspelled_keyword_or_an_argument_of_the_wrong_type_is_named():
    # Before: "synth() got an unexpected keyword argument 'duraton'" (which it misspells unsaid), and
    # pybind11's "synth(): incompatible function arguments. ..." for duration="1", seed=1.5, scene=3.
    cases = [
        (lambda: evlife.synth("edges", duraton=1), TypeError,
         "evlife.synth() got an unexpected keyword argument 'duraton' (did you mean 'duration'?)"),
        (lambda: evlife.synth("edges", pixel="dvs", latncy_us=300), TypeError,
         "evlife.synth() got an unexpected keyword argument 'latncy_us' (did you mean 'latency_us'?)"),
        (lambda: evlife.synth("edges", bogus="x"), TypeError, "evlife.synth() got an unexpected keyword argument 'bogus'"),
        (lambda: evlife.synth("edges", duration="1"), TypeError,
         "evlife.synth(): duration must be a number (seconds), got str '1'"),
        (lambda: evlife.synth("edges", seed=1.5), TypeError, "evlife.synth(): seed must be a whole number, got float 1.5"),
        (lambda: evlife.synth("edges", seed=-1), ValueError, "evlife.synth(): seed must be at least 0, got -1"),
        (lambda: evlife.synth(3), TypeError, "evlife.synth(): scene must be a str, got int 3"),
        (lambda: evlife.synth("edges", pixel="dvs", latency_us="300"), TypeError,
         "evlife.synth(): latency_us must be a number, got str '300'"),
        (lambda: evlife.synth("edges", noise_rate=np.zeros(10000)), TypeError,
         "evlife.synth(): noise_rate must be a number, got ndarray array([0., 0., 0., ..., 0., 0., 0.])"),
    ]
    for call, error, message in cases:
        with pytest.raises(error) as e:
            call()
        assert str(e.value) == message
    # What passed before passes as before (NumPy scalars, an int duration).
    a, _, _ = evlife.synth("edges", (32, 32), np.float64(0.05), np.int64(2), noise_rate=np.float32(1))
    b, _, _ = evlife.synth(scene="edges", sensor=(32, 32), duration=0.05, seed=2, noise_rate=1.0)
    assert np.array_equal(a, b)
    assert len(evlife.synth("edges", sensor=(32, 32), duration=1)[0]) > 0


def test_a_scene_larger_than_the_memory_is_a_memory_error_that_says_what_to_lower():
    # 4096 x 4096 pixels x 3600 s x 1e4 Hz = 6.04e14 noise events x 64 bytes (event 16, truth 48),
    # in no machine's memory: refused before any allocation (it failed after a minute of paging).
    with pytest.raises(MemoryError, match=r"sensor 4096x4096, 3600 s, noise_rate 10000 per pixel per second, "
                       r"its background alone 3.87e\+07 GB\): shorten the duration"):
        evlife.synth("mixed", sensor=(4096, 4096), duration=3600, noise_rate=1e4)
