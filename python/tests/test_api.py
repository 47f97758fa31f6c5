"""The contract: keywords from config/evlife.yaml, docs, the stub."""
import ast
import os

import numpy as np
import pytest

import evlife
from conftest import data

yaml = pytest.importorskip("yaml")
SOURCE = os.path.join(os.path.dirname(__file__), "..", "..")


def yaml_estimator_keys():
    with open(os.path.join(SOURCE, "config", "evlife.yaml")) as f:
        section = yaml.safe_load(f)["estimator"]
    flat = {}
    for k, v in section.items():
        if isinstance(v, dict) or v is None:  # None: a section of comments (the sensor)
            flat.update({k + "." + kk: vv for kk, vv in (v or {}).items()})
        else:
            flat[k] = v
    return flat


def test_every_estimator_key_of_the_yaml_is_a_keyword_with_its_default():
    keys = yaml_estimator_keys()
    table = evlife.estimator_options()
    # (The key table may hold keys the YAML does not document yet: test_config's job.)
    assert {k for k in keys if not k.startswith("sensor.")} <= set(table)
    for k, v in keys.items():
        if k.startswith("sensor."):
            continue
        assert table[k]["default"] == v, k
        evlife.LifetimeEstimator(sensor=(32, 32), **{k: v})  # accepted as given
    assert {"window_size", "regularization", "seed"} <= set(table)
    # Its allowed text is the rule the estimator checks (it said "[0, 112]", but 1 and, at N = 5, 13 are refused).
    assert table["continuation_min_support"]["allowed"] == "0 or 2..(N^2-1)/2, N = window_size"
    for refused in (1, 13):
        with pytest.raises(ValueError, match="continuation_min_support"):
            evlife.LifetimeEstimator(sensor=(32, 32), continuation_min_support=refused)


def test_config_file_as_cli_config(tmp_path):
    cfg = tmp_path / "my.yaml"
    cfg.write_text("estimator:\n  window_size: 9\n")
    est = evlife.LifetimeEstimator(sensor=(32, 32), config=cfg)
    assert est.options["window_size"] == 9
    assert evlife.estimator_options(cfg)["window_size"]["default"] == 9
    cfg.write_text("estimator:\n  window_size: 8\n")
    with pytest.raises(ValueError, match="my.yaml:2"):
        evlife.LifetimeEstimator(sensor=(32, 32), config=cfg)


def test_help_shows_docstrings():
    for obj in (evlife, evlife.read, evlife.open, evlife.process, evlife.process_file,
                evlife.frame, evlife.LifetimeEstimator, evlife.LifetimeEstimator.process,
                evlife.Reader, evlife.InputError, evlife.estimator_options, evlife.write,
                evlife.read_augmented):
        assert obj.__doc__ and len(obj.__doc__) > 40, obj
    from evlife import batch
    assert "Dask" in batch.__doc__ and batch.process_files.__doc__


def test_stub_lists_every_public_name_and_keyword():
    path = os.path.join(os.path.dirname(evlife.__file__), "__init__.pyi")
    tree = ast.parse(open(path).read())
    names = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    names |= {t.target.id for t in tree.body if isinstance(t, ast.AnnAssign)}
    assert set(evlife.__all__) - {"batch"} <= names
    init = next(n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef) and n.name == "__init__")
    stub_keywords = {a.arg for a in init.args.kwonlyargs} - {"config"}
    assert stub_keywords == set(evlife.estimator_options())


def test_functions_pickle_by_name_and_objects_say_why_not():
    # Dask's client.submit(evlife.read, path) and multiprocessing.Pool.map
    # pickle the function: functools.wraps had named the wrappers
    # evlife._evlife.PyCapsule.read, and the C++ functions cannot be pickled.
    import pickle
    for name in ("read", "open", "scan", "process", "process_file", "read_augmented", "synth",
                 "estimator_options", "formats", "write", "frame"):
        f = getattr(evlife, name)
        assert pickle.loads(pickle.dumps(f)) is f, name
    with pytest.raises(TypeError, match="cannot be pickled"):
        pickle.dumps(evlife.LifetimeEstimator(sensor=(8, 8)))
    with evlife.open(data("reference/garfield.mat")) as reader:
        with pytest.raises(TypeError, match="cannot be pickled"):
            pickle.dumps(reader)


