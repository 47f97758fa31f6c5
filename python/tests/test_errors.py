"""Errors: Python exceptions carrying the command line's messages."""
import errno
import os
import warnings

import numpy as np
import pytest

import evlife
from conftest import BIN_DTYPE, RECORDINGS, assert_same_events, cli, data


def cli_error(*args):
    """The CLI's message for a failing `evlife process` (its stderr, prefix and notes cut)."""
    r = cli("process", *args, check=False)
    assert r.returncode != 0
    lines = r.stderr.rstrip("\n").split("\n")
    keep = [lines[0]] + [l for l in lines[1:] if not l.startswith("evlife process: ")]
    message = "\n".join(keep)
    for prefix in ("evlife process: configuration error: ", "evlife process: input error: "):
        if message.startswith(prefix):
            return message[len(prefix):]
    raise AssertionError("unexpected CLI message: " + r.stderr)


@pytest.mark.parametrize("key,value,python_value", [
    ("window_size", "4", 4),
    ("outlier_fraction", "0.95", 0.95),
    ("inlier_tolerance_us", "0", 0),
    ("seed", "-1", -1),
    ("regularization", "maybe", "maybe"),
])
def test_bad_option_values_raise_valueerror_with_the_cli_message(key, value, python_value, tmp_path):
    expected = cli_error(data(RECORDINGS["mat"]), "-o", tmp_path / "x.bin",
                         "--set", "estimator.%s=%s" % (key, value))
    with pytest.raises(ValueError) as e:
        evlife.LifetimeEstimator(sensor=(128, 128), **{key: python_value})
    origin = "evlife.LifetimeEstimator(%s=%s)" % (key, value)
    assert str(e.value) == expected.replace("--set estimator.%s=%s" % (key, value), origin)


def test_wrong_types_and_unknown_keywords_raise_typeerror():
    with pytest.raises(TypeError, match="did you mean 'estimator.window_size'"):
        evlife.LifetimeEstimator(sensor=(128, 128), windowsize=5)
    with pytest.raises(TypeError, match="regularization: expected True or False"):
        evlife.LifetimeEstimator(sensor=(128, 128), regularization=1)
    with pytest.raises(TypeError, match="window_size: expected an integer"):
        evlife.LifetimeEstimator(sensor=(128, 128), window_size=5.0)
    with pytest.raises(TypeError, match="sensor"):
        evlife.LifetimeEstimator(sensor=128)
    # None built a 128x128 estimator unsaid (its errors then named a size never given).
    with pytest.raises(TypeError, match=r"sensor=\(width, height\) is required"):
        evlife.LifetimeEstimator(None)
    with pytest.raises(ValueError, match=r"sensor: width and height must be 1..4096, got \(0, 128\)"):
        evlife.LifetimeEstimator(sensor=(0, 128))
    with pytest.raises(TypeError):
        evlife.process(data(RECORDINGS["mat"]), windowsize=5)
    with pytest.raises(TypeError, match=r"^config: expected a path \(str, bytes or os.PathLike\), got int$"):
        evlife.LifetimeEstimator(sensor=(128, 128), config=3)


def test_a_misspelled_keyword_of_the_function_is_named_as_such(tmp_path):
    # Before: "evlife.process() got an unexpected keyword argument 'one_thred': evlife.process:
    # unknown configuration key 'estimator.one_thred'; keys of 'estimator': ..." (process_file's
    # named evlife.process, and sensr= was asked "did you mean 'estimator.seed'?").
    path = data(RECORDINGS["mat"])
    events = np.zeros(1, evlife.EVENT_DTYPE)
    cases = [
        (lambda: evlife.process_file(path, tmp_path / "x.bin", one_thred=True), "process_file", "one_thred",
         "one_thread"),
        (lambda: evlife.process(path, form_s=0.5), "process", "form_s", "from_s"),
        (lambda: evlife.process(events, sensr=(8, 8)), "process", "sensr", "sensor"),
        (lambda: evlife.process(path, time_units="us"), "process", "time_units", "time_unit"),
        (lambda: evlife.LifetimeEstimator((8, 8), confg="c.yaml"), "LifetimeEstimator", "confg", "config"),
    ]
    for call, function, given, meant in cases:
        with pytest.raises(TypeError) as e:
            call()
        assert str(e.value) == "evlife.%s() got an unexpected keyword argument '%s' (did you mean '%s'?)" % (
            function, given, meant)
    assert not (tmp_path / "x.bin").exists()
    # An estimator key's misspelling keeps the configuration's message.
    with pytest.raises(TypeError, match=r"^evlife.process_file\(\) got .*'windowsize'.*did you mean 'estimator.window_size'"):
        evlife.process_file(path, tmp_path / "x.bin", windowsize=5)


