"""evlife: lifetime and velocity of every event of an event camera, from Python.

The C++ engine of the `evlife` command line (Mueggler et al., ICRA 2015) over
NumPy arrays, with the same results bit for bit:

    import evlife
    events = evlife.read("recording.aedat4")              # t, x, y, p
    augmented = evlife.process(events, sensor=(240, 180))  # + lifetime, vx, vy, prediction_error
    image = evlife.frame(augmented, events["t"][0] + 500_000, sensor=(240, 180))

Reading:    read, open (chunks of bounded size), read_augmented, formats
Estimating: LifetimeEstimator (state across calls), process (path or array),
            process_file (`evlife process IN -o OUT`), scan, estimator_options
Drawing:    frame (the image `evlife render` draws at an instant)
Test data:  synth (the scenes of `evlife synth`, with ground truth per event)
Writing:    write (.bin / .csv / .h5 as `evlife process -o`)
Many files: evlife.batch.process_files, process_slices (Dask distributed)
Errors:     InputError (a ValueError; bad input, with file, event index and
            byte offset), FileNotFoundError, ValueError (bad options), OSError;
            Interrupted (a KeyboardInterrupt: Ctrl-C in a long call, with what
            was done: .partial, .events_processed, .events_written).
Streams:    a named pipe or socket (`<(zcat x.txt.gz)`, /dev/stdin) given to
            read, open, scan, process or process_file is first copied into a
            temporary file in $TMPDIR (the readers read a file's start twice).

Units: t in microseconds (int64), lifetime and prediction_error in
microseconds, vx and vy in pixels per second; lifetime 0 = noise.
"""
import atexit as _atexit
import operator as _operator

import numpy as _np

from ._evlife import (  # noqa: F401  (the public C++ API)
    AUGMENTED_DTYPE,
    EVENT_DTYPE,
    TRUTH_DTYPE,
    InputError,
    Interrupted,
    LifetimeEstimator,
    Reader,
    estimator_options,
    formats,
    open,
    process,
    process_file,
    read,
    read_augmented,
    scan,
    synth,
)
from . import _evlife
from . import _streams
from ._arguments import naming_arguments as _naming_arguments

# Named pipes and sockets as input: read from a temporary copy (_streams.py). Each function says a
# call that does not fit its signature as Python says it (_arguments.py).
read = _streams.reading_streams(read, "path")
scan = _streams.reading_streams(scan, "input")
process = _streams.reading_streams(process, "input")
process_file = _streams.reading_streams(process_file, "input", output="output")
open = _streams.open_reading_streams(open)  # noqa: A001  (evlife.open, as the C++ module names it)
Reader.read = _streams.reader_read
read_augmented = _naming_arguments(read_augmented)
synth = _naming_arguments(synth)
estimator_options = _naming_arguments(estimator_options)
formats = _naming_arguments(formats)
LifetimeEstimator.__init__ = _naming_arguments(LifetimeEstimator.__init__, "LifetimeEstimator.__init__")
LifetimeEstimator.process = _naming_arguments(LifetimeEstimator.process, "LifetimeEstimator.process")
LifetimeEstimator.reset = _naming_arguments(LifetimeEstimator.reset, "LifetimeEstimator.reset")
Reader.close = _naming_arguments(Reader.close, "Reader.close")

__all__ = [
    "AUGMENTED_DTYPE", "EVENT_DTYPE", "TRUTH_DTYPE", "InputError", "Interrupted", "LifetimeEstimator", "Reader",
    "estimator_options", "formats", "frame", "open", "process", "process_file", "read", "read_augmented",
    "scan", "synth", "write", "batch",
]

_FRAME_FIELDS = ("t", "x", "y", "p", "lifetime", "vx", "vy")


def _as_augmented(augmented):
    """The array as a contiguous AUGMENTED_DTYPE array (no copy when it is one)."""
    a = _np.asarray(augmented)
    if a.ndim != 1:  # a record (0-d) raised IndexError
        raise TypeError("augmented: expected a 1-D array of events, got shape %s" % (a.shape,))
    # As the C++ side takes it without a copy: aligned for its int64 t too (a buffer at offset 4 was refused).
    if a.dtype == AUGMENTED_DTYPE and a.flags.c_contiguous and a.ctypes.data % 8 == 0:
        return a
    missing = [f for f in _FRAME_FIELDS if a.dtype.names is None or f not in a.dtype.names]
    if missing:
        raise TypeError("augmented: missing field(s) %s (expected the output of "
                        "evlife.process or evlife.read_augmented)" % ", ".join(missing))
    out = _np.zeros(a.shape[0], dtype=AUGMENTED_DTYPE)
    for name in AUGMENTED_DTYPE.names:
        if name in a.dtype.names:
            out[name] = _fitting_column(a[name], name, AUGMENTED_DTYPE[name])
        elif name == "prediction_error":
            out[name] = _np.nan
    return out


def _fitting_column(column, name, target):
    # NumPy's assignment wraps (x = 65541 becomes 5), truncates (x = 3.7
    # becomes 3) and overflows (a float64 lifetime of 1e300 becomes float32's
    # inf): a field takes values its type holds only.
    if target.kind == "f":
        if column.dtype.kind == "f" and column.dtype.itemsize > target.itemsize:
            high = float(_np.finfo(target).max)
            outside = _np.flatnonzero(_np.isfinite(column) & (_np.abs(column) > high))
            if outside.size:
                i = int(outside[0])
                _raise_field_error(i, "%s = %g, beyond %s's range (+-%g)" % (name, float(column[i]), target, high))
        return column
    if column.dtype.kind not in "iub":
        raise TypeError("augmented: field %s must hold integers (%s), got %s" % (name, target, column.dtype))
    info = _np.iinfo(target)
    outside = _np.flatnonzero((column < info.min) | (column > info.max))
    if outside.size:
        i = int(outside[0])
        _raise_field_error(i, "%s = %d, outside %s's range [%d, %d]" % (name, int(column[i]), target, info.min,
                                                                      info.max))
    return column