def test_a_readers_path_is_as_os_fsdecode_gives_it(tmp_path):
    import shutil
    name = os.fsdecode(os.path.join(os.fsencode(str(tmp_path)), b"g\xff.mat"))
    shutil.copy(data("reference/garfield.mat"), name)
    with evlife.open(name) as reader:
        assert reader.path == name  # raised UnicodeDecodeError


def test_a_large_estimator_is_made_without_holding_the_gil():
    # Its planes (1.4 GB at 4096x4096) were allocated and zeroed with the GIL held: every other
    # Python thread stopped for the whole call. A thread counting meanwhile now advances.
    import threading
    count, done = [0], threading.Event()

    def counter():
        while not done.is_set():
            count[0] += 1

    thread = threading.Thread(target=counter)
    thread.start()
    try:
        before = count[0]
        estimator = evlife.LifetimeEstimator(sensor=(2048, 2048))
        during = count[0] - before
    finally:
        done.set()
        thread.join()
    del estimator
    assert during > 1000, during


def test_odd_but_valid_inputs_are_taken_and_odd_invalid_ones_named(tmp_path):
    events = evlife.read(data("reference/garfield.mat"))[:5000]
    augmented = evlife.process(events, sensor=(128, 128))
    # A memoryview of the events, as frame and write take one ("no field 't'" before).
    assert evlife.process(memoryview(events), sensor=(128, 128)).tobytes() == augmented.tobytes()
    # An AUGMENTED_DTYPE array only 4-byte aligned (write refused it as not one).
    buffer = np.zeros(augmented.nbytes + 8, dtype=np.uint8)
    shifted = np.ndarray(augmented.shape, dtype=evlife.AUGMENTED_DTYPE, buffer=buffer, offset=4)
    shifted[:] = augmented
    evlife.write(tmp_path / "shifted.bin", shifted, sensor=(128, 128))
    assert evlife.read_augmented(tmp_path / "shifted.bin")[0].tobytes() == augmented.tobytes()
    # One record (0-d) is named, not an IndexError.
    with pytest.raises(TypeError, match="expected a 1-D array"):
        evlife.frame(augmented[0], int(events["t"][100]), sensor=(128, 128))
    # A name with a NUL is the value's fault (it said "expected a path ..., got str").
    import pathlib
    for name in ("rec\0.aedat", b"rec\0.aedat", pathlib.Path("rec\0.aedat"), "\udcff\0x"):
        with pytest.raises(ValueError, match="embedded null byte"):
            evlife.scan(name)
    # read(0) is refused: an empty chunk means the end of the recording.
    with evlife.open(data("reference/garfield.mat")) as reader:
        with pytest.raises(ValueError, match="max_events must be at least 1"):
            reader.read(0)
        assert len(reader.read(10)) == 10


def test_every_public_callable_has_a_signature():
    # An API audit's finding: inspect.signature() raised "no signature found for builtin" for the
    # functions that wrap the C++ ones (functools.wraps of a pybind11 function), and help() showed
    # read(...). Their signature is pybind11's first docstring line, with its defaults.
    import inspect
    for f in (evlife.read, evlife.open, evlife.process, evlife.process_file, evlife.scan, evlife.synth,
              evlife.read_augmented, evlife.estimator_options, evlife.formats, evlife.frame, evlife.write,
              evlife.LifetimeEstimator, evlife.LifetimeEstimator.process, evlife.Reader.read):
        inspect.signature(f)
    open_ = inspect.signature(evlife.open).parameters
    assert open_["chunk_events"].default == 1048576 and open_["from_s"].kind is inspect.Parameter.KEYWORD_ONLY
    assert list(inspect.signature(evlife.LifetimeEstimator).parameters)[:2] == ["sensor", "config"]
    assert inspect.signature(evlife.synth).parameters["scene"].default == "mixed"