def test_reading_functions_name_a_misspelled_keyword_and_an_argument_of_the_wrong_type(tmp_path):
    # Before: pybind11's "read(): incompatible function arguments. The following argument types are
    # supported: 1. (path: os.PathLike, ...) Invoked with: '...'; kwargs: form_s=0.5", naming nothing.
    path = data(RECORDINGS["mat"])
    reader = evlife.open(path)
    misspelled = [
        (lambda: evlife.read(path, form_s=0.5), "read", "form_s", "from_s"),
        (lambda: evlife.open(path, chunk_event=10), "open", "chunk_event", "chunk_events"),
        (lambda: evlife.scan(path, sensr=(8, 8)), "scan", "sensr", "sensor"),
        (lambda: reader.read(max_event=5), "Reader.read", "max_event", "max_events"),
    ]
    for call, function, given, meant in misspelled:
        with pytest.raises(TypeError) as e:
            call()
        assert str(e.value) == "evlife.%s() got an unexpected keyword argument '%s' (did you mean '%s'?)" % (
            function, given, meant)
    with pytest.raises(TypeError) as e:
        evlife.read(path, colour="red")
    assert str(e.value) == "evlife.read() got an unexpected keyword argument 'colour'"
    wrong_types = [
        (lambda: evlife.read(path, from_s="0.5"), TypeError, "evlife.read(): from_s must be a number (seconds), got str '0.5'"),
        (lambda: evlife.read(path, to_s=[1]), TypeError, "evlife.read(): to_s must be a number (seconds), got list [1]"),
        (lambda: evlife.read(path, topic=3), TypeError, "evlife.read(): topic must be a str, got int 3"),
        (lambda: evlife.read(path, polarity=1), TypeError, "evlife.read(): polarity must be a str, got int 1"),
        (lambda: evlife.read(3), TypeError, "evlife.read(): path: expected a path (str, bytes or os.PathLike), got int"),
        (lambda: evlife.open(path, chunk_events="10"), TypeError,
         "evlife.open(): chunk_events must be a whole number (events), got str '10'"),
        (lambda: evlife.open(path, chunk_events=2.5), TypeError,
         "evlife.open(): chunk_events must be a whole number (events), got float 2.5"),
        (lambda: evlife.open(path, chunk_events=-1), ValueError, "evlife.open(): chunk_events must be at least 1, got -1"),
        (lambda: evlife.open(path, time_unit=1), TypeError, "evlife.open(): time_unit must be a str, got int 1"),
        (lambda: evlife.scan(path, topic=3), TypeError, "evlife.scan(): topic must be a str, got int 3"),
        (lambda: reader.read(max_events="5"), TypeError,
         "evlife.Reader.read(): max_events must be a whole number (events), got str '5'"),
        (lambda: reader.read(-1), ValueError, "evlife.Reader.read(): max_events must be at least 1, got -1"),
        (lambda: evlife.process(path, from_s="0.5"), TypeError,
         "evlife.process(): from_s must be a number (seconds), got str '0.5'"),
        (lambda: evlife.process(np.zeros(2, evlife.EVENT_DTYPE), to_s="1"), TypeError,
         "evlife.process(): to_s must be a number (seconds), got str '1'"),
        (lambda: evlife.process_file(path, tmp_path / "x.bin", from_s="0.5"), TypeError,
         "evlife.process_file(): from_s must be a number (seconds), got str '0.5'"),
        # A bool is no number (True passed as 1: from 1 s, 1 event per chunk, a frame at 1 µs, a 1 s scene).
        (lambda: evlife.read(path, from_s=True), TypeError, "evlife.read(): from_s must be a number (seconds), got bool True"),
        (lambda: evlife.open(path, chunk_events=np.bool_(True)), TypeError,
         "evlife.open(): chunk_events must be a whole number (events), got bool_ True"),
        (lambda: reader.read(True), TypeError, "evlife.Reader.read(): max_events must be a whole number (events), got bool True"),
        (lambda: evlife.synth(duration=True), TypeError, "evlife.synth(): duration must be a number (seconds), got bool True"),
        (lambda: evlife.synth(duration=0.01, seed=False), TypeError, "evlife.synth(): seed must be a whole number, got bool False"),
        (lambda: evlife.frame(np.zeros(0, evlife.AUGMENTED_DTYPE), True, (8, 8)), TypeError,
         "frame: t_us is microseconds on the recording's clock (an integer), got True"),
        # A long value is cut short, not printed whole.
        (lambda: evlife.read(path, from_s=np.arange(10000)), TypeError,
         "evlife.read(): from_s must be a number (seconds), got ndarray array([   0,    1,    2, ..., 9997, 9998, 9999])"),
    ]
    for call, error, message in wrong_types:
        with pytest.raises(error) as e:
            call()
        assert str(e.value) == message
    with pytest.raises(TypeError) as e:
        evlife.read(path, topic=["x"] * 100)
    assert len(str(e.value)) < 150 and str(e.value).endswith("...")
    assert not (tmp_path / "x.bin").exists()
    # What pybind11 converted before still passes, as before.
    n = len(evlife.read(path))
    assert len(evlife.read(path, from_s=np.float64(0.0), to_s=np.int64(1000))) == n
    assert len(evlife.read(path, topic=None, time_unit=None, polarity=None)) == n
    with evlife.open(path, None, np.int64(7)) as r:
        assert r.chunk_events == 7 and len(r.read(np.int64(5))) == 5 and len(r.read()) == 7
    with pytest.raises(ValueError, match="^chunk_events must be at least 1$"):
        evlife.open(path, chunk_events=0)
    with pytest.raises(ValueError, match="^max_events must be at least 1$"):
        reader.read(0)
    reader.close()


