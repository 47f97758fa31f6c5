"""evlife.frame: the pixels of the PNG `evlife render --at` writes."""
import numpy as np
import pytest

import evlife
from conftest import cli, data

PIL_Image = pytest.importorskip("PIL.Image")


def cli_frame(tmp_path, augmented_bin, at_s, *args):
    png = tmp_path / ("frame_%s.png" % at_s)
    cli("render", augmented_bin, "--at", at_s, "-o", png, "-q", *args)
    return np.asarray(PIL_Image.open(png).convert("RGB"))


@pytest.fixture(scope="module")
def stripes(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("frame")
    path = data("reference/stripes.mat")
    cli("process", path, "-o", tmp / "stripes.bin", "-q")
    aug, sensor = evlife.read_augmented(tmp / "stripes.bin")
    return tmp, tmp / "stripes.bin", aug, sensor


@pytest.mark.parametrize("mode,at_s", [("lifetime", "0.5"), ("compare", "0.25"),
                                        ("window:10ms", "1.0")])
def test_frame_equals_cli_render(stripes, mode, at_s):
    tmp, bin_path, aug, sensor = stripes
    expected = cli_frame(tmp, bin_path, at_s, "--mode", mode)
    t_us = int(aug["t"][0]) + int(round(float(at_s) * 1e6))
    image = evlife.frame(aug, t_us, sensor=sensor, mode=mode)
    assert image.dtype == np.uint8 and image.ndim == 3 and image.shape[2] == 3
    assert image.shape == expected.shape
    assert np.array_equal(image, expected)
    assert (image.reshape(-1, 3).max(axis=1) > 0).mean() > 0.01  # something is drawn


def test_frame_options_as_cli_flags(stripes):
    tmp, bin_path, aug, sensor = stripes
    expected = cli_frame(tmp, bin_path, "0.5", "--color", "polarity", "--scale", "2",
                         "--no-caption", "--no-legend", "--no-thinning")
    image = evlife.frame(aug, int(aug["t"][0]) + 500_000, sensor=sensor, color="polarity",
                         scale=2, caption=False, legend=False, thinning=False)
    assert image.shape[1] == 2 * sensor[0]
    assert np.array_equal(image, expected)


def test_frame_moves_with_time_and_rejects_bad_arguments(stripes):
    _, _, aug, sensor = stripes
    t0 = int(aug["t"][0])
    a = evlife.frame(aug, t0 + 300_000, sensor=sensor, caption=False, legend=False)
    b = evlife.frame(aug, t0 + 900_000, sensor=sensor, caption=False, legend=False)
    assert not np.array_equal(a, b)
    with pytest.raises(ValueError):
        evlife.frame(aug, t0, sensor=sensor, mode="sideways")
    with pytest.raises(ValueError):
        evlife.frame(aug, t0, sensor=sensor, color="purple")
    with pytest.raises(ValueError):
        evlife.frame(aug[:0], t0, sensor=sensor)
    with pytest.raises(TypeError, match="lifetime"):
        evlife.frame(evlife.read(data("reference/stripes.mat")), t0, sensor=sensor)
    # As render --lifetime-range: the scale's ends within (0, 1e9] ms (inf drew every edge one colour).
    for bad in ((0.3, float("inf")), (0.3, 1e300), (0.0, 30.0), (30.0, 0.3)):
        with pytest.raises(ValueError, match=r"0 < MIN < MAX <= 1e9, got"):
            evlife.frame(aug, t0, sensor=sensor, lifetime_range_ms=bad)
    assert evlife.frame(aug, t0, sensor=sensor, lifetime_range_ms=(0.3, 1e9)).ndim == 3
    # A review's findings: a range of one number (IndexError), an instant in seconds by mistake
    # (0.5 drawn at t = 0, silently); a whole float and a NumPy integer are instants.
    with pytest.raises(ValueError, match=r"lifetime_range_ms must be \(MIN, MAX\)"):
        evlife.frame(aug, t0, sensor=sensor, lifetime_range_ms=(1,))
    with pytest.raises(ValueError, match="microseconds on the recording's clock, got 0.5"):
        evlife.frame(aug, 0.5, sensor=sensor)
    assert np.array_equal(evlife.frame(aug, float(t0 + 300_000), sensor=sensor, caption=False, legend=False), a)
    assert np.array_equal(evlife.frame(aug, aug["t"][0] + 300_000, sensor=sensor, caption=False, legend=False), a)
    # Before: t_us past int64 raised pybind11's "_frame(): incompatible function arguments" with the whole
    # array printed; None, a text ("5" was drawn at t = 5 us) or an array named no argument.
    for beyond in (2**63, -2**63 - 1, 1e19, np.uint64(2**64 - 1)):
        with pytest.raises(ValueError, match=r"^frame: t_us = \S+ is beyond int64 \(evlife's time type"):
            evlife.frame(aug, beyond, sensor=sensor)
    for no_instant in (None, "5", b"5", aug["t"][:2], [t0]):
        with pytest.raises(TypeError, match=r"^frame: t_us is microseconds on the recording's clock \(an integer\), got"):
            evlife.frame(aug, no_instant, sensor=sensor)
    assert evlife.frame(aug, 2**63 - 1, sensor=sensor).ndim == 3
    assert evlife.frame(aug, np.array(t0), sensor=sensor).ndim == 3  # a 0-d array is a number


def test_a_misspelled_keyword_or_a_mode_of_the_wrong_type_is_named_without_the_array(stripes):
    # Before: pybind11's "_frame(): incompatible function arguments. ... Invoked with: array([...])"
    # (the augmented array printed) for mode=3, and Python's "frame() got an unexpected keyword
    # argument 'scal'" (which it misspells unsaid).
    _, _, augmented, sensor = stripes
    t = int(augmented["t"][0]) + 100_000
    cases = [
        (lambda: evlife.frame(augmented, t, sensor, mode=3), "evlife.frame(): mode must be a str, got int 3"),
        (lambda: evlife.frame(augmented, t, sensor, color=None), "evlife.frame(): color must be a str, got NoneType None"),
        # (an API audit's finding: caption="no" drew the caption, any object having a truth value)
        (lambda: evlife.frame(augmented, t, sensor, caption="no"), "evlife.frame(): caption must be True or False, got "
         "str 'no'"),
        (lambda: evlife.frame(augmented, t, sensor, thinning=0), "evlife.frame(): thinning must be True or False, got "
         "int 0"),
        (lambda: evlife.frame(augmented, t, sensor, scal=2),
         "evlife.frame() got an unexpected keyword argument 'scal' (did you mean 'scale'?)"),
        (lambda: evlife.frame(augmented, t, sensr=sensor), "evlife.frame() got an unexpected keyword argument 'sensr' "
         "(did you mean 'sensor'?)"),
    ]
    for call, message in cases:
        with pytest.raises(TypeError) as e:
            call()
        assert str(e.value) == message
    # A TypeError of the call itself is its own (no keyword is unknown).
    with pytest.raises(TypeError, match="multiple values for argument 't_us'"):
        evlife.frame(augmented, t, t_us=t)
    assert evlife.frame(augmented, t, sensor, "lifetime", color="plain").shape[2] == 3


def test_an_augmented_array_of_0_1_polarity_is_refused_naming_the_convention(stripes):
    # A review helper's finding: bool or 0/1 polarity (as `process` takes it) was "corrupt record: polarity 0"
    # without a word of what it should be.
    _, _, aug, sensor = stripes
    zero_one = aug.copy()
    zero_one["p"] = (aug["p"] > 0).astype(zero_one.dtype["p"])
    with pytest.raises(evlife.InputError, match=r"polarity 0 \(an augmented event's is \+1 or -1\)"):
        evlife.frame(zero_one, int(aug["t"][0]), sensor=sensor)


def test_the_clocks_ends_are_captioned_on_their_side_of_the_first_event():
    # A review helper's finding: t_us - first_t overflowed at -2**63, captioned "t = 9223372036854.771484 s"
    # as 2**63 - 1 is: the two images were equal.
    aug = evlife.process(evlife.read(data("rpg_txt/slider_depth_events_chunk.txt")))
    assert not np.array_equal(evlife.frame(aug, -2**63), evlife.frame(aug, 2**63 - 1))


def _available_memory_bytes():
    with open("/proc/meminfo") as meminfo:
        for line in meminfo:
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    return None


def test_a_frame_larger_than_the_memory_is_refused_naming_its_size():
    # A review helper's finding: OpenCV's "Insufficient memory" came out as a RuntimeError after it
    # tried; `evlife render` refuses such a frame up front (RenderCliTest.AFrameLargerThanTheMemoryIsRefusedUpFront).
    available = _available_memory_bytes()
    if available is None or available > 150e9:
        pytest.skip("this machine has the memory")
    aug = evlife.process(evlife.read(data("rpg_txt/slider_depth_events_chunk.txt")))
    # compare, caption: 3 x (4096 x 32 + 36) px wide, 4096 x 32 + 46 px high, 154.7 GB.
    with pytest.raises(MemoryError, match=r"^frame: a frame of 393324x131118 px needs at least 154\.7 GB, more than "
                                          r"the .* of memory available \(sensor 4096x4096 at scale 32\): lower scale$"):
        evlife.frame(aug, int(aug["t"][0]), sensor=(4096, 4096), mode="compare", scale=32)