def _raise_field_error(i, what):
    error = InputError("augmented: event %d has %s (event index %d)" % (i, what, i))
    error.path, error.byte_offset, error.event_index, error.partial = "augmented", -1, i, None
    raise error


@_naming_arguments
def frame(augmented, t_us, sensor=None, mode="lifetime", *, color="lifetime", scale=None,
          caption=True, legend=True, thinning=True, lifetime_range_ms=(0.3, 30.0)):
    """The frame `evlife render` draws at instant t_us, as an RGB image.

    augmented: the output of evlife.process (or any array with t, x, y, p,
    lifetime, vx, vy fields), in time order.
    t_us: the instant, microseconds on the recording's clock (e.g.
    augmented["t"][0] + 500_000 is `evlife render --at 0.5`).
    sensor: (width, height); default: the smallest sensor holding every event.
    mode: "lifetime" (the active events), "window:30ms" (a fixed window) or
    "compare" (1 ms window | 30 ms window | lifetime), as `evlife render --mode`.
    color, scale, caption, legend, thinning, lifetime_range_ms: as --color,
    --scale (default 512 / larger sensor side), --no-caption, --no-legend,
    --no-thinning, --lifetime-range.

    Returns a uint8 array of shape (height, width, 3), RGB (the pixels of the
    PNG `evlife render` writes), ready for matplotlib's imshow. A frame larger
    than the memory available raises MemoryError naming its size.
    """
    instant = _whole_microseconds(t_us)
    try:
        low_ms, high_ms = (float(v) for v in lifetime_range_ms)
    except (TypeError, ValueError):
        raise ValueError("frame: lifetime_range_ms must be (MIN, MAX) in milliseconds, got %r"
                         % (lifetime_range_ms,)) from None
    return _evlife._frame(_as_augmented(augmented), instant, sensor, mode, color, scale,
                          caption, legend, thinning, (low_ms, high_ms))  # True or False only: "no" drew the caption


def _whole_microseconds(t_us):
    """t_us as an int; a fraction is refused (0.5 meant as seconds was drawn at 0), so is what is no
    number (None, a text, an array: the float() or pybind11 error named no argument) or lies beyond
    int64 (pybind11's TypeError printed the whole augmented array)."""
    message = "frame: t_us is microseconds on the recording's clock (an integer), got %s"
    if isinstance(t_us, (bool, _np.bool_)):  # True is no instant (it was drawn at t = 1 µs)
        raise TypeError(message % t_us)
    try:
        instant = _operator.index(t_us)
    except TypeError:
        try:
            if isinstance(t_us, (str, bytes)):
                raise TypeError
            value = float(t_us)
        except (TypeError, ValueError):
            raise TypeError(message % _short_repr(t_us)) from None
        if not value.is_integer():
            raise ValueError("frame: t_us is microseconds on the recording's clock, got %r (not whole: seconds? "
                             "augmented['t'][0] + 500_000 is 0.5 s in)" % (t_us,))
        instant = int(value)
    if not -2**63 <= instant < 2**63:
        raise ValueError("frame: t_us = %s is beyond int64 (evlife's time type: microseconds on the "
                         "recording's clock)" % _short_repr(t_us))
    return instant


def _short_repr(value):
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


@_naming_arguments
def write(path, augmented, sensor):
    return _evlife.write(path, _as_augmented(augmented), sensor)


# Any array with the fields of AUGMENTED_DTYPE, as frame() takes: np.concatenate of
# process()'s chunks drops its padding (29-byte records), a slice is strided.
write.__doc__ = _evlife.write.__doc__


def _leave_before_hdf5_crashes():
    # An HDF5 output that failed to close (its OSError was raised) leaves
    # libhdf5 1.10 unable to run its exit handler without a crash (HDF5 issue
    # #2257): flush, say so and leave before it runs, with status 1.
    import os
    import sys
    if _evlife._hdf5_exit_would_loop() and not _evlife._hdf5_exit_would_crash():
        # A file that could not be created (its OSError was raised) leaves
        # libhdf5's exit handler, after this one, printing "HDF5: infinite loop
        # closing library" and a line of FL,FL,...: nothing was lost (no file
        # was made), so that noise goes to /dev/null; the exit status stays
        # the program's.
        sys.stderr.flush()
        os.dup2(os.open(os.devnull, os.O_WRONLY), 2)
        return
    if not _evlife._hdf5_exit_would_crash():
        return
    import logging
    logging.shutdown()
    sys.stdout.flush()
    print("evlife: an HDF5 file failed to close (disk full?); leaving without libhdf5's exit "
          "handler, which would crash", file=sys.stderr, flush=True)
    os._exit(1)


_atexit.register(_leave_before_hdf5_crashes)


def __getattr__(name):  # evlife.batch imports Dask: only when asked for
    if name == "batch":
        import importlib
        return importlib.import_module(__name__ + ".batch")
    raise AttributeError("module 'evlife' has no attribute %r" % name)