def test_every_keyword_of_the_signature_is_offered_for_its_misspelling():
    # The C++ lists of each function's keywords (kReadKeywords, ...) are those help() shows: a
    # misspelling of any of them is said to be one (a list behind the signature would drop it).
    path = data(RECORDINGS["mat"])
    reader = evlife.open(path)
    functions = [("read", evlife.read, evlife._evlife.read), ("open", evlife.open, evlife._evlife.open),
                 ("scan", evlife.scan, evlife._evlife.scan), ("Reader.read", reader.read, evlife._evlife.Reader.read),
                 ("synth", evlife.synth, evlife._evlife.synth),
                 ("estimator_options", evlife.estimator_options, evlife._evlife.estimator_options)]
    for name, call, binding in functions:
        signature = binding.__doc__.split("\n")[0]
        parameters = signature[signature.index("(") + 1:signature.rindex(") ->")].split(", ")
        keywords = [p.split(":")[0] for p in parameters if p.split(":")[0] not in ("self", "*", "**kwargs")]
        assert len(keywords) >= 1, signature
        for keyword in keywords:
            with pytest.raises(TypeError) as e:
                call(path, **{keyword + "x": 1}) if name not in ("Reader.read", "synth", "estimator_options") \
                    else call(**{keyword + "x": 1})
            assert str(e.value) == "evlife.%s() got an unexpected keyword argument '%sx' (did you mean '%s'?)" % (
                name, keyword, keyword)
    reader.close()


def test_write_read_augmented_and_the_estimator_name_a_bad_keyword_or_path_without_the_array(tmp_path):
    # Before: pybind11's "write(): incompatible function arguments. ... Invoked with: 3, array([...])"
    # (the array printed), "read_augmented(): incompatible function arguments", Python's "write() got
    # an unexpected keyword argument 'sensr'", and for LifetimeEstimator.process(a, inplace=True) and
    # estimator_options(confg=...) pybind11's message with every argument.
    augmented = evlife.process(data(RECORDINGS["mat"]))
    estimator = evlife.LifetimeEstimator((240, 180))
    cases = [
        (lambda: evlife.write(3, augmented, (240, 180)),
         "evlife.write(): path: expected a path (str, bytes or os.PathLike), got int"),
        (lambda: evlife.write(tmp_path / "x.bin", augmented, sensr=(240, 180)),
         "evlife.write() got an unexpected keyword argument 'sensr' (did you mean 'sensor'?)"),
        (lambda: evlife.read_augmented(3),
         "evlife.read_augmented(): path: expected a path (str, bytes or os.PathLike), got int"),
        (lambda: estimator.process(augmented, inplace=True),
         "evlife.LifetimeEstimator.process() got an unexpected keyword argument 'inplace'"),
        (lambda: evlife.estimator_options(confg="c.yaml"),
         "evlife.estimator_options() got an unexpected keyword argument 'confg' (did you mean 'config'?)"),
    ]
    for call, message in cases:
        with pytest.raises(TypeError) as e:
            call()
        assert str(e.value) == message
    assert not (tmp_path / "x.bin").exists()
    evlife.write(path=tmp_path / "x.bin", augmented=augmented, sensor=(240, 180))
    assert len(evlife.read_augmented(path=tmp_path / "x.bin")[0]) == len(augmented)


def test_a_misspelled_or_missing_required_argument_is_named(tmp_path):
    # Before: pybind11's "read(): incompatible function arguments. The following argument types are
    # supported: 1. (path: os.PathLike, ...) Invoked with: kwargs: pth='...'", naming nothing (the
    # optional arguments' misspellings were named); Python's "frame() missing 1 required positional
    # argument: 't_us'" for frame and write.
    path, out = data(RECORDINGS["mat"]), tmp_path / "x.bin"
    augmented = evlife.process(path)
    estimator = evlife.LifetimeEstimator((240, 180))
    misspelled = [
        (lambda: evlife.read(pth=path), "read", "pth", "path"),
        (lambda: evlife.read(pth=path, from_s=0.5), "read", "pth", "path"),
        (lambda: evlife.open(paht=path, chunk_events=5), "open", "paht", "path"),
        (lambda: evlife.scan(inptu=path), "scan", "inptu", "input"),
        (lambda: evlife.process(inpt=path, window_size=7), "process", "inpt", "input"),
        (lambda: evlife.process_file(path, outpt=out), "process_file", "outpt", "output"),
        (lambda: evlife.read_augmented(pth=out), "read_augmented", "pth", "path"),
        (lambda: evlife.write(out, augmentd=augmented, sensor=(240, 180)), "write", "augmentd", "augmented"),
        (lambda: evlife.frame(augmented, t_u=0), "frame", "t_u", "t_us"),
        (lambda: estimator.process(event=augmented), "LifetimeEstimator.process", "event", "events"),
        (lambda: evlife.LifetimeEstimator(sensr=(8, 8)), "LifetimeEstimator", "sensr", "sensor"),
    ]
    for call, function, given, meant in misspelled:
        with pytest.raises(TypeError) as e:
            call()
        assert str(e.value) == "evlife.%s() got an unexpected keyword argument '%s' (did you mean '%s'?)" % (
            function, given, meant)
    missing = [
        (lambda: evlife.read(), "read", "path"),
        (lambda: evlife.read(sensor=(8, 8), colour="red"), "read", "path"),
        (lambda: evlife.open(chunk_events=5), "open", "path"),
        (lambda: evlife.scan(), "scan", "input"),
        (lambda: evlife.process(window_size=7), "process", "input"),  # an estimator option, not a misspelling
        (lambda: evlife.process_file(path), "process_file", "output"),
        (lambda: evlife.read_augmented(), "read_augmented", "path"),
        (lambda: evlife.write(out, augmented), "write", "sensor"),
        (lambda: evlife.frame(augmented), "frame", "t_us"),
        (lambda: estimator.process(), "LifetimeEstimator.process", "events"),
    ]
    for call, function, name in missing:
        with pytest.raises(TypeError) as e:
            call()
        assert str(e.value) == "evlife.%s() missing required argument '%s'" % (function, name)
    assert not out.exists()
    # The estimator's sensor may come from config= (below): without either, its own message.
    with pytest.raises(TypeError, match=r"^evlife.LifetimeEstimator: sensor=\(width, height\) is required"):
        evlife.LifetimeEstimator(window_size=7)
    # The calls that fit are as before, by position or keyword.
    assert len(evlife.read(path=path)) == len(augmented) == len(estimator.process(events=evlife.read(path)))


def test_too_many_positional_arguments_are_said_as_python_says_them():
    # Before: pybind11's "formats(): incompatible function arguments. The following argument types are
    # supported: 1. () -> list Invoked with: 1", which said neither that formats takes no argument nor
    # how many were given (an argument given twice alike).
    path = data(RECORDINGS["mat"])
    events = evlife.read(path)
    cases = [
        (lambda: evlife.formats(1), "evlife.formats() takes 0 positional arguments but 1 was given"),
        (lambda: evlife.formats(1, 2), "evlife.formats() takes 0 positional arguments but 2 were given"),
        (lambda: evlife.estimator_options(None, 1), "evlife.estimator_options() takes from 0 to 1 positional "
         "arguments but 2 were given"),
        (lambda: evlife.read(path, None, 0.5), "evlife.read() takes from 1 to 2 positional arguments but 3 were given"),
        (lambda: evlife.read_augmented(path, 1), "evlife.read_augmented() takes 1 positional argument but 2 were given"),
        (lambda: evlife.synth("edges", None, 1.0, 1, None, 2), "evlife.synth() takes from 0 to 5 positional arguments "
         "but 6 were given"),
        # An argument given twice: pybind11's message too.
        (lambda: evlife.read(path, path=path), "evlife.read() got multiple values for argument 'path'"),
        (lambda: evlife.process_file(path, "x.bin", output="y.bin"),
         "evlife.process_file() got multiple values for argument 'output'"),
        # A method counts its self, as Python's do.
        (lambda: evlife.LifetimeEstimator((8, 8)).process(events, 1),
         "evlife.LifetimeEstimator.process() takes 2 positional arguments but 3 were given"),
        # A class is called by its name, without self: its count is the call's (it said "takes 2
        # positional arguments but 3 were given" of LifetimeEstimator((8, 8), 1)).
        (lambda: evlife.LifetimeEstimator((8, 8), 1),
         "evlife.LifetimeEstimator() takes from 0 to 1 positional arguments but 2 were given"),
        (lambda: evlife.LifetimeEstimator((8, 8), 1, 2),
         "evlife.LifetimeEstimator() takes from 0 to 1 positional arguments but 3 were given"),
        # The methods that take nothing (pybind11 said "close(): incompatible function arguments").
        (lambda: evlife.LifetimeEstimator((8, 8)).reset(True),
         "evlife.LifetimeEstimator.reset() takes 1 positional argument but 2 were given"),
        (lambda: evlife.open(path).close(1), "evlife.Reader.close() takes 1 positional argument but 2 were given"),
        (lambda: evlife.open(path).close(force=True), "evlife.Reader.close() got an unexpected keyword argument "
         "'force'"),
    ]
    for call, message in cases:
        with pytest.raises(TypeError) as e:
            call()
        assert str(e.value) == message
    assert len(evlife.formats()) > 5


def test_reader_read_with_arguments_that_do_not_fit_is_said_as_python_says_it_and_warns_at_the_callers_line(
        tmp_path):
    # Before: reader.read(1, 2) raised pybind11's "read(): incompatible function arguments. The following
    # argument types are supported: 1. (self: evlife._evlife.Reader, max_events: Optional[int] = None,
    # **kwargs) ...", naming neither the function nor what did not fit.
    import inspect
    path = data(RECORDINGS["mat"])
    pipe = tmp_path / "pipe.mat"
    os.mkfifo(pipe)
    for make in ("file", "pipe"):
        with open(path, "rb") as f:
            payload = f.read()
        if make == "pipe":
            import threading
            writer = threading.Thread(target=lambda: pipe.write_bytes(payload))
            writer.start()
        with evlife.open(path if make == "file" else pipe, from_s=1000.0) as reader:
            cases = [
                (lambda: reader.read(1, 2), "evlife.Reader.read() takes from 1 to 2 positional arguments "
                 "but 3 were given"),
                (lambda: reader.read(1, max_events=2), "evlife.Reader.read() got multiple values for argument "
                 "'max_events'"),
            ]
            for call, message in cases:
                with pytest.raises(TypeError) as e:
                    call()
                assert str(e.value) == message, make
            # The wrapper's warnings stay at the line that called read (Reader._read warns 2 frames up).
            with pytest.warns(RuntimeWarning, match="^evlife.open: no event of") as caught:
                line = inspect.currentframe().f_lineno + 1
                assert len(reader.read()) == 0
            assert (caught[0].filename, caught[0].lineno) == (__file__, line), make
        if make == "pipe":
            writer.join()
    with evlife.open(path) as reader:
        assert len(reader.read(5)) == len(reader.read(max_events=5)) == 5


def test_config_paths_as_bytes_and_pathlike(tmp_path):
    config = tmp_path / "c.yaml"
    config.write_text("estimator:\n  window_size: 7\n")
    for spelling in (str(config), bytes(config), config):  # bytes read as "b'...'" before: not found
        assert evlife.LifetimeEstimator(sensor=(8, 8), config=spelling).options["window_size"] == 7
        assert evlife.estimator_options(config=spelling)["window_size"]["default"] == 7


def test_missing_file_is_filenotfounderror(tmp_path):
    missing = tmp_path / "nope.aedat4"
    expected = cli_error(missing, "-o", tmp_path / "x.bin")
    for call in (evlife.read, evlife.open, evlife.process):
        with pytest.raises(FileNotFoundError) as e:
            call(missing)
        assert str(e.value) == expected
        assert isinstance(e.value, OSError) and e.value.errno == errno.ENOENT
    # An empty name, as Python's open(""): an InputError before (a review's finding).
    for call in (evlife.read, evlife.open, evlife.process):
        with pytest.raises(FileNotFoundError):
            call("")


def test_unknown_format_is_inputerror_with_the_cli_message(tmp_path):
    bad = tmp_path / "noise.aedat"
    bad.write_bytes(b"this is no recording\n" * 10)
    expected = cli_error(bad, "-o", tmp_path / "x.bin")
    with pytest.raises(evlife.InputError) as e:
        evlife.process(bad)
    # The command line's flags it names, said as Python's keywords after it.
    assert str(e.value) == expected + " (in Python --topic is topic=, --time-unit is time_unit=)"
    assert isinstance(e.value, ValueError)
    assert e.value.path == str(bad)


def test_evlifes_own_bin_given_as_a_recording_says_what_reads_it(tmp_path):
    """Before: "unknown event file format" and the list of every format."""
    out = tmp_path / "out.bin"
    evlife.process_file(data(RECORDINGS["mat"]), out)
    expected = cli_error(out, "-o", tmp_path / "x.bin")
    assert "evlife.read_augmented read it" in expected
    for call in (evlife.read, evlife.open, evlife.process, evlife.scan):
        with pytest.raises(evlife.InputError) as e:
            call(out)
        assert str(e.value) == expected
    assert len(evlife.read_augmented(out)) > 0
    bad = tmp_path / "bad.bin"
    bad.write_bytes(b"ZZZZZZZZ" + out.read_bytes()[8:])
    with pytest.raises(evlife.InputError, match="not evlife's .bin: it starts with 'ZZZZZZZZ'"):
        evlife.read_augmented(bad)
    with pytest.raises(evlife.InputError, match="not evlife's .bin: it starts with 'ZZZZZZZZ'"):
        evlife.read(bad)


def test_truncated_file_keeps_the_events_before_the_fault(tmp_path):
    src = data(RECORDINGS["aedat2"])
    cut = tmp_path / "cut.aedat"
    cut.write_bytes(open(src, "rb").read()[:100_001])
    expected = cli_error(cut, "-o", tmp_path / "cli.bin")
    written = np.fromfile(tmp_path / "cli.bin", dtype=BIN_DTYPE, offset=32)
    with pytest.raises(evlife.InputError) as e:
        evlife.process(cut)
    assert str(e.value) == expected
    assert e.value.event_index == len(written) and e.value.byte_offset > 0
    assert_same_events(e.value.partial, written)  # nothing good is lost
    assert e.value.events_written is None  # declared by the stub for every InputError: only process_file's count
    for one_thread in (False, True):  # read ahead (and written behind) or not: the same
        with pytest.raises(evlife.InputError) as e:
            evlife.process(cut, one_thread=one_thread)
        assert str(e.value) == expected
        assert_same_events(e.value.partial, written)
        with pytest.raises(evlife.InputError) as e:
            evlife.process_file(cut, tmp_path / "py.bin", one_thread=one_thread)
        assert str(e.value) == expected
        assert e.value.events_written == len(written)
        assert (tmp_path / "py.bin").read_bytes() == (tmp_path / "cli.bin").read_bytes()
    with evlife.open(cut, chunk_events=10_000_000) as r:
        first = r.read()  # the good events first ...
        assert len(first) == len(written)
        with pytest.raises(evlife.InputError):  # ... the fault next
            r.read()


def test_bad_arrays_name_the_event_and_leave_the_state_unchanged():
    events = evlife.read(data(RECORDINGS["mat"]))
    whole = evlife.process(events, sensor=(128, 128))
    est = evlife.LifetimeEstimator(sensor=(128, 128))
    first = est.process(events[:1000])
    bad = events[1000:2000].copy()
    bad["x"][17] = 500
    with pytest.raises(evlife.InputError, match=r"outside the 128x128 sensor.*event index 17"):
        est.process(bad)
    backwards = events[1000:2000].copy()
    backwards["t"][5] = 0
    with pytest.raises(evlife.InputError, match=r"timestamp goes backwards.*event index 5"):
        est.process(backwards)
    polarity = events[1000:2000].copy()
    polarity["p"][3] = 2
    with pytest.raises(evlife.InputError, match=r"polarity 2.*event index 3"):
        est.process(polarity)
    mixed = events[1000:2000].copy()  # 0/1 and +1/-1 in one array: a mistake upstream
    mixed["p"][:] = 1
    mixed["p"][4], mixed["p"][9] = -1, 0
    with pytest.raises(evlife.InputError, match=r"mixes the 0/1 and \+1/-1 conventions.*event index 9"):
        est.process(mixed)
    huge = {f: events[f][1000:2000].copy() for f in "xyp"}  # an unsigned time past int64: not clamped
    huge["t"] = events["t"][1000:2000].astype(np.uint64)
    huge["t"][7] = np.uint64(2**63)
    with pytest.raises(evlife.InputError, match=r"9223372036854775808 us does not fit.*event index 7"):
        est.process(huge)
    far = {f: events[f][1000:2000].copy() for f in "typ"}  # an unsigned x past int64: named as written
    far["x"] = events["x"][1000:2000].astype(np.uint64)
    far["x"][6] = np.uint64(2**63 + 5)
    with pytest.raises(evlife.InputError, match=r"\(x 9223372036854775813, y .*outside the 128x128 sensor.*event index 6"):
        est.process(far)
    beyond = events[1000:2000].copy()  # labelled noise uncounted before
    beyond["t"][2], beyond["t"][3:] = 2**62, 2**62 + 1  # the last time within the range, then past it
    with pytest.raises(evlife.InputError, match=r"timestamp 4611686018427387905 us is beyond \+-2\^62 us.*event index 3"):
        est.process(beyond)
    wide = {f: events[f][1000:2000].copy() for f in "txy"}  # an unsigned polarity: named as written
    wide["p"] = np.ones(1000, np.uint64)
    wide["p"][8] = np.uint64(2**64 - 1)
    with pytest.raises(evlife.InputError, match=r"polarity 18446744073709551615 is none.*event index 8"):
        est.process(wide)
    rest = est.process(events[1000:])  # as if the bad calls never happened
    assert_same_events(np.concatenate([first, rest]), whole)


def test_arrays_without_integer_t_x_y_p_raise_typeerror():
    est = evlife.LifetimeEstimator(sensor=(128, 128))
    with pytest.raises(TypeError, match="no field 'p'"):
        est.process(np.zeros(3, dtype=[("t", "i8"), ("x", "u2"), ("y", "u2")]))
    # Before: "events: no field 't' (expected an array with fields t, x, y, p, e.g. from evlife.read)" alone,
    # for a DSEC-like array whose fields (ts, polarity) evlife.read takes from a file: what it has is said.
    with pytest.raises(TypeError) as e:
        est.process(np.zeros(3, dtype=[("ts", "i8"), ("x", "u2"), ("y", "u2"), ("polarity", "i1")]))
    assert str(e.value) == ("events: no field 't' (expected an array with fields t, x, y, p, e.g. from evlife.read, "
                            "it has fields ts, x, y, polarity)")
    with pytest.raises(TypeError, match=r"no field 'p' \(.*, it has fields t, x, y, pol\)$"):
        evlife.process({"t": [1], "x": [1], "y": [1], "pol": [1]})
    with pytest.raises(TypeError, match=r"^events: no field 't' \(expected an array with fields t, x, y, p, e.g. "
                                        r"from evlife.read\)$"):
        est.process(np.zeros(3, "i8"))  # no fields at all: nothing more to say
    with pytest.raises(TypeError, match="integer microseconds"):
        est.process(np.zeros(3, dtype=[("t", "f8"), ("x", "u2"), ("y", "u2"), ("p", "i1")]))
    with pytest.raises(ValueError, match="differ in length"):
        est.process({"t": np.zeros(3, "i8"), "x": np.zeros(2, "u2"), "y": np.zeros(3, "u2"),
                     "p": np.ones(3, "i1")})


def test_unwritable_output_is_oserror(tmp_path):
    aug = evlife.process(evlife.read(data(RECORDINGS["mat"]))[:100], sensor=(128, 128))
    # Missing folders are created (as the CLI does); none can be made inside a file.
    (tmp_path / "a_file").write_text("x")
    with pytest.raises(OSError) as e:
        evlife.write(tmp_path / "a_file" / "x.bin", aug, (128, 128))
    assert e.value.errno == errno.ENOTDIR  # as data; str() is the CLI's message
    assert str(e.value).startswith(str(tmp_path / "a_file" / "x.bin") + ": cannot create the folder " +
                                   str(tmp_path / "a_file") + ": Not a directory")
    evlife.write(tmp_path / "new" / "dir" / "x.bin", aug, (128, 128))
    assert (tmp_path / "new" / "dir" / "x.bin").stat().st_size > 0
    with pytest.raises(OSError):
        evlife.write(tmp_path / "x.xyz", aug, (128, 128))


def test_records_the_readers_refuse_are_not_written_nor_drawn(tmp_path):
    aug = evlife.process(evlife.read(data(RECORDINGS["mat"]))[:2000], sensor=(128, 128))
    outside = int(np.argmax((aug["x"] >= 64) | (aug["y"] >= 64)))
    with pytest.raises(evlife.InputError, match=r"outside the 64x64 sensor.*event index %d" % outside):
        evlife.write(tmp_path / "small.bin", aug, (64, 64))
    assert not (tmp_path / "small.bin").exists()
    t = int(aug["t"][-1])
    with pytest.raises(evlife.InputError, match="outside the 64x64 sensor"):
        evlife.frame(aug, t, sensor=(64, 64))
    with pytest.raises(evlife.InputError, match="timestamp goes backwards"):
        evlife.frame(aug[::-1].copy(), t, sensor=(128, 128))


def test_an_event_beyond_any_sensor_is_named_when_the_sensor_is_inferred():
    # The smallest sensor holding the events stops at the largest camera's; the
    # event beyond it is named (x near 2**63 overflowed the size to 0 before).
    for x in (65536, 2**63 - 1):
        events = {"t": np.arange(3), "x": np.array([1, x, 2]), "y": np.zeros(3, "i8"), "p": np.ones(3, "i8")}
        # Named as the CLI names it in a file that states no sensor: it said "outside the 4096x1
        # sensor", a size the user never gave.
        with pytest.raises(evlife.InputError, match=r"event at \(x %d, y 0\) is beyond any camera \(at most 4096 px "
                                                    r"a side\) and no sensor= is given.*event index 1" % x):
            evlife.process(events)
        with pytest.raises(evlife.InputError, match=r"outside the 4096x4096 sensor.*event index 1"):
            evlife.process(events, sensor=(4096, 4096))  # a size given is named as given
    # A bad option is said as such, not blamed on the inferred sensor.
    with pytest.raises(ValueError, match="window_size"):
        evlife.process({"t": np.arange(3), "x": np.arange(3), "y": np.zeros(3, "i8"), "p": np.ones(3, "i8")},
                       window_size=4)


def test_no_event_to_infer_a_sensor_from_is_the_clis_error(tmp_path):
    # evlife.process / scan / process_file take the CLI's rule (io::sensor_size_from_data):
    # a recording of no event is an InputError, not a made-up 1 x 1 sensor.
    empty = tmp_path / "empty.txt"
    empty.write_text("# no events\n")
    message = cli_error(str(empty), "-o", str(tmp_path / "cli.bin"))
    for call in (lambda: evlife.process(empty), lambda: evlife.scan(empty),
                 lambda: evlife.process_file(empty, tmp_path / "py.bin")):
        with pytest.raises(evlife.InputError) as raised:
            call()
        assert str(raised.value) == message
    assert not (tmp_path / "py.bin").exists()


def test_bytes_quoted_from_a_corrupt_file_and_its_name_stay_text(tmp_path):
    # A stray byte in a bad line (or the file's name) made a UnicodeDecodeError
    # of the InputError, losing .partial; the message writes it \xNN.
    bad = tmp_path / b"caf\xe9.txt".decode(errors="surrogateescape")
    bad.write_bytes(b"0.1 1 1 1\n0.2 1 \xff 1\n")
    with pytest.raises(evlife.InputError) as raised:
        evlife.read(bad)
    assert "got '0.2 1 \\xff 1'" in str(raised.value)
    assert raised.value.path == str(bad)
    assert len(raised.value.partial) == 1
    for call in (evlife.process, evlife.scan, evlife.read):  # bytes are a path too (process read them as an array)
        with pytest.raises(evlife.InputError, match="event index 1"):
            call(bytes(bad))


def test_values_an_integer_field_cannot_hold_are_named_not_wrapped():
    aug = np.zeros(3, [("t", "i8"), ("x", "i8"), ("y", "i8"), ("p", "i8"), ("lifetime", "f8"),
                       ("vx", "f8"), ("vy", "f8")])
    aug["t"] = [0, 10, 20]
    aug["x"] = [1, 65541, 2]  # wrapped to 5 before, and drawn
    aug["p"] = 1
    with pytest.raises(evlife.InputError, match=r"event 1 has x = 65541") as raised:
        evlife.frame(aug, 30, sensor=(16, 16))
    assert raised.value.event_index == 1
    floats = aug.astype([(n, "f8") for n in aug.dtype.names])
    with pytest.raises(TypeError, match="field t must hold integers"):
        evlife.frame(floats, 30, sensor=(16, 16))
    with pytest.raises(TypeError, match="scale must be a whole number"):
        evlife.frame(evlife.process(evlife.read(data(RECORDINGS["mat"]))[:100], sensor=(128, 128)), 0, scale=2.5)
    # A review helper's finding: a float64 lifetime beyond float32 became inf on the conversion and was
    # then called "lifetime inf us", a value the array never held.
    aug["x"] = 1
    aug["lifetime"] = [100.0, 200.0, 1e300]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nor NumPy's "overflow encountered in cast"
        with pytest.raises(evlife.InputError, match=r"^augmented: event 2 has lifetime = 1e\+300, beyond float32's "
                                                    r"range \(\+-3\.40282e\+38\) \(event index 2\)$") as raised:
            evlife.frame(aug, 30, sensor=(16, 16))
        assert raised.value.event_index == 2
        aug["lifetime"][2] = -np.inf  # not finite: the record's own check names it, as before
        with pytest.raises(evlife.InputError, match=r"lifetime -inf us"):
            evlife.frame(aug, 30, sensor=(16, 16))


def test_sensors_no_camera_has_are_refused_before_writing(tmp_path):
    aug = np.zeros(1, evlife.AUGMENTED_DTYPE)
    aug["p"] = 1
    for sensor in ((-5, 10), (70000, 70000), (0, 0)):
        with pytest.raises(ValueError, match="sensor: width and height must be 1..4096"):
            evlife.write(tmp_path / "bad.bin", aug, sensor)
        assert not (tmp_path / "bad.bin").exists()


def test_one_path_is_not_a_list_of_recordings(tmp_path):
    with pytest.raises(TypeError, match="a list of recordings, not one path"):
        evlife.batch.process_files(data(RECORDINGS["mat"]), tmp_path)


def test_a_subnormal_option_value_reads_back():
    e = evlife.LifetimeEstimator(sensor=(64, 64), inlier_tolerance_us=1e-320)
    assert e.options["inlier_tolerance_us"] == 1e-320


def test_a_fault_before_the_first_event_gives_an_empty_partial(tmp_path):
    # A ROS bag cut before its first chunk fails as it is opened: .partial is
    # still an array (it was None for evlife.read), as evlife.process gives it.
    bag = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "ros1", "evt3_none.bag")
    cut = tmp_path / "cut.bag"
    cut.write_bytes(open(bag, "rb").read()[:5000])
    for call in (evlife.read, evlife.process):
        with pytest.raises(evlife.InputError) as e:
            call(cut)
        assert "cut.bag" in str(e.value)
        assert e.value.partial is not None and len(e.value.partial) == 0, call.__name__


def test_one_thread_takes_a_bool_only(tmp_path):
    # An API audit's finding: one_thread="no" was pybind11's "incompatible function arguments" printing
    # the whole input array and naming no argument; None and 1 were taken silently.
    events = evlife.read(data(RECORDINGS["mat"]))[:100]
    for value, shown in [("no", "str 'no'"), (None, "NoneType None"), (1, "int 1")]:
        with pytest.raises(TypeError) as e:
            evlife.process(events, (128, 128), one_thread=value)
        assert str(e.value) == "evlife.process(): one_thread must be True or False, got %s" % shown
        with pytest.raises(TypeError, match=r"^evlife.process_file\(\): one_thread must be True or False"):
            evlife.process_file(data(RECORDINGS["mat"]), tmp_path / "x.bin", one_thread=value)
    assert not (tmp_path / "x.bin").exists()
    same = evlife.process(events, (128, 128), one_thread=np.bool_(True))  # a mask's element is a bool too
    assert same.tobytes() == evlife.process(events, (128, 128)).tobytes()


def test_an_estimators_sensor_may_come_from_its_config_alone(tmp_path):
    # Its error said "sensor=(width, height) is required (or a config= file stating estimator.sensor)",
    # but LifetimeEstimator(config=...) was refused: "missing required argument 'sensor'".
    config = tmp_path / "sensor.yaml"
    config.write_text("estimator:\n  sensor:\n    width: 200\n    height: 150\n")
    assert evlife.LifetimeEstimator(config=config).sensor == (200, 150)
    with pytest.raises(TypeError, match=r"sensor=\(width, height\) is required \(or a config= file stating"):
        evlife.LifetimeEstimator()


def test_a_sensor_the_file_overrules_is_warned_of_as_the_cli_does(tmp_path):
    # An audit's finding: evlife.process(path, sensor=...) of a file stating its size ignored the
    # size unsaid (the CLI warns: "--sensor ... ignored: ... states 320x240").
    path = data("aedat4/sample.aedat4")
    with pytest.warns(RuntimeWarning, match=r"evlife.process: sensor=\(640, 480\) ignored: .*sample.aedat4 states "
                                             r"320x240"):
        evlife.process(path, sensor=(640, 480))
    config = tmp_path / "sensor.yaml"
    config.write_text("estimator:\n  sensor:\n    width: 200\n    height: 150\n")
    with pytest.warns(RuntimeWarning, match=r"evlife.process_file: config='s estimator.sensor \(200, 150\) ignored"):
        evlife.process_file(path, tmp_path / "x.bin", config=config)
    import warnings
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        evlife.process(path, sensor=(320, 240))  # the size it states: nothing to say
    assert not [w for w in caught if "ignored" in str(w.message)]
